"""Motion tables from other sources: GNSS/INS exports (OxTS, VBOX), research datasets.

``read_motion_table(path, columns)`` turns a CSV or Parquet table into the motion table the
friction core uses (:func:`gripsense.estimate.friction.friction_from_motion`): body velocities
of the measurement point (the antenna position of the vehicle file), ISO yaw rate, optional
lateral acceleration and road-wheel steer angle, and time.

Column mapping: ``{"t": "Time", "vx": "VelForward", "vy": "VelLateral:kmh", ...}`` or the
command-line form ``t=Time,vx=VelForward,vy=VelLateral:kmh,yaw_rate=AngRateZ:dps``. Keys:

==========  ============================================================  ==============
key         meaning                                                       default unit
==========  ============================================================  ==============
t           time                                                          s
vx, vy      body velocity of the measurement point, x forward, y left     m/s
speed, slip alternative to vx, vy: speed and body slip angle (ISO, left+) m/s, rad
yaw_rate    yaw rate, ISO (counter-clockwise positive)                    rad/s
ay          lateral acceleration of the CG, ISO (left positive)           m/s²
steer       road-wheel steer angle, ISO (left positive)                   rad
==========  ============================================================  ==============

A unit after a colon converts: ``deg``, ``rad``, ``dps`` (deg/s), ``rps``, ``mps``, ``kmh``,
``mph``, ``kn``, ``g``, ``mps2``, ``s``, ``ms``. A leading ``-`` flips the sign
(``yaw_rate=-YawRate:dps`` for a clockwise-positive source).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.io.text import read_bytes, read_text

__all__ = [
    "MOTION_ALIASES",
    "TABLE_READERS",
    "auto_columns",
    "describe_columns",
    "numeric_column",
    "parse_columns",
    "read_motion_table",
    "read_table",
]

UNITS = {
    "deg": np.pi / 180,
    "rad": 1.0,
    "dps": np.pi / 180,
    "rps": 1.0,
    "mps": 1.0,
    "kmh": 1 / 3.6,
    "mph": 0.44704,
    "kn": 1852 / 3600,
    "g": G0,
    "mps2": 1.0,
    "s": 1.0,
    "ms": 1e-3,
}
UNITS.update({"m/s": 1.0, "km/h": 1 / 3.6, "N": 1.0, "kN": 1e3, "mm": 1e-3, "m": 1.0})
UNIT_LABELS = {"mps2": "m/s²", "mps": "m/s", "kmh": "km/h", "dps": "deg/s", "rps": "rad/s"}
KEYS = ("t", "vx", "vy", "speed", "slip", "yaw_rate", "ay", "steer")


def auto_columns(headers, aliases: dict[str, tuple[str, ...]]) -> dict[str, str]:
    """A column mapping from headers that carry a known name and a unit suffix (``time_s``,
    ``t_ms``, ``ax_mps2``, ``ay_g``, ``speed_kmh``, ``yaw_rate_dps``, ``fz_kN`` …).

    Parameters
    ----------
    headers : iterable of str
        The table's column names.
    aliases : dict
        Key -> the names (lower case, without unit) that mean it, e.g. ``{"t": ("t", "time")}``.

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
        for key, names in aliases.items():
            if key not in out and name.lower() in names:
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
    return df


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


def parse_columns(
    spec: str | dict, keys: tuple[str, ...] = KEYS, units: dict[str, float] | None = None
) -> dict[str, tuple[str, float]]:
    """Column mapping -> {key: (column, factor)} (see the module documentation).

    Parameters
    ----------
    spec : str or dict
        ``key=column[:unit]`` pairs (a leading ``-`` on the column flips the sign).
    keys : tuple of str
        Allowed keys.
    units : dict, optional
        Unit name -> factor to SI; default the motion-table units.
    """
    units = UNITS if units is None else units
    items = (
        spec.items()
        if isinstance(spec, dict)
        else (part.split("=", 1) for part in spec.split(",") if part.strip())
    )
    out = {}
    for item in items:
        if len(item) != 2:
            raise InputError(f"--columns: {item!r} is not key=column")
        key, col = (x.strip() for x in item)
        if key not in keys:
            raise InputError(f"--columns: unknown key {key!r}; use {', '.join(keys)}")
        sign = -1.0 if col.startswith("-") else 1.0
        col = col.lstrip("-")
        factor = 1.0
        if ":" in col:
            col, unit = col.rsplit(":", 1)
            if unit not in units:
                raise InputError(f"--columns: {key}: unknown unit {unit!r}; use {sorted(units)}")
            factor = units[unit]
        out[key] = (col, sign * factor)
    return out


