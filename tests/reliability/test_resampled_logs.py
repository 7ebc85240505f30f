"""A logger that resamples its receiver — writes a 10 Hz compass at 20 or 50 Hz by linear
interpolation, or by holding the last value, at new time stamps — adds no measurement: the
measured grip and its model-free bound stay those of the receiver's own epochs, never higher,
and the collapsed epochs are counted (docs/reliability.md, docs/physics.md §14.2). A receiver
that really measures at 20–50 Hz is not collapsed.

The faulty logs are written here, independently of gripsense's writers: sentences at the
emulated receiver's resolution (heading and course to 0.001°, speed to 0.0001 kn, position to
1e-7 minute, time to 0.01 s), the interpolated values rounded to the same digits.
"""

from __future__ import annotations

import datetime as dt
import functools
from functools import reduce

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense import FrictionRun
from gripsense.estimate.noise import NoiseModel
from gripsense.io import read_nmea
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import (
    limit_speed,
    simulate_drive,
    truth_tyre,
    truth_vehicle,
    user_vehicle,
)
from gripsense.sim.gnss import CompassNoise, emulate_compass
from gripsense.sim.vehicle import SimParams

KNOT = 1852.0 / 3600.0  # [m/s] per knot (exact, by definition of the nautical mile)


def _sentence(body: str) -> str:
    """``$body*hh`` with the NMEA 0183 XOR checksum."""
    return f"${body}*{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


def _ddmm(value: float, pos: str, neg: str, width: int) -> tuple[str, str]:
    h = pos if value >= 0 else neg
    v = abs(value)
    d = int(v)
    m = round((v - d) * 60.0, 7)
    if m >= 60.0:
        d, m = d + 1, 0.0
    return f"{d:0{width}d}{m:010.7f}", h


def _write_nmea(ep: pd.DataFrame) -> list[list[str]]:
    """Per epoch its sentences (HDT, GGA, VTG, RMC, ROT) at the emulator's resolution."""
    out = []
    for rec in ep.itertuples(index=False):
        when = rec.time_utc.to_pydatetime()
        cs = round(when.microsecond / 1e4)
        when = when.replace(microsecond=0) + dt.timedelta(milliseconds=10 * cs)
        hms = when.strftime("%H%M%S") + f".{when.microsecond // 10000:02d}"
        la, ns = _ddmm(rec.lat_deg, "N", "S", 2)
        lo, ew = _ddmm(rec.lon_deg, "E", "W", 3)
        kn = rec.speed_mps / KNOT
        hdg, crs = np.mod(rec.heading_deg, 360.0), np.mod(rec.course_deg, 360.0)
        rot = -np.rad2deg(rec.yaw_rate_rps) * 60.0  # deg/min, positive clockwise
        out.append(
            [
                _sentence(f"GPHDT,{hdg:.3f},T"),
                _sentence(f"GPGGA,{hms},{la},{ns},{lo},{ew},2,12,0.8,100.000,M,30.000,M,1.0,0001"),
                _sentence(f"GPVTG,{crs:.3f},T,,M,{kn:.4f},N,{rec.speed_mps * 3.6:.4f},K,D"),
                _sentence(
                    f"GPRMC,{hms},A,{la},{ns},{lo},{ew},{kn:.4f},{crs:.3f},{when:%d%m%y},,,D"
                ),
                _sentence(f"GPROT,{rot:.2f},A"),
            ]
        )
    return out


_RESAMPLED = ("lat_deg", "lon_deg", "speed_mps", "course_deg", "heading_deg", "yaw_rate_rps")


def _resample(ep: pd.DataFrame, k: int, how: str) -> pd.DataFrame:
    """The epochs written k times as often: ``linear`` interpolation between them (angles the
    shorter way round) or ``hold`` the last one, at new time stamps."""
    t = ep["t_s"].to_numpy(float)
    tt = np.concatenate([t[:-1, None] + np.diff(t)[:, None] * np.arange(k) / k]).ravel()
    tt = np.append(tt, t[-1])
    out: dict = {"t_s": tt}
    for c in _RESAMPLED:
        x = ep[c].to_numpy(float)
        angle = c in ("course_deg", "heading_deg")
        if angle:
            x = np.rad2deg(np.unwrap(np.deg2rad(x)))
        y = np.interp(tt, t, x) if how == "linear" else x[np.searchsorted(t, tt, "right") - 1]
        out[c] = np.mod(y, 360.0) if angle else y
    out["time_utc"] = ep["time_utc"].iloc[0] + pd.to_timedelta(np.round((tt - t[0]) * 100) / 100,
                                                               unit="s")  # fmt: skip
    return pd.DataFrame(out)


