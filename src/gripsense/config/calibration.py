"""What a vehicle's own driving taught about its tyres: the calibration file.

``gripsense calibrate DRIVES… --vehicle car.toml -o car.calibration.toml`` learns, per axle, the
cornering stiffness at the static load from the linear range of everyday driving (the thesis's
linear-range fit, ``docs/physics.md`` §15.7) with its uncertainty and the drives it came from;
``friction``, ``live`` and ``fleet`` take it (``--calibration FILE``) as the prior of the stiffness
instead of the vehicle file's declaration. The file keeps each drive's least-squares sums, so
adding a drive (``--update``) combines them exactly::

    # gripsense calibration — written by gripsense; learned from the drives listed below
    [calibration]
    vehicle = "Corolla-like sedan (simulation)"

    [calibration.rear]
    cornering_stiffness_N_per_rad = 41250.0   # one wheel at the static load
    stiffness_uncertainty = 0.032             # relative, 1σ
    scale = 1.031                             # over the vehicle file's declaration
    bins = 412

    [[calibration.drive]]
    file = "monday.nmea.gz"
    sha256 = "…"
    axle = "rear"
    bins = 201
    sums = [ … ]                              # XᵀWX (2 × 2), XᵀWk (2), kᵀWk, centred

With a steering-torque channel the file also keeps the steering's lever at low grip (the caster
plus zero-slip pneumatic trail times the channel's scale, ``docs/physics.md`` §16.8), which the
torque estimator then takes as a constraint of its trail nuisances::

    [calibration.steering]
    lever_m = 0.0391                          # k (t_c + t₀), moment at the axes per axle force
    lever_uncertainty = 0.031                 # relative, 1σ
    bins = 388

(its drives have ``axle = "steering"``, their sums those of the lever and the friction).

A drive that took an axle near its limit also says what it taught of the axle's curve shape:
its record keeps the deviance of each shape of :data:`~gripsense.physics.shape_grid.LEARN_GRID`
(``shape = [...]``, ``docs/physics.md`` §15.10), which :func:`apply_calibration` combines into
the tyre's ``shape_evidence``. Every drive and axle table is marked with the tyres it was driven
on (``tyre_set``, from the vehicle file's ``[tyre.front|rear] tyre_set``): learning on another
set is kept in the file but not applied.

Where the drives disagreed (``docs/calibration.md``) an axle's table also keeps the line
``calibrate`` said, ``drives_disagree = "…"``, which ``friction`` repeats; a declaration more
than 2 combined σ from the learned stiffness is not blended with it (:func:`apply_calibration`,
:func:`stiffness_conflict`).

Unknown keys are errors, like everywhere else. Every number has the range the reader accepts
(:data:`AXLE_LIMITS`, :data:`STEERING_LIMITS`), and the writer keeps to it: a learned value
outside it (a slalom's stiffness known to ±800 %) is not written — the file says why in a
comment, and keeps the drives' sums so that more drives (``--update``) can learn it — and the
text is read back with the same reader before anyone installs it, so gripsense never writes a
calibration that ``friction`` or ``calibrate --update`` would refuse.
"""

from __future__ import annotations

import dataclasses
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gripsense.config.toml_reader import TomlReader
from gripsense.config.vehicle import Tyre, Vehicle
from gripsense.errors import InputError
from gripsense.io.text import read_toml
from gripsense.physics.shape_grid import LEARN_GRID, learned_evidence, possible_members

__all__ = [
    "AXLE_KEYS",
    "AXLE_LIMITS",
    "STEERING_LIMITS",
    "AxleCalibration",
    "Calibration",
    "DriveSums",
    "SteeringCalibration",
    "apply_calibration",
    "calibrated_vehicle",
    "calibration_toml",
    "parse_calibration",
    "read_calibration",
    "shape_lines",
    "stiffness_conflict",
    "usable_calibration",
]

