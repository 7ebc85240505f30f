"""A mixed fleet on a road network, as a road operator would have it.

Cars of different vehicle models (CommonRoad's single-track and multi-body models, gripsense's
simulator on Magic Formula truth tyres), each with its own vehicle file, receiver and
calibration learned from its own everyday drives (``gripsense calibrate``'s
:func:`~gripsense.pipeline.learn_calibration`), pass the bends of a network (each at its own
place, with a known road μ per time bucket) as drivers do every day, mostly far from the limit;
the truth per pass and per H3 cell and bucket (``benchmarks/fleet_cells.py``). The simpler
fleet of the tests, one vehicle file near the limit: :func:`gripsense.sim.fleet_data.write_fleet`.
"""

from __future__ import annotations

import datetime as dt
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.sim import maneuvers as M
from gripsense.sim.vehicle import SimParams

__all__ = [
    "NETWORK_BUCKETS",
    "NETWORK_CARS",
    "Bend",
    "Bucket",
    "Car",
    "FleetNetwork",
    "car_vehicle_toml",
    "network_bends",
    "write_road_network",
]


@dataclass(frozen=True)
class Car:
    """A car of the simulated fleet, as its owner describes it.

    Attributes
    ----------
    name : str
        Its id (its logs' folder).
    model : str
        ``cr-std`` / ``cr-mb``: CommonRoad's single-track drift model or its multi-body model
        (vehicle 2, Pacejka tyres; :mod:`gripsense.sim.commonroad`); else a truth vehicle of
        gripsense's simulator (``sedan``, ``sports``, ``suv``: :data:`gripsense.sim.drives.
        VEHICLES`).
    tyre : str
        The truth tyre of gripsense's simulator (:data:`gripsense.sim.drives.TRUTH_TYRES`;
        unused for CommonRoad, whose tyre is its own).
    receiver : str
        The compass that records its drives and that its vehicle file declares.
    stiffness_error : float
        Error of the cornering stiffness its owner declares [-].
    stiffness_uncertainty : float
        The 1σ its owner declares with it [-].
    """

    name: str
    model: str
    tyre: str = ""
    receiver: str = "white-0.3"
    stiffness_error: float = -0.1
    stiffness_uncertainty: float = 0.2


@dataclass(frozen=True)
class Bend:
    """A bend of the road network: the centre of its arc, its radius, which way it turns, how
    far, and the road μ in each time bucket.

    Attributes
    ----------
    name : str
        Its name (part of the logs' names).
    lat_deg, lon_deg : float
        Centre of the arc [deg].
    radius_m : float
        Radius of the arc [m].
    mu : tuple of float
        Road μ in each bucket of the network, in order [-].
    left : bool
        A left-hand bend (else right-hand).
    arc_deg : float
        Heading change of the bend [deg] (270: a cloverleaf ramp).
    """

    name: str
    lat_deg: float
    lon_deg: float
    radius_m: float
    mu: tuple[float, ...]
    left: bool = True
    arc_deg: float = 270.0


@dataclass(frozen=True)
class Bucket:
    """A time bucket of the network: its name and the UTC hour it starts.

    Attributes
    ----------
    name : str
        Its name (part of the logs' names).
    start : datetime.datetime
        Its start (UTC, on the hour).
    length_s : float
        Its length [s].
    """

    name: str
    start: dt.datetime
    length_s: float = 3600.0


NETWORK_CARS = (
    Car("cr-std", "cr-std", receiver="white-0.3", stiffness_error=-0.1),
    Car("cr-mb", "cr-mb", receiver="rtk", stiffness_error=0.1),
    Car("sedan", "sedan", "mf-sedan", receiver="white-0.3", stiffness_error=0.1),
    Car("suv", "suv", "mf-book", receiver="rtk", stiffness_error=-0.1),
    Car("sports", "sports", "mf61", receiver="white-0.3", stiffness_error=-0.05),
)
"""The default fleet: CommonRoad's single-track and multi-body cars and three of gripsense's
simulated cars on Magic Formula truth tyres (PAC2002 sedan, MF 5.2 book defaults, MF 6.1), with
V100-free 0.3° compasses (``white-0.3``) or RTK-class ones, each declaring its stiffness 5–10 %
off to ±20 %."""