@functools.cache
def _drive(mu: float, u: float):
    """A simulated circle (V100-like receiver, 10 Hz): its epochs and the declared vehicle."""
    d = simulate_drive(
        "sedan", "mf-book", None, mu, seed=3, circle=(limit_speed(mu, 40.0, u), 40.0)
    )
    return read_nmea(d.lines).epochs, user_vehicle(truth_vehicle("sedan"), "mf-book")


def _run(lines, vehicle):
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    res = run.run(read_nmea(lines).epochs)
    s = res.summary.set_index("axle")
    w = res.windows.groupby("axle")["grip_used_lower"].max()
    return s["grip_used"], s["grip_used_lower"], w, res


@functools.cache
def _clean(mu: float, u: float):
    ep, vehicle = _drive(mu, u)
    grip, bound, win, _ = _run([x for b in _write_nmea(ep) for x in b], vehicle)
    return grip, bound, win


@settings(max_examples=10, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
@given(
    mu=st.sampled_from([0.5, 0.9]),
    u=st.sampled_from([0.8, 1.05]),
    factor=st.sampled_from([2, 5]),
    how=st.sampled_from(["linear", "hold"]),
    epoch_share=st.floats(0.0, 0.5),
    late_share=st.floats(0.0, 0.2),
    shuffle=st.booleans(),
    seed=st.integers(0, 10_000),
)
def test_resampled_duplicated_and_reordered_logs_never_raise_the_bound(
    mu, u, factor, how, epoch_share, late_share, shuffle, seed
):
    """Resampled (×2, ×5, linear or held), some epochs written twice in a row, some again
    after a later one, the sentences of an epoch in any order: the drive's measured grip, its
    bound and every window's bound are at most the clean log's (float rounding only)."""
    ep, vehicle = _drive(mu, u)
    grip0, bound0, win0 = _clean(mu, u)
    rng = np.random.default_rng(seed)
    blocks = _write_nmea(_resample(ep, factor, how))
    lines: list[str] = []
    for i, b in enumerate(blocks):
        b = list(rng.permutation(b)) if shuffle else b
        lines += b * (1 + (rng.random() < epoch_share))
        if i >= 3 and rng.random() < late_share:  # an earlier epoch written again, late
            lines += blocks[i - 2]
    grip, bound, win, res = _run(lines, vehicle)
    assert (bound <= bound0 + 1e-9).all(), (bound.to_dict(), bound0.to_dict())
    assert (grip <= grip0 + 1e-9).all(), (grip.to_dict(), grip0.to_dict())
    assert (win <= win0 + 1e-9).all(), (win.to_dict(), win0.to_dict())
    # every copy is counted once, and said
    m = res.meta
    n_copies = m["epochs_duplicate"] + m["epochs_held"] + m["epochs_interpolated"]
    assert n_copies >= (factor - 1) * (len(ep) - 1) * 0.99
    assert f"{n_copies} epochs collapsed" in res.explain()
    key = "epochs_interpolated" if how == "linear" else "epochs_held"
    assert m[key] >= (factor - 1) * (len(ep) - 1) * 0.99, m


@pytest.mark.parametrize("factor", [2, 5])
def test_an_interpolating_logger_is_collapsed_to_the_receivers_epochs(factor):
    """Linear interpolation ×2 and ×5: exactly the interpolated epochs are collapsed, and the
    bound is the clean log's to float rounding."""
    ep, vehicle = _drive(0.9, 1.05)
    _, bound0, win0 = _clean(0.9, 1.05)
    _, bound, win, res = _run(
        [x for b in _write_nmea(_resample(ep, factor, "linear")) for x in b], vehicle
    )
    assert res.meta["epochs_interpolated"] == (factor - 1) * (len(ep) - 1)
    assert res.meta["epochs_used"] == len(ep)
    np.testing.assert_allclose(bound, bound0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(win, win0, rtol=0, atol=1e-9)
    assert "lie on the line between their neighbours" in res.meta["epochs_collapsed"]


def test_without_the_collapse_interpolated_epochs_would_raise_the_bound():
    """The tests above can fail: the same ×5 interpolation with its heading nudged by ±0.01°
    (ten times its resolution, far below the receiver's noise) is no longer on a line, nothing
    collapses, and the bound rises (the noise averaged over five times the samples)."""
    ep, vehicle = _drive(0.9, 1.05)
    _, bound0, _ = _clean(0.9, 1.05)
    faulty = _resample(ep, 5, "linear")
    faulty["heading_deg"] = faulty["heading_deg"] + 0.01 * (-1.0) ** np.arange(len(faulty))
    _, raised, _, res = _run([x for b in _write_nmea(faulty) for x in b], vehicle)
    assert res.meta["epochs_interpolated"] < 0.01 * len(faulty)
    assert (raised > bound0 + 0.003).any(), (bound0.to_dict(), raised.to_dict())


@pytest.mark.parametrize("receiver", ["v100", "rtk", "white-0.3"])
@pytest.mark.parametrize("rate_hz", [20.0, 50.0])
def test_a_genuine_high_rate_receiver_is_not_collapsed(receiver, rate_hz):
    """A receiver measuring at 20 or 50 Hz with its own independent noise: not one epoch is
    taken for a copy, and its bound uses every epoch."""
    vehicle = truth_vehicle("sedan")
    tyre = truth_tyre("mf-book")
    p = SimParams.from_vehicle(vehicle, relaxation_length_m=0.5,
                               sim_tyres={"front": tyre, "rear": tyre})  # fmt: skip
    res = M.run(p, M.circle(limit_speed(0.9, 40.0, 1.0), 40.0, laps=1.0, params=p), mu=0.9)
    antenna = (-vehicle.cg_offset[0], -vehicle.cg_offset[1])
    log = emulate_compass(res, antenna, rate_hz=rate_hz, noise=CompassNoise.preset(receiver),
                          seed=11)  # fmt: skip
    ep = read_nmea(log.lines).epochs
    uv = user_vehicle(vehicle, "mf-book")
    out = FrictionRun(uv, noise=NoiseModel.for_vehicle(uv, receiver)).run(ep)
    m = out.meta
    assert m["epochs_interpolated"] == m["epochs_held"] == m["epochs_duplicate"] == 0, m
    assert m["epochs_used"] == len(ep)
    assert "epochs_collapsed" not in m


def test_live_collapses_an_interpolating_logger_and_says_so(tmp_path):
    """``live`` on a ×2 interpolated replay: its rows' measured grip and bounds are those of the
    clean replay (float rounding only), and the run's notes count the collapsed epochs."""
    from gripsense.live.runner import run_live
    from gripsense.live.sources import ReplaySource

    ep, vehicle = _drive(0.9, 1.05)
    out = {}
    for name, epochs in (("clean", ep), ("faulty", _resample(ep, 2, "linear"))):
        log = tmp_path / f"{name}.nmea"
        log.write_text("\r\n".join(x for b in _write_nmea(epochs) for x in b) + "\r\n")
        res = run_live(ReplaySource(log, speed=0), vehicle, receiver="v100",
                       output=tmp_path / f"{name}.csv", handle_signals=False)  # fmt: skip
        rows = pd.read_csv(tmp_path / f"{name}.csv")
        out[name] = (rows.groupby("unit")[["grip_used", "grip_used_lower"]].max(), res["notes"])
    (clean, clean_notes), (faulty, notes) = out["clean"], out["faulty"]
    assert len(clean) and (faulty <= clean + 1e-9).all().all(), (clean, faulty)
    assert not any("collapsed" in n for n in clean_notes)
    assert any("lie on the line between their neighbours" in n for n in notes), notes
