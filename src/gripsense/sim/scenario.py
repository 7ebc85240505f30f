"""Scenario files: which drives to simulate and which sensors to emulate, TOML in, files out.

Layout (see ``gripsense/data/demo_scenario.toml``)::

    [scenario]
    name = "thesis-2018 grid"
    vehicle = "corolla_sim.toml"    # relative to the scenario file, or a bundled file name
    seed = 1
    drive = "front"                 # front | rear | all
    relaxation_length_m = 0.0       # first-order tyre lag (0: none)
    tyre = "brush"                  # or a .tir / PAC89 .json path (next to the scenario or
                                    # bundled: "PacejkaBook_Defaults.tir"), or per axle:
                                    # { front = "brush", rear = "Sedan_Pac02Tire.tir" }

    [road]
    mu = 0.9                        # outside the patches
    patches = [{ x_m = [0, 50], y_m = [-30, 30], mu = 0.3 }]   # optional, later wins

    [gnss]
    rate_hz = 10
    noise = "v100"                  # v100 | white-0.3 | rtk | none; single terms may be
    mounting_offset_deg = 0.5       # overridden here

    [steering]                      # optional: a road-wheel angle channel <id>_steer.csv
    rate_hz = 50
    noise_deg = 0.05                # white noise, 1 σ
    scale_error = 0.03              # the channel reads (1 + scale_error) × the true angle
    offset_deg = 0.0
    torque = false                  # true: also torque_Nm at torque_rate_hz (the column torque
                                    # of the vehicle file's [steering], docs/physics.md §16.4)

    [accelerometer]                 # optional: 50 Hz CSV for the braking test
    rate_hz = 50
    pitch_deg = 1.0

    [[case]]                        # one drive ...
    maneuver = "circle"             # circle | constant_radius | fixed_steer | ramp_steer |
                                    # sine_with_dwell | everyday | slalom | braking (their
                                    # keys: MANEUVER_KEYS, docs/simulation.md)
    speed_kmh = 30
    radius_m = 25
    laps = 2

    [[grid]]                        # ... or every combination of the listed values
    maneuver = "circle"
    speed_kmh = [20, 30, 40, 50]
    radius_m = [20, 30, 40]
    mu = [0.9, 0.5]                 # optional: the road μ as a grid dimension, and
    tyre = ["brush", "PacejkaBook_Defaults.tir"]   # the tyre and
    receiver = ["v100", "rtk"]      # the receiver: a class, "none" or a TOML file with a
                                    # [receiver] table (overrides [gnss] noise)
    laps = 2

Output folder: ``vehicle.toml`` (the vehicle used), for cases with tyres from files
``vehicle_<tyre>.toml`` (the vehicle file a user would write for them: the tyre's cornering
stiffness at the static load instead of the brush parameters, :func:`gripsense.sim.drives.
user_vehicle_toml`); every vehicle file a case names carries the ``[receiver]`` that recorded
it (several receivers in one scenario: one file per receiver, ``vehicle_<receiver>.toml``,
``vehicle_<tyre>_<receiver>.toml``); ``cases.csv`` (one row per case with its parameters, road
μ, receiver, the vehicle file to estimate with, a ``warning`` when the case cannot be driven as
asked, and file names: ``log``, and ``columns`` when reading it needs a channel mapping), and
per case the emulated receiver's log: ``<id>.nmea.gz`` (NMEA),
or with ``--format`` ``<id>.vbo`` (VBOX, with the steering channel inside), ``<id>.ubx`` (UBX
frames interleaved with the NMEA sentences) or ``<id>.mf4`` (MDF4, with the steering channel),
``<id>_truth.parquet`` (per epoch and wheel: true μ — the wheel's peak friction at its load and
inclination —, road μ, inclination, slip angle, load, lateral force), with ``[accelerometer]``
``<id>_accel.csv`` and with ``[steering]`` ``<id>_steer.csv``.
"""

from __future__ import annotations