_DAY = dt.datetime(2026, 11, 20, tzinfo=dt.UTC)
NETWORK_BUCKETS = (
    Bucket("dry", _DAY.replace(hour=7)),
    Bucket("wet", _DAY.replace(hour=15)),
)
"""A dry morning hour (07:00–08:00 UTC) and a wet, cold afternoon hour (15:00–16:00) of one
day."""

_NETWORK = (  # name, radius [m], left, μ dry, μ wet
    ("b1", 45.0, True, 0.95, 0.55),
    ("b2", 60.0, False, 0.9, 0.55),
    ("b3", 35.0, True, 1.0, 0.6),
    ("b4", 70.0, False, 0.55, 0.3),
    ("b5", 80.0, True, 0.9, 0.2),
    ("b6", 50.0, False, 0.95, 0.65),
    ("b7", 65.0, True, 0.55, 0.15),
    ("b8", 40.0, False, 0.9, 0.4),
)
NETWORK_ORIGIN = (33.60, 133.70)
"""South-west corner of the network's bends [deg] (near the bundled demo's origin)."""
BEND_SPACING_DEG = 0.02
"""Distance between neighbouring bends' centres [deg] (≈ 1.9–2.2 km: no H3 cell is shared)."""
DRY_AY_G = (0.2, 0.45)
"""Lateral acceleration a driver takes a bend with on a grippy road [g]."""
SLIPPERY_UTILISATION = (0.5, 0.9)
"""Share of the road's grip a driver uses on a slippery road (μ below :data:`GRIPPY_MU`) [-]."""
GRIPPY_MU = 0.6
"""Road μ from which a driver corners as on a dry road [-]."""
LEAD_IN_M = 90.0
"""Length of the straight before each bend [m] (the heading calibration's straight)."""
TURN_S = 2.5
"""Time of the turn-in and of the turn-out of a bend [s]."""
EXIT_S = 4.0
"""Straight after the bend [s]."""
EVERYDAY_SPEED_MPS = 60 / 3.6
"""Speed of the calibration's everyday drives [m/s]."""