AXLE_KEYS = ("cornering_stiffness_N_per_rad", "stiffness_uncertainty", "scale", "bins")
AXLE_NOTE_KEY = "drives_disagree"
"""Optional text key of ``[calibration.front|rear]``: the line ``calibrate`` said when the
drives' learnings disagreed and the uncertainty was widened (``friction`` repeats it)."""
CONFLICT_SIGMAS = 2.0
"""A declaration and a learned value (or two learnings) conflict when they differ by more than
this many combined standard deviations (in ln C) [-] (``docs/physics.md`` §15.7)."""
DRIVE_KEYS = ("file", "sha256", "axle", "bins", "sums", "tyre_set", "shape")
"""Keys of ``[[calibration.drive]]``; ``tyre_set`` (the tyres it was driven on) and ``shape``
(what it said of the axle's curve shape, one deviance per shape of
:data:`~gripsense.physics.shape_grid.LEARN_GRID`) are written when there is something to say."""
AXLE_TEXT_KEYS = (AXLE_NOTE_KEY, "tyre_set")
STEERING_KEYS = ("lever_m", "lever_uncertainty", "bins")
N_SUMS = {"front": 7, "rear": 7, "steering": 7}  # 2 × 2 + 2 + 1

AXLE_LIMITS: dict[str, tuple[float, float, str]] = {
    "cornering_stiffness_N_per_rad": (1e3, 1e6, "N/rad"),
    "stiffness_uncertainty": (0.001, 1.0, "-"),
    "scale": (0.05, 20.0, "-"),
    "bins": (1, 1e9, "-"),
}
"""Key of ``[calibration.front|rear]`` -> (low, high, unit): what the reader accepts, and so
what the writer may write (a learned value outside is left out with the reason)."""
STEERING_LIMITS: dict[str, tuple[float, float, str]] = {
    "lever_m": (0.002, 0.5, "m"),
    "lever_uncertainty": (0.001, 1.0, "-"),
    "bins": (1, 1e9, "-"),
}
"""Key of ``[calibration.steering]`` -> (low, high, unit), as :data:`AXLE_LIMITS`."""
_DIGITS = {
    "cornering_stiffness_N_per_rad": ".1f",
    "stiffness_uncertainty": ".4f",
    "scale": ".4f",
    "bins": "d",
    "lever_m": ".6f",
    "lever_uncertainty": ".4f",
}
"""How the writer formats each number (the limits are checked on the value as written)."""


@dataclass(frozen=True)
class DriveSums:
    """One drive's weighted least-squares sums of one axle's linear-range fit.

    Attributes
    ----------
    file : str
        The drive's file name.
    sha256 : str
        Its content hash (the same drive is not counted twice).
    axle : str
        ``front`` or ``rear`` (the stiffness), or ``steering`` (the steering's lever).
    bins : int
        Bins used.
    sums : numpy.ndarray
        XᵀWX (2 × 2, row-major), XᵀWk (2) and kᵀWk of the drive's bins centred on their
        weighted means: 7 numbers.
    tyre_set : str
        The tyres it was driven on (the axle's, the front's for the steering; ``""``: not
        named).
    shape : numpy.ndarray or None
        What the drive said of the axle's normalised curve shape: the deviance of each shape of
        :data:`~gripsense.physics.shape_grid.LEARN_GRID` (``docs/physics.md`` §15.10) [-]; None
        when it did not tell the shapes apart (it never left the linear range).
    """

    file: str
    sha256: str
    axle: str
    bins: int
    sums: np.ndarray
    tyre_set: str = ""
    shape: np.ndarray | None = None


@dataclass(frozen=True)
class AxleCalibration:
    """The learned stiffness of one axle.

    Attributes
    ----------
    cornering_stiffness_N_per_rad : float
        One wheel's cornering stiffness at the static load [N/rad].
    stiffness_uncertainty : float
        Its relative 1σ [-].
    scale : float
        Learned over declared stiffness [-].
    bins : int
        Bins of all drives used.
    drives_disagree : str
        One line when the drives' learnings disagreed beyond 2σ and the uncertainty was widened
        to cover them (``""``: they agree; :func:`gripsense.estimate.calibration.solve_sums`).
    tyre_set : str
        The tyres it was learned on (``""``: not named); it is applied to these tyres only.
    """

    cornering_stiffness_N_per_rad: float
    stiffness_uncertainty: float
    scale: float
    bins: int
    drives_disagree: str = ""
    tyre_set: str = ""


