"""The one column convention of every table gripsense reads (motion tables, steering,
accelerometer and laser tables, tyre measurements, the named channels of logs): a shared
leaf of :mod:`gripsense.io`, imported by the logs, sensors and tyres rooms alike.

Column mapping: ``{"t": "Time", "vx": "VelForward", "vy": "VelLateral:kmh", ...}`` or the
command-line form ``t=Time,vx=VelForward,vy=VelLateral:kmh,yaw_rate=AngRateZ:dps``; each
reader names its keys (:data:`gripsense.io.sensors.motion.MOTION_QUANTITIES`, …) as
:class:`Quantity` entries.

A unit after a colon converts, with the same words in every command that reads a table
(``friction --table``, ``brake-mu``, ``tyre fit``, ``camber``, ``fit-contact``, ``steering
identify``, ``--steer``): ``s``, ``ms``; ``m/s`` (``mps``), ``km/h`` (``kmh``), ``mph``, ``kn``;
``mps2``, ``g``; ``deg``, ``rad``; ``dps``, ``rps``; ``N``, ``kN``, ``lbf``; ``m``, ``cm``,
``mm``; ``kg``; ``Nm``. A unit must be of the quantity's kind (``slip=beta:kmh`` is an
error). A leading
``-`` flips the sign (``yaw_rate=-YawRate:dps`` for a clockwise-positive source). Without
``--columns``, headers that carry a known name and a unit suffix are mapped by themselves
(``time_s``, ``speed_kmh``, ``slip_deg``, ``yaw_rate_dps``, ``ax_mps2``, ``fz_kN`` …;
:func:`map_table`); every command prints the mapping it used.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.text import read_bytes, read_text

__all__ = [
    "ACCEL_LIMIT",
    "ACCEL_TYPICAL",
    "ROAD_WHEEL_LIMIT",
    "SPEED_LIMIT",
    "TABLE_READERS",
    "UNITS",
    "UNIT_DIMENSIONS",
    "YAW_RATE_LIMIT",
    "Quantity",
    "auto_columns",
    "channel_rows",
    "describe_columns",
    "map_table",
    "numeric_column",
    "parse_columns",
    "read_table",
    "resolve_column",
]

UNITS = {
    "deg": np.pi / 180,
    "rad": 1.0,
    "dps": np.pi / 180,
    "rps": 1.0,
    "mps": 1.0,
    "m/s": 1.0,
    "kmh": 1 / 3.6,
    "km/h": 1 / 3.6,
    "mph": 0.44704,
    "kn": 1852 / 3600,
    "g": G0,
    "mps2": 1.0,
    "s": 1.0,
    "ms": 1e-3,
    "N": 1.0,
    "kN": 1e3,
    "lbf": 4.4482216152605,
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "kg": 1.0,
    "Nm": 1.0,
}
"""Unit word -> factor to SI; the same words in every command's ``--columns``."""

UNIT_DIMENSIONS = {
    **dict.fromkeys(("deg", "rad"), "angle"),
    **dict.fromkeys(("dps", "rps"), "angular rate"),
    **dict.fromkeys(("mps", "m/s", "kmh", "km/h", "mph", "kn"), "speed"),
    **dict.fromkeys(("g", "mps2"), "acceleration"),
    **dict.fromkeys(("s", "ms"), "time"),
    **dict.fromkeys(("N", "kN", "lbf"), "force"),
    **dict.fromkeys(("m", "cm", "mm"), "length"),
    "kg": "mass",
    "Nm": "torque",
}
"""Unit word -> what it measures; a unit is accepted only for a quantity of its kind."""

UNIT_LABELS = {"mps2": "m/s²", "mps": "m/s", "kmh": "km/h", "dps": "deg/s", "rps": "rad/s"}
_SUFFIX_EXAMPLE = {
    "angle": "deg",
    "angular rate": "dps",
    "speed": "kmh",
    "acceleration": "mps2",
    "time": "s",
    "force": "N",
    "length": "mm",
    "mass": "kg",
    "torque": "Nm",
}


