"""Scenario files: which drives to simulate and which sensors to emulate, TOML in, files out.

Layout (see ``gripsense/data/demo_scenario.toml``)::

    [scenario]
    name = "thesis-2018 grid"
    vehicle = "corolla_sim.toml"    # relative to the scenario file, or a bundled file name
    seed = 1
    drive = "front"                 # front | rear | all
    relaxation_length_m = 0.0       # first-order tyre lag (0: none)

    [road]
    mu = 0.9                        # outside the patches
    patches = [{ x_m = [0, 50], y_m = [-30, 30], mu = 0.3 }]   # optional, later wins

    [gnss]
    rate_hz = 10
    noise = "v100"                  # or "none"; single terms may be overridden below
    mounting_offset_deg = 0.5

    [accelerometer]                 # optional: 50 Hz CSV for the braking test
    rate_hz = 50
    pitch_deg = 1.0

    [[case]]                        # one drive ...
    maneuver = "circle"             # circle | fixed_steer | ramp_steer | slalom | braking
    speed_kmh = 30
    radius_m = 25
    laps = 2

    [[grid]]                        # ... or every combination of the listed values
    maneuver = "circle"
    speed_kmh = [20, 30, 40, 50]
    radius_m = [20, 30, 40]
    mu = [0.9, 0.5]                 # optional: the road μ as a grid dimension
    laps = 2

Output folder: ``vehicle.toml`` (the vehicle used), ``cases.csv`` (one row per case with its
parameters, road μ and file names), and per case ``<id>.nmea.gz`` (the emulated receiver),
``<id>_truth.parquet`` (per epoch and wheel: true μ, slip angle, load, lateral force) and, with
``[accelerometer]``, ``<id>_accel.csv``.
"""

from __future__ import annotations

import itertools
import shutil
from dataclasses import fields
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.config.toml_reader import TomlReader
from gripsense.errors import InputError
from gripsense.io.results import ResultWriter
from gripsense.io.text import read_toml
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import CompassNoise, emulate_compass
from gripsense.sim.sensors import emulate_accelerometer
from gripsense.sim.vehicle import SimParams

__all__ = ["run_scenario"]

SCENARIO_TABLES = ("scenario", "road", "gnss", "accelerometer", "case", "grid")
ACCEL_KEYS = ("rate_hz", "pitch_deg", "roll_deg", "noise_g")