@dataclass(frozen=True)
class SteeringCalibration:
    """The learned lever of the steering at low grip.

    Attributes
    ----------
    lever_m : float
        k (t_c + t₀): the moment at the steering axes per front axle force at low grip, the
        caster plus zero-slip pneumatic trail times the torque channel's scale [m].
    lever_uncertainty : float
        Its relative 1σ [-].
    bins : int
        Bins of all drives used.
    """

    lever_m: float
    lever_uncertainty: float
    bins: int


@dataclass(frozen=True)
class Calibration:
    """A calibration file's content.

    Attributes
    ----------
    vehicle : str
        The vehicle's name (a calibration of another vehicle is refused).
    axles : dict
        ``front`` / ``rear`` → :class:`AxleCalibration`.
    drives : list of DriveSums
        What it was learned from.
    source : str
        The file, for messages.
    steering : SteeringCalibration or None
        The steering's lever, when the drives had a torque channel.
    left_out : dict
        ``front`` / ``rear`` / ``steering`` / ``drive …`` / ``tyres …`` -> why a learned part
        was not kept or drives were not used (:func:`usable_calibration`; the file writes it as
        a comment).
    repeated : tuple of str
        Drives given again that the calibration already held (same content): not counted
        twice (not written; ``calibrate`` says so).
    """

    vehicle: str
    axles: dict[str, AxleCalibration]
    drives: list[DriveSums] = field(default_factory=list)
    source: str = "<calibration>"
    steering: SteeringCalibration | None = None
    left_out: dict[str, str] = field(default_factory=dict)
    repeated: tuple[str, ...] = ()


def read_calibration(path: str | Path) -> Calibration:
    """Read a calibration file (strict keys).

    Parameters
    ----------
    path : str or Path
        The ``.calibration.toml`` file.

    Returns
    -------
    Calibration
        Its content.
    """
    return _from_doc(read_toml(path), str(path))