@dataclass(frozen=True)
class Quantity:
    """A quantity a command reads from a table column.

    Parameters
    ----------
    dimension : str
        What it measures (a value of :data:`UNIT_DIMENSIONS`): ``"time"``, ``"speed"``,
        ``"angle"`` …; a value without a unit word is in SI (s, m/s, rad …).
    names : tuple of str
        Header names (lower case, before the unit suffix) mapped without being told.
    limit : float, optional
        The largest |value| one sample can plausibly have, in SI [SI]: a larger one says the
        column's declared unit is wrong (degrees declared as ``:rad``), an error that names the
        file, line, column and the unit that would fit (:func:`map_table`).
    typical : float, optional
        The largest plausible median of |value| over the column [SI] (an accelerometer's
        gravity read as 9.81 g).
    meaning : str
        What it is, for messages (``"a road-wheel angle"``).
    """

    dimension: str
    names: tuple[str, ...]
    limit: float | None = None
    typical: float | None = None
    meaning: str = ""


def auto_columns(headers, quantities: dict[str, Quantity]) -> dict[str, str]:
    """A column mapping from headers that carry a known name and a unit suffix (``time_s``,
    ``t_ms``, ``ax_mps2``, ``ay_g``, ``speed_kmh``, ``yaw_rate_dps``, ``fz_kN`` …).

    Parameters
    ----------
    headers : iterable of str
        The table's column names.
    quantities : dict
        Key -> :class:`Quantity`: the names (lower case, without unit) that mean it; the unit
        suffix must be of the quantity's kind.

    Returns
    -------
    dict
        Key -> ``"HEADER:unit"`` for every key found (the first matching header wins).
    """
    out: dict[str, str] = {}
    for h in headers:
        name, _, unit = str(h).rpartition("_")
        if not name or unit not in UNITS:
            continue
        for key, q in quantities.items():
            if key not in out and name.lower() in q.names and UNIT_DIMENSIONS[unit] == q.dimension:
                out[key] = f"{h}:{unit}"
    return out


def describe_columns(mapping: dict[str, tuple[str, float]] | dict[str, str]) -> str:
    """One line saying which column gave which quantity, for the command's output.

    Parameters
    ----------
    mapping : dict
        Key -> ``(column, factor)`` (:func:`parse_columns`) or ``"column[:unit]"``.

    Returns
    -------
    str
        E.g. ``t ← time_s [s], ax ← ax_mps2 [m/s²]``.
    """
    parts = []
    for key, v in mapping.items():
        if isinstance(v, str):
            col, _, unit = v.lstrip("-").rpartition(":") if ":" in v else ("", "", "")
            col = col or v.lstrip("-")
            sign = "−" if v.startswith("-") else ""
            parts.append(
                f"{key} ← {sign}{col}" + (f" [{UNIT_LABELS.get(unit, unit)}]" if unit else "")
            )
        else:
            col, factor = v
            parts.append(f"{key} ← {col} (× {factor:g})")
    return ", ".join(parts)