import itertools
import json
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.config.receiver import EXACT, RECEIVERS
from gripsense.config.scenario_schema import (
    ACCELEROMETER,
    GNSS,
    ROAD,
    SCENARIO,
    STEERING_CHANNEL,
)
from gripsense.config.scenario_schema import SCENARIO_TABLES as TABLES
from gripsense.config.toml_reader import TomlReader
from gripsense.errors import InputError
from gripsense.io.logs import SUFFIXES, WRITABLE, write_log
from gripsense.io.output_folder import ResultWriter
from gripsense.io.text import read_toml
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import OLD_NOISE_KEYS, CompassNoise, emulate_compass
from gripsense.sim.sensors import emulate_accelerometer, emulate_steering
from gripsense.sim.tyres import SimTyre, load_sim_tyre
from gripsense.sim.vehicle import SimParams

__all__ = ["MANEUVER_KEYS", "demand_warning", "run_scenario"]

SCENARIO_TABLES = (*(t.name for t in TABLES), "case", "grid")
CASE_KEYS = ("maneuver", "mu", "name", "tyre", "receiver")  # besides the manoeuvre's own

_ARGS: dict[str, tuple[Callable[..., M.Maneuver], dict[str, tuple[str, float]]]] = {
    # maneuver -> (builder, {scenario key: (builder argument, scale)})
    "circle": (
        M.circle,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "radius_m": ("radius_m", 1.0),
            "laps": ("laps", 1.0),
            "lead_s": ("lead_s", 1.0),
        },
    ),
    "fixed_steer": (
        M.fixed_steer,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "steer_deg": ("steer_rad", np.pi / 180),
            "duration_s": ("duration_s", 1.0),
        },
    ),
    "ramp_steer": (
        M.ramp_steer,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "rate_deg_s": ("rate_rad_s", np.pi / 180),
            "max_steer_deg": ("max_steer_rad", np.pi / 180),
            "hold_s": ("hold_s", 1.0),
        },
    ),
    "everyday": (
        M.everyday,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "seed": ("seed", 1.0),
            "curves": ("curves", 1.0),
            "hold_s": ("hold_s", 1.0),
            "max_steer_deg": ("max_steer_deg", 1.0),
            "lead_s": ("lead_s", 1.0),
        },
    ),
    "constant_radius": (
        M.constant_radius,
        {
            "radius_m": ("radius_m", 1.0),
            "speed_start_kmh": ("speed_start_mps", 1 / 3.6),
            "speed_end_kmh": ("speed_end_mps", 1 / 3.6),
            "accel_mps2": ("accel_mps2", 1.0),
        },
    ),
    "sine_with_dwell": (
        M.sine_with_dwell,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "amplitude_deg": ("amplitude_rad", np.pi / 180),
            "frequency_hz": ("frequency_hz", 1.0),
            "dwell_s": ("dwell_s", 1.0),
        },
    ),
    "slalom": (
        M.slalom,
        {
            "speed_kmh": ("speed_mps", 1 / 3.6),
            "amplitude_deg": ("amplitude_rad", np.pi / 180),
            "period_s": ("period_s", 1.0),
            "cycles": ("cycles", 1.0),
        },
    ),
    "braking": (M.braking, {"speed_kmh": ("speed_mps", 1 / 3.6), "cruise_s": ("cruise_s", 1.0)}),
}
"""Manoeuvre → (builder, {scenario key: (builder argument, scale)}): the keys a ``[[case]]`` or
``[[grid]]`` of that manoeuvre takes (docs/simulation.md lists them)."""

_COUNTS = ("cycles", "seed", "curves")  # builder arguments that are whole numbers

MANEUVER_KEYS = {kind: tuple(keys) for kind, (_, keys) in _ARGS.items()}
"""Manoeuvre → the scenario keys it takes (besides ``maneuver``, ``mu``, ``name``, ``tyre``,
``receiver``)."""