def parse_calibration(text: str, source: str = "<calibration>") -> Calibration:
    """Read the text of a calibration file with the same checks as :func:`read_calibration`
    (the writer reads back what it would install).

    Parameters
    ----------
    text : str
        TOML text.
    source : str
        Its name, for messages.

    Returns
    -------
    Calibration
        Its content.
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{source}: not valid TOML ({e})") from None
    return _from_doc(doc, source)


def _from_doc(doc: dict, src: str) -> Calibration:
    r = TomlReader(doc, src)
    r.known(doc, "", ("calibration",))
    t = doc.get("calibration")
    if not isinstance(t, dict):
        raise InputError(f"{src}: no [calibration] table; write one with gripsense calibrate")
    r.known(t, "calibration", ("vehicle", "front", "rear", "steering", "drive"))
    vehicle = t.get("vehicle")
    if not isinstance(vehicle, str):
        raise InputError(f"{src}: [calibration] vehicle: a string (the vehicle's name) is needed")
    axles = {}
    for axle in ("front", "rear"):
        a = t.get(axle)
        if a is None:
            continue
        where = f"calibration.{axle}"
        if not isinstance(a, dict):
            raise InputError(f"{src}: [{where}] must be a table")
        r.known(a, where, (*AXLE_KEYS, *AXLE_TEXT_KEYS))
        c, u, s, n = _limited(r, a, where, AXLE_LIMITS)
        note, tyre_set = (_text(a, key, f"{src}: [{where}]") for key in AXLE_TEXT_KEYS)
        axles[axle] = AxleCalibration(c, u, s, int(n), note, tyre_set)
    steering = None
    st = t.get("steering")
    if st is not None:
        if not isinstance(st, dict):
            raise InputError(f"{src}: [calibration.steering] must be a table")
        r.known(st, "calibration.steering", STEERING_KEYS)
        lever, u, n = _limited(r, st, "calibration.steering", STEERING_LIMITS)
        steering = SteeringCalibration(lever, u, int(n))
    drives = []
    if not isinstance(t.get("drive", []), list):
        raise InputError(
            f"{src}: calibration.drive: an array of tables is needed ([[calibration.drive]])"
        )
    for i, d in enumerate(t.get("drive", []) or []):
        where = f"calibration.drive[{i}]"
        if not isinstance(d, dict):
            raise InputError(f"{src}: {where}: a table is needed")
        r.known(d, where, DRIVE_KEYS)
        sums = d.get("sums")
        if d.get("axle") not in N_SUMS:
            raise InputError(
                f"{src}: {where}: axle = {d.get('axle')!r}; use front, rear or steering"
            )
        need = N_SUMS[d["axle"]]
        if not (isinstance(sums, list) and len(sums) == need):
            raise InputError(f"{src}: {where}: sums: {need} numbers are needed")
        if not all(
            isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v) for v in sums
        ):
            raise InputError(
                f"{src}: {where}: sums: {need} finite numbers are needed; write the file again "
                "with gripsense calibrate"
            )
        bins = r.num(d, where, "bins", unit="-", required=False, plausible=(0, 1e9))
        drives.append(
            DriveSums(
                str(d.get("file", "")),
                str(d.get("sha256", "")),
                str(d["axle"]),
                int(bins or 0),
                np.asarray(sums, dtype=float),
                _text(d, "tyre_set", f"{src}: {where}"),
                _shape(d, f"{src}: {where}"),
            )
        )
    return Calibration(vehicle, axles, drives, src, steering)


def _text(t: dict, key: str, where: str) -> str:
    """An optional text key (``""`` when absent)."""
    v = t.get(key, "")
    if not isinstance(v, str):
        raise InputError(f"{where} {key}: a string is needed")
    return v


def _shape(d: dict, where: str) -> np.ndarray | None:
    """A drive's shape evidence: one deviance ≥ 0 (or ``inf``) per shape of the learning grid,
    0 at the drive's best.
    """
    v = d.get("shape")
    if v is None:
        return None
    how = "write the file again with gripsense calibrate (its drives' logs are needed)"
    if not (isinstance(v, list) and len(v) == len(LEARN_GRID)):
        raise InputError(
            f"{where}: shape: {len(LEARN_GRID)} numbers are needed (one per shape of this "
            f"gripsense's learning grid); {how}"
        )
    if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in v):
        raise InputError(f"{where}: shape: numbers are needed; {how}")
    a = np.asarray(v, dtype=float)
    if np.isnan(a).any() or (a < 0).any() or not np.isfinite(a).any() or np.min(a) != 0:
        raise InputError(
            f"{where}: shape: deviances ≥ 0 with 0 at the best shape are needed; {how}"
        )
    return a


def _limited(r: TomlReader, t: dict, where: str, limits: dict) -> list[float]:
    """The numbers of one table, each required and within its limits."""
    out = []
    for key, (lo, hi, unit) in limits.items():
        v = r.num(t, where, key, unit=unit, plausible=(lo, hi))
        out.append(float(v if v is not None else np.nan))
    return out


_HOW = {
    "stiffness_uncertainty": (
        "these drives change the lateral force too little, or too fast, for the linear-range "
        "fit; add drives with steady curves in both directions (gripsense calibrate --update "
        "adds them to the sums this file keeps)"
    ),
    "lever_uncertainty": (
        "these drives hold too few steady low-grip curves; add drives (--update adds them to the "
        "sums this file keeps)"
    ),
}
_HOW_RANGE = (
    "check the steering channel's unit and sign and the vehicle file's declared stiffness, or "
    "add drives with steady curves in both directions (--update adds them to the sums this file "
    "keeps)"
)


def _outside(part: object, limits: dict) -> str:
    """Why a learned part cannot be written (``""`` when it can): the first value that, as
    the writer formats it, is outside what the reader accepts.
    """
    for key, (lo, hi, unit) in limits.items():
        v = getattr(part, key)
        written = float(format(v, _DIGITS[key])) if np.isfinite(v) else v
        if not (np.isfinite(written) and lo <= written <= hi):
            u = "" if unit == "-" else f" {unit}"
            if key.endswith("uncertainty") and np.isfinite(v) and v > hi:
                what = f"{key} would be {100 * v:,.0f} %".replace(",", " ")
                return f"{what} (a calibration holds at most {100 * hi:.0f} %): {_HOW[key]}"
            return f"{key} = {v:.6g}{u} is outside {lo:g}–{hi:g}{u}: {_HOW_RANGE}"
    return ""


def usable_calibration(cal: Calibration) -> Calibration:
    """The calibration without the learned parts a calibration file may not hold: an axle or
    the steering's lever with a value outside :data:`AXLE_LIMITS` / :data:`STEERING_LIMITS`
    (as written), a drive whose sums are not finite; each with its reason in ``left_out``.

    Parameters
    ----------
    cal : Calibration
        As learned.

    Returns
    -------
    Calibration
        What :func:`calibration_toml` writes and :func:`read_calibration` reads back.
    """
    left = dict(cal.left_out)
    axles = {}
    for axle, a in cal.axles.items():
        why = _outside(a, AXLE_LIMITS)
        if why:
            left[axle] = f"{axle} axle not learned: {why}"
        else:
            axles[axle] = a
    steering = cal.steering
    if steering is not None:
        why = _outside(steering, STEERING_LIMITS)
        if why:
            left["steering"] = f"steering lever not learned: {why}"
            steering = None
    drives = []
    for d in cal.drives:
        written = [float(f"{v:.10g}") for v in np.asarray(d.sums, dtype=float)]
        if np.isfinite(written).all() and d.axle in N_SUMS and len(written) == N_SUMS[d.axle]:
            drives.append(d)
        else:
            left[f"drive {d.file} ({d.axle})"] = (
                f"drive {d.file!r} ({d.axle}) not kept: its sums are not finite numbers"
            )
    return dataclasses.replace(cal, axles=axles, steering=steering, drives=drives, left_out=left)


def calibration_toml(cal: Calibration) -> str:
    """The text of a calibration file (the header marks it as gripsense's own output).

    Only what :func:`read_calibration` accepts is written (:func:`usable_calibration`: a part
    left out is named in a comment with the reason), and the text is read back with the same
    reader before it is returned.

    Parameters
    ----------
    cal : Calibration
        The content.

    Returns
    -------
    str
        TOML text.

    Raises
    ------
    InputError
        When the text would not read back as *cal* (nothing is written then).
    """
    cal = usable_calibration(cal)
    out = [
        "# gripsense calibration — written by gripsense; learned from the drives listed below",
        "# (per axle: one wheel's cornering stiffness at the static load, docs/physics.md §15.7)",
        *(f"# {_comment(why)}" for why in cal.left_out.values()),
        "[calibration]",
        f"vehicle = {_q(cal.vehicle)}",
    ]
    for axle, a in sorted(cal.axles.items()):
        out += [
            "",
            f"[calibration.{axle}]",
            f"cornering_stiffness_N_per_rad = {a.cornering_stiffness_N_per_rad:.1f}",
            f"stiffness_uncertainty = {a.stiffness_uncertainty:.4f}",
            f"scale = {a.scale:.4f}",
            f"bins = {a.bins}",
        ]
        if a.drives_disagree:
            out.append(f"{AXLE_NOTE_KEY} = {_q(_comment(a.drives_disagree))}")
        if a.tyre_set:
            out.append(f"tyre_set = {_q(a.tyre_set)}")
    if cal.steering is not None:
        out += [
            "",
            "[calibration.steering]",
            f"lever_m = {cal.steering.lever_m:.6f}",
            f"lever_uncertainty = {cal.steering.lever_uncertainty:.4f}",
            f"bins = {cal.steering.bins}",
        ]
    for d in cal.drives:
        sums = ", ".join(f"{v:.10g}" for v in d.sums)
        out += [
            "",
            "[[calibration.drive]]",
            f"file = {_q(d.file)}",
            f"sha256 = {_q(d.sha256)}",
            f"axle = {_q(d.axle)}",
            f"bins = {d.bins}",
            f"sums = [{sums}]",
        ]
        if d.tyre_set:
            out.append(f"tyre_set = {_q(d.tyre_set)}")
        if d.shape is not None:
            out.append(f"shape = [{', '.join(_deviance(v) for v in d.shape)}]")
    text = "\n".join(out) + "\n"
    back = parse_calibration(text, "the calibration to be written")
    if back.vehicle != cal.vehicle or set(back.axles) != set(cal.axles):
        raise InputError(
            f"the calibration of {cal.vehicle!r} would not read back as written; not written "
            "(a bug: please report it)"
        )
    return text


def _deviance(v: float) -> str:
    """A shape's deviance as written: 4 significant digits, ``inf`` beyond what any interval
    level can reach (more than :data:`DEVIANCE_CAP`).
    """
    return "inf" if not v <= DEVIANCE_CAP else f"{v:.4g}"


DEVIANCE_CAP = 1e4
"""A drive's deviance of a shape beyond this is written ``inf`` (excluded at any level) [-]."""


def _comment(text: str) -> str:
    return "".join(c if c.isprintable() else " " for c in text)


def _q(s: str) -> str:
    """A TOML basic string: control characters escaped, text that is not Unicode (a file name
    of undecodable bytes) with replacement characters.
    """
    try:
        raw = s.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:
        raw = s.encode("utf-8", "replace")
    out = []
    for ch in raw.decode("utf-8", "replace"):
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def apply_calibration(
    vehicle: Vehicle, cal: Calibration, notes: list[str] | None = None
) -> Vehicle:
    """The vehicle with each calibrated axle's stiffness and its uncertainty taken from *cal*.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle file's description.
    cal : Calibration
        A calibration of this vehicle.
    notes : list of str, optional
        Receives one line per conflict (:func:`stiffness_conflict`) and per axle whose drives
        disagreed (its ``drives_disagree``), for the command to print.

    Returns
    -------
    Vehicle
        The description the estimators use: per axle the declaration and the learned stiffness
        combined by their uncertainties (in ln C: the vehicle file's value is the prior, the
        drives the data) — a calibration that knows less than the vehicle file (a receiver too
        noisy for the slips of everyday driving) leaves the declaration nearly as it is, never
        widens it; where the two conflict (more than :data:`CONFLICT_SIGMAS` combined σ apart)
        the learned stiffness and its uncertainty alone (the car's own data outrank a
        datasheet; a blend would be a value neither supports); the steering's learned lever, a
        constraint the torque estimator adds to its trail priors (docs/physics.md §16.8); the
        members of the prior family its drives on the fitted tyres leave possible
        (``shape_members``, §15.10). An axle learned on another ``tyre_set`` keeps its
        declaration (a note says so).
    """
    if cal.vehicle != vehicle.name:
        raise InputError(
            f"{cal.source}: a calibration of {cal.vehicle!r}, not of {vehicle.name!r}; "
            "use the vehicle's own calibration file"
        )
    tyres = dict(vehicle.tyres)
    for axle in tyres:  # the curve's shape, from every drive on these tyres that taught it
        tyres[axle] = _with_shape(tyres[axle], axle, cal, notes)
    for axle, a in cal.axles.items():
        if axle not in tyres:
            continue
        if a.tyre_set != tyres[axle].tyre_set:
            if notes is not None:
                notes.append(_other_tyres(axle, a.tyre_set, tyres[axle].tyre_set, cal.source))
            continue
        c_d = float(vehicle.cornering_stiffness(axle, vehicle.static_load(axle)))
        if notes is not None and a.drives_disagree:
            notes.append(a.drives_disagree)
        conflict = stiffness_conflict(axle, c_d, tyres[axle].stiffness_uncertainty, a)
        if conflict:
            if notes is not None:
                notes.append(conflict)
            c_n, u_n = a.cornering_stiffness_N_per_rad, a.stiffness_uncertainty
        else:
            w_d = 1.0 / np.log1p(tyres[axle].stiffness_uncertainty) ** 2
            w_l = 1.0 / np.log1p(a.stiffness_uncertainty) ** 2
            ln_c = (w_d * np.log(c_d) + w_l * np.log(a.cornering_stiffness_N_per_rad)) / (w_d + w_l)
            c_n, u_n = float(np.exp(ln_c)), float(np.expm1(1.0 / np.sqrt(w_d + w_l)))
        tyres[axle] = dataclasses.replace(
            tyres[axle], cornering_stiffness_N_per_rad=c_n, stiffness_uncertainty=u_n
        )
    steering = vehicle.steering
    if cal.steering is not None and steering is not None:
        steering = dataclasses.replace(
            steering,
            calibrated_lever_m=cal.steering.lever_m,
            calibrated_lever_uncertainty=cal.steering.lever_uncertainty,
        )
    return dataclasses.replace(vehicle, tyres=tyres, steering=steering)


def shape_lines(vehicle: Vehicle, cal: Calibration) -> list[str]:
    """One line per axle of what its drives taught of the curve's shape (``calibrate`` says
    them): the drives, the shapes they leave within the 95 % level, the closest Magic Formula
    one and how many shapes of the prior family stay possible on another road
    (:func:`~gripsense.physics.shape_grid.possible_members`), or that no drive on these tyres
    took the axle near its limit.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (its tyres' ``tyre_set``).
    cal : Calibration
        The calibration.

    Returns
    -------
    list of str
        One line per axle of *vehicle*.
    """
    from scipy.stats import chi2

    from gripsense.physics.tyre_curves import shape_members

    out = []
    notes: list[str] = []
    for axle, tyre in vehicle.tyres.items():
        d, n = _learned_shape(tyre, axle, cal, notes)
        if d is None:
            out.append(
                f"{axle} axle: curve shape not learned (no drive took it near its limit; a "
                "steady-state sweep or a track session teaches it, docs/calibration.md)"
            )
            continue
        kept = int(np.sum(d <= chi2.ppf(0.95, 2)))
        best = LEARN_GRID[int(np.argmin(d))]
        members = possible_members(d, tyre.shape)
        out.append(
            f"{axle} axle: curve shape learned from {n} drive(s): {kept} of {len(LEARN_GRID)} "
            f"shapes within the 95 % level, closest {best.name}; on another road "
            f"{len(members)} of the {len(shape_members(tyre.shape))} real-tyre shapes stay "
            "possible"
        )
    return out + notes


def _set_name(tyre_set: str) -> str:
    return repr(tyre_set) if tyre_set else "(not named)"


def _other_tyres(axle: str, learned_on: str, fitted: str, source: str) -> str:
    """The line that says a calibration was learned on other tyres than those fitted."""
    return (
        f"{source}: {axle} axle: learned on tyre set {_set_name(learned_on)}, but the vehicle "
        f"file's {axle} tyres are {_set_name(fitted)}: the declared stiffness is used; learn "
        f"the new tyres with gripsense calibrate --update (drives on them)"
    )


def _with_shape(tyre: Tyre, axle: str, cal: Calibration, notes: list[str] | None) -> Tyre:
    """The tyre with the members of its prior family that its drives on the tyres fitted leave
    possible on another road (``docs/physics.md`` §15.10); as it is when no drive taught the
    shape.
    """
    deviance, _ = _learned_shape(tyre, axle, cal, notes)
    if deviance is None:
        return tyre
    return dataclasses.replace(tyre, shape_members=possible_members(deviance, tyre.shape))


def _learned_shape(
    tyre: Tyre, axle: str, cal: Calibration, notes: list[str] | None
) -> tuple[np.ndarray | None, int]:
    """The deviance per shape the drives on the fitted tyres taught together and how many drives
    (None, 0 when none did); a line in *notes* when they disagree or learned on other tyres.
    """
    mine = [d for d in cal.drives if d.axle == axle and d.shape is not None]
    fitted = [d for d in mine if d.tyre_set == tyre.tyre_set]
    if not fitted:
        if mine and notes is not None and not cal.axles.get(axle):
            sets = sorted({d.tyre_set for d in mine})
            notes.append(_other_tyres(axle, sets[0], tyre.tyre_set, cal.source))
        return None, 0
    deviance, disagree = learned_evidence([d.shape for d in fitted if d.shape is not None])
    if disagree and notes is not None:
        names = ", ".join(sorted({d.file for d in fitted}))
        notes.append(
            f"{axle} axle: the curve shapes learned from {names} disagree (no shape explains "
            f"them all at 2σ): the learned shape covers each drive's instead of a blend"
        )
    return deviance, len(fitted)


def calibrated_vehicle(
    vehicle: Vehicle | str | Path,
    calibration: Calibration | str | Path | None = None,
    notes: list[str] | None = None,
) -> Vehicle:
    """A vehicle description with its calibration applied: *calibration* when given, else the
    file the vehicle file names (``[calibration] file``), else the declaration as it is.

    Parameters
    ----------
    vehicle : Vehicle or str or Path
        The vehicle or its file.
    calibration : Calibration or str or Path, optional
        A calibration of this vehicle or its file.
    notes : list of str, optional
        Receives the conflicts' lines (:func:`apply_calibration`).

    Returns
    -------
    Vehicle
        The description the estimators use (its ``calibration_file`` cleared once applied).
    """
    veh = vehicle if isinstance(vehicle, Vehicle) else Vehicle.from_toml(vehicle)
    if calibration is None:
        calibration = veh.calibration_file
    if calibration is None:
        return veh
    cal = calibration if isinstance(calibration, Calibration) else read_calibration(calibration)
    return dataclasses.replace(apply_calibration(veh, cal, notes), calibration_file=None)


def stiffness_conflict(
    axle: str, declared_N_per_rad: float, declared_uncertainty: float, learned: AxleCalibration
) -> str:
    """The line that says a declared and a learned stiffness conflict, or ``""``.

    They conflict when their logarithms differ by more than :data:`CONFLICT_SIGMAS` times the
    combined σ, √(ln²(1 + u_d) + ln²(1 + u_l)) (the relative uncertainties as
    :func:`apply_calibration` combines them); the learned value is then used alone.

    Parameters
    ----------
    axle : str
        ``front`` or ``rear``.
    declared_N_per_rad : float
        The vehicle file's stiffness of one wheel at the static load [N/rad].
    declared_uncertainty : float
        Its relative 1σ [-].
    learned : AxleCalibration
        The learned stiffness.

    Returns
    -------
    str
        One line naming the axle, both values with their σ and which is used.
    """
    c_l, u_l = learned.cornering_stiffness_N_per_rad, learned.stiffness_uncertainty
    sd = float(np.hypot(np.log1p(declared_uncertainty), np.log1p(u_l)))
    if not (declared_N_per_rad > 0 and c_l > 0 and sd > 0):
        return ""
    z = abs(float(np.log(c_l / declared_N_per_rad))) / sd
    if not z > CONFLICT_SIGMAS:
        return ""
    return (
        f"{axle} axle: the vehicle file's cornering stiffness {_n(declared_N_per_rad)} N/rad "
        f"± {100 * declared_uncertainty:.0f} % and the learned {_n(c_l)} N/rad "
        f"± {100 * u_l:.1f} % disagree ({z:.1f}σ apart); used: the learned {_n(c_l)} N/rad "
        f"± {100 * u_l:.1f} % (the car's own drives outrank the declaration, no blend)"
    )


def _n(x: float) -> str:
    """A stiffness for a message: whole N/rad with a thin space between thousands."""
    return f"{x:,.0f}".replace(",", " ")