def _read_csv(path: Path) -> pd.DataFrame:
    text = read_text(path, "file")
    df = pd.read_csv(io.StringIO(text), comment="#")
    # file line of each data row: the header is the first line that is neither blank nor a
    # comment, data rows are the following such lines
    lines = [
        i
        for i, ln in enumerate(text.splitlines(), start=1)
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if len(lines) == len(df) + 1:
        df.attrs["line"] = np.asarray(lines[1:])
    if lines:
        # the header as written: pandas renames a repeated name (x, x.1, x.2)
        first = text.splitlines()[lines[0] - 1]
        names = next(csv.reader([first]), [])
        if len(names) == df.shape[1]:
            df.attrs["header"] = names
            df = _two_row_header(df, names)
    return df


def _two_row_header(df: pd.DataFrame, top: list[str]) -> pd.DataFrame:
    """A header of two rows: each vector's name over its first column (``Velocity,,,``) and
    the components under it (``x,y,z``). Read as the components, each with its vector
    (``attrs["groups"]``), when the second row is text that repeats names and the first has
    blank or repeated cells (a units row under unique names is not such a header).
    """
    if len(df) < 2:
        return df
    second = ["" if pd.isna(v) else str(v).strip() for v in df.iloc[0]]
    if any(v and _is_number(v) for v in second):
        return df
    named = [v for v in second if v]
    top = [t.strip() for t in top]
    if len(set(named)) == len(named) or (all(top) and len(set(top)) == len(top)):
        return df
    groups: list[str] = []
    names: list[str] = []
    g = ""
    for t, c in zip(top, second, strict=True):
        g = t or g
        names.append(c or t)
        groups.append(g if c else "")
    out = df.iloc[1:].reset_index(drop=True)
    seen: dict[str, int] = {}
    labels = []
    for n in names:
        k = seen.get(n, 0)
        seen[n] = k + 1
        labels.append(n if k == 0 else f"{n}.{k}")
    out.columns = labels
    out.attrs = dict(df.attrs)
    out.attrs["header"] = names
    out.attrs["groups"] = groups
    if "line" in df.attrs:
        out.attrs["line"] = np.asarray(df.attrs["line"])[1:]
    return out


def _is_number(v: str) -> bool:
    try:
        float(v)
    except ValueError:
        return False
    return True


TABLE_READERS = {".parquet": pd.read_parquet, ".csv": _read_csv, ".txt": _read_csv}
"""File suffix → reader; other suffixes are read as CSV."""


def read_table(path: str | Path) -> pd.DataFrame:
    """Read a table: ``.parquet``, or CSV (``#`` comment lines); errors name the file.

    Parameters
    ----------
    path : str or Path
        The table file.

    Returns
    -------
    pandas.DataFrame
        The table; for CSV, ``attrs["line"]`` holds each row's line number in the file.
    """
    path = Path(path)
    reader = TABLE_READERS.get(path.suffix.lower(), _read_csv)
    try:
        if reader is not _read_csv:
            read_bytes(path, "file")  # the same clear errors for a missing or unreadable file
        df = reader(path)
    except InputError:
        raise
    except pd.errors.EmptyDataError:
        raise InputError(
            f"{path}: empty table (no header line); give a CSV with a header"
        ) from None
    except (ValueError, pd.errors.ParserError, OSError) as e:
        raise InputError(f"{path}: not a readable table ({e})") from None
    if df.columns.size == 0:
        raise InputError(f"{path}: empty table (no columns)")
    return df


def numeric_column(df: pd.DataFrame, name: str, path: str | Path) -> np.ndarray:
    """Column *name* as floats (empty cells NaN).

    Parameters
    ----------
    df : pandas.DataFrame
        Table from :func:`read_table`.
    name : str
        Column name.
    path : str or Path
        The file, for the message.

    Returns
    -------
    numpy.ndarray
        The values; an :class:`~gripsense.errors.InputError` naming the file, line (or row) and
        column at the first value that is not a number.
    """
    if name not in df.columns:
        raise InputError(f"{path}: no column {name!r} (columns: {list(df.columns)[:20]})")
    v = pd.to_numeric(df[name], errors="coerce")
    bad = v.isna() & df[name].notna()
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0])
        lines = df.attrs.get("line")
        where = f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"
        raise InputError(
            f"{path}: {where}, column {name!r}: {df[name].iloc[row]!r} is not a number"
        )
    return v.to_numpy(float)


