"""One receiver description: the estimator's noise model and the simulator's compass emulator are
built from the same :class:`gripsense.config.Receiver`, named or read from a file, and
``gripsense simulate --receiver`` takes it as ``gripsense friction`` does."""

from __future__ import annotations

import warnings

import pandas as pd
import pytest

from gripsense.config import RECEIVERS, Receiver, receiver_from
from gripsense.estimate import NoiseModel
from gripsense.sim.gnss import CompassNoise
from gripsense.sim.scenario import run_scenario
from tests.cli.inprocess import cli

# the receiver classes as the documentation states them (docs/friction.md, sim/gnss.py):
# heading white / slow [deg], slow τ [s], position slow / white [m], velocity [m/s], rate [deg/s]
DOCUMENTED = {
    "v100": (0.3, 0.4, 20.0, 0.7, 0.3, 0.05, 0.3),
    "white-0.3": (0.3, 0.0, 20.0, 0.7, 0.3, 0.05, 0.3),
    "rtk": (0.05, 0.05, 20.0, 0.02, 0.01, 0.02, 0.1),
}


@pytest.mark.parametrize("name", sorted(DOCUMENTED))
def test_estimator_and_emulator_are_built_from_one_receiver(name):
    hw, hs, tau, ps, pw, v, r = DOCUMENTED[name]
    cn = CompassNoise.preset(name)
    assert (cn.heading_white_deg, cn.heading_slow_deg, cn.heading_slow_tau_s) == (hw, hs, tau)
    assert (cn.position_slow_m, cn.position_white_m, cn.velocity_mps, cn.yaw_rate_dps) == (
        ps,
        pw,
        v,
        r,
    )
    nm = NoiseModel.for_vehicle(None, name)
    assert (nm.heading_white_deg, nm.heading_slow_deg, nm.heading_slow_tau_s) == (hw, hs, tau)
    assert (nm.velocity_mps, nm.yaw_rate_dps) == (v, r)
    assert CompassNoise.from_receiver(RECEIVERS[name]) == cn


def test_a_receiver_file_feeds_both(tmp_path):
    f = tmp_path / "mine.toml"
    f.write_text(
        "[receiver]\nheading_white_deg = 0.1\nheading_slow_deg = 0.2\nheading_slow_tau_s = 40\n"
        "position_white_m = 0.05\n"
    )
    rec = receiver_from(f)
    assert rec == Receiver("mine", 0.1, 0.2, heading_slow_tau_s=40.0, position_white_m=0.05)
    cn, nm = CompassNoise.preset(f), NoiseModel.for_vehicle(None, f)
    assert cn.heading_slow_tau_s == nm.heading_slow_tau_s == 40.0
    assert cn.position_white_m == 0.05 and cn.position_slow_m == 0.7  # the rest: V100 class
    f.write_text("[receiver]\nheading_slow_tau_s = 0.01\n")
    with pytest.raises(Exception, match=r"heading_slow_tau_s.*plausible"):
        receiver_from(f)


def test_none_is_exact_and_not_a_receiver_to_estimate_with():
    exact = CompassNoise.preset("none")
    assert exact == CompassNoise.none(0.5)
    assert exact.heading_white_deg == exact.velocity_mps == exact.position_slow_m == 0.0
    with pytest.raises(Exception, match="receiver 'none'"):
        receiver_from("none")


def test_string_noise_is_a_deprecated_receiver():
    from gripsense import FrictionRun
    from gripsense.demo import demo_dir

    with pytest.warns(DeprecationWarning, match="receiver='rtk'"):
        run = FrictionRun(demo_dir() / "vehicle.toml", noise="rtk")
    assert run.receiver == "rtk"


SCENARIO = """
[scenario]
vehicle = "corolla_sim.toml"

[gnss]
{gnss}

[[case]]
maneuver = "circle"
speed_kmh = 30
radius_m = 25
laps = 0.25
"""


def test_simulate_takes_receiver_like_friction(tmp_path):
    """The command in the test's process (``tests.cli.inprocess``: the console script's entry
    point, its stdout, stderr and exit code), without a console script's imports per call."""
    sc = tmp_path / "sc.toml"
    sc.write_text(SCENARIO.format(gnss='noise = "v100"'))
    rec = tmp_path / "rx.toml"
    rec.write_text('[receiver]\nname = "bench"\nheading_white_deg = 0.02\nheading_slow_deg = 0\n')
    for spec, want in (("rtk", "rtk"), (str(rec), str(rec))):
        out = tmp_path / f"out-{len(want)}"
        p = cli("simulate", sc, "-o", out, "--receiver", spec)
        assert p.returncode == 0, p.stderr
        assert list(pd.read_csv(out / "cases.csv")["receiver"]) == [want]
    p = cli("simulate", sc, "-o", tmp_path / "x", "--receiver", "gps")
    assert p.returncode != 0 and "Traceback" not in p.stderr
    assert "receiver = 'gps'" in p.stderr + p.stdout


def test_former_emulator_names_are_read_with_a_warning(tmp_path):
    old, new = tmp_path / "old.toml", tmp_path / "new.toml"
    old.write_text(SCENARIO.format(gnss="heading_gm_deg = 0.1\nrot_dps = 0.2"))
    new.write_text(SCENARIO.format(gnss="heading_slow_deg = 0.1\nyaw_rate_dps = 0.2"))
    with pytest.warns(FutureWarning) as said:
        a = run_scenario(old, tmp_path / "a")
    text = " ".join(str(w.message) for w in said)
    assert "heading_gm_deg is deprecated; write heading_slow_deg" in text
    assert "rot_dps is deprecated; write yaw_rate_dps" in text
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        b = run_scenario(new, tmp_path / "b")
    la = (tmp_path / "a" / a["nmea"].iloc[0]).read_bytes()
    lb = (tmp_path / "b" / b["nmea"].iloc[0]).read_bytes()
    import gzip

    assert gzip.decompress(la) == gzip.decompress(lb)