def network_bends(n: int = 8) -> list[Bend]:
    """The default network's first *n* bends (at most 8): radii 35–80 m, both directions, a
    dry μ of 0.9–1.0 (0.55 on two worn roads) and a wet one of 0.55–0.65, 0.4, 0.3 and two icy
    bends (0.2, 0.15), on a grid :data:`BEND_SPACING_DEG` apart.

    Parameters
    ----------
    n : int
        Number of bends [-].

    Returns
    -------
    list of Bend
        The bends, μ per bucket of :data:`NETWORK_BUCKETS`.
    """
    if not 1 <= n <= len(_NETWORK):
        raise ValueError(f"n={n}: the network has 1 to {len(_NETWORK)} bends")
    lat0, lon0 = NETWORK_ORIGIN
    out = []
    for i, (name, r, left, dry, wet) in enumerate(_NETWORK[:n]):
        lat, lon = lat0 + BEND_SPACING_DEG * (i // 4), lon0 + BEND_SPACING_DEG * (i % 4)
        out.append(Bend(name, lat, lon, r, (dry, wet), left))
    return out


@dataclass
class FleetNetwork:
    """A simulated fleet on a road network: where its files are, and the truth.

    Attributes
    ----------
    outdir : Path
        The folder: ``<car>/<bend>_<bucket>_<k>.nmea.gz`` (with ``<stem>_steer.csv`` beside),
        ``vehicles/<car>.toml`` (naming ``<car>.calibration.toml`` beside it),
        ``everyday/<car>/`` (the calibration's drives), ``vehicles.csv`` and ``truth.csv``.
    cars : list of Car
        The fleet.
    bends : list of Bend
        The network.
    buckets : list of Bucket
        The time buckets.
    logs : pandas.DataFrame
        One row per pass: ``car, model, receiver, bend, bucket, k, log, mu_road, radius_m,
        speed_mps, ay_g, utilisation`` (the driver's a_y/(μ g)), ``utilisation_front`` /
        ``_rear`` (95th percentile of the axle's true utilisation), ``mu_front`` / ``_rear``
        (the axle's true μ, median), ``start`` and ``cells`` (the H3 cells the true path
        crosses, ``;``-separated).
    h3_res : int
        Resolution of ``cells``.
    """

    outdir: Path
    cars: list[Car]
    bends: list[Bend]
    buckets: list[Bucket]
    logs: pd.DataFrame
    h3_res: int = 11

    @property
    def vehicle_map(self) -> Path:
        """``vehicles.csv``: each car's logs → its vehicle file (``--vehicle-map``)."""
        return self.outdir / "vehicles.csv"

    @property
    def patterns(self) -> list[str]:
        """Glob patterns of the fleet's logs (not the calibration's everyday drives)."""
        return [str(self.outdir / c.name / "*.nmea.gz") for c in self.cars]

    def cell_truth(self, cells: pd.DataFrame) -> pd.DataFrame:
        """The truth of cell-buckets: *cells* (``cell``, ``bucket``) with the bend the cell lies
        at (the nearest bend's centre, within :data:`BEND_SPACING_DEG` / 3), its road μ in the
        bucket (``mu_true``), the span of the true axle μ of the passes there (``mu_axle_min``,
        ``mu_axle_max``: each tyre's peak at its load) and of the drivers' utilisation, and
        ``on_path`` (a true path crosses the cell).

        Parameters
        ----------
        cells : pandas.DataFrame
            At least ``cell`` (H3 index) and ``bucket`` (its start, UTC).

        Returns
        -------
        pandas.DataFrame
            *cells* with ``bend``, ``mu_true``, ``mu_axle_min``, ``mu_axle_max``,
            ``on_path`` (NaN/empty where no bend or bucket matches).
        """
        import h3

        out = cells.copy()
        ll = np.array([h3.cell_to_latlng(c) for c in out["cell"]], dtype=float).reshape(-1, 2)
        lat, lon = ll[:, 0], ll[:, 1]
        blat = np.array([b.lat_deg for b in self.bends])
        blon = np.array([b.lon_deg for b in self.bends])
        d = np.hypot(lat[:, None] - blat, (lon[:, None] - blon) * np.cos(np.deg2rad(blat)))
        near = d.argmin(axis=1) if len(self.bends) else np.zeros(len(out), int)
        ok = d[np.arange(len(out)), near] < BEND_SPACING_DEG / 3
        t = pd.to_datetime(out["bucket"], utc=True)
        bk = np.full(len(out), -1)
        for j, b in enumerate(self.buckets):
            s = pd.Timestamp(b.start)
            bk[(t >= s) & (t < s + pd.Timedelta(seconds=b.length_s))] = j
        names = [b.name for b in self.buckets]
        out["bend"] = np.where(ok, [self.bends[i].name for i in near], "")
        out["mu_true"] = [
            self.bends[i].mu[j] if o and j >= 0 else np.nan
            for i, j, o in zip(near, bk, ok, strict=True)
        ]
        lg = self.logs.assign(
            lo=self.logs[["mu_front", "mu_rear"]].min(axis=1),
            hi=self.logs[["mu_front", "mu_rear"]].max(axis=1),
        )
        span = lg.groupby(["bend", "bucket"]).agg(mu_axle_min=("lo", "min"),
                                                  mu_axle_max=("hi", "max"))  # fmt: skip
        keys = list(zip(out["bend"], [names[j] if j >= 0 else "" for j in bk], strict=True))
        out["mu_axle_min"] = [span["mu_axle_min"].get(k, np.nan) for k in keys]
        out["mu_axle_max"] = [span["mu_axle_max"].get(k, np.nan) for k in keys]
        crossed = {
            (c, b) for cs, b in zip(self.logs["cells"], self.logs["bucket"], strict=True)
            for c in str(cs).split(";")
        }  # fmt: skip
        out["on_path"] = [k in crossed for k in zip(
            out["cell"], [names[j] if j >= 0 else "" for j in bk], strict=True)]  # fmt: skip
        return out


def write_road_network(
    outdir: str | Path,
    *,
    cars: tuple[Car, ...] | list[Car] = NETWORK_CARS,
    bends: list[Bend] | None = None,
    buckets: tuple[Bucket, ...] | list[Bucket] = NETWORK_BUCKETS,
    passes: tuple[int, int] = (2, 3),
    h3_res: int = 11,
    seed: int = 0,
    workers: int = 2,
) -> FleetNetwork:
    """Simulate a mixed fleet driving a road network and write it as a user would have it.

    Every car is calibrated as its owner would: three everyday drives of its own (μ 0.9, curves
    up to ~0.35 g at 60 km/h, :func:`gripsense.sim.maneuvers.everyday`) teach its stiffness
    (:func:`gripsense.pipeline.learn_calibration`), written to ``vehicles/<car>.calibration.toml``
    and named by its vehicle file's ``[calibration]``; the vehicle file also declares its
    ``[receiver]``. Then each car passes each bend 2–3 times per time bucket (``passes``, drawn
    from the seed) at a start time inside the bucket: a straight of :data:`LEAD_IN_M`, the arc
    (turned in and out over :data:`TURN_S`), :data:`EXIT_S` straight. The driver's speed gives a
    lateral acceleration a_y = v²/R of :data:`DRY_AY_G` on a grippy road (μ ≥
    :data:`GRIPPY_MU`), else a utilisation a_y/(μ g) of :data:`SLIPPERY_UTILISATION`. Each pass
    is placed so that its arc's fitted centre is the bend's (all cars on one geometry, their
    passes in the same cells).

    Parameters
    ----------
    outdir : str or Path
        Output folder (created; see :class:`FleetNetwork`).
    cars : sequence of Car
        The fleet (default :data:`NETWORK_CARS`).
    bends : list of Bend, optional
        The network (default :func:`network_bends`); one μ per bucket.
    buckets : sequence of Bucket
        The time buckets (default :data:`NETWORK_BUCKETS`).
    passes : (int, int)
        Fewest and most passes of a car at a bend per bucket [-].
    h3_res : int
        H3 resolution of the truth's cells [-].
    seed : int
        Random seed of the speeds, passes, start times and receiver noise (with the car's and
        the bend's names: a car's passes of a bend are the same in a smaller network).
    workers : int
        Processes that simulate [-] (1: in this process).

    Returns
    -------
    FleetNetwork
        Where the files are and the truth (also written to ``outdir/truth.csv``).
    """
    from concurrent.futures import ProcessPoolExecutor

    outdir = Path(outdir)
    bends = network_bends() if bends is None else list(bends)
    cars, buckets = list(cars), list(buckets)
    for b in bends:
        if len(b.mu) != len(buckets):
            raise ValueError(f"bend {b.name}: {len(b.mu)} μ for {len(buckets)} buckets")
    outdir.mkdir(parents=True, exist_ok=True)
    # seeds from the names: a car's drives and passes are the same in any fleet and network
    jobs: list[tuple] = [("car", outdir, c, seed + zlib.crc32(c.name.encode()) % 10**6)
                         for c in cars]  # fmt: skip
    jobs += [
        ("passes", outdir, c, b, buckets, passes, h3_res,
         (seed, zlib.crc32(c.name.encode()), zlib.crc32(b.name.encode())))
        for c in cars
        for b in bends
    ]  # fmt: skip
    jobs.sort(key=lambda j: (j[2].model != "cr-mb", j[0] != "car"))  # the slow ones first
    if workers > 1:
        with ProcessPoolExecutor(workers) as ex:
            results = list(ex.map(_network_job, jobs))
    else:
        results = [_network_job(j) for j in jobs]
    rows = [r for part in results for r in part]
    logs = pd.DataFrame(rows).sort_values(["car", "bend", "bucket", "k"]).reset_index(drop=True)
    logs.to_csv(outdir / "truth.csv", index=False)
    with open(outdir / "vehicles.csv", "w", encoding="utf-8") as f:
        f.write("pattern,vehicle_toml,vehicle_id\n")
        for c in cars:
            f.write(f"*/{c.name}/*,{(outdir / 'vehicles' / f'{c.name}.toml').resolve()},{c.name}\n")
    return FleetNetwork(outdir, cars, bends, buckets, logs, h3_res)


def _network_job(job: tuple) -> list[dict]:
    if job[0] == "car":
        _calibrated_car(*job[1:])
        return []
    return _passes(*job[1:])


def _receiver_table(name: str) -> str:
    from gripsense.config.receiver import RECEIVER, receiver_from

    r = receiver_from(name)
    lines = ["[receiver]  # the car's compass", f'name = "{r.name}"']
    lines += [f"{k.name} = {getattr(r, k.name)!r}" for k in RECEIVER.keys if k.kind == "number"]
    return "\n".join(lines) + "\n"


def _commonroad_toml(car: Car) -> str:
    """The vehicle file a user would write for CommonRoad's vehicle 2
    (:func:`gripsense.sim.commonroad.commonroad_vehicle_toml`).
    """
    from gripsense.sim.commonroad import commonroad_vehicle_toml

    return commonroad_vehicle_toml(
        stiffness_error=car.stiffness_error,
        stiffness_uncertainty=car.stiffness_uncertainty,
        name=f"{car.name}: CommonRoad vehicle 2 ({car.model})",
    )


def car_vehicle_toml(car: Car) -> str:
    """The vehicle file a car's owner writes: the geometry, the declared stiffness (off by
    ``stiffness_error``, with ``stiffness_uncertainty``) and the ``[receiver]`` table.

    Parameters
    ----------
    car : Car
        The car.

    Returns
    -------
    str
        TOML text (without the ``[calibration]`` table).
    """
    from gripsense.sim.drives import truth_tyre, truth_vehicle, user_vehicle_toml

    if car.model.startswith("cr-"):
        text = _commonroad_toml(car)
    else:
        text = user_vehicle_toml(
            truth_vehicle(car.model), truth_tyre(car.tyre), stiffness_error=car.stiffness_error,
            stiffness_uncertainty=car.stiffness_uncertainty,
        )  # fmt: skip
        text = text.replace('name = "', f'name = "{car.name}: ', 1)
    return text + "\n" + _receiver_table(car.receiver)


def _simulate(car: Car, kind: str, mu: float, seed: int = 0, **spec):
    """Simulate one drive of *car* → (SimResult, the truth Vehicle, settle time [s]).

    *kind* ``everyday`` (60 km/h, curves from *seed*) or ``bend`` (``speed``, ``radius``,
    ``left``, ``arc_deg``).
    """
    from gripsense.sim import commonroad as CR
    from gripsense.sim.drives import truth_tyre, truth_vehicle

    if car.model.startswith("cr-"):
        if kind == "everyday":
            plan = CR.cr_everyday(EVERYDAY_SPEED_MPS, seed=seed)
        else:
            plan = _cr_bend(**spec)
        res = CR.commonroad_result(plan, mu, model=car.model[3:])
        return res, CR.commonroad_vehicle(), plan.settle_s
    veh = truth_vehicle(car.model)
    t = truth_tyre(car.tyre)
    p = SimParams.from_vehicle(veh, relaxation_length_m=0.5,
                               sim_tyres={} if t is None else {"front": t, "rear": t})  # fmt: skip
    if kind == "everyday":
        m = M.everyday(EVERYDAY_SPEED_MPS, seed=seed)
        return M.run(p, m, mu=mu), veh, m.settle_s
    m, res = _sim_bend(p, mu, **spec)
    return res, veh, m.settle_s


def _cr_bend(speed: float, radius: float, left: bool, arc_deg: float):
    """CommonRoad's driver: :data:`LEAD_IN_M` straight, the yaw rate v/R turned in and out
    over :data:`TURN_S` (the arc's heading change *arc_deg*), :data:`EXIT_S` straight.
    """
    from gripsense.sim.commonroad import DrivePlan

    r = (1.0 if left else -1.0) * speed / radius
    t0 = LEAD_IN_M / speed
    hold = max(np.deg2rad(arc_deg) * radius / speed - TURN_S, 0.0)
    knots_t = np.array([0.0, t0, t0 + TURN_S, t0 + TURN_S + hold, t0 + 2 * TURN_S + hold])
    knots_r = np.array([0.0, 0.0, r, r, 0.0])

    def target(t):
        return float(np.interp(t, knots_t, knots_r)), None, speed

    return DrivePlan(duration_s=float(knots_t[-1] + EXIT_S), settle_s=t0, target=target)


def _sim_bend(p: SimParams, mu: float, speed: float, radius: float, left: bool, arc_deg: float):
    """The driver of gripsense's simulator: the bend followed by pure pursuit after
    :data:`LEAD_IN_M` straight, then its steer replayed and unwound over :data:`TURN_S`,
    :data:`EXIT_S` straight.
    """
    from gripsense.sim import control as C

    lead = LEAD_IN_M / speed
    m = M.circle(speed, radius, laps=arc_deg / 360.0, left=left, lead_s=lead, settle_s=0.0,
                 params=p)  # fmt: skip
    first = M.run(p, m, mu=mu)
    b = first.body
    t = b["t_s"].to_numpy(float)
    d = b["steer_rad"].to_numpy(float)
    tt = np.concatenate([t, [t[-1] + TURN_S, t[-1] + TURN_S + EXIT_S]])
    dd = np.concatenate([d, [0.0, 0.0]])
    ctrl = m.controller.copy()
    ctrl[C.C_STEER_MODE] = C.STEER_TABLE
    out = M.Maneuver(m.name + " + exit", ctrl, float(tt[-1]), m.initial, (tt, dd), lead, m.info)
    return out, M.run(p, out, mu=mu)


def _arc_centre(res, speed: float, radius: float) -> tuple[float, float]:
    """Centre of the arc the CG drove (x east, y north) [m]: a circle fitted (algebraically)
    to the samples whose yaw rate is within 10 % of v/R.
    """
    b = res.body
    x, y = b["x_m"].to_numpy(float), b["y_m"].to_numpy(float)
    steady = (
        np.abs(np.abs(b["yaw_rate_rps"].to_numpy(float)) - speed / radius) < 0.1 * speed / radius
    )
    a = np.column_stack([x[steady], y[steady], np.ones(steady.sum())])
    sol = np.linalg.lstsq(a, x[steady] ** 2 + y[steady] ** 2, rcond=None)[0]
    return float(sol[0] / 2.0), float(sol[1] / 2.0)


def _latlon(origin: tuple[float, float], x: np.ndarray, y: np.ndarray):
    """(lat, lon) [deg] of points x east, y north [m] of *origin* (the compass emulator's
    local frame, :func:`gripsense.sim.gnss.emulate_compass`).
    """
    from gripsense.sim.gnss import WGS84_A, WGS84_E2

    s2 = np.sin(np.deg2rad(origin[0])) ** 2
    r_n = WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * s2) ** 1.5
    r_e = WGS84_A / np.sqrt(1 - WGS84_E2 * s2)
    return (origin[0] + np.rad2deg(y / r_n),
            origin[1] + np.rad2deg(x / (r_e * np.cos(np.deg2rad(origin[0])))))  # fmt: skip


