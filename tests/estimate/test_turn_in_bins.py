"""A bin whose slip sweeps through the curve's peak (a turn-in) is explained by the curve's mean
over its slips, not only by the force at its mean slip (``docs/physics.md`` §15.8).

A step to a circle drives the front slip to ~8° and back to ~1° within the first second of
cornering: the axle reaches its peak for a few tenths of a second and is linear for the rest, so
the bin's mean force lies well below the curve at the bin's mean slip. Modelled at the mean slip,
a Magic Formula front on μ 0.5 at 25 km/h on R 20 m (steady utilisation 0.49) read as saturated
and the drive's upper end excluded the truth (0.46 and 0.47 for μ 0.50).

References: the simulator's own Magic Formula tyre (``PacejkaBook_Defaults.tir``, similarity
scaled to the road) gives the truth of the bundled drives; the closed-form Magic Formula curve
sin(C atan(B x − E (B x − atan(B x)))) gives a bin's true mean force.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense import FrictionRun
from gripsense.demo import demo_dir
from gripsense.estimate import _axle_kernel as K
from gripsense.estimate.bins import BIN_COLUMNS
from gripsense.estimate.profile import curve_lookup
from gripsense.physics.tyre_curves import SHAPE_FAMILY
from gripsense.sim.drives import axle_truth

DEMO = demo_dir()


@pytest.mark.parametrize("case", ["case019", "case022"])
def test_magic_formula_turn_in_on_a_wet_road_keeps_the_truth(case):
    """The bundled drives: Magic Formula tyre, μ 0.5, 25 km/h on R 20 m, V100 and RTK."""
    c = pd.read_csv(DEMO / "cases.csv").set_index("case").loc[case]
    assert c["tyre"] == "PacejkaBook_Defaults.tir" and c["mu_road"] == 0.5
    run = FrictionRun(DEMO / c["vehicle_file"], method="axle-window", receiver=c["receiver"])
    res = run.run_log(DEMO / c["nmea"], steer_csv=DEMO / c["steer"])
    truth = axle_truth(pd.read_parquet(DEMO / c["truth"]), c["settle_s"]).set_index("axle")
    front = res.unit_table().set_index("unit").loc["front"]
    mu_true = float(truth.loc["front", "mu_true"])
    assert 0.45 < float(truth.loc["front", "utilisation"]) < 0.55  # the steady circle's
    assert front["grip_used_lower"] <= mu_true
    # the turn-in's bin is the only one that bounds the front (the steady circle is linear):
    # its upper end is stated, and it holds the truth
    assert np.isfinite(front["mu_high"])
    assert front["mu_high"] >= mu_true


def _mf(x: np.ndarray, c: float, e: float) -> np.ndarray:
    """The Magic Formula's normalised curve with unit initial slope (B = 1/C): the reference."""
    bx = np.asarray(x, dtype=float) / c
    return np.sin(c * np.arctan(bx - e * (bx - np.arctan(bx))))


def test_a_bin_through_the_peak_is_the_curve_s_mean_over_its_slips():
    """One bin of an axle whose slip falls from 8° to 1° within it (two equal wheels, load and
    stiffness known, no nuisance moved): the curve's true mean force over those slips lies
    between the force at the mean slip and the two-point mean, so at the true μ the kernel's
    residual is well inside its 1σ (the force at the mean slip alone misses it by 670 N); a
    linear tyre's (μ large) is its force at the mean slip."""
    i_shape = next(i for i, s in enumerate(SHAPE_FAMILY) if s.name == "mf C1.28 E-0.32")
    c_s, e = SHAPE_FAMILY[i_shape].c, SHAPE_FAMILY[i_shape].e
    mu, fz, c_alpha = 0.5, 3500.0, 44000.0
    # the bin's samples: the simulator's front slip 0.1-1 s after a step to R 20 m at 25 km/h
    slips = np.deg2rad([8.1, 7.4, 6.2, 4.9, 3.5, 2.2, 1.3, 1.0, 1.0, 1.0])
    x = c_alpha * np.tan(slips) / (mu * fz)
    f_true = 2 * mu * fz * float(np.mean(_mf(x, c_s, e)))  # the axle's mean force
    a_mean = float(slips.mean())
    f_at_mean = 2 * mu * fz * float(_mf(c_alpha * np.tan(a_mean) / (mu * fz), c_s, e))
    assert f_at_mean - f_true > 0.1 * f_true  # the Jensen gap is large here

    row = dict.fromkeys(BIN_COLUMNS, 0.0)
    row.update(
        alpha_L=-a_mean, alpha_R=-a_mean, fz_L=fz, fz_R=fz, c_L=c_alpha, c_R=c_alpha,
        force=f_true, force_sigma=1.0, slip_sigma=1e-5, fz_static=fz,
        slip_spread=float(slips.std()), force_model_sd=1.0,
    )  # fmt: skip
    b = np.ascontiguousarray([[row[k] for k in BIN_COLUMNS]], dtype=float)
    tab_f, tab_df, inv_dx = curve_lookup()
    ws, _, _ = K.workspace(b)
    pre = ws[K._PRE :]
    th = np.zeros(K.NG)
    r, v, jd = np.zeros(1), np.zeros(1), np.zeros(1)
    j = np.zeros((1, K.NG))

    def residual(mu_model):
        K._residuals(mu_model, th, np.zeros(1), i_shape, tab_f, tab_df, inv_dx, b, pre, 0.0,
                     r, v, j, jd)  # fmt: skip
        return float(r[0]), float(np.sqrt(v[0]))

    res, sd = residual(mu)
    assert abs(res) < sd  # the truth is carried
    # the model carries the curve's mean over the slips, not only its force at the mean slip
    assert abs(res) < 0.35 * (f_at_mean - f_true)
    # far from the peak (μ 100: x ≤ 0.05) the curve is straight, the two points its mean slip's
    res_lin, _ = residual(100.0)
    x_lin = c_alpha * np.tan(a_mean) / (100.0 * fz)
    f_lin_at_mean = 2 * 100.0 * fz * float(_mf(x_lin, c_s, e))
    assert res_lin == pytest.approx(f_true - f_lin_at_mean, rel=0.02)