def parse_columns(spec: str | dict, keys: dict[str, Quantity]) -> dict[str, tuple[str, float]]:
    """Column mapping -> {key: (column, factor)} (see the module documentation).

    Parameters
    ----------
    spec : str or dict
        ``key=column[:unit]`` pairs (a leading ``-`` on the column flips the sign); in a dict a
        value may also be ``(column, factor)`` with the factor to SI given directly.
    keys : dict
        Key -> :class:`Quantity`: the allowed keys; a unit must be of the quantity's kind.

    Returns
    -------
    dict
        Key -> (column, factor to SI including the sign).
    """
    items = (
        spec.items()
        if isinstance(spec, dict)
        else (part.split("=", 1) for part in spec.split(",") if part.strip())
    )
    out = {}
    for item in items:
        if len(item) != 2:
            raise InputError(f"--columns: {item!r} is not key=column")
        key, col = item[0].strip(), item[1]
        if key not in keys:
            raise InputError(f"--columns: unknown key {key!r}; use {', '.join(keys)}")
        if isinstance(col, tuple):
            out[key] = (col[0], float(col[1]))
            continue
        col = col.strip()
        sign = -1.0 if col.startswith("-") else 1.0
        col = col.lstrip("-")
        factor = 1.0
        if ":" in col:
            col, unit = col.rsplit(":", 1)
            if unit not in UNITS:
                raise InputError(f"--columns: {key}: unknown unit {unit!r}; use {sorted(UNITS)}")
            dim = keys[key].dimension
            if UNIT_DIMENSIONS[unit] != dim:
                fits = sorted(u for u, d in UNIT_DIMENSIONS.items() if d == dim)
                raise InputError(
                    f"--columns: {key}={col}:{unit}: {unit} is a unit of "
                    f"{UNIT_DIMENSIONS[unit]}, but {key} needs a unit of {dim}; use "
                    f"{', '.join(fits)}"
                )
            factor = UNITS[unit]
        out[key] = (col, sign * factor)
    return out


def _spec_dict(spec: str | dict) -> dict[str, str]:
    if isinstance(spec, dict):
        return dict(spec)
    return {k.strip(): v.strip() for k, v in (p.split("=", 1) for p in spec.split(",") if "=" in p)}


_POSITION = re.compile(r"^#(\d+)$")
_NTH = re.compile(r"^(.*)\[(\d+)\]$")


def _vector(header: list[str], j: int, groups: list[str] | None = None) -> str | None:
    """The vector a column of a repeated name belongs to: its name in the header's row of
    vector names (*groups*), else the nearest column before it whose name the header does not
    repeat (``vel`` for the ``x`` of ``t,vel,x,y,z,rate,x,y,z``).
    """
    if groups is not None:
        return groups[j] or None
    for i in range(j - 1, -1, -1):
        if header.count(header[i]) == 1:
            return header[i]
    return None


