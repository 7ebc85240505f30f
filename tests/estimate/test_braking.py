"""Braking μ = a/g (docs/physics.md §7) on synthetic and simulated traces.

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense import InputError
from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.estimate.braking import estimate_braking
from gripsense.io.sensors.accel import read_accel_csv
from gripsense.sim import SimParams
from gripsense.sim import maneuvers as M
from gripsense.sim.sensors import emulate_accelerometer


def trace(mu, *, bias_g=0.03, noise_g=0.05, spikes=True, rebound=True, seed=0, rate=50.0):
    """Hand-built 50 Hz trace (independent of the simulator): cruise, 0.25 s pressure ramp,
    plateau at −μ g, stop rebound, rest; plus bias, noise and outlier spikes."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 12, 1 / rate)
    v0 = 60 / 3.6
    t_on = 3.0
    t_stop = t_on + 0.25 + v0 / (mu * G0)
    a = np.zeros_like(t)
    ramp = (t >= t_on) & (t < t_on + 0.25)
    a[ramp] = -mu * G0 * (t[ramp] - t_on) / 0.25
    a[(t >= t_on + 0.25) & (t < t_stop)] = -mu * G0
    if rebound:
        rb = (t >= t_stop) & (t < t_stop + 0.3)
        a[rb] = 0.4 * G0 * np.sin(np.pi * (t[rb] - t_stop) / 0.3)
    a = a + bias_g * G0 + rng.normal(0, noise_g * G0, t.size)
    if spikes:
        idx = rng.choice(t.size, 12, replace=False)
        a[idx] += rng.choice([-1, 1], 12) * 0.8 * G0
    return pd.DataFrame({"t_s": t, "ax": a, "ay": np.nan, "az": np.nan})


@pytest.mark.parametrize("mu", [0.2, 0.3, 0.5, 0.7, 0.9, 1.0])
def test_synthetic_traces(mu):
    res = estimate_braking(trace(mu, seed=int(mu * 10)))
    assert len(res.events) == 1
    assert res.mu == pytest.approx(mu, abs=0.03)
    # a naive mean of all negative samples is far off when the stop is short (docs/physics.md §7)
    if mu >= 0.5:
        tr = trace(mu, seed=1)
        assert abs(-tr.loc[tr["ax"] < 0, "ax"].mean() / G0 - mu) > 0.1


@pytest.mark.parametrize("mu", [0.2, 0.6, 1.0])
def test_simulated_braking_with_pitch(mu):
    veh = Vehicle.from_toml(sample_path("corolla_sim.toml"))
    p = SimParams.from_vehicle(veh)
    res = M.run(p, M.braking(60 / 3.6), mu=mu)
    acc = emulate_accelerometer(res, noise_g=0.02, pitch_deg=2.0, bias_g=(0.02, 0, 0), seed=2)
    df = acc.rename(columns={"ax_g": "ax", "ay_g": "ay", "az_g": "az"})
    df[["ax", "ay", "az"]] *= G0
    out = estimate_braking(df)
    assert out.mu == pytest.approx(mu, abs=0.03)
    assert out.events["mu_3axis"].iloc[0] == pytest.approx(mu, abs=0.03)


def test_two_events_and_csv(tmp_path):
    a, b = trace(0.8, seed=3), trace(0.8, seed=4)
    b["t_s"] += a["t_s"].iloc[-1] + 0.02
    both = pd.concat([a, b], ignore_index=True)
    res = estimate_braking(both)
    assert len(res.events) == 2 and res.mu == pytest.approx(0.8, abs=0.03)
    f = tmp_path / "arduino.csv"
    pd.DataFrame({"millis": (both["t_s"] * 1000).astype(int), "X": -both["ax"] / G0}).to_csv(
        f, index=False
    )
    acc = read_accel_csv(
        f, t_col="millis", ax_col="X", ay_col=None, az_col=None, ax_sign=-1.0, time_scale=1e-3
    )
    assert estimate_braking(acc).mu == pytest.approx(res.mu, abs=1e-3)


