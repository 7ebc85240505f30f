"""Pressure distributions, the l–m model and its fit to the thesis's Table 18 (physics §5)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad

from gripsense.data import sample_path
from gripsense.identify import fit_contact_length
from gripsense.physics import contact
from gripsense.physics.surface import surface_class, surface_class_interval


@pytest.mark.parametrize("fn", [contact.pressure_parabolic, contact.pressure_quartic])
def test_pressure_integrates_to_load(fn):
    l, w, fz = 0.134, 0.185, 2353.6
    total, _ = quad(lambda x: fn(x, l, w, fz), 0, l)
    assert total * w == pytest.approx(fz, rel=1e-10)
    assert fn(-0.01, l, w, fz) == 0.0 and fn(l + 0.01, l, w, fz) == 0.0


def test_pressure_peaks_and_gradients():
    l, w, fz = 0.134, 0.185, 2353.6
    assert contact.pressure_parabolic(l / 2, l, w, fz) == pytest.approx(1.5 * fz / (l * w))
    assert contact.pressure_quartic(l / 2, l, w, fz) == pytest.approx(1.25 * fz / (l * w))
    for fn, k in ((contact.pressure_parabolic, 6), (contact.pressure_quartic, 10)):
        h = 1e-7
        grad = (fn(l, l, w, fz) - fn(l - h, l, w, fz)) / h
        assert abs(grad) == pytest.approx(k * fz / (l**2 * w), rel=1e-5)
        name = "parabolic" if k == 6 else "quartic"
        assert contact.edge_pressure_gradient(l, w, fz, name) == pytest.approx(abs(grad), rel=1e-5)


def test_table18_fit_physics_5():
    """docs/physics.md §5: all 15 rows -> a = 0.010398, b = −1.0172e-4, R² 0.9953, RMSE 0.286 cm."""
    t = pd.read_csv(sample_path("thesis_table18.csv"), comment="#")
    assert len(t) == 15
    p, s = fit_contact_length(t["mass_kg"], t["length_m"])
    assert p["a"] == pytest.approx(0.010398, abs=5e-7)
    assert p["b"] == pytest.approx(-1.0172e-4, abs=5e-9)
    assert s["r2"] == pytest.approx(0.9953, abs=5e-5)
    assert s["rmse_m"] * 100 == pytest.approx(0.286, abs=5e-4)
    assert s["rmse_dof_m"] * 100 == pytest.approx(0.307, abs=5e-4)
    assert s["m_peak_kg"] == pytest.approx(2614, abs=3)
    # without the (0, 0) and static rows: a = 0.010415, b = −1.0253e-4
    sub = t[~t["item"].isin(["lifted", "static"])]
    p2, _ = fit_contact_length(sub["mass_kg"], sub["length_m"])
    assert p2["a"] == pytest.approx(0.010415, abs=5e-7)
    assert p2["b"] == pytest.approx(-1.0253e-4, abs=5e-9)
    # l(230 kg) = 0.1343 m (measured 0.134), l(240 kg) = 0.1367 m
    assert contact.contact_length_lm(230, **p) == pytest.approx(0.1343, abs=5e-5)
    assert contact.contact_length_lm(240, **p) == pytest.approx(0.1367, abs=5e-5)


def test_fit_errors():
    with pytest.raises(ValueError, match="need at least 3"):
        fit_contact_length([100, 200], [0.1, 0.12])
    with pytest.raises(ValueError, match="negative"):
        fit_contact_length([-1, 100, 200], [0.0, 0.1, 0.12])


def test_surface_classes_table4():
    # Table 4: DRY 1.2–0.7, WET 0.6–0.4, SNOW 0.3–0.2, ICE 0.1–0.0 (gaps split in the middle)
    assert list(surface_class([1.2, 0.7, 0.6, 0.4, 0.3, 0.2, 0.1, 0.0])) == [
        "DRY",
        "DRY",
        "WET",
        "WET",
        "SNOW",
        "SNOW",
        "ICE",
        "ICE",
    ]
    assert surface_class(np.nan) == "undetermined"
    assert surface_class_interval(0.45, 0.55) == "WET"
    assert surface_class_interval(0.5, 0.9) == "undetermined"