def resolve_column(df: pd.DataFrame, ref: str, path: str | Path, key: str = "") -> tuple[str, str]:
    """The table column a ``--columns`` reference names, for a header that may repeat names.

    A reference is a header name; where the header repeats it (``x,y,z`` after each vector of a
    GNSS/INS or rosbag export) one of: ``NAME[k]`` (its k-th column), ``#N`` (the file's N-th
    column, counted from 1) or ``VECTOR.NAME`` / ``VECTOR/NAME`` (the ``NAME`` column after
    the column ``VECTOR``, the nearest column before it whose name is not repeated). A
    repeated name given alone is read when its columns hold the same values (the first is
    taken and said) and is otherwise an error naming every column and how to choose.

    Parameters
    ----------
    df : pandas.DataFrame
        The table (:func:`read_table`; ``attrs["header"]`` holds the header as written).
    ref : str
        The header part of the mapping (no sign, no unit).
    path : str or Path
        The file, for messages.
    key : str
        The key mapped, for messages.

    Returns
    -------
    column : str
        The label of the column in *df*.
    said : str
        How it was chosen (``"x (column 7, after 'rate')"``); ``""`` for a name the header
        holds once.

    Raises
    ------
    InputError
        Naming the file, the reference and the columns it could mean.
    """
    header = [str(h) for h in df.attrs.get("header", list(df.columns))]
    labels = list(df.columns)
    if len(header) != len(labels):
        header = [str(h) for h in labels]
    rows = df.attrs.get("groups")
    vec: list[str] | None = list(rows) if rows is not None and len(rows) == len(labels) else None

    def _group(h: list[str], j: int) -> str | None:
        return _vector(h, j, vec)

    def said(j: int) -> str:
        groups = [_group(header, i) for i, h in enumerate(header) if h == header[j]]
        g = _group(header, j)
        tells = len(groups) > 1 and None not in groups and len(set(groups)) == len(groups)
        return f"{header[j]} (column {j + 1}" + (f", after {g!r})" if tells else ")")

    same = [j for j, h in enumerate(header) if h == ref]
    if len(same) == 1:
        return str(labels[same[0]]), ""
    if len(same) > 1:
        x = df.iloc[:, same]
        equal = all(x.iloc[:, 0].equals(x.iloc[:, i]) for i in range(1, len(same)))
        if equal:
            first = f"{ref} (column {same[0] + 1}; the first of {len(same)} equal columns)"
            return str(labels[same[0]]), first
        cols = ", ".join(said(j) for j in same)
        groups = [_group(header, j) for j in same]
        by_path = (
            [f"{key}={g}.{ref}" for g in groups]
            if None not in groups and len(set(groups)) == len(groups)
            else []
        )
        ways = by_path + [f"{key}={ref}[{k}]" for k in range(1, len(same) + 1)]
        raise InputError(
            f"{path}: the header names {len(same)} columns {ref!r} ({cols}) and they differ; say "
            f"which with --columns {' or '.join(ways[: len(same)])} (or {key}=#{same[0] + 1} "
            "for a column by its position)"
        )
    if ref in labels:  # pandas' own name of a repeated column (x.1)
        j = labels.index(ref)
        return ref, said(j)
    m = _POSITION.match(ref.strip())
    if m:
        j = int(m.group(1)) - 1
        if not 0 <= j < len(labels):
            raise InputError(
                f"{path}: --columns {key}={ref}: the table has {len(labels)} columns (#1 to "
                f"#{len(labels)})"
            )
        return str(labels[j]), said(j)
    m = _NTH.match(ref)
    if m:
        same = [j for j, h in enumerate(header) if h == m.group(1)]
        k = int(m.group(2))
        if same and 1 <= k <= len(same):
            return str(labels[same[k - 1]]), said(same[k - 1])
        if same:
            raise InputError(
                f"{path}: --columns {key}={ref}: the header names {len(same)} columns "
                f"{m.group(1)!r}; use [1] to [{len(same)}]"
            )
    for sep in (".", "/"):
        if sep in ref:
            g, _, name = ref.rpartition(sep)
            hits = [j for j, h in enumerate(header) if h == name and _group(header, j) == g]
            if len(hits) == 1:
                return str(labels[hits[0]]), said(hits[0])
    raise InputError(f"{path}: no column {ref!r} for {key} (columns: {header[:20]})")


Required = str | tuple[str, ...] | tuple[tuple[str, ...], ...]
"""What :func:`map_table` needs: a key, keys that go together, or alternatives of those."""


def _alternatives(need: Required) -> tuple[tuple[str, ...], ...]:
    """The alternatives of a :data:`Required`, each the keys that go together."""
    if isinstance(need, str):
        return ((need,),)
    if isinstance(need[0], tuple):
        return cast("tuple[tuple[str, ...], ...]", need)
    return (cast("tuple[str, ...]", need),)