def _write_drive(d, log: Path) -> None:
    from gripsense.fleet.tasks import steer_csv_for
    from gripsense.io.logs import write_nmea_lines

    log.parent.mkdir(parents=True, exist_ok=True)
    write_nmea_lines(d.lines, log)
    d.steer.to_csv(steer_csv_for(log), index=False)


def _calibrated_car(outdir: Path, car: Car, seed: int) -> None:
    """The car's vehicle file and the calibration learned from three everyday drives."""
    import tomllib

    from gripsense.config.calibration import calibration_toml
    from gripsense.fleet.tasks import steer_csv_for
    from gripsense.pipeline import learn_calibration
    from gripsense.sim.drives import record_drive

    text = car_vehicle_toml(car)
    veh = Vehicle.from_dict(tomllib.loads(text), source=f"{car.name}.toml")
    folder = outdir / "everyday" / car.name
    logs: list[str | Path] = []
    for i in range(3):
        res, veh_true, settle = _simulate(car, "everyday", 0.9, seed + i)
        d = record_drive(res, veh_true, settle, receiver=car.receiver, seed=seed + i,
                         origin=(NETWORK_ORIGIN[0] - 0.05, NETWORK_ORIGIN[1], 10.0),
                         start=_DAY - dt.timedelta(days=3 - i))  # fmt: skip
        log = folder / f"everyday{i}.nmea.gz"
        _write_drive(d, log)
        logs.append(log)
    cal = learn_calibration(logs, veh, receiver=car.receiver,
                            steer_csvs=[steer_csv_for(x) for x in logs])  # fmt: skip
    vdir = outdir / "vehicles"
    vdir.mkdir(parents=True, exist_ok=True)
    (vdir / f"{car.name}.calibration.toml").write_text(calibration_toml(cal), encoding="utf-8")
    text += f'\n[calibration]\nfile = "{car.name}.calibration.toml"\n'
    (vdir / f"{car.name}.toml").write_text(text, encoding="utf-8")


