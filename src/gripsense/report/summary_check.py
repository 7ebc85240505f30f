"""What a report reads from a friction result is checked first: a hand-edited ``summary.json``
whose value has the wrong kind (text where a number was, a list where text was, a method that
does not exist) is one line naming the key, never an error from deep inside the report.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from gripsense.errors import InputError

__all__ = ["check_record", "check_summary", "check_summary_file"]

NUMBER, WHOLE, TEXT, FLAG, TEXTS = "a number", "a whole number", "text", "true or false", "a list"

META_KINDS: dict[str, str] = {
    "vehicle": TEXT,
    "method": TEXT,
    "receiver": TEXT,
    "heading_offset_source": TEXT,
    "front_wheels": TEXT,
    "front_axle": TEXT,
    "note": TEXT,
    "epochs_total": WHOLE,
    "epochs_used": WHOLE,
    "epochs_missing_inputs": WHOLE,
    "epochs_aligned": WHOLE,
    "straight_samples": WHOLE,
    "heading_offset_deg": NUMBER,
    "heading_offset_spread_deg": NUMBER,
    "wheels": TEXTS,
}
"""The kind of each ``meta`` entry gripsense writes (others are not read by the report)."""

ROW_KINDS: dict[str, str] = {
    "axle": TEXT,
    "wheel": TEXT,
    "surface": TEXT,
    "slippery": TEXT,
    "fit": TEXT,
    "shape": TEXT,
    "limited_by": TEXT,
    "steering_torque": TEXT,
    "note": TEXT,
    "observable": FLAG,
    "mu": NUMBER,
    "mu_low": NUMBER,
    "mu_high": NUMBER,
    "mu_best": NUMBER,
    "grip_used": NUMBER,
    "grip_used_lower": NUMBER,
    "utilisation_p95": NUMBER,
    "valid_fraction": NUMBER,
    "stiffness_scale": NUMBER,
    "heading_bias_deg": NUMBER,
    "camber_slip_deg_per_g": NUMBER,
    "load_transfer_error": NUMBER,
    "cornering_stiffness_N_per_rad": NUMBER,
    "n": WHOLE,
}
"""The kind of each summary row entry (any other ``n_…`` is a whole number: a count)."""


def _fits(value: Any, kind: str) -> bool:
    if value is None:  # JSON null: a value that is not known (NaN)
        return True
    if kind == TEXT:
        return isinstance(value, str)
    if kind == FLAG:
        return isinstance(value, bool) or (
            isinstance(value, int | float) and not isinstance(value, bool) and value in (0, 1)
        )
    if kind == TEXTS:
        return isinstance(value, list | tuple) and all(isinstance(v, str) for v in value)
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    if kind == WHOLE:
        return not math.isfinite(value) or float(value).is_integer()
    return True


def _axle_number(pair: Any) -> bool:
    """An [axle, number] pair of the record."""
    return (
        isinstance(pair, list)
        and len(pair) == 2
        and isinstance(pair[0], str)
        and _fits(pair[1], NUMBER)
    )


def _check(value: Any, kind: str, where: str, source: str) -> None:
    if hasattr(value, "item") and not isinstance(value, str):  # numpy scalars
        value = value.item()
    if isinstance(value, float) and math.isnan(value):
        value = None
    if not _fits(value, kind):
        raise InputError(
            f"{source}: {where} is {value!r}, but must be {kind}; restore the value gripsense "
            "wrote (or run gripsense friction again)"
        )


def check_summary(
    meta: Mapping[str, Any],
    rows: Sequence[Mapping[str, Any]],
    *,
    unit: str,
    source: str = "summary.json",
) -> None:
    """Check the kind of every value a report reads from a friction summary.

    Parameters
    ----------
    meta : mapping
        The summary's ``meta`` (run description) [-].
    rows : sequence of mapping
        The summary's rows, one per wheel or axle [-].
    unit : str
        ``wheel`` or ``axle``: the rows are ``<unit>s[i]`` in the messages [-].
    source : str
        The file named in the message [-].

    Raises
    ------
    InputError
        Naming the first key whose value has the wrong kind, or a method that does not exist.
    """
    from gripsense.estimate import ESTIMATORS

    if not isinstance(meta, Mapping):
        raise InputError(f"{source}: meta is {meta!r}, but must be a table of entries")
    for key, kind in META_KINDS.items():
        if key in meta:
            _check(meta[key], kind, f"meta.{key}", source)
    method = meta.get("method")
    if method is not None and method not in ESTIMATORS:
        raise InputError(
            f"{source}: meta.method is {method!r}, not a friction method "
            f"({', '.join(sorted(ESTIMATORS))})"
        )
    check_record(meta.get("record"), source)
    for i, row in enumerate(rows):
        if not isinstance(row, Mapping):
            raise InputError(f"{source}: {unit}s[{i}] is {row!r}, but must be a table")
        for key, value in row.items():
            kind = ROW_KINDS.get(str(key), WHOLE if str(key).startswith("n_") else "")
            if kind:
                _check(value, kind, f"{unit}s[{i}].{key}", source)
            elif isinstance(value, Mapping | list | tuple):  # a row holds single values only
                raise InputError(
                    f"{source}: {unit}s[{i}].{key} is {value!r}, but must be a single value; "
                    "restore the value gripsense wrote (or run gripsense friction again)"
                )


def _pair(value: Any) -> bool:
    """``[C, u]``: two numbers (or null: not known)."""
    return value is None or (
        isinstance(value, list | tuple)
        and len(value) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    )


def check_record(record: Any, source: str = "summary.json") -> None:
    """Check the kind of every value of a result's record of its run
    (:meth:`gripsense.estimate.results.FrictionResult.record`): the report states it.

    Parameters
    ----------
    record : Any
        The ``record`` table (None: a result of an earlier version, nothing to check) [-].
    source : str
        The file named in the message [-].

    Raises
    ------
    InputError
        Naming the first entry whose value has the wrong kind.
    """
    if record is None:
        return
    fix = "restore the value gripsense wrote (or run gripsense friction again)"
    if not isinstance(record, Mapping):
        raise InputError(f"{source}: record is {record!r}, but must be a table; {fix}")
    for key in ("source", "receiver"):
        if key in record:
            _check(record[key], TEXT, f"record.{key}", source)
    noise = record.get("noise")
    if noise is not None and not isinstance(noise, Mapping):
        raise InputError(f"{source}: record.noise is {noise!r}, but must be a table; {fix}")
    for key, value in (noise or {}).items():
        if key == "axle_stiffness_rel":  # [[axle, relative 1σ], …] or null
            if value is not None and not (
                isinstance(value, list) and all(_axle_number(p) for p in value)
            ):
                raise InputError(
                    f"{source}: record.noise.{key} is {value!r}, but must be a list of [axle, "
                    f"number] pairs; {fix}"
                )
            continue
        _check(value, NUMBER, f"record.noise.{key}", source)
    stiff = record.get("stiffness") or {}
    if not isinstance(stiff, Mapping):
        raise InputError(f"{source}: record.stiffness is {stiff!r}, but must be a table; {fix}")
    for axle, st in stiff.items():
        for kind in ("declared", "used"):
            v = st.get(kind) if isinstance(st, Mapping) else st
            if not _pair(v):
                raise InputError(
                    f"{source}: record.stiffness.{axle}.{kind} is {v!r}, but must be two "
                    f"numbers [N/rad, relative 1σ]; {fix}"
                )
    cal = record.get("calibration")
    if cal is None:
        return
    if not isinstance(cal, Mapping):
        raise InputError(f"{source}: record.calibration is {cal!r}, but must be a table; {fix}")
    _check(cal.get("file"), TEXT, "record.calibration.file", source)
    _check(cal.get("drives"), WHOLE, "record.calibration.drives", source)
    _check(cal.get("notes"), TEXTS, "record.calibration.notes", source)
    learned = cal.get("learned") or {}
    for axle, v in learned.items() if isinstance(learned, Mapping) else [("", learned)]:
        if not _pair(v) or v is None:
            raise InputError(
                f"{source}: record.calibration.learned.{axle} is {v!r}, but must be two numbers "
                f"[N/rad, relative 1σ]; {fix}"
            )


def check_summary_file(folder: str | Path) -> None:
    """Check a result folder's ``summary.json`` as written on disk (before the reader turns a
    number it cannot read into NaN): :func:`check_summary` of its ``meta`` and rows.

    Parameters
    ----------
    folder : str or Path
        A friction result folder [-].

    Raises
    ------
    InputError
        A file that is not JSON, not a table, or a key whose value has the wrong kind.
    """
    path = Path(folder) / "summary.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return  # the reader says what is missing
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not a JSON file gripsense wrote ({e})") from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: must be a JSON table (meta, axles or wheels)")
    unit = "axle" if "axles" in doc else "wheel"
    rows = doc.get(f"{unit}s", [])
    if not isinstance(rows, list):
        raise InputError(f"{path}: {unit}s is {rows!r}, but must be a list of rows")
    check_summary(doc.get("meta", {}), rows, unit=unit, source=str(path))
    check_record(doc.get("record"), source=str(path))