def map_table(
    df: pd.DataFrame,
    path: str | Path,
    quantities: dict[str, Quantity],
    columns: str | dict | None = None,
    *,
    required: tuple[Required, ...] = (),
    example: str = "",
    non_numeric: str = "error",
    rejected: dict[str, np.ndarray] | None = None,
) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """The one column-mapping convention: values in SI for the quantities a command reads.

    Parameters
    ----------
    df : pandas.DataFrame
        The table (:func:`read_table`).
    path : str or Path
        The file, for messages.
    quantities : dict
        Key -> :class:`Quantity` the command knows.
    columns : str or dict, optional
        ``key=HEADER[:unit],…`` (``-`` before the header flips the sign), or ``None`` /
        ``"auto"``: headers with a known name and a unit suffix (``time_s``, ``ax_mps2`` …).
    required : tuple
        Keys that must be mapped; a tuple inside is a group of alternatives (one complete
        group is enough, e.g. ``(("vx", "vy"), ("speed", "slip"))`` as a single entry).
    example : str
        A ``--columns`` example for the message when something is missing.
    non_numeric : {"error", "nan"}
        A cell that is not a number: an error naming file, line and column, or NaN (for a
        caller that counts such rows as rejected).
    rejected : dict, optional
        A caller that counts rejected rows passes a dict: a cell that is ``inf`` or ``-inf``
        becomes NaN and ``rejected[key]`` the boolean mask of such rows
        (:func:`channel_rows` counts them). Without it such a cell is NaN with
        ``non_numeric="nan"`` (counted by the caller like any cell that is not a number) and
        otherwise an error naming the file, line and column. It is never a number.

    Returns
    -------
    values : dict
        Key -> values in SI units [SI] (empty cells NaN).
    mapping : dict
        Key -> ``"HEADER:unit"`` as used (for :func:`describe_columns`).

    Raises
    ------
    InputError
        Naming the file and the key, with how to map it; or naming the file, line, column and
        the unit that would fit when a value is implausible for the unit the column declares
        (:attr:`Quantity.limit`, :attr:`Quantity.typical`).
    """
    auto = columns is None or (isinstance(columns, str) and columns == "auto")
    spec = auto_columns(df.columns, quantities) if auto or columns is None else columns
    m = parse_columns(spec, quantities)
    for need in required:
        groups = _alternatives(need)
        if any(all(k in m for k in g) for g in groups):
            continue
        missing = [k for k in groups[0] if k not in m]
        if auto:
            names = ", ".join(
                f"{quantities[k].names[0]}_{_SUFFIX_EXAMPLE[quantities[k].dimension]}"
                for k in missing
            )
            how = (
                f"name the header{'s' if len(missing) > 1 else ''} with a unit suffix "
                f"(e.g. {names}) or give --columns {example or missing[0] + '=HEADER:unit'}"
            )
        else:
            how = f"add {', '.join(k + '=HEADER:unit' for k in missing)} to --columns"
        raise InputError(
            f"{path}: no column for {' and '.join(missing)} "
            f"(columns: {list(df.columns)[:20]}); {how}"
        )
    values = {}
    chosen: dict[str, str] = {}
    for key, (ref, factor) in m.items():
        name, how = resolve_column(df, ref, path, key)
        if how:
            chosen[key] = how
        if non_numeric == "nan":
            col = pd.to_numeric(df[name], errors="coerce").to_numpy(float)
        else:
            col = numeric_column(df, name, path)
        inf = np.isinf(col)
        if inf.any():
            if rejected is None and non_numeric == "nan":
                col = np.where(inf, np.nan, col)  # counted by the caller as not a number
            elif rejected is None:
                row = int(np.flatnonzero(inf)[0])
                raise InputError(
                    f"{path}: {_where(df, row)}, column {ref!r} ({key}): "
                    f"{col[row]:g} is not a finite number; correct the value, or "
                    "leave the cell empty or delete the row"
                )
            else:
                rejected[key] = inf
                col = np.where(inf, np.nan, col)
        _check_plausible(df, path, key, ref, quantities[key], col, factor, spec)
        values[key] = col * factor
    used: dict = _spec_dict(spec)
    for key, how in chosen.items():  # say which column a repeated name gave
        v = used.get(key)
        if isinstance(v, tuple):
            used[key] = (how, v[1])
        elif isinstance(v, str):
            sign = "-" if v.strip().startswith("-") else ""
            unit = v.rsplit(":", 1)[1] if ":" in v else ""
            used[key] = f"{sign}{how}" + (f":{unit}" if unit else "")
    return values, used


def _declared_unit(spec: str | dict, key: str, dimension: str) -> str:
    """The unit the mapping declares for *key*, for messages."""
    v = _spec_dict(spec).get(key) if not isinstance(spec, dict) else spec.get(key)
    if isinstance(v, tuple):
        return f"× {float(v[1]):g} to SI"
    if isinstance(v, str) and ":" in v:
        return v.rsplit(":", 1)[1].strip()
    return f"no unit: {_SI[dimension]}"


_SI = {
    "angle": "rad",
    "angular rate": "rps",
    "speed": "m/s",
    "acceleration": "mps2",
    "time": "s",
    "force": "N",
    "length": "m",
    "mass": "kg",
    "torque": "Nm",
}


