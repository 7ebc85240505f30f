"""The simulated road network of the fleet benchmark (``gripsense.fleet.network.
write_road_network``), checked from what a user would read: the logs (their positions and times
as the NMEA reader decodes them), the vehicle files and calibrations, and the truth table against
the bends' declared μ and the drivers' stated speeds.

Reduced size: two cars (CommonRoad's single-track model, whose truth is the road μ itself, and
gripsense's simulator on the PAC2002 sedan tyre), two bends (one grippy-then-wet, one worn-then-
slippery), one pass per car, bend and bucket.
"""

from __future__ import annotations

import fnmatch
import math

import h3
import numpy as np
import pandas as pd
import pytest

from gripsense.config import Vehicle
from gripsense.config.calibration import calibrated_vehicle, read_calibration
from gripsense.constants import G0
from gripsense.fleet.network import (
    DRY_AY_G,
    GRIPPY_MU,
    NETWORK_BUCKETS,
    NETWORK_CARS,
    SLIPPERY_UTILISATION,
    network_bends,
    write_road_network,
)
from gripsense.fleet.run import account_inputs, read_vehicle_map
from gripsense.io import read_nmea
from gripsense.sim.commonroad import commonroad_vehicle

CARS = [c for c in NETWORK_CARS if c.name in ("cr-std", "sedan")]
BENDS = [b for b in network_bends() if b.name in ("b1", "b4")]


@pytest.fixture(scope="module")
def net(tmp_path_factory):
    out = tmp_path_factory.mktemp("network")
    return write_road_network(out, cars=CARS, bends=BENDS, passes=(1, 1), seed=3, workers=1)


def _local_xy(lat, lon, lat0, lon0):
    """East, north [m] of (lat, lon) from (lat0, lon0) on a sphere of the Earth's mean radius
    (an independent conversion: the generator uses the WGS84 ellipsoid's radii).
    """
    r = 6_371_000.0
    return (np.deg2rad(lon - lon0) * r * math.cos(math.radians(lat0)),
            np.deg2rad(lat - lat0) * r)  # fmt: skip


def _circle_fit(x, y):
    """Centre and radius of the least-squares circle through the points (Kåsa)."""
    a = np.column_stack([x, y, np.ones_like(x)])
    c = np.linalg.lstsq(a, x**2 + y**2, rcond=None)[0]
    xc, yc = c[0] / 2, c[1] / 2
    return xc, yc, math.sqrt(c[2] + xc**2 + yc**2)


def test_files_as_a_user_has_them(net):
    assert len(net.logs) == len(CARS) * len(BENDS) * len(NETWORK_BUCKETS)
    logs, problems = account_inputs(net.patterns)
    assert problems == [] and len(logs) == len(net.logs)  # steering CSVs are not logs
    assert not any("everyday" in lg for lg in logs)
    vmap = read_vehicle_map(net.vehicle_map)
    for car in CARS:
        ((pat, vfile, _),) = [r for r in vmap if r[2] == car.name]
        veh = Vehicle.from_toml(vfile)
        assert veh.receiver is not None and veh.receiver.name == car.receiver
        cal = read_calibration(veh.calibration_file)
        assert cal.vehicle == veh.name and set(cal.axles) == {"front", "rear"}
        assert len({d.file for d in cal.drives}) == 3  # three everyday drives of its own
        used = calibrated_vehicle(vfile)
        for axle in ("front", "rear"):  # the vehicle file applies what the drives taught
            declared = veh.tyres[axle].cornering_stiffness_N_per_rad
            learned = cal.axles[axle].cornering_stiffness_N_per_rad
            now = used.tyres[axle].cornering_stiffness_N_per_rad
            assert abs(now - learned) < abs(declared - learned)
            assert used.tyres[axle].stiffness_uncertainty < veh.tyres[axle].stiffness_uncertainty
        for lg in net.logs.loc[net.logs["car"] == car.name, "log"]:
            assert fnmatch.fnmatch(lg, pat)
    # CommonRoad's car: the vehicle file states vehicle 2 as commonroad_vehicle describes it
    cr = Vehicle.from_toml(next(v for _, v, i in vmap if i == "cr-std"))
    ref = commonroad_vehicle(stiffness_error=CARS[0].stiffness_error,
                             stiffness_uncertainty=CARS[0].stiffness_uncertainty)  # fmt: skip
    keys = ("mass_kg", "front_weight_fraction", "wheelbase_m", "cg_height_m", "track_front_m",
            "track_rear_m", "yaw_inertia_kgm2", "cg_offset", "drive")  # fmt: skip
    for key in keys:
        assert getattr(cr, key) == getattr(ref, key), key
    for axle in ("front", "rear"):
        assert cr.tyres[axle] == ref.tyres[axle]


