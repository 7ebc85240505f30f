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
from pathlib import Path

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


def _write_nmea(ep: pd.DataFrame, digits: int = 2) -> list[list[str]]:
    """Per epoch its sentences (HDT, GGA, VTG, RMC, ROT) at the emulator's resolution, the time
    stamp to *digits* decimals of a second (rounded)."""
    out = []
    q = 10 ** (6 - digits)  # [µs]
    for rec in ep.itertuples(index=False):
        when = rec.time_utc.to_pydatetime(warn=False)
        cs = round(when.microsecond / q)
        when = when.replace(microsecond=0) + dt.timedelta(microseconds=q * cs)
        hms = when.strftime("%H%M%S") + f".{when.microsecond // q:0{digits}d}"
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


def _columns(ep: pd.DataFrame, t: np.ndarray, tt: np.ndarray, idx: np.ndarray | None) -> dict:
    """The resampled columns at the logger's times *tt*: linear interpolation between the
    receiver's epochs at *t* (angles the shorter way round), or with *idx* the receiver epoch
    each logged one repeats."""
    out: dict = {"t_s": tt}
    for c in _RESAMPLED:
        x = ep[c].to_numpy(float)
        angle = c in ("course_deg", "heading_deg")
        if angle:
            x = np.rad2deg(np.unwrap(np.deg2rad(x)))
        y = np.interp(tt, t, x) if idx is None else x[idx]
        out[c] = np.mod(y, 360.0) if angle else y
    return out


def _resample(ep: pd.DataFrame, k: int, how: str) -> pd.DataFrame:
    """The epochs written k times as often: ``linear`` interpolation between them (angles the
    shorter way round) or ``hold`` the last one, at new time stamps."""
    t = ep["t_s"].to_numpy(float)
    tt = np.concatenate([t[:-1, None] + np.diff(t)[:, None] * np.arange(k) / k]).ravel()
    tt = np.append(tt, t[-1])
    out = _columns(ep, t, tt, None if how == "linear" else np.searchsorted(t, tt, "right") - 1)
    out["time_utc"] = ep["time_utc"].iloc[0] + pd.to_timedelta(np.round((tt - t[0]) * 100) / 100,
                                                               unit="s")  # fmt: skip
    return pd.DataFrame(out)


@functools.cache
def _drive(mu: float, u: float, receiver: str = "v100"):
    """A simulated circle (a V100-like receiver unless told, 10 Hz): its epochs and the
    declared vehicle."""
    d = simulate_drive(
        "sedan", "mf-book", None, mu, receiver=receiver, seed=3,
        circle=(limit_speed(mu, 40.0, u), 40.0),
    )  # fmt: skip
    return read_nmea(d.lines).epochs, user_vehicle(truth_vehicle("sedan"), "mf-book")


def _run(lines, vehicle):
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    res = run.run(read_nmea(lines).epochs)
    s = res.summary.set_index("axle")
    w = res.windows.groupby("axle")["grip_used_lower"].max()
    return s["grip_used"], s["grip_used_lower"], w, res


@functools.cache
def _clean(mu: float, u: float, receiver: str = "v100"):
    ep, vehicle = _drive(mu, u, receiver)
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
    assert m["epochs_resampled"] == 0 and "receiver_rate_hz" not in m, m
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


# --- any ratio: 10 Hz written at 11 … 200 Hz, linearly, held or nearest (docs/physics.md §14.2)

_RX_PERIOD_S = 0.1  # the emulated receiver's epochs (10 Hz)


def _resample_ratio(ep: pd.DataFrame, ratio: float, how: str, offset: float) -> pd.DataFrame:
    """The receiver's epochs written by a logger at ``ratio`` × 10 Hz from ``offset`` [s]
    after the first receiver epoch: ``linear`` interpolation (angles the shorter way round),
    ``hold`` the last receiver epoch or ``nearest`` the nearest one, at the logger's exact
    times (the writer rounds the stamps)."""
    t = np.round(ep["t_s"].to_numpy(float), 6)  # the receiver's stamps, without float noise
    step = _RX_PERIOD_S / ratio
    tt = t[0] + offset + np.arange(int((t[-1] - t[0] - offset) / step + 1e-9) + 1) * step
    pos = (tt - t[0]) / _RX_PERIOD_S
    idx = np.floor(pos + (0.5 if how == "nearest" else 0.0) + 1e-9).astype(int)
    idx = np.clip(idx, 0, t.size - 1)
    out = _columns(ep, t, tt, None if how == "linear" else idx)
    out["time_utc"] = ep["time_utc"].iloc[0] + pd.to_timedelta(np.round(tt - t[0], 6), unit="s")
    return pd.DataFrame(out)