def _check_plausible(
    df: pd.DataFrame,
    path: str | Path,
    key: str,
    name: str,
    q: Quantity,
    raw: np.ndarray,
    factor: float,
    spec: str | dict,
) -> None:
    """An error naming file, line, column and the unit that would fit when a column's values
    are implausible for the unit it declares (:attr:`Quantity.limit`, :attr:`Quantity.typical`).
    """
    if q.limit is None and q.typical is None:
        return
    a = np.abs(raw)
    fin = np.isfinite(a)
    if not fin.any():
        return
    si = a * abs(factor)
    declared = _declared_unit(spec, key, q.dimension)
    what = q.meaning or key
    si_unit = UNIT_LABELS.get(_SI[q.dimension], _SI[q.dimension])
    big = max_raw = float(np.max(a[fin]))
    problem = ""
    if q.limit is not None and np.nanmax(si) > q.limit:
        row = int(np.flatnonzero(fin & (si > q.limit))[0])
        problem = (
            f"{_where(df, row)}, column {name!r} ({key}): {raw[row]:.6g} [{declared}] is "
            f"{si[row]:.4g} {si_unit}, more than {what} can be ({q.limit:g} {si_unit})"
        )
    elif q.typical is not None and np.median(si[fin]) > q.typical:
        big = float(np.median(a[fin]))
        problem = (
            f"column {name!r} ({key}): its median |value| {big:.4g} [{declared}] is "
            f"{big * abs(factor):.4g} {si_unit}, more than {what} holds ({q.typical:g} {si_unit})"
        )
    if not problem:
        return
    fits = [
        u
        for u, d in UNIT_DIMENSIONS.items()
        if d == q.dimension
        and (q.limit is None or max_raw * UNITS[u] <= q.limit)
        and (q.typical is None or np.median(a[fin]) * UNITS[u] <= q.typical)
        and "/" not in u
    ]
    head = name if not isinstance(spec, str) or f"-{name}" not in spec else f"-{name}"
    how = (
        f"if the column is in {' or '.join(fits)}, map it as {key}={head}:{fits[0]}"
        + "".join(f" (or :{u})" for u in fits[1:])
        if fits
        else "check the column and the unit it is mapped with"
    )
    raise InputError(f"{path}: {problem}; the unit is wrong or the value is; {how}")


def _header(value) -> str:
    """The header of one mapping value (``"[-]HEADER[:unit]"`` or ``(HEADER, factor)``)."""
    if isinstance(value, tuple):
        return str(value[0])
    v = str(value).strip().lstrip("-")
    return v.rsplit(":", 1)[0] if ":" in v else v


def _where(df: pd.DataFrame, row: int) -> str:
    lines = df.attrs.get("line")
    return f"line {int(lines[row])}" if lines is not None else f"row {row + 1}"