_ARGS = {  # maneuver -> (builder, {scenario key: (builder argument, scale)})
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


def _fail(src: str, where: str, msg: str):
    raise InputError(f"{src}: {where}: {msg}")


def _maneuver(spec: dict, src: str, where: str, params: SimParams) -> M.Maneuver:
    kind = spec.get("maneuver")
    if kind not in _ARGS:
        _fail(src, where, f"maneuver = {kind!r}; use one of {sorted(_ARGS)}")
    builder, keys = _ARGS[kind]
    kw = {}
    for k, v in spec.items():
        if k in ("maneuver", "mu", "name"):
            continue
        if k not in keys:
            _fail(src, where, f"unknown key {k!r} for {kind}; known: {sorted(keys)}")
        if isinstance(v, bool) or not isinstance(v, int | float):
            _fail(src, where, f"{k} = {v!r} must be a number")
        arg, scale = keys[k]
        kw[arg] = int(v) if arg == "cycles" else v * scale
    if kind == "circle":
        kw["params"] = params
    try:
        return builder(**kw)
    except TypeError as e:
        _fail(src, where, f"{e}")
        raise


def run_scenario(
    path: str | Path,
    outdir: str | Path,
    *,
    progress=None,
    overwrite: bool = False,
    command: str = "",
) -> pd.DataFrame:
    """Simulate every case of a scenario file and write the outputs (see module docs).

    Parameters
    ----------
    path : path
        Scenario TOML.
    outdir : path
        Output folder: written atomically with a manifest (:class:`gripsense.io.results.
        ResultWriter`); an earlier simulation there is replaced only with *overwrite*.
    progress : callable or None
        Called as ``progress(i, n, case_id)`` before each case.
    overwrite : bool
        Replace an earlier simulation in *outdir*.
    command : str
        Command line recorded in the manifest.

    Returns
    -------
    pandas.DataFrame
        The case index written to ``cases.csv``.
    """
    path = Path(path)
    src = str(path)
    doc = read_toml(path, "scenario file")
    r = TomlReader(doc, src)
    r.known(doc, "", SCENARIO_TABLES)
    sc = r.table("scenario", required=True)
    r.known(sc, "scenario", ("name", "vehicle", "seed", "drive", "relaxation_length_m"))
    vref = sc.get("vehicle")
    if not vref:
        _fail(src, "[scenario] vehicle", "missing (a vehicle TOML path or bundled name)")
    vpath = path.parent / vref
    if not vpath.exists():
        from gripsense.data import sample_path

        try:
            vpath = sample_path(vref)
        except FileNotFoundError:
            _fail(
                src,
                "[scenario] vehicle",
                f"{vref!r} is neither a file next to the scenario nor a bundled vehicle",
            )
    vehicle = Vehicle.from_toml(vpath)
    if vehicle.cg_offset is None:
        _fail(
            src,
            "[scenario] vehicle",
            f"{vpath.name} needs [antenna] x_m, y_m (the antenna "
            "position relative to the CG) to emulate the receiver",
        )
    params = SimParams.from_vehicle(
        vehicle,
        drive=sc.get("drive", "front"),
        relaxation_length_m=float(sc.get("relaxation_length_m", 0)),
    )
    seed = int(sc.get("seed", 0))
    road = r.table("road", required=False)
    r.known(road, "road", ("mu", "patches"))
    mu0 = float(road.get("mu", 0.9))
    patches = []
    for k, pt in enumerate(road.get("patches", [])):
        try:
            (x0, x1), (y0, y1), mu = pt["x_m"], pt["y_m"], float(pt["mu"])
        except (KeyError, TypeError, ValueError):
            _fail(src, f"[road] patches[{k}]", "needs x_m = [min, max], y_m = [min, max], mu")
        patches.append((x0, x1, y0, y1, mu))
    g = r.table("gnss", required=False)
    r.known(g, "gnss", ("rate_hz", "noise", *(f.name for f in fields(CompassNoise))))
    base = CompassNoise.none() if g.get("noise", "v100") == "none" else CompassNoise()
    names = {f.name for f in fields(CompassNoise)}
    over = {k: float(v) for k, v in g.items() if k in names}
    noise = CompassNoise(
        **{**{f.name: getattr(base, f.name) for f in fields(CompassNoise)}, **over}
    )
    rate = float(g.get("rate_hz", 10.0))
    acc = doc.get("accelerometer")
    if acc is not None:
        r.known(r.table("accelerometer", required=False), "accelerometer", ACCEL_KEYS)

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

    maneuvers = [_maneuver(spec, src, f"case {i + 1}", params) for i, (spec, _) in enumerate(specs)]
    with ResultWriter(
        outdir, "simulation", overwrite=overwrite, command=command, inputs=[path, vpath]
    ) as out:
        return _simulate_cases(
            out, specs, maneuvers, params, vehicle, vpath, patches, noise, rate, acc, seed, progress
        )


def _simulate_cases(
    out, specs, maneuvers, params, vehicle, vpath, patches, noise, rate, acc, seed, progress
):
    shutil.copyfile(vpath, out / "vehicle.toml")
    antenna = (-vehicle.cg_offset[0], -vehicle.cg_offset[1])
    rows = []
    for i, ((spec, mu), m) in enumerate(zip(specs, maneuvers, strict=True)):
        cid = f"case{i + 1:03d}"
        if progress:
            progress(i, len(specs), cid)
        res = M.run(params, m, mu=mu, patches=np.array(patches) if patches else None)
        log = emulate_compass(res, antenna, rate_hz=rate, noise=noise, seed=seed + i)
        log.write(out / f"{cid}.nmea.gz")
        truth = log.truth.copy()
        truth["wheel"] = truth["wheel"].astype(str)
        truth.to_parquet(out / f"{cid}_truth.parquet", index=False)
        row = {
            "case": cid,
            "name": m.name,
            "maneuver": spec["maneuver"],
            "mu_road": mu,
            **{k: v for k, v in spec.items() if k not in ("maneuver", "mu")},
            "nmea": f"{cid}.nmea.gz",
            "truth": f"{cid}_truth.parquet",
            "settle_s": m.settle_s,
            "sim_s": float(res.body["t_s"].iloc[-1]),
            "realtime_factor": res.realtime_factor,
            "diverged": res.meta["diverged"],
        }
        if acc is not None:
            a = emulate_accelerometer(
                res,
                rate_hz=float(acc.get("rate_hz", 50.0)),
                pitch_deg=float(acc.get("pitch_deg", 0.0)),
                roll_deg=float(acc.get("roll_deg", 0.0)),
                noise_g=float(acc.get("noise_g", 0.01)),
                seed=seed + i,
            )
            a.to_csv(out / f"{cid}_accel.csv", index=False, float_format="%.5f")
            row["accel"] = f"{cid}_accel.csv"
        rows.append(row)
    cases = pd.DataFrame(rows)
    cases.to_csv(out / "cases.csv", index=False)
    return cases