def test_errors(tmp_path):
    quiet = trace(0.8)
    quiet["ax"] = np.random.default_rng(0).normal(0, 0.02 * G0, len(quiet))
    with pytest.raises(InputError, match="no braking event"):
        estimate_braking(quiet)
    clipped = trace(1.0, noise_g=0.0, spikes=False)
    clipped["ax"] = clipped["ax"].clip(lower=-0.5 * G0)
    with pytest.raises(InputError, match="clipped"):
        estimate_braking(clipped, clip_g=0.5)
    wrong = trace(0.9, spikes=False)
    wrong["ax"] *= G0  # m/s² values read as g
    with pytest.raises(InputError, match="units"):
        estimate_braking(wrong)
    f = tmp_path / "a.csv"
    f.write_text("t_s,ax_g\n0,0.1\n0.02,x\n")
    with pytest.raises(InputError, match="line 3"):
        read_accel_csv(f, ay_col=None, az_col=None)
    with pytest.raises(InputError, match="no column 'ax_g'"):
        f.write_text("t_s,X\n0,1\n")
        read_accel_csv(f)


def test_cli(tmp_path):
    from tests.cli.inprocess import cli

    tr = trace(0.7, seed=9)
    f = tmp_path / "acc.csv"
    pd.DataFrame({"t_s": tr["t_s"], "ax_g": tr["ax"] / G0}).to_csv(f, index=False)
    r = cli("brake-mu", str(f), "--az-col", "", "--ay-col", "", "-o", str(tmp_path / "ev.csv"))
    assert r.returncode == 0, r.stderr
    assert "μ = 0.7" in r.stdout
    assert pd.read_csv(tmp_path / "ev.csv")["mu"].iloc[0] == pytest.approx(0.7, abs=0.03)


def test_cli_maps_unit_suffixed_headers_without_flags(tmp_path):
    """Headers time_ms, ax_mps2, ay_mps2, az_mps2 need no flag; the mapping is printed; the old
    flags still work with a deprecation note; old and new together are an error."""
    from tests.cli.inprocess import cli

    tr = trace(0.7, seed=9)
    f = tmp_path / "acc.csv"
    pd.DataFrame(
        {
            "time_ms": tr["t_s"] * 1e3,
            "ax_mps2": tr["ax"],
            "ay_mps2": np.zeros(len(tr)),
            "az_mps2": np.full(len(tr), G0),
        }
    ).to_csv(f, index=False)
    r = cli("brake-mu", str(f))
    assert r.returncode == 0, r.stderr
    assert "t ← time_ms [ms], ax ← ax_mps2 [m/s²], ay ← ay_mps2 [m/s²]" in r.stdout, r.stdout
    assert "μ = 0.7" in r.stdout
    # the same with an explicit mapping, a flipped sign and g units converted back
    g = tmp_path / "flip.csv"
    pd.DataFrame({"clock": tr["t_s"], "acc": -tr["ax"] / G0}).to_csv(g, index=False)
    r = cli("brake-mu", str(g), "--columns", "t=clock:s,ax=-acc:g")
    assert r.returncode == 0 and "μ = 0.7" in r.stdout, r.stdout + r.stderr
    old = cli("brake-mu", str(f), "--t-col", "time_ms", "--time-scale", "0.001",
              "--ax-col", "ax_mps2", "--ay-col", "ay_mps2", "--az-col", "az_mps2",
              "--units", "mps2")  # fmt: skip
    assert old.returncode == 0 and "deprecated" in old.stdout and "μ = 0.7" in old.stdout
    both = cli("brake-mu", str(f), "--units", "mps2", "--columns", "t=time_ms:ms,ax=ax_mps2")
    assert both.returncode == 2 and "either --columns or the old flags" in both.stderr