def _fail(src: str, where: str, msg: str) -> NoReturn:
    raise InputError(f"{src}: {where}: {msg}")


_POSITIVE = (
    "speed_kmh", "speed_start_kmh", "speed_end_kmh", "radius_m", "laps", "period_s",
    "frequency_hz", "rate_deg_s", "accel_mps2", "max_steer_deg",
)  # fmt: skip

DEMAND_LIMIT = 1.25
"""A circle asking for more lateral acceleration than this times μ g (the most grip anywhere on
the road) is beyond any tyre: the scenario is simulated with a warning."""


def demand_warning(m: M.Maneuver, mu_max: float) -> str | None:
    """What a steady-circle manoeuvre asks of the road, when it is far beyond what it gives.

    A circle of radius R at speed v needs the lateral acceleration a_y = v²/R (thesis eq. 4.5,
    docs/physics.md §4.4); no tyre gives much more than μ g (§14), so a demand above
    :data:`DEMAND_LIMIT` μ g cannot be driven: the car runs wide.

    Parameters
    ----------
    m : Maneuver
        The manoeuvre (its ``info``: ``circle`` or ``constant_radius``).
    mu_max : float
        The largest road μ of the drive (outside and inside patches) [-].

    Returns
    -------
    str or None
        One sentence, or None when the demand is within reach (or not a circle).
    """
    info = m.info
    if info.get("maneuver") == "circle":
        v = float(info["speed_mps"])
    elif info.get("maneuver") == "constant_radius":
        v = float(info["speed_end_mps"])
    else:
        return None
    a_g = v**2 / float(info["radius_m"]) / 9.80665
    if a_g <= DEMAND_LIMIT * mu_max:
        return None
    return (
        f"{m.name} asks for a lateral acceleration v²/R = {a_g:.2g} g on a road of μ ≤ "
        f"{mu_max:g}: far beyond the limit (about μ g), the car cannot follow the circle and "
        "runs wide — simulated as asked, but it is no steady circle"
    )


def _maneuver(spec: dict, src: str, where: str, params: SimParams) -> M.Maneuver:
    kind = spec.get("maneuver")
    if kind not in _ARGS:
        _fail(src, where, f"maneuver = {kind!r}; use one of {sorted(_ARGS)}")
    builder, keys = _ARGS[kind]
    kw: dict[str, object] = {}
    for k, v in spec.items():
        if k in CASE_KEYS:
            continue
        if k not in keys:
            _fail(src, where, f"unknown key {k!r} for {kind}; known: {sorted(keys)}")
        if isinstance(v, bool) or not isinstance(v, int | float):
            _fail(src, where, f"{k} = {v!r} must be a number")
        if k in _POSITIVE and not v > 0:
            _fail(src, where, f"{k} = {v!r} must be > 0")
        arg, scale = keys[k]
        if arg in _COUNTS and (float(v) != int(v) or v < (0 if arg == "seed" else 1)):
            _fail(
                src, where, f"{k} = {v!r} must be a whole number{'' if arg == 'seed' else ' ≥ 1'}"
            )
        kw[arg] = int(v) if arg in _COUNTS else v * scale
    if kind in ("circle", "constant_radius"):
        kw["params"] = params
    try:
        return builder(**kw)
    except TypeError as e:
        _fail(src, where, f"{e}")