def _passes(
    outdir: Path, car: Car, bend: Bend, buckets: list[Bucket], passes: tuple[int, int],
    h3_res: int, key: tuple[int, int, int],
) -> list[dict]:  # fmt: skip
    """Simulate and write one car's passes of one bend in every bucket; their truth rows."""
    import h3

    from gripsense.fleet.tasks import steer_csv_for
    from gripsense.sim.drives import record_drive

    rng = np.random.default_rng(np.random.SeedSequence(list(key)))
    rows = []
    for j, bucket in enumerate(buckets):
        mu = float(bend.mu[j])
        for k in range(int(rng.integers(passes[0], passes[1] + 1))):
            if mu >= GRIPPY_MU:
                ay = rng.uniform(*DRY_AY_G) * G0
            else:
                ay = rng.uniform(*SLIPPERY_UTILISATION) * mu * G0
            speed = float(np.sqrt(ay * bend.radius_m))
            offset = rng.uniform(0.0, bucket.length_s - 180.0)
            noise_seed = int(rng.integers(0, 2**31 - 1))
            start = bucket.start + dt.timedelta(seconds=round(offset, 1))
            spec: dict[str, Any] = {"speed": speed, "radius": bend.radius_m, "left": bend.left,
                    "arc_deg": bend.arc_deg}  # fmt: skip
            # simulated in the local frame, then placed so that its arc is the bend's
            res, veh, settle = _simulate(car, "bend", mu, **spec)
            xc, yc = _arc_centre(res, speed, bend.radius_m)
            lat0, lon0 = _latlon((bend.lat_deg, bend.lon_deg), np.array(-xc), np.array(-yc))
            origin = (float(lat0), float(lon0), 10.0)
            d = record_drive(res, veh, settle, receiver=car.receiver, seed=noise_seed,
                             origin=origin, start=start)  # fmt: skip
            log = outdir / car.name / f"{bend.name}_{bucket.name}_{k}.nmea.gz"
            _write_drive(d, log)
            b = res.body.iloc[::10]
            lat, lon = _latlon(origin[:2], b["x_m"].to_numpy(float), b["y_m"].to_numpy(float))
            cells = sorted({h3.latlng_to_cell(a, o, h3_res) for a, o in zip(lat, lon, strict=True)})
            ax = d.axles.set_index("axle")
            rows.append({
                "car": car.name, "model": car.model, "receiver": car.receiver,
                "bend": bend.name, "bucket": bucket.name, "k": k, "log": str(log),
                "steer_csv": str(steer_csv_for(log)), "mu_road": mu,
                "radius_m": bend.radius_m, "speed_mps": speed, "ay_g": ay / G0,
                "utilisation": ay / (mu * G0),
                "utilisation_front": float(ax.loc["front", "utilisation_max"]),
                "utilisation_rear": float(ax.loc["rear", "utilisation_max"]),
                "mu_front": float(ax.loc["front", "mu_true"]),
                "mu_rear": float(ax.loc["rear", "mu_true"]),
                "start": start.isoformat(), "cells": ";".join(cells),
            })  # fmt: skip
    return rows