def channel_rows(
    df: pd.DataFrame,
    path: str | Path,
    values: dict[str, np.ndarray],
    mapping: dict,
    *,
    time_key: str = "t",
    needed: tuple[str, ...] = (),
    flag: str = "--columns",
    rejected: dict[str, np.ndarray] | None = None,
) -> tuple[np.ndarray, dict]:
    """The rows of a table of several channels at their own rates (a row carries the channels
    sampled at its time and leaves the others empty), with their accounting.

    A row is used when it carries a time and at least one mapped channel; a row that carries
    none of the mapped channels (the samples of a channel that is not mapped) is counted, not
    used; a row whose channels have no time is an error naming the file, line and column; a
    mapped channel that no row carries is an error naming its column.

    Parameters
    ----------
    df : pandas.DataFrame
        The table (:func:`read_table`; ``attrs["line"]`` gives line numbers).
    path : str or Path
        The file, for messages.
    values : dict
        Key -> values of :func:`map_table` [SI] (NaN where a row leaves the channel empty).
    mapping : dict
        Key -> ``"HEADER[:unit]"`` of :func:`map_table` (for the columns' names).
    time_key : str
        The key of the time.
    needed : tuple of str
        Keys whose channel a used row must carry (the others are optional per row) — rows
        without them are counted like rows without any channel.
    flag : str
        The option that maps the columns, for messages.
    rejected : dict, optional
        Key -> mask of the rows whose cell was not a finite number (``inf``; ``rejected`` of
        :func:`map_table`): those rows are not used and are counted apart.

    Returns
    -------
    keep : numpy.ndarray
        Boolean mask of the rows used.
    accounting : dict
        ``rows`` (data rows), ``rows_used``, ``rows_without_channel`` (counted, not used),
        ``first_line_without_channel`` (its line or row, ``""`` when none),
        ``rows_not_finite`` (rows with an ``inf`` cell: rejected) and ``note`` (one line saying
        so, ``""`` when every row was used).
    """
    n = len(df)
    t = values[time_key]
    chans = [k for k in values if k != time_key]
    bad = np.zeros(n, bool)
    for mask in (rejected or {}).values():
        bad |= mask
    some = np.zeros(n, bool)
    for k in chans:
        if not np.isfinite(values[k]).any() and not bad.any():
            head = _header(mapping.get(k, k))
            raise InputError(
                f"{path}: column {head!r} ({k}) has no value on any row; map another column "
                f"or leave {k} out of {flag}"
            )
        some |= np.isfinite(values[k])
    untimed = some & ~np.isfinite(t)
    if untimed.any():
        row = int(np.flatnonzero(untimed)[0])
        head = _header(mapping.get(time_key, time_key))
        raise InputError(
            f"{path}: {_where(df, row)}, column {head!r} ({time_key}): no time for the row's "
            "values; fill it or delete the row"
        )
    keep = some & ~bad
    for k in needed:
        keep &= np.isfinite(values[k])
    n_bad = int(bad.sum())
    n_without = int(n - keep.sum()) - n_bad
    if not keep.any() and n_bad:
        first = _where(df, int(np.flatnonzero(bad)[0]))
        raise InputError(
            f"{path}: every row with a value has one that is not a finite number (inf; the "
            f"first at {first}); correct the values"
        )
    acc = {
        "rows": n,
        "rows_used": int(keep.sum()),
        "rows_without_channel": n_without,
        "first_line_without_channel": "",
        "rows_not_finite": n_bad,
        "note": "",
    }
    notes = []
    if n_bad:
        heads = ", ".join(
            _header(mapping.get(k, k)) for k, m in (rejected or {}).items() if m.any()
        )
        first = _where(df, int(np.flatnonzero(bad)[0]))
        notes.append(
            f"{Path(path).name}: {n_bad} of {n} rows with a value that is not a finite number "
            f"(inf) in {heads}: rejected, not used (the first at {first})"
        )
    if n_without:
        first = _where(df, int(np.flatnonzero(~keep & ~bad)[0]))
        heads = ", ".join(_header(mapping.get(k, k)) for k in (needed or chans))
        acc["first_line_without_channel"] = first
        notes.append(
            f"{Path(path).name}: {n_without} of {n} rows carry none of the mapped channels "
            f"({heads}): not used (the first at {first})"
            if not needed
            else f"{Path(path).name}: {n_without} of {n} rows without {heads}: not used "
            f"(the first at {first})"
        )
    acc["note"] = "; ".join(notes)
    return keep, acc


ROAD_WHEEL_LIMIT = 1.0
"""The largest road-wheel steer angle a road vehicle has [rad] (57°; full lock is 35–45°)."""
SPEED_LIMIT = 120.0
"""The largest speed a measured vehicle plausibly has [m/s] (432 km/h)."""
YAW_RATE_LIMIT = 5.0
"""The largest yaw rate a vehicle plausibly has [rad/s] (286°/s; a spin reaches ~3 rad/s)."""
ACCEL_LIMIT = 16 * G0
"""The largest acceleration one sample plausibly has [m/s²] (a MEMS sensor's ±16 g range)."""
ACCEL_TYPICAL = 2 * G0
"""The largest median |acceleration| of a drive [m/s²] (a vehicle holds well under 2 g; an
accelerometer's z axis reads 1 g)."""