MOTION_ALIASES = {
    "t": ("t", "time"),
    "vx": ("vx", "v_x", "vel_x", "velforward"),
    "vy": ("vy", "v_y", "vel_y", "vellateral"),
    "speed": ("speed", "v", "vel"),
    "slip": ("slip", "beta", "sideslip", "slip_angle"),
    "yaw_rate": ("yaw_rate", "yawrate"),
    "ay": ("ay", "a_y", "acc_y", "accel_y"),
    "steer": ("steer", "delta", "steer_angle", "road_wheel"),
}
"""Header names (before the unit suffix) that ``read_motion_table`` maps without being told."""


def read_motion_table(path: str | Path, columns: str | dict = "auto") -> pd.DataFrame:
    """Read a CSV/Parquet table into a motion table.

    Parameters
    ----------
    path : path
        ``.csv`` (comment lines ``#``) or ``.parquet``.
    columns : str or dict
        Column mapping (see the module documentation). Needs ``t``, ``yaw_rate`` and either
        ``vx`` + ``vy`` or ``speed`` + ``slip``. ``"auto"`` (default): headers with a known name
        and unit suffix (``time_s``, ``speed_kmh``, ``slip_deg``, ``yaw_rate_dps`` …;
        :data:`MOTION_ALIASES`).

    Returns
    -------
    pandas.DataFrame
        ``t_s``, ``epoch`` (row), ``u_mps``, ``v_mps``, ``yaw_rate_rps``, ``ay_mps2``,
        ``steer_rad`` (NaN where not given); ``attrs["columns"]`` holds the mapping used.

    Raises
    ------
    InputError
        Naming the file, key and column when something is missing or not numeric.
    """
    path = Path(path)
    df = read_table(path)
    auto = isinstance(columns, str) and columns == "auto"
    spec = auto_columns(df.columns, MOTION_ALIASES) if auto else columns
    m = parse_columns(spec)
    need = ["t", "yaw_rate"] + (["vx", "vy"] if "vx" in m or "vy" in m else ["speed", "slip"])
    for key in need:
        if key not in m:
            how = (
                "name the headers with a unit suffix (time_s, speed_kmh, slip_deg, "
                "yaw_rate_dps …) or give --columns"
                if auto
                else "add it to --columns"
            )
            raise InputError(f"{path}: no column for {key} (have {sorted(m)}); {how}")

    def col(key: str) -> np.ndarray:
        name, factor = m[key]
        if name not in df.columns:
            raise InputError(
                f"{path}: column {name!r} for {key} not found; columns: {list(df.columns)[:20]}"
            )
        return numeric_column(df, name, path) * factor

    if "vx" in m:
        u, v = col("vx"), col("vy")
    else:
        sp, sl = col("speed"), col("slip")
        u, v = sp * np.cos(sl), sp * np.sin(sl)
    n = len(df)
    out = (
        pd.DataFrame(
            {
                "t_s": col("t"),
                "epoch": np.arange(n),
                "u_mps": u,
                "v_mps": v,
                "yaw_rate_rps": col("yaw_rate"),
                "ay_mps2": col("ay") if "ay" in m else np.full(n, np.nan),
                "steer_rad": col("steer") if "steer" in m else np.full(n, np.nan),
            }
        )
        .dropna(subset=["t_s", "u_mps", "v_mps", "yaw_rate_rps"])
        .reset_index(drop=True)
    )
    out.attrs["columns"] = (
        spec
        if isinstance(spec, dict)
        else dict(p.split("=", 1) for p in str(spec).split(",") if "=" in p)
    )
    return out
