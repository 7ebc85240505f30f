"""Tread stiffness G from cornering on simulated circles with a known tyre (G = 5e7).

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import numpy as np

from gripsense import FrictionRun
from gripsense.config import Vehicle
from gripsense.data import sample_path
from gripsense.estimate.conditions import conditions
from gripsense.estimate.stiffness import g_sweep, tread_stiffness
from gripsense.io import read_nmea
from gripsense.report.figures import g_sweep_figure
from gripsense.sim import SimParams
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import CompassNoise, emulate_compass

VEH = Vehicle.from_toml(sample_path("corolla_sim.toml"))
P = SimParams.from_vehicle(VEH)
G_TRUE = VEH.tyres["rear"].tread_stiffness_N_per_m3


def _wheels(speed_kmh, radius, mu=0.9):
    m = M.circle(speed_kmh / 3.6, radius, laps=1.5, params=P)
    res = M.run(P, m, mu=mu)
    log = emulate_compass(res, (-VEH.cg_offset[0], -VEH.cg_offset[1]), noise=CompassNoise.none(0.5))
    return FrictionRun(VEH).run(read_nmea(log.lines).epochs).wheels


def test_linear_range_recovers_g():
    t = tread_stiffness(_wheels(20, 40), VEH)
    assert len(t) == 2 and not t["near_limit"].any()
    # the wheel force split (equal utilisation) and β²/3 effects: within 6 %
    np.testing.assert_allclose(t["G"], G_TRUE, rtol=0.06)
    np.testing.assert_allclose(t["G_thesis"], t["G"], rtol=0.03)  # forms differ by ~β²/3


def test_biased_low_near_the_limit():
    """docs/physics.md §6: with partial sliding F/tanβ = C(1 − θ + θ²/3) < C."""
    lin = tread_stiffness(_wheels(20, 40), VEH)["G"].mean()
    high = tread_stiffness(_wheels(50, 30), VEH)
    assert high["near_limit"].all()
    assert high["G"].mean() < 0.85 * lin


def test_g_sweep_thesis_criteria(tmp_path):
    w = _wheels(40, 30)
    c = conditions(w)[0]
    sw = g_sweep(w, VEH, *c)
    assert np.isfinite(sw.chosen)
    k = int(np.argmin(np.abs(sw.G - sw.chosen)))
    mus = [mu[k] for mu in sw.mu.values()]
    assert all(0 < m <= 1.2 for m in mus)
    g_sweep_figure(sw).savefig(tmp_path / "sweep.png")
    # an impossible condition: no G keeps μ ≤ 0.05 on both wheels
    bad = g_sweep(w, VEH, *c, mu_max=0.05)
    assert not np.isfinite(bad.chosen) and "no G" in bad.reason


def test_cli(tmp_path):
    from tests.cli.inprocess import cli

    log = tmp_path / "c.nmea"
    m = M.circle(30 / 3.6, 30, laps=1.0, params=P)
    res = M.run(P, m, mu=0.9)
    emulate_compass(
        res, (-VEH.cg_offset[0], -VEH.cg_offset[1]), noise=CompassNoise.none(0.5)
    ).write(log)
    r = cli(
        "stiffness",
        str(log),
        "--vehicle",
        str(sample_path("corolla_sim.toml")),
        "--sweep",
        "-o",
        str(tmp_path / "out"),
    )
    assert r.returncode == 0, r.stderr
    assert "Tread stiffness" in r.stdout and "G sweep" in r.stdout
    assert (tmp_path / "out" / "stiffness.csv").exists()
    assert list((tmp_path / "out").glob("gsweep_*.png"))