def test_passes_on_each_bend_geometry_time_and_speed(net):
    for r in net.logs.itertuples():
        bend = next(b for b in BENDS if b.name == r.bend)
        j = [b.name for b in NETWORK_BUCKETS].index(r.bucket)
        assert r.mu_road == bend.mu[j]
        ep = read_nmea(r.log).epochs
        t = pd.to_datetime(ep["time_utc"], utc=True)
        start = pd.Timestamp(NETWORK_BUCKETS[j].start)
        assert (t >= start).all() and (t < start + pd.Timedelta(hours=1)).all()
        # the arc read from the log: where the course turns at a steady rate
        x, y = _local_xy(ep["lat_deg"].to_numpy(), ep["lon_deg"].to_numpy(),
                         bend.lat_deg, bend.lon_deg)  # fmt: skip
        rate = ep["yaw_rate_rps"].to_numpy()
        speed = ep["speed_mps"].to_numpy()
        steady = np.abs(np.abs(rate) - np.median(speed) / bend.radius_m) < 0.1 * (
            np.median(speed) / bend.radius_m)  # fmt: skip
        assert steady.sum() > 50
        xc, yc, radius = _circle_fit(x[steady], y[steady])
        assert math.hypot(xc, yc) < 3.0  # the arc's centre is the bend's, to the metre
        assert radius == pytest.approx(bend.radius_m, rel=0.05)
        assert np.sign(np.median(rate[steady])) == (1 if bend.left else -1)
        ay = np.median(speed[steady]) ** 2 / radius / G0  # the driver's lateral acceleration
        if r.mu_road >= GRIPPY_MU:
            assert DRY_AY_G[0] - 0.02 <= ay <= DRY_AY_G[1] + 0.02
        else:
            u = ay / r.mu_road
            assert SLIPPERY_UTILISATION[0] - 0.05 <= u <= SLIPPERY_UTILISATION[1] + 0.05
        # the simulator's own utilisation of the axles agrees with the driver's
        assert r.utilisation == pytest.approx(ay / r.mu_road, rel=0.08)
        if r.model == "cr-std":  # CommonRoad's tyre peaks at the road's μ
            assert r.mu_front == pytest.approx(r.mu_road) and r.mu_rear == pytest.approx(r.mu_road)


def test_cells_shared_by_cars_distinct_between_bends(net):
    cells = {(r.bend, r.car): set(r.cells.split(";")) for r in net.logs.itertuples()}
    for bend in BENDS:
        a, b = (cells[(bend.name, c.name)] for c in CARS)
        assert len(a & b) >= 0.7 * min(len(a), len(b))  # the cars drive one geometry
    every = [set().union(*(v for (bn, _), v in cells.items() if bn == b.name)) for b in BENDS]
    assert not every[0] & every[1]
    # no cell of one bend is within reach of another's: their grid disks do not meet
    near = [set().union(*(h3.grid_disk(c, 2) for c in e)) for e in every]
    assert not near[0] & near[1]


def test_cell_truth(net):
    r = net.logs.iloc[0]
    cell = r.cells.split(";")[0]
    far = h3.latlng_to_cell(BENDS[0].lat_deg + 0.5, BENDS[0].lon_deg, net.h3_res)
    cells = pd.DataFrame({
        "cell": [cell, cell, cell, far],
        "bucket": pd.to_datetime([b.start for b in NETWORK_BUCKETS]
                                 + [pd.Timestamp("2026-11-21T07:00Z")] + [NETWORK_BUCKETS[0].start],
                                 utc=True),
    })  # fmt: skip
    t = net.cell_truth(cells)
    bend = next(b for b in BENDS if b.name == r.bend)
    assert t["mu_true"].iloc[0] == bend.mu[0] and t["mu_true"].iloc[1] == bend.mu[1]
    assert np.isnan(t["mu_true"].iloc[2]) and np.isnan(t["mu_true"].iloc[3])  # no bucket, no bend
    assert t["on_path"].iloc[0] and t["bend"].iloc[3] == ""
    here = net.logs[(net.logs["bend"] == r.bend) & (net.logs["bucket"] == NETWORK_BUCKETS[0].name)]
    assert t["mu_axle_min"].iloc[0] == here[["mu_front", "mu_rear"]].min().min()
    assert t["mu_axle_max"].iloc[0] == here[["mu_front", "mu_rear"]].max().max()
    empty = net.cell_truth(cells.iloc[:0])
    assert empty.empty and {"bend", "mu_true", "mu_axle_min", "on_path"} <= set(empty.columns)
