"""Named channels of measurement logs (VBOX, MDF4, CAN) mapped onto the epoch table.

One ``--columns`` convention for every format (the same words as the tables of
:mod:`gripsense.io.table`): ``heading=True_Head,steer=SteerAngle:deg,torque=-TrqCol:Nm``. A
unit after the colon overrides the file's own; without one the unit the file states for the
channel is used (MDF4 and DBC signals carry units, a VBOX file its ``[channel units]``), and a
channel without either is an error naming it. A leading ``-`` flips the sign.

==============  ===================================================  =========================
key             epoch-table column                                   kind (unit words)
==============  ===================================================  =========================
heading         ``heading_deg``: true heading, clockwise from north  angle (deg, rad)
course          ``course_deg``: course over ground                   angle
speed           ``speed_mps``: speed over ground                     speed (m/s, km/h, mph, kn)
lat, lon        ``lat_deg``, ``lon_deg`` (north, east positive)      angle
alt             ``alt_m``                                            length (m, cm, mm)
yaw_rate        ``yaw_rate_rps``: ISO, counter-clockwise positive    angular rate (dps, rps)
pitch, roll     ``pitch_deg``, ``roll_deg``                          angle
steer           ``steer_rad``: road-wheel angle, ISO left positive   angle
steering_wheel  ``steering_wheel_rad``: hand-wheel angle (÷ ratio)   angle
torque          ``torque_nm``: steering-column torque                torque (Nm)
assist          ``assist_nm``: power-steering assist torque          torque (Nm)
rack            ``rack_n``: rack force                               force (N, kN, lbf)
==============  ===================================================  =========================

A steering channel is found without ``--columns`` when its name **and** its unit say what it is
(:data:`STEERING_CHANNELS`, :func:`recognise_steering`): the name, compared without case,
spaces, ``_``, ``-`` or ``.``, is one of the table's and the unit the file states is an angle
(``deg``, ``°``, ``rad`` …). A road-wheel angle fills ``steer``; a steering-wheel angle fills
``steering_wheel`` (divided by the vehicle file's ``steering_ratio``). A name the table knows
with no unit or a unit that is not an angle, or a name that does not say which angle it is
(``SteeringAngle``), is not used: the ingest notes name it and the mapping that would use it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from gripsense.errors import InputError
from gripsense.io.table import (
    ROAD_WHEEL_LIMIT,
    SPEED_LIMIT,
    UNIT_DIMENSIONS,
    UNITS,
    YAW_RATE_LIMIT,
)

__all__ = [
    "CHANNEL_KEYS",
    "STEERING_CHANNELS",
    "Channel",
    "ChannelSpec",
    "add_steering",
    "channels_to_epochs",
    "file_unit_factor",
    "parse_channel_spec",
    "recognise_steering",
    "resample",
]


@dataclass(frozen=True)
class ChannelKey:
    """One quantity a log channel can give.

    Parameters
    ----------
    column : str
        Epoch-table column it fills.
    dimension : str
        What it measures (a value of :data:`gripsense.io.table.UNIT_DIMENSIONS`).
    to_column : float
        Factor from SI to the column's unit (degrees for angles stored in degrees) [-].
    limit : float, optional
        The largest |value| a sample can plausibly have, in SI [SI]: a larger one says the
        channel's unit is wrong (degrees stated or mapped as ``rad``) — an error naming the
        channel and the unit that fits.
    meaning : str
        What it is, for messages.
    """

    column: str
    dimension: str
    to_column: float = 1.0
    limit: float | None = None
    meaning: str = ""


_DEG = 180.0 / np.pi
CHANNEL_KEYS = {
    "heading": ChannelKey("heading_deg", "angle", _DEG),
    "course": ChannelKey("course_deg", "angle", _DEG),
    "speed": ChannelKey("speed_mps", "speed", limit=SPEED_LIMIT, meaning="a vehicle's speed"),
    "lat": ChannelKey("lat_deg", "angle", _DEG),
    "lon": ChannelKey("lon_deg", "angle", _DEG),
    "alt": ChannelKey("alt_m", "length"),
    "yaw_rate": ChannelKey(
        "yaw_rate_rps", "angular rate", limit=YAW_RATE_LIMIT, meaning="a vehicle's yaw rate"
    ),
    "pitch": ChannelKey("pitch_deg", "angle", _DEG),
    "roll": ChannelKey("roll_deg", "angle", _DEG),
    "steer": ChannelKey("steer_rad", "angle", limit=ROAD_WHEEL_LIMIT, meaning="a road-wheel angle"),
    "steering_wheel": ChannelKey(
        "steering_wheel_rad", "angle", limit=20.0, meaning="a steering-wheel angle"
    ),
    "torque": ChannelKey("torque_nm", "torque", limit=200.0, meaning="a steering torque"),
    "assist": ChannelKey("assist_nm", "torque", limit=200.0, meaning="a steering torque"),
    "rack": ChannelKey("rack_n", "force", limit=1e5, meaning="a rack force"),
}
"""``--columns`` key of a log -> the epoch-table column it fills."""

_FILE_UNITS = {
    "°": "deg",
    "degrees": "deg",
    "degree": "deg",
    "deg": "deg",
    "rad": "rad",
    "radians": "rad",
    "°/s": "dps",
    "deg/s": "dps",
    "degrees/s": "dps",
    "dps": "dps",
    "rad/s": "rps",
    "km/h": "kmh",
    "kmh": "kmh",
    "kph": "kmh",
    "m/s": "mps",
    "mps": "mps",
    "mph": "mph",
    "knots": "kn",
    "kn": "kn",
    "kts": "kn",
    "m": "m",
    "metres": "m",
    "meters": "m",
    "cm": "cm",
    "mm": "mm",
    "newton": "N",
    "nm": "Nm",
    "n·m": "Nm",
    "n.m": "Nm",
    "n m": "Nm",
    "n": "N",
    "s": "s",
    "sec": "s",
    "secs": "s",
    "ms": "ms",
    "g": "g",
    "m/s²": "mps2",
    "m/s^2": "mps2",
    "m/s2": "mps2",
}


def file_unit_factor(unit: str | None, dimension: str) -> float | None:
    """The factor to SI of a unit as a file writes it, if it is one of *dimension*.

    Parameters
    ----------
    unit : str or None
        The file's unit text (``"deg"``, ``"°/s"``, ``"km/h"``, ``"Nm"`` …).
    dimension : str
        The quantity's kind.

    Returns
    -------
    float or None
        Factor to SI [-]; None when the text is empty, unknown or of another kind.
    """
    if not unit:
        return None
    text = unit.strip()
    # the exact unit word first (kN is not kn, knots), then the file spellings
    word = text if text in UNITS else _FILE_UNITS.get(text.lower())
    if word is None or UNIT_DIMENSIONS.get(word) != dimension:
        return None
    return UNITS[word]


@dataclass(frozen=True)
class ChannelSpec:
    """One mapped channel: ``key=[-]CHANNEL[:unit]``.

    Parameters
    ----------
    key : str
        A key of :data:`CHANNEL_KEYS`.
    channel : str
        The channel (signal) name in the file.
    sign : float
        +1, or −1 for a leading ``-`` [-].
    factor : float or None
        Factor to SI of the unit given after the colon [-]; None: take the file's unit.
    """

    key: str
    channel: str
    sign: float
    factor: float | None

    def column_values(self, raw: np.ndarray, file_unit: str | None, where: str) -> np.ndarray:
        """The channel's values in the epoch-table column's unit.

        Parameters
        ----------
        raw : numpy.ndarray
            Values as the file stores them [the file's unit].
        file_unit : str or None
            The unit the file states for the channel.
        where : str
            File (and section) for the message.

        Returns
        -------
        numpy.ndarray
            Values [the column's unit]; a sample that is not a finite number is NaN. A value
            beyond what the unit makes plausible (:attr:`ChannelKey.limit`) is an error naming
            the channel, the unit and the unit that would fit.
        """
        ck = CHANNEL_KEYS[self.key]
        factor = self.factor
        if factor is None:
            factor = file_unit_factor(file_unit, ck.dimension)
        if factor is None:
            stated = (
                f"its unit {file_unit!r} is not one of {ck.dimension}"
                if file_unit
                else ("it has no unit")
            )
            raise InputError(
                f"{where}: channel {self.channel!r} ({self.key}): {stated}; give it in --columns "
                f"({self.key}={self.channel}:UNIT, e.g. "
                f"{self.key}={self.channel}:{_EXAMPLE[ck.dimension]})"
            )
        raw = np.asarray(raw, dtype=float)
        raw = np.where(np.isfinite(raw), raw, np.nan)
        self._check_plausible(raw, factor, file_unit, where)
        return raw * (self.sign * factor * ck.to_column)

    def _check_plausible(
        self, raw: np.ndarray, factor: float, file_unit: str | None, where: str
    ) -> None:
        ck = CHANNEL_KEYS[self.key]
        if ck.limit is None or not np.isfinite(raw).any():
            return
        big = float(np.nanmax(np.abs(raw)))
        if big * factor <= ck.limit:
            return
        unit = file_unit
        if self.factor is not None:
            same = [
                u for u, f in UNITS.items() if f == factor and UNIT_DIMENSIONS[u] == ck.dimension
            ]
            unit = same[0] if same else f"× {factor:g}"
        told = "as mapped by --columns" if self.factor is not None else "as the file states"
        fits = [
            u
            for u, d in UNIT_DIMENSIONS.items()
            if d == ck.dimension and big * UNITS[u] <= ck.limit and "/" not in u
        ]
        how = (
            f"if it is in {' or '.join(fits)}, map it with --columns "
            f"{self.key}={self.channel}:{fits[0]}"
            if fits
            else "check the channel and its unit"
        )
        raise InputError(
            f"{where}: channel {self.channel!r} ({self.key}): {big:.4g} [{unit}, {told}] is "
            f"{big * factor:.4g} in SI, more than {ck.meaning} can be ({ck.limit:g}); the unit "
            f"is wrong or the channel is; {how}"
        )


_EXAMPLE = {
    "angle": "deg",
    "speed": "kmh",
    "length": "m",
    "angular rate": "dps",
    "torque": "Nm",
    "force": "N",
}


def parse_channel_spec(spec: str | dict | None) -> dict[str, ChannelSpec]:
    """``--columns`` of a log -> mapped channels.

    Parameters
    ----------
    spec : str, dict or None
        ``key=[-]CHANNEL[:unit],…`` or a dict key -> ``"[-]CHANNEL[:unit]"``.

    Returns
    -------
    dict
        Key -> :class:`ChannelSpec`.
    """
    if not spec:
        return {}
    if isinstance(spec, dict):
        items = list(spec.items())
    else:
        items = []
        for part in spec.split(","):
            if not part.strip():
                continue
            if "=" not in part:
                raise InputError(f"--columns: {part.strip()!r} is not key=CHANNEL[:unit]")
            k, v = part.split("=", 1)
            items.append((k, v))
    out = {}
    for key, value in items:
        key = key.strip()
        if key not in CHANNEL_KEYS:
            raise InputError(
                f"--columns: unknown key {key!r} for a log; use {', '.join(CHANNEL_KEYS)}"
            )
        v = str(value).strip()
        sign = -1.0 if v.startswith("-") else 1.0
        v = v.lstrip("-")
        factor = None
        if ":" in v:
            v, unit = v.rsplit(":", 1)
            dim = CHANNEL_KEYS[key].dimension
            if unit not in UNITS:
                raise InputError(f"--columns: {key}: unknown unit {unit!r}; use {sorted(UNITS)}")
            if UNIT_DIMENSIONS[unit] != dim:
                raise InputError(
                    f"--columns: {key}={v}:{unit}: {unit} is a unit of {UNIT_DIMENSIONS[unit]}, "
                    f"but {key} needs a unit of {dim}"
                )
            factor = UNITS[unit]
        if not v:
            raise InputError(f"--columns: {key}: no channel name")
        out[key] = ChannelSpec(key, v, sign, factor)
    return out


@dataclass
class Channel:
    """One decoded channel of a measurement log.

    Parameters
    ----------
    name : str
        Channel (signal) name in the file.
    t : numpy.ndarray
        Sample times [s] (the log's clock).
    values : numpy.ndarray
        Samples [the file's unit].
    unit : str
        The unit the file states ("" when none).
    """

    name: str
    t: np.ndarray
    values: np.ndarray
    unit: str = ""


_ANGLES = ("heading", "course")
_GAP = 2.5  # a channel is not interpolated across intervals longer than this × its median


def resample(t_to: np.ndarray, t: np.ndarray, v: np.ndarray, *, circular: bool = False):
    """Linear interpolation of a channel onto other times, NaN outside its span and across its
    gaps (intervals over 2.5 × its median interval).

    Parameters
    ----------
    t_to : numpy.ndarray
        Target times [s].
    t, v : numpy.ndarray
        The channel's times [s] (increasing) and values.
    circular : bool
        Values are compass angles in degrees (interpolated unwrapped, returned in [0, 360)).

    Returns
    -------
    numpy.ndarray
        Values at *t_to*.
    """
    ok = np.isfinite(t) & np.isfinite(v)
    t, v = t[ok], v[ok]
    out = np.full(np.shape(t_to), np.nan)
    if t.size < 1:
        return out
    if t.size == 1:
        out[t_to == t[0]] = v[0]
        return out
    x = np.rad2deg(np.unwrap(np.deg2rad(v))) if circular else v
    out = np.interp(t_to, t, x)
    out[(t_to < t[0]) | (t_to > t[-1])] = np.nan
    dt = np.diff(t)
    big = np.flatnonzero(dt > _GAP * np.median(dt))
    if big.size:
        k = np.searchsorted(t, t_to, side="right") - 1
        inside = np.isin(k, big) & (t_to > t[np.clip(k, 0, t.size - 1)])
        out[inside] = np.nan
    return np.mod(out, 360.0) if circular else out


def channels_to_epochs(
    mapped: dict[str, ChannelSpec], found: dict[str, Channel], where: str
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Mapped channels on one time base: the heading channel's samples (else the speed's, else
    the first mapped channel's); the others interpolated onto it (:func:`resample`).

    Parameters
    ----------
    mapped : dict
        Key -> :class:`ChannelSpec` (``--columns``).
    found : dict
        Key -> the decoded :class:`Channel`.
    where : str
        File, for messages.

    Returns
    -------
    t : numpy.ndarray
        Epoch times [s] (the log's clock).
    values : dict
        Epoch-table column -> values [the column's unit].
    """
    base_key = next((k for k in ("heading", "speed", *found) if k in found), None)
    if base_key is None:
        return np.zeros(0), {}
    base = found[base_key]
    ok = np.isfinite(base.t) & np.isfinite(base.values)
    t = base.t[ok]
    order = np.argsort(t, kind="stable")
    t = t[order]
    values = {}
    for key, ch in found.items():
        spec = mapped[key]
        si = spec.column_values(ch.values, ch.unit, where)
        srt = np.argsort(ch.t, kind="stable")
        col = CHANNEL_KEYS[key].column
        if key == base_key:
            values[col] = si[ok][order]
        elif ch.t.shape == base.t.shape and np.array_equal(ch.t, base.t):
            values[col] = si[ok][order]  # sampled with the heading: nothing to interpolate
        else:
            values[col] = resample(t, ch.t[srt], si[srt], circular=key in _ANGLES)
            _check_overlap(ch, si, base, t, values[col], where)
        if key in _ANGLES:
            values[col] = np.mod(values[col], 360.0)
    return t, values


def _check_overlap(
    ch: Channel, si: np.ndarray, base: Channel, t: np.ndarray, out: np.ndarray, where: str
) -> None:
    """An error when a channel with values lands on no epoch because its times never overlap
    the base channel's (another clock): it would vanish without a word.
    """
    ok = np.isfinite(ch.t) & np.isfinite(si)
    if not ok.any() or t.size == 0 or np.isfinite(out).any():
        return
    tc = ch.t[ok]
    if tc.max() >= t.min() and tc.min() <= t.max():
        return  # overlapping spans (a channel too sparse for its epochs is another matter)
    raise InputError(
        f"{where}: channel {ch.name!r} has values at {tc.min():.6g}–{tc.max():.6g} s, which "
        f"never overlap the epochs of {base.name!r} ({t.min():.6g}–{t.max():.6g} s): the two "
        "are on different clocks; map a channel on the log's clock or leave it out of --columns"
    )


STEERING_CHANNELS: dict[str, tuple[str, ...]] = {
    "steer": (
        "roadwheelangle",  # RoadWheelAngle: gripsense simulate (VBOX, MDF4)
        "roadwheelang",
        "roadwheelsteerangle",
        "roadwheelsteeringangle",
        "frontwheelangle",
        "frontwheelsteerangle",
        "wheelsteerangle",
    ),
    "steering_wheel": (
        "steeringwheelangle",  # SteeringWheelAngle: the CAN DBC of the tests, VBOX CAN channels
        "steeringwheelang",
        "steeringwheel",
        "steeringwhlangle",
        "steeringwhlang",
        "steerwheelangle",
        "stwheelangle",
        "stwhlangle",
        "stwhlang",
        "handwheelangle",
        "handwheel",
        "swa",
        "steeringwh*",  # any name that starts so (VBOX cuts long channel names)
    ),
}
"""Channel names (compared without case, spaces, ``_``, ``-`` or ``.``; a trailing ``*``
matches any rest) that are read as a steering channel without ``--columns`` when the file's unit
for them is an angle: key of :data:`CHANNEL_KEYS` -> names. A road-wheel angle is preferred to a
steering-wheel angle (which needs the vehicle's ``steering_ratio``)."""

_UNSAID = ("steer", "steering", "steerangle", "steeringangle", "steerang", "steeringang",
           "steeringpos", "steeringposition")  # fmt: skip
"""Names of a steering angle that do not say whether it is the road wheel's or the hand
wheel's: never used unmapped, named in a note."""


def _norm(name: str) -> str:
    return re.sub(r"[\s_.\-]", "", name).lower()


def _steering_key(name: str) -> tuple[str | None, bool]:
    """The steering key a channel name says (or None), and whether the name is a whole one of
    the table (not only its start).
    """
    n = _norm(name)
    for key, names in STEERING_CHANNELS.items():
        if n in names:
            return key, True
        if any(p.endswith("*") and n.startswith(p[:-1]) for p in names):
            return key, False
    return None, False


_WHAT = {"steer": "road-wheel angle", "steering_wheel": "steering-wheel angle"}


def recognise_steering(
    names: Iterable[str], unit_of: Callable[[str], str | None]
) -> tuple[ChannelSpec | None, list[str]]:
    """The steering channel of a log found by its name and unit (:data:`STEERING_CHANNELS`).

    Parameters
    ----------
    names : iterable of str
        The log's channel names, in the file's order (those ``--columns`` already maps left
        out).
    unit_of : callable
        Channel name -> the unit the file states for it (``None`` or ``""`` when none); called
        only for the names of the table and the ambiguous ones.

    Returns
    -------
    spec : ChannelSpec or None
        ``steer`` (road-wheel angle) or ``steering_wheel`` mapped with the file's unit, or None.
    notes : list of str
        One line per channel the table knows that was not used, and why (for the ingest
        report).
    """
    found: dict[str, list[tuple[str, str]]] = {"steer": [], "steering_wheel": []}
    notes: list[str] = []
    for name in names:
        key, whole = _steering_key(name)
        if key is None:
            if _norm(name) in _UNSAID:
                unit = unit_of(name) or ""
                if file_unit_factor(unit, "angle") is not None:
                    notes.append(
                        f"channel {name!r} [{unit}] may be a steering angle, but its name does not "
                        f"say which: map it with --columns steer={name} (road-wheel angle) or "
                        f"steering_wheel={name} (steering-wheel angle)"
                    )
            continue
        unit = unit_of(name) or ""
        if file_unit_factor(unit, "angle") is None:
            if not whole:  # SteeringWheelSpeed [deg/s], SteeringWheelTorque [Nm]: not an angle
                continue
            stated = f"its unit {unit!r} is not an angle" if unit else "it has no unit"
            notes.append(
                f"channel {name!r} is named like a {_WHAT[key]} but {stated}: not used; if it "
                f"is one, map it with --columns {key}={name}:deg (or :rad)"
            )
            continue
        found[key].append((name, unit))
    key = "steer" if found["steer"] else "steering_wheel" if found["steering_wheel"] else None
    if key is None:
        return None, notes
    (name, unit), *others = found[key]
    other = [n for k in found if k != key for n, _ in found[k]] + [n for n, _ in others]
    if other:
        notes.append(
            f"steering channel {name!r} used; {', '.join(repr(o) for o in other)} not used "
            "(map another with --columns)"
        )
    notes.insert(
        0,
        f"steering channel found by its name and unit: {key}={name} [{unit}] ({_WHAT[key]}; "
        "docs/ingest.md)",
    )
    return ChannelSpec(key, name, 1.0, None), notes


def add_steering(
    mapped: dict[str, ChannelSpec], names: Iterable[str], unit_of: Callable[[str], str | None]
) -> tuple[dict[str, str], list[str]]:
    """Add the log's steering channel to *mapped* when ``--columns`` maps none, if its name and
    unit say what it is (:func:`recognise_steering`).

    Parameters
    ----------
    mapped : dict
        Key -> :class:`ChannelSpec` of ``--columns``; completed in place.
    names : iterable of str
        The log's channel names in the file's order.
    unit_of : callable
        Channel name -> the unit the file states for it.

    Returns
    -------
    steering : dict
        ``key``, ``channel``, ``unit`` (the file's) and ``source`` (``--columns`` or ``name and
        unit``) of the steering channel read; empty when the log gives none
        (:attr:`gripsense.io.logs.nmea.accounting.IngestReport.steering`).
    notes : list of str
        What the ingest report should say about steering channels found or not used.
    """
    for key in STEERING_CHANNELS:
        if key in mapped:
            ch = mapped[key].channel
            return {"key": key, "channel": ch, "unit": unit_of(ch) or "", "source": "--columns"}, []
    used = {s.channel for s in mapped.values()}
    spec, notes = recognise_steering([n for n in names if n not in used], unit_of)
    if spec is None:
        return {}, notes
    mapped[spec.key] = spec
    unit = unit_of(spec.channel) or ""
    return {
        "key": spec.key,
        "channel": spec.channel,
        "unit": unit,
        "source": "name and unit",
    }, notes
