"""Channels at different rates: course/speed at 1 Hz, heading at 10 Hz (an OxTS-like log).

Truth: the simulator's full-rate log of the same drive — every epoch has its own course and
speed — so the course interpolated onto the heading epochs by the side slip is compared with
the course the receiver measured there. Also the real ``rst39`` log (OxTS $PASHR 25 Hz + RMC
1 Hz, decoded values checked against GPSD elsewhere).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gripsense
from gripsense.io import align_channels, read_nmea
from gripsense.sim import maneuvers as M
from gripsense.sim.drives import simulate_drive

RST39 = Path(gripsense.__file__).parent / "data" / "rst39.log"


def _slalom(period_s, amp_deg, duration_s=30.0):
    t = np.linspace(0.0, duration_s, 1501)
    amp = np.deg2rad(amp_deg)
    steer = np.where(t < 6.0, 0.0, amp * np.sin(2 * np.pi * (t - 6.0) / period_s))
    m = M.slalom(60 / 3.6, amplitude_rad=amp, period_s=period_s, cycles=6)
    m.steer_table, m.duration_s, m.settle_s = (t, steer), duration_s, 6.0
    return simulate_drive("sedan", "mf-book", m, 0.9, receiver="rtk", seed=5).lines


@pytest.fixture(scope="module")
def slalom():
    """A quick slalom (4 s period): the side slip bends too fast for 1 Hz course samples."""
    return _slalom(4.0, 4.0)


@pytest.fixture(scope="module")
def weave():
    """A slow weave (12 s period): the side slip is smooth between 1 Hz course samples."""
    return _slalom(12.0, 2.0, duration_s=42.0)


def _one_hz_course(lines, shift_epochs=0):
    """The log with RMC and VTG kept only at whole seconds (their course and speed taken
    *shift_epochs* epochs earlier: a course channel that lags)."""
    out, burst, bursts = [], [], []
    for ln in lines:
        if ln.startswith("$GPHDT") and burst:
            bursts.append(burst)
            burst = []
        burst.append(ln)
    bursts.append(burst)
    for k, b in enumerate(bursts):
        gga = next(x for x in b if x.startswith("$GPGGA"))
        whole = gga.split(",")[1].split(".")[1] == "00"
        for ln in b:
            if ln.startswith(("$GPRMC", "$GPVTG")):
                if not whole:
                    continue
                if shift_epochs:
                    src = next(x for x in bursts[max(k - shift_epochs, 0)] if x[:6] == ln[:6])
                    ln = _with_course_of(ln, src)
            out.append(ln)
    return out


def _with_course_of(line, src):
    from tests.nmea_helpers import sentence

    f, g = line[1:].split("*")[0].split(","), src[1:].split("*")[0].split(",")
    idx = (7, 8) if f[0].endswith("RMC") else (1, 5, 7)
    for i in idx:
        f[i] = g[i]
    return sentence(",".join(f))


def _aligned_errors(lines):
    full = read_nmea(lines).epochs
    low = read_nmea(_one_hz_course(lines)).epochs
    assert low["course_deg"].notna().sum() < 0.15 * len(low)  # 1 Hz of 10 Hz
    out, al = align_channels(low)
    missing = al.n_heading - al.n_course
    assert al.n_aligned + al.n_not_smooth + al.n_gap == missing
    filled = low["course_deg"].isna() & out["course_deg"].notna()
    truth = full.set_index("time_utc").loc[out.loc[filled, "time_utc"]]
    err = out.loc[filled, "course_deg"].to_numpy() - truth["course_deg"].to_numpy()
    dv = out.loc[filled, "speed_mps"].to_numpy() - truth["speed_mps"].to_numpy()
    # a plain interpolation of the course itself, for comparison
    have = low["course_deg"].notna()
    cc = np.rad2deg(np.unwrap(np.deg2rad(low.loc[have, "course_deg"])))
    naive = np.interp(out.loc[filled, "t_s"], low.loc[have, "t_s"], cc)
    naive_err = naive - truth["course_deg"].to_numpy()
    wrap = lambda x: np.abs((x + 180.0) % 360.0 - 180.0)  # noqa: E731
    return al, missing, wrap(err), np.abs(dv), wrap(naive_err)


def test_course_from_the_side_slip_matches_the_measured_course(weave):
    """Slow weave: most epochs filled, the course within 0.4° (median 0.1°) of what the
    receiver measured there — a plain interpolation of the course errs several times more."""
    al, missing, err, dv, naive = _aligned_errors(weave)
    assert al.n_aligned >= 0.6 * missing, al
    assert err.max() <= 0.4 and np.median(err) <= 0.1, (err.max(), np.median(err))
    assert dv.max() <= 0.1
    assert np.median(naive) > 3 * np.median(err), (np.median(naive), np.median(err))


def test_fast_transients_are_left_alone_rather_than_filled_wrongly(slalom):
    """Quick slalom: the curvature gate keeps out the epochs a straight line would miss; the
    ones filled stay within 0.5°."""
    al, missing, err, _, _ = _aligned_errors(slalom)
    assert al.n_not_smooth >= 0.5 * missing, al
    assert err.size == 0 or err.max() <= 0.5, err.max()


def test_skew_of_a_lagging_course_channel_is_found(slalom):
    """A course channel 0.2 s late shows as a skew 0.2 s more negative than the synchronous
    one; the synchronous one reads within 0.1 s of zero (the side slip's own rate in a 4 s
    slalom biases the check by about that much)."""
    _, al = align_channels(read_nmea(_one_hz_course(slalom, shift_epochs=2)).epochs)
    _, al0 = align_channels(read_nmea(_one_hz_course(slalom)).epochs)
    assert abs(al0.skew_s) <= 0.1 + 1e-9, al0
    assert al.skew_s - al0.skew_s == pytest.approx(-0.2, abs=0.05), (al, al0)


def test_rst39_gets_usable_epochs_and_the_summary_says_how():
    ep = read_nmea(RST39).epochs
    usable = (ep[["heading_deg", "course_deg", "speed_mps", "yaw_rate_rps"]].notna()).all(axis=1)
    out, al = align_channels(ep)
    usable2 = (out[["heading_deg", "course_deg", "speed_mps", "yaw_rate_rps"]].notna()).all(axis=1)
    assert usable.sum() <= 5 and usable2.sum() >= 20
    # GPSD's decodes of the four RMC samples are kept unchanged
    same = ep["course_deg"].notna()
    assert (out.loc[same, "course_deg"] == ep.loc[same, "course_deg"]).all()
    text = al.describe()
    assert "1 Hz" in text and "25 Hz" in text and "filled" in text