def run_scenario(
    path: str | Path,
    outdir: str | Path,
    *,
    progress=None,
    overwrite: bool = False,
    command: str = "",
    receiver: str | Path | None = None,
    fmt: str = "nmea",
    warn: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Simulate every case of a scenario file and write the outputs (see module docs).

    Parameters
    ----------
    path : path
        Scenario TOML.
    outdir : path
        Output folder: written atomically with a manifest (:class:`gripsense.io.output_folder.
        ResultWriter`); an earlier simulation there is replaced only with *overwrite*.
    progress : callable or None
        Called as ``progress(i, n, case_id)`` before each case.
    overwrite : bool
        Replace an earlier simulation in *outdir*.
    command : str
        Command line recorded in the manifest.
    receiver : str or Path, optional
        The receiver of every case (``gripsense simulate --receiver``): a class of
        :data:`gripsense.config.RECEIVERS`, ``none`` or a TOML file with a ``[receiver]`` table;
        it replaces the scenario's ``[gnss] noise`` and the cases' ``receiver``.
    fmt : {"nmea", "vbo", "ubx", "mf4"}
        Format of the emulated logs (``gripsense simulate --format``;
        :func:`gripsense.io.logs.write_log`).
    warn : callable, optional
        Called with one sentence per case that does not simulate what it says (a circle far
        beyond the road's grip, a diverged integration); the sentence is also the case's
        ``warning`` in ``cases.csv``. Default: :func:`warnings.warn` (``UserWarning``).

    Returns
    -------
    pandas.DataFrame
        The case index written to ``cases.csv``.
    """
    if fmt not in WRITABLE:
        raise InputError(f"--format {fmt!r}: use one of {', '.join(WRITABLE)}")
    path = Path(path)
    src = str(path)
    doc = read_toml(path, "scenario file")
    r = TomlReader(doc, src)
    r.known(doc, "", SCENARIO_TABLES)
    sc = SCENARIO.read(r, r.table("scenario", required=True))
    vref = sc["vehicle"]
    if not vref:
        _fail(src, "[scenario] vehicle", "missing (a vehicle TOML path or bundled name)")
    vpath = _resolve(path, vref, "", src, "[scenario] vehicle", "vehicle")
    vehicle = Vehicle.from_toml(vpath)
    if vehicle.cg_offset is None:
        _fail(
            src,
            "[scenario] vehicle",
            f"{vpath.name} needs [antenna] x_m, y_m (the antenna "
            "position relative to the CG) to emulate the receiver",
        )
    sim_kw = {"drive": sc["drive"], "relaxation_length_m": sc["relaxation_length_m"]}
    default_tyre = sc["tyre"]
    seed = int(sc["seed"])
    mu0, patches = _road(r, src)
    gnss, over = _gnss(r, src)
    default_receiver, rate = gnss["noise"], gnss["rate_hz"]
    acc = steer = None
    if "accelerometer" in doc:
        acc = ACCELEROMETER.read(r, r.table("accelerometer", required=False))
    if "steering" in doc:
        steer = STEERING_CHANNEL.read(r, r.table("steering", required=False))
        for key in ("torque", "assist_channel"):
            if not isinstance(steer[key], bool):
                r.fail("steering", key, f"= {steer[key]!r}: use true or false")

    specs = _cases(doc, mu0, src)

    tyre_cache: dict = {}
    setups = []
    for i, (spec, _) in enumerate(specs):
        where = f"case {i + 1}"
        tyres = _tyres(path, spec.get("tyre", default_tyre), src, where, tyre_cache)
        params = SimParams.from_vehicle(vehicle, sim_tyres=tyres, **sim_kw)
        rec = receiver if receiver is not None else spec.get("receiver", default_receiver)
        noise = _compass(path, rec, src, where)
        if "receiver" not in spec and receiver is None:
            noise = CompassNoise(**{**noise.__dict__, **over})
        setups.append((params, _maneuver(spec, src, where, params), noise, rec))
    if warn is None:

        def warn(msg: str) -> None:
            warnings.warn(msg, UserWarning, stacklevel=3)

    mu_max = max([mu for _, mu in specs] + [pt[4] for pt in patches])
    receivers = {str(rec) for *_, rec in setups}
    inputs = [path, vpath, *(t for t in tyre_cache if isinstance(t, Path))]
    with ResultWriter(
        outdir, "simulation", overwrite=overwrite, command=command, inputs=inputs
    ) as out:
        return _simulate_cases(
            out, specs, setups, vehicle, vpath, patches, rate, acc, steer, seed, progress, fmt,
            warn=lambda cid, msg: warn(f"{src}: {cid}: {msg}"),
            receiver_files={
                r: _receiver_toml(path, r, over if r == str(default_receiver) else {})
                for r in receivers
            },
            mu_max=mu_max,
        )  # fmt: skip


def _road(r: TomlReader, src: str) -> tuple[float, list[tuple]]:
    """The ``[road]`` table: the road's μ and its patches (x0, x1, y0, y1, μ)."""
    road = ROAD.read(r, r.table("road", required=False))
    patches = []
    for k, pt in enumerate(road["patches"] or []):
        try:
            (x0, x1), (y0, y1), mu = pt["x_m"], pt["y_m"], float(pt["mu"])
        except (KeyError, TypeError, ValueError):
            _fail(src, f"[road] patches[{k}]", "needs x_m = [min, max], y_m = [min, max], mu")
        patches.append((x0, x1, y0, y1, mu))
    return road["mu"], patches


def _gnss(r: TomlReader, src: str) -> tuple[dict, dict]:
    """The ``[gnss]`` table (deprecated keys renamed, with a warning) and the noise values it
    sets over the receiver's.
    """
    g = dict(r.table("gnss", required=False))
    for old, new in OLD_NOISE_KEYS.items():
        if old in g:
            warnings.warn(
                f"{src}: [gnss] {old} is deprecated; write {new}", FutureWarning, stacklevel=3
            )
            g[new] = g.pop(old)
    gnss = GNSS.read(r, g)
    return gnss, {k: gnss[k] for k in g if k not in ("rate_hz", "noise")}


def _cases(doc: dict, mu0: float, src: str) -> list[tuple[dict, float]]:
    """Every case of ``[[case]]`` and of the products of ``[[grid]]``, with its road's μ."""
    specs: list[tuple[dict, float]] = []
    for c in doc.get("case", []):
        specs.append((c, float(c.get("mu", mu0))))
    for gr in doc.get("grid", []):
        dims = {
            key: (v if isinstance(v, list) else [v]) for key, v in gr.items() if key != "maneuver"
        }
        keys = list(dims)
        for combo in itertools.product(*(dims[key] for key in keys)):
            c = {"maneuver": gr.get("maneuver"), **dict(zip(keys, combo, strict=True))}
            specs.append((c, float(c.get("mu", mu0))))
    if not specs:
        _fail(src, "[[case]] / [[grid]]", "no case to simulate")
    return specs


def _receiver_toml(base: Path, rec: str | Path, over: dict) -> str:
    """The ``[receiver]`` table of the vehicle file a user of this receiver would write (empty
    for ``none``: exact values are no receiver an estimate can be made for).
    """
    from gripsense.config.receiver import RECEIVER, receiver_from

    if str(rec) == EXACT.name:
        return (
            "\n# receiver: none (the simulation's exact values); give gripsense friction "
            "--receiver for the receiver to assume\n"
        )
    if str(rec) not in RECEIVERS:
        rec = Path(rec) if Path(rec).is_file() else base.parent / rec
    r = receiver_from(rec)
    r = type(r)(**{**r.__dict__, **{k: v for k, v in over.items() if hasattr(r, k)}})
    lines = ["", "[receiver]  # the receiver that recorded the drives (gripsense simulate)"]
    lines.append(f"name = {json.dumps(r.name, ensure_ascii=False)}")
    lines += [f"{k.name} = {getattr(r, k.name)!r}" for k in RECEIVER.keys if k.kind == "number"]
    return "\n".join(lines) + "\n"


def _slug(rec: str | Path) -> str:
    """A receiver's part of a file name: its class, or its file's stem."""
    return re.sub(r"[^\w.-]+", "-", Path(str(rec)).stem if str(rec).endswith(".toml") else str(rec))


def _without_receiver(text: str) -> str:
    """A vehicle file's text without its ``[receiver]`` table (the simulation's receiver takes
    its place).
    """
    out, skip = [], False
    for line in text.splitlines():
        head = line.strip()
        if head.startswith("["):
            skip = re.match(r"\[\s*receiver\s*[].]", head) is not None
        if not skip:
            out.append(line)
    return "\n".join(out).rstrip() + "\n"


def _compass(base: Path, rec: str | Path, src: str, where: str) -> CompassNoise:
    """The emulator of a receiver named in a scenario (or given on the command line)."""
    if str(rec) in RECEIVERS or str(rec) == EXACT.name:
        return CompassNoise.preset(str(rec))
    if Path(rec).suffix.lower() != ".toml":
        _fail(
            src,
            where,
            f"receiver = {str(rec)!r}; use one of {', '.join([*RECEIVERS, EXACT.name])} or a "
            ".toml file with a [receiver] table",
        )
    path = Path(rec) if Path(rec).is_file() else base.parent / rec
    return CompassNoise.preset(path)


def _resolve(base: Path, ref: str, bundled_dir: str, src: str, where: str, what: str) -> Path:
    """A file named in a scenario: next to the scenario file, else a bundled one."""
    p = base.parent / ref
    if p.exists():
        return p
    from gripsense.data import sample_path

    try:
        return sample_path(f"{bundled_dir}{ref}")
    except FileNotFoundError:
        _fail(src, where, f"{ref!r} is neither a file next to the scenario nor a bundled {what}")
        raise


def _tyres(base: Path, spec, src: str, where: str, cache: dict) -> dict[str, SimTyre]:
    """Axle → tabulated tyre for the axles that do not use the brush tyre."""
    per_axle = spec if isinstance(spec, dict) else {"front": spec, "rear": spec}
    unknown = set(per_axle) - {"front", "rear"}
    if unknown:
        _fail(src, f"{where}: tyre", f"unknown axle {sorted(unknown)}; use front and rear")
    out = {}
    for axle, ref in per_axle.items():
        if not isinstance(ref, str):
            _fail(src, f"{where}: tyre", f'{ref!r}: use "brush" or a .tir / .json path')
        if ref == "brush":
            continue
        p = _resolve(base, ref, "tyres/", src, f"{where}: tyre", "tyre file")
        if p not in cache:
            cache[p] = load_sim_tyre(p)
        out[axle] = cache[p]
    return out


def _with_torque(st, res, vehicle, steer: dict, seed: int):
    """The steering table with the column torque (and assist) rows at their own rate."""
    from gripsense.sim.steering_torque import emulate_torque

    if vehicle.steering is None or not vehicle.steering_ratio:
        raise InputError(
            f"{vehicle.source}: [steering] torque = true needs the vehicle file's [steering] "
            "table (ratio, caster trail, assist)"
        )
    tq = emulate_torque(
        res, vehicle.steering, vehicle.steering_ratio, rate_hz=steer["torque_rate_hz"],
        noise_Nm=steer["torque_noise_Nm"], scale_error=steer["torque_scale_error"],
        offset_Nm=steer["torque_offset_Nm"], assist_channel=bool(steer["assist_channel"]),
        seed=seed,
    )  # fmt: skip
    return st.merge(tq, on="t_s", how="outer").sort_values("t_s").reset_index(drop=True)


def _simulate_cases(
    out, specs, setups, vehicle, vpath, patches, rate, acc, steer, seed, progress, fmt="nmea",
    *, warn, receiver_files, mu_max,
):  # fmt: skip
    # the vehicle file(s) a user would write: the truth vehicle, or for tyres from files the
    # declared stiffness (user_vehicle_toml), each with the [receiver] that recorded its drives
    # — one receiver: vehicle.toml / vehicle_<tyre>.toml; several: ..._<receiver>.toml each
    truth_text = _without_receiver(vpath.read_text(encoding="utf-8"))
    many = len(receiver_files) > 1
    antenna = (-vehicle.cg_offset[0], -vehicle.cg_offset[1])
    rows = []
    user_files: dict = {}
    for i, ((spec, mu), (params, m, noise, rec)) in enumerate(zip(specs, setups, strict=True)):
        cid = f"case{i + 1:03d}"
        if progress:
            progress(i, len(specs), cid)
        res = M.run(params, m, mu=mu, patches=np.array(patches) if patches else None)
        log = emulate_compass(res, antenna, rate_hz=rate, noise=noise, seed=seed + i)
        st = None
        if steer is not None:
            st = emulate_steering(
                res,
                rate_hz=steer["rate_hz"],
                noise_deg=steer["noise_deg"],
                scale_error=steer["scale_error"],
                offset_deg=steer["offset_deg"],
                seed=seed + 7919 + i,
            )
        if st is not None and steer["torque"]:
            st = _with_torque(st, res, vehicle, steer, seed + 104729 + i)
        log_name = f"{cid}{SUFFIXES[fmt]}"
        log_columns = write_log(log.epochs, out / log_name, fmt, nmea_lines=log.lines, steer=st)
        tyres = tuple(sorted((a, t.name) for a, t in params.sim_tyres.items()))
        key = (tyres, str(rec))
        if key not in user_files:
            from gripsense.sim.drives import user_vehicle_toml

            stem = "_".join(
                [*dict.fromkeys(Path(n).stem for _, n in tyres), *([_slug(rec)] if many else [])]
            )
            user_files[key] = f"vehicle_{stem}.toml" if stem else "vehicle.toml"
            text = truth_text
            if tyres:
                text = _without_receiver(user_vehicle_toml(vehicle, params.sim_tyres))
            (out / user_files[key]).write_text(text + receiver_files[str(rec)], encoding="utf-8")
        truth = log.truth.copy()
        truth["wheel"] = truth["wheel"].astype(str)
        truth.to_parquet(out / f"{cid}_truth.parquet", index=False)
        row = {
            "case": cid,
            "name": m.name,
            "maneuver": spec["maneuver"],
            "mu_road": mu,
            "receiver": rec,
            "vehicle_file": user_files[key],
            **{
                k: (v if not isinstance(v, dict) else " / ".join(f"{a}: {t}" for a, t in v.items()))
                for k, v in spec.items()
                if k not in ("maneuver", "mu")
            },
            **({"nmea": log_name} if fmt == "nmea" else {}),
            "log": log_name,
            **({"columns": log_columns} if log_columns else {}),
            "truth": f"{cid}_truth.parquet",
            "settle_s": m.settle_s,
            "sim_s": float(res.body["t_s"].iloc[-1]),
            "realtime_factor": res.realtime_factor,
            "diverged": res.meta["diverged"],
            "warning": "",
        }
        notes = [demand_warning(m, mu_max)]
        if res.meta["diverged"]:
            notes.append(f"{m.name}: the integration diverged; the drive ends where it did")
        row["warning"] = "; ".join(n for n in notes if n)
        if row["warning"]:
            warn(cid, row["warning"])
        if acc is not None:
            a = emulate_accelerometer(
                res,
                rate_hz=acc["rate_hz"],
                pitch_deg=acc["pitch_deg"],
                roll_deg=acc["roll_deg"],
                noise_g=acc["noise_g"],
                seed=seed + i,
            )
            a.to_csv(out / f"{cid}_accel.csv", index=False, float_format="%.5f")
            row["accel"] = f"{cid}_accel.csv"
        if st is not None:
            st.to_csv(out / f"{cid}_steer.csv", index=False, float_format="%.5f")
            row["steer"] = f"{cid}_steer.csv"
        rows.append(row)
    if "vehicle.toml" not in {f for f in user_files.values()}:
        (out / "vehicle.toml").write_text(truth_text, encoding="utf-8")  # the vehicle used
    cases = pd.DataFrame(rows)
    cases.to_csv(out / "cases.csv", index=False)
    return cases
