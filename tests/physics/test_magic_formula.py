"""Magic Formula evaluation against MFeval 4.0's own outputs and closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gripsense.config.tyre_files import load_mf_tyre
from gripsense.errors import InputError
from gripsense.io.tyres.pac89 import read_pac89_json
from gripsense.io.tyres.tir import read_tir
from gripsense.physics.magic_formula.pac89 import pac89_lateral, pac89_longitudinal

DATA = Path(__file__).parents[1] / "data" / "tyre"
REF_FILES = ["PacejkaBook_Defaults", "MagicFormula61_Paramerters", "MagicFormula62_Paramerters"]


@pytest.mark.parametrize("name", REF_FILES)
def test_fx_fy_match_mfeval_to_1e6(name):
    """MFeval 4.0.0 useMode 111 outputs (README in tests/data/tyre/mfeval_ref): 243 points each,
    combined slip, camber and pressure; Fx, Fy, mux, muy, Kya, Kxk to 1e-6 relative."""
    ref = pd.read_csv(DATA / "mfeval_ref" / f"{name}.csv")
    tyre = load_mf_tyre(DATA / "tir" / f"{name}.tir")
    r = tyre.forces(
        ref.Fz_N, ref.kappa, ref.alpha_rad, ref.gamma_rad, vx=ref.Vx_mps, pressure=ref.P_Pa
    )
    for col, val in (
        ("Fx", r.fx),
        ("Fy", r.fy),
        ("mux", r.mux),
        ("muy", np.abs(r.muy)),
        ("Kya", r.kya),
        ("Kxk", r.kxk),
    ):
        np.testing.assert_allclose(val, ref[col], rtol=1e-6, atol=1e-6, err_msg=col)
    assert len(ref) == 243


@pytest.mark.parametrize("name", REF_FILES)
def test_mz_trail_and_residual_moment_match_mfeval_to_1e6(name):
    """The aligning moment against MFeval 4.0.0's Mz, t and Mzr on the same 243 points
    (combined slip, camber, pressure; the MF 6.2 file included)."""
    ref = pd.read_csv(DATA / "mfeval_ref" / f"{name}.csv")
    tyre = load_mf_tyre(DATA / "tir" / f"{name}.tir")
    m = tyre.aligning_moment(
        ref.Fz_N, ref.kappa, ref.alpha_rad, ref.gamma_rad, vx=ref.Vx_mps, pressure=ref.P_Pa
    )
    for col, val in (("Mz", m.mz), ("t", m.trail), ("Mzr", m.mzr), ("Fy", m.fy)):
        np.testing.assert_allclose(val, ref[col], rtol=1e-6, atol=1e-6, err_msg=col)
    assert tyre.forces(4000.0, 0.0, 0.05).fy == tyre.aligning_moment(4000.0, 0.0, 0.05).fy


@pytest.mark.parametrize("name", ["PacejkaBook_Defaults", "FSAE_Defaults"])
def test_mz_closed_form_at_small_slip(name):
    """Symmetric files (no shifts, no residual moment at γ = 0): the trail at zero slip is
    Dt = QDZ1 (Fz/Fz0) R0 LTR LFZO with dfz = 0, and it falls steadily as the force saturates
    (at the force's peak it is under half its start)."""
    tir = read_tir(DATA / "tir" / f"{name}.tir")
    p = tir.parameters()
    tyre = load_mf_tyre(tir)
    fz = p["FNOMIN"]
    m0 = tyre.aligning_moment(fz, 0.0, 1e-6)
    dt = p["QDZ1"] * p["UNLOADED_RADIUS"] * p.get("LTR", 1.0) * p.get("LFZO", 1.0)
    assert m0.trail == pytest.approx(dt, rel=1e-6)
    a = np.deg2rad(np.linspace(0.5, 12, 24))
    m = tyre.aligning_moment(fz, 0.0, a)
    assert np.all(np.diff(m.trail) < 0)
    peak = np.argmax(np.abs(tyre.forces(fz, 0.0, np.deg2rad(np.linspace(0.5, 30, 300))).fy))
    a_peak = np.deg2rad(np.linspace(0.5, 30, 300))[peak]
    assert tyre.aligning_moment(fz, 0.0, a_peak).trail < 0.5 * dt


def test_mz_mirrors_with_the_side():
    tyre = load_mf_tyre(DATA / "tir" / "MagicFormula61_Paramerters.tir")  # TYRESIDE RIGHT
    a = np.deg2rad(np.linspace(-8, 8, 9))
    right = tyre.aligning_moment(5000.0, 0.05, -a, -0.02)
    left = tyre.aligning_moment(5000.0, 0.05, a, 0.02, side="left")
    np.testing.assert_allclose(left.mz, -right.mz, rtol=1e-12)
    np.testing.assert_allclose(left.trail, right.trail, rtol=1e-12)


def test_pacejka_book_sanity_table():
    """The README's hand check: Fz = FNOMIN = 4000 N, κ = γ = 0."""
    tyre = load_mf_tyre(DATA / "tir" / "PacejkaBook_Defaults.tir")
    alpha = np.deg2rad([-12, -4, -1, 0, 1, 4, 12])
    fy = tyre.forces(4000.0, 0.0, alpha).fy
    np.testing.assert_allclose(
        fy, [3955.49, 2709.49, 824.66, 0, -824.66, -2709.49, -3955.49], atol=0.006
    )


@pytest.mark.parametrize("name", ["PacejkaBook_Defaults", "FSAE_Defaults"])
def test_closed_form_slope_and_peak(name):
    """Symmetric files (no shifts): dFy/dα(0) = Kya = PKY1 Fz0 sin(PKY4 atan(Fz/(PKY2 Fz0))),
    and the pure-slip peak |Fy| = |PDY1 + PDY2 dfz| Fz (C > 1, E < 1)."""
    tir = read_tir(DATA / "tir" / f"{name}.tir")
    p = tir.parameters()
    tyre = load_mf_tyre(tir)
    fz = 0.8 * p["FNOMIN"]
    fz0 = p["FNOMIN"]
    kya_hand = p["PKY1"] * fz0 * np.sin(p["PKY4"] * np.arctan(fz / (p["PKY2"] * fz0)))
    h = 1e-7
    slope = (
        tyre.forces(fz, 0, h, combined=False).fy - tyre.forces(fz, 0, -h, combined=False).fy
    ) / (2 * h)
    assert slope == pytest.approx(kya_hand, rel=1e-6)
    a = np.linspace(-0.6, 0.6, 20001)
    peak = np.max(np.abs(tyre.forces(fz, 0, a, combined=False).fy))
    dfz = (fz - fz0) / fz0
    assert peak == pytest.approx(abs(p["PDY1"] + p["PDY2"] * dfz) * fz, rel=1e-6)


def test_mf52_file_runs_with_its_own_camber_terms():
    """MF 5.2 (FITTYP 6): SHy = PHY1 + PHY2 dfz + PHY3 γ; at the horizontal shift, Fy = SVy."""
    tir = read_tir(DATA / "tir" / "MagicFormula52_Paramerters.tir")
    p = tir.parameters()
    tyre = load_mf_tyre(tir)
    assert tyre.version == "5.2"
    fz, g = p["FNOMIN"], 0.02
    shy = p["PHY1"] + p["PHY3"] * g * p["LGAY"]
    svy = fz * p["PVY1"] + fz * p["PVY3"] * g * p["LGAY"]
    fy = tyre.forces(fz, 0.0, -shy, g, combined=False).fy
    assert fy == pytest.approx(svy, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize(
    "name", ["HMMWV_Pac02Tire", "Sedan_Pac02Tire", "mf_185_80R14", "335_65R22_5_G275MSA_40psi"]
)
def test_chrono_files_evaluate(name):
    tyre = load_mf_tyre(DATA / "tir" / f"{name}.tir")
    r = tyre.forces(tyre.params["FNOMIN"], np.linspace(-0.2, 0.2, 5), np.deg2rad(5.0))
    assert np.all(np.isfinite(r.fx)) and np.all(np.isfinite(r.fy))
    assert np.all(np.abs(r.fy) < 1.5 * tyre.params["FNOMIN"])


def test_negative_pdy1_gives_the_same_curve():
    """Real files carry PDY1 < 0 (MFeval takes |muy|): flipping PDY1, PDY2 leaves the
    pure lateral force unchanged because Dy and By change sign together."""
    tir = read_tir(DATA / "tir" / "MagicFormula61_Paramerters.tir")
    a = np.deg2rad(np.linspace(-12, 12, 25))
    base = load_mf_tyre(tir).forces(5000.0, 0.0, a, 0.03, combined=False).fy
    tir.set("PDY1", -tir["PDY1"])
    tir.set("PDY2", -tir["PDY2"])
    flipped = load_mf_tyre(tir).forces(5000.0, 0.0, a, 0.03, combined=False).fy
    np.testing.assert_allclose(flipped, base, rtol=1e-12, atol=1e-9)


def test_mirroring_for_the_other_side():
    """A RIGHT tyre used on the LEFT: Fy_left(α, γ) = −Fy_right(−α, −γ); ply-steer flips sign."""
    tyre = load_mf_tyre(DATA / "tir" / "MagicFormula61_Paramerters.tir")  # TYRESIDE RIGHT
    a = np.deg2rad(np.linspace(-8, 8, 9))
    right = tyre.forces(5000.0, 0.05, -a, -0.02)
    left = tyre.forces(5000.0, 0.05, a, 0.02, side="left")
    np.testing.assert_allclose(left.fy, -right.fy, rtol=1e-12)
    np.testing.assert_allclose(left.fx, right.fx, rtol=1e-12)
    same = tyre.forces(5000.0, 0.05, a, 0.02, side="right")
    np.testing.assert_allclose(same.fy, tyre.forces(5000.0, 0.05, a, 0.02).fy)
    assert tyre.forces(5000.0, 0, 0.0).fy * tyre.forces(5000.0, 0, 0.0, side="left").fy < 0
    with pytest.raises(ValueError, match="left"):
        tyre.forces(5000.0, side="centre")


def test_limit_checks_clip_inputs():
    tyre = load_mf_tyre(DATA / "tir" / "MagicFormula61_Paramerters.tir")
    amax = tyre.params["ALPMAX"]
    clipped = tyre.forces(5000.0, 0.0, [amax, 1.5 * amax]).fy
    assert clipped[0] == clipped[1]
    free = tyre.forces(5000.0, 0.0, [amax, 1.5 * amax], limits=False).fy
    assert free[0] != free[1]


def test_low_speed_reduces_slip_forces_smoothly():
    tyre = load_mf_tyre(DATA / "tir" / "PacejkaBook_Defaults.tir")
    vx = np.array([0.0, 0.25, 0.5, 0.999, 2.0])
    fx = tyre.forces(4000.0, 0.1, 0.0, vx=vx).fx
    assert fx[0] == 0.0 and np.all(np.diff(fx) > 0)


def test_missing_mandatory_key_is_named(tmp_path):
    text = (DATA / "tir" / "PacejkaBook_Defaults.tir").read_text().replace("FNOMIN", "XNOMIN")
    (tmp_path / "x.tir").write_text(text)
    with pytest.raises(InputError, match="FNOMIN"):
        load_mf_tyre(tmp_path / "x.tir")
    text = (DATA / "tir" / "PacejkaBook_Defaults.tir").read_text().replace("PKY1 ", "XKY1 ")
    (tmp_path / "y.tir").write_text(text)
    with pytest.raises(InputError, match="PKY1"):
        load_mf_tyre(tmp_path / "y.tir").forces(4000.0)
    text = (DATA / "tir" / "PacejkaBook_Defaults.tir").read_text().replace("=    61", "=    99")
    (tmp_path / "z.tir").write_text(text)
    with pytest.raises(InputError, match="FITTYP"):
        load_mf_tyre(tmp_path / "z.tir")


def test_pac89_hmmwv_closed_forms():
    """At Fz = a4 kN, BCD = a3 exactly (sin(2 atan 1) = 1): the slope at α = 0 is a3 N/deg;
    the peak is D = (a1 Fz + a2) Fz; the longitudinal slope is BCD in N per % slip."""
    c = read_pac89_json(DATA / "tir" / "HMMWV_Pac89Tire.json")
    lat, lon = c["lateral"], c["longitudinal"]
    fz = lat["a4"] * 1000.0
    h = 1e-7
    slope = (pac89_lateral(lat, fz, h) - pac89_lateral(lat, fz, -h)) / (2 * h)
    assert slope * np.pi / 180 == pytest.approx(lat["a3"], rel=1e-6)
    a = np.deg2rad(np.linspace(0, 60, 60001))
    fz_kn = 40.0
    d = (lat["a1"] * fz_kn + lat["a2"]) * fz_kn
    assert np.max(pac89_lateral(lat, fz_kn * 1000, a)) == pytest.approx(d, rel=1e-6)
    k_slope = (pac89_longitudinal(lon, 30e3, 1e-7) - pac89_longitudinal(lon, 30e3, -1e-7)) / 2e-7
    bcd = (lon["b3"] * 30**2 + lon["b4"] * 30) * np.exp(-lon["b5"] * 30)
    assert k_slope / 100 == pytest.approx(bcd, rel=1e-6)