def _shifted_bounds(mu: float, u: float, receiver: str, shift: float):
    """The clean log's bounds with every time stamp moved by *shift* [s] (the same data)."""
    ep, vehicle = _drive(mu, u, receiver)
    clean = read_nmea([x for b in _write_nmea(ep) for x in b]).epochs
    clean["t_s"] = clean["t_s"] + shift
    run = FrictionRun(vehicle, method="axle-window", noise=NoiseModel.for_vehicle(vehicle, "v100"))
    res = run.run(clean)
    return (
        res.summary.set_index("axle")["grip_used_lower"],
        res.windows.groupby("axle")["grip_used_lower"].max(),
    )


RESAMPLE_TOL = 1e-4
"""How far a resampled log's bound may lie above the receiver's own: the logger rounds the
values it writes to the format's digits (0.001°, 1e-4 kn, 1e-7 minute) and, at a rate its
stamps cannot hold (15 Hz in 0.01 s stamps), its times; the knots fitted from them come back
within a fraction of that, and the bound within 7.6e-6 on these drives (two receivers, ×1.1 to
×20, two clock offsets). Without the reconstruction a 10 → 25 Hz log rose 1.7e-3 (linear) and
3.0e-3 (held) [-]."""


@settings(max_examples=16, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
@given(
    mu=st.sampled_from([0.5, 0.9]),
    u=st.sampled_from([0.8, 1.05]),
    rate_hz=st.integers(11, 200),
    how=st.sampled_from(["linear", "hold", "nearest"]),
    offset_share=st.floats(0.0, 1.0),
    receiver=st.sampled_from(["v100", "rtk"]),
)
def test_a_resampling_at_any_ratio_never_raises_the_bound(
    mu, u, rate_hz, how, offset_share, receiver
):
    """A 10 Hz compass written at any whole rate from 11 to 200 Hz (×1.1 … ×20, a whole
    multiple or not), by linear interpolation, holding the last value or the nearest one, the
    logger's clock starting anywhere within its step; stamps to 0.01 s up to 100 Hz, to 1 ms
    above (rounded: 15 Hz steps 0.06 and 0.07 s); a V100-like and an RTK-class compass
    (:func:`_check_resampled`)."""
    _check_resampled(mu, u, rate_hz / 10.0, how, offset_share, receiver)


@pytest.mark.parametrize("how", ["linear", "hold", "nearest"])
@pytest.mark.parametrize("ratio", [1.5, 2.5, 12.0, 20.0])
def test_the_named_ratios_never_raise_the_bound(ratio, how):
    """10 → 15, 25, 120 and 200 Hz, each way of resampling (:func:`_check_resampled`)."""
    _check_resampled(0.9, 1.05, ratio, how, 0.37, "v100")


def _check_resampled(mu, u, ratio, how, offset_share, receiver):
    """The receiver's 10 Hz epochs come back — the knots of the piecewise-linear curve, or the
    changes of the held values — and the drive's bound and every window's are at most the
    receiver's own (+ :data:`RESAMPLE_TOL`); the epochs collapsed are counted and said. A held
    log does not say where within a step the receiver's epoch came: its epochs come back
    shifted by one constant under a step, and are compared with the receiver's shifted by it
    (the bins lie on the data clock)."""
    ep, vehicle = _drive(mu, u, receiver)
    offset = offset_share * _RX_PERIOD_S / ratio
    faulty = _resample_ratio(ep, ratio, how, offset)
    digits = 2 if _RX_PERIOD_S / ratio >= 0.01 else 3
    _, bound, win, res = _run([x for b in _write_nmea(faulty, digits) for x in b], vehicle)
    if how == "linear":
        _, bound0, win0 = _clean(mu, u, receiver)
    else:
        # the one constant the held log leaves open: where the receiver's epochs come back
        t0 = np.round(ep["t_s"].to_numpy(float), 6)
        t1 = np.sort(res.wheels["t_s"].unique())
        x = t1 - t0[0]
        back = x - np.floor(x / _RX_PERIOD_S + 1e-4) * _RX_PERIOD_S  # each epoch's, [0, step)
        shift = float(np.median(back))
        assert np.all(np.abs(back - shift) < 1e-6), back
        bound0, win0 = _shifted_bounds(mu, u, receiver, round(shift, 6))
    assert (bound <= bound0 + RESAMPLE_TOL).all(), (bound.to_dict(), bound0.to_dict())
    assert (win <= win0 + RESAMPLE_TOL).all(), (win.to_dict(), win0.to_dict())
    m = res.meta
    assert m["receiver_rate_hz"] == pytest.approx(10.0), m
    assert abs(m["epochs_used"] - len(ep)) <= 3, (m["epochs_used"], len(ep))
    n_copies = m["epochs_duplicate"] + m["epochs_held"] + m["epochs_interpolated"]
    assert n_copies + m["epochs_resampled"] >= len(faulty) - len(ep) - 3, m
    assert "epochs collapsed" in res.explain()


@pytest.mark.parametrize("ratio", [2.5, 1.5])
def test_a_non_integer_linear_resampling_comes_back_as_the_receivers_epochs(ratio):
    """10 → 25 Hz and 10 → 15 Hz by linear interpolation (the cases the on-line test alone
    missed: a knot between every second pair of epochs, or every pair): exactly the receiver's
    epochs come back, at its times, with its values within the format's resolution."""
    ep, _ = _drive(0.9, 1.05)
    faulty = _resample_ratio(ep, ratio, "linear", 0.0)
    log = read_nmea([x for b in _write_nmea(faulty) for x in b]).epochs
    from gripsense.estimate.wheels import receiver_epochs

    out, _, counts = receiver_epochs(log)
    clean = read_nmea([x for b in _write_nmea(ep) for x in b]).epochs
    assert counts["receiver_rate_hz"] == pytest.approx(10.0)
    assert len(out) == len(clean)
    np.testing.assert_allclose(out["t_s"], clean["t_s"], rtol=0, atol=1e-6)
    # the writer's resolution: 0.001° of heading, 1e-4 kn of speed; and 15 Hz stamps are
    # rounded to 0.01 s: each written epoch up to 5 ms off its time, which moves a value by up
    # to its rate of change × 5 ms, and a knot taken from the line through two epochs a third
    # of a step from it (×1.5 and ×3 of the way) by up to twice that
    late = 0.0 if ratio == 2.5 else 2 * 0.005
    t = clean["t_s"].to_numpy(float)
    rate_h = np.abs(np.gradient(np.rad2deg(np.unwrap(np.deg2rad(clean["heading_deg"]))), t))
    rate_v = np.abs(np.gradient(clean["speed_mps"].to_numpy(float), t))
    d_h = np.abs(np.mod(out["heading_deg"] - clean["heading_deg"] + 180.0, 360.0) - 180.0)
    assert d_h.max() <= 0.001 + rate_h.max() * late, (d_h.max(), rate_h.max())
    d_v = np.abs(out["speed_mps"] - clean["speed_mps"])
    assert d_v.max() <= 1e-4 * KNOT + rate_v.max() * late, (d_v.max(), rate_v.max())


def test_bundled_logs_are_not_taken_for_a_resampling():
    """The bundled demo drives (10 Hz compass) and every bundled real log with a position: no
    resampling found, no epoch moved or replaced."""
    from gripsense import data
    from gripsense.estimate.wheels import receiver_epochs
    from gripsense.io import read_log

    root = Path(__file__).resolve().parents[1] / "data"
    logs = sorted((data.path("demo")).glob("*.nmea.gz"))
    logs += [data.path("rst39.log"), *sorted((root / "gpsd").glob("*.log"))]
    logs += sorted((root / "formats" / "nmea").glob("*.log"))
    # the GPL VBOX file is in the repository, not in the sdist
    logs += [p for p in [root / "formats" / "vbox" / "vb3i_imu_can.vbo"] if p.exists()]
    seen = 0
    for path in logs:
        ep = read_log(path).epochs
        if "lat_deg" not in ep or ep["lat_deg"].notna().sum() < 20:
            continue
        seen += 1
        out, src, counts = receiver_epochs(ep)
        assert counts["epochs_resampled"] == 0 and np.isnan(counts["receiver_rate_hz"]), path
        np.testing.assert_array_equal(out["t_s"], ep["t_s"].to_numpy()[src])
    assert seen >= 28
