"""The tyre prior made of real tyres (docs/physics.md §14.3): the bundled files are read by the
project's own readers and are distinct tyres, the normalisation agrees with the Magic Formula's
closed form, the family is rebuilt from the files, every file's curves lie within the stated
margin, and a vehicle file's tyre category selects its members."""

from __future__ import annotations

import copy
import tomllib
from itertools import combinations
from pathlib import Path

import numpy as np
import pytest

from gripsense import data
from gripsense.config import Vehicle
from gripsense.config import tyre_library as L
from gripsense.config.tyre_files import load_tyre_model
from gripsense.errors import InputError
from gripsense.estimate.profile import shape_ids
from gripsense.io.tyres.tir import read_tir
from gripsense.physics.tyre_curves import SHAPE_FAMILY, magic_formula_normalised, shape_members


def test_at_least_fifteen_distinct_files_each_read_and_listed_with_its_origin():
    sources = Path(data.path("tyres/library/SOURCES.md")).read_text(encoding="utf-8")
    assert len(L.LIBRARY) >= 15
    assert {e.category for e in L.LIBRARY} >= {"passenger", "suv", "performance", "racing"}
    fz_factor = np.array([0.6, 1.0, 1.4])
    alpha = np.array([0.02, 0.08, 0.2])
    forces = {}
    for e in L.LIBRARY:
        path = data.path(e.file)
        assert path.name in sources, f"{path.name} missing from SOURCES.md"
        model = load_tyre_model(path)  # strict: no unknown keys
        if path.suffix == ".tir":
            assert read_tir(path).warnings == []
        fy = model.fy_iso(fz_factor * model.fz_nominal, alpha, np.zeros(3))
        forces[e.file] = np.asarray(fy, dtype=float) / model.fz_nominal
    # distinct parameter sets: no two files give the same forces (no copy under another name)
    for a, b in combinations(forces, 2):
        assert np.max(np.abs(forces[a] - forces[b])) > 1e-3, (a, b)


def test_adams_model_keys_are_read_strictly(tmp_path):
    """FUNCTION_NAME (an ADAMS [MODEL] key) is part of the format; a typo still is an error."""
    text = data.path("tyres/library/car235_80R17.tir").read_text(encoding="utf-8")
    assert "FUNCTION_NAME" in text
    bad = tmp_path / "bad.tir"
    bad.write_text(text.replace("FUNCTION_NAME ", "FUNCTION_NAMX "), encoding="utf-8")
    with pytest.raises(InputError, match="FUNCTION_NAMX"):
        read_tir(bad)


@pytest.mark.parametrize("load_factor", [0.5, 1.0, 1.5])
def test_normalised_curve_is_the_magic_formulas_closed_form(load_factor):
    """PacejkaBook_Defaults: C 1.3, E 0, no shifts. At zero inclination F = D sin(C atan(Bα)),
    D = (PDY1 + PDY2 dfz) Fz, K = −PKY1 Fz0 sin(2 atan(Fz/(PKY2 Fz0))) (Pacejka 2012 4.E19–E30)
    → with x = K tan α / D: F/D = sin(1.3 atan(K atan(x D/K) / (1.3 D)))."""
    entry = next(e for e in L.LIBRARY if e.file.endswith("PacejkaBook_Defaults.tir"))
    curves = L.normalised_curves(entry, load_factors=(load_factor,), cambers_deg=(0.0,))
    fz0 = 4000.0
    fz = load_factor * fz0
    d = (1.0 - 0.05 * (fz - fz0) / fz0) * fz
    k = 15.0 * fz0 * np.sin(2.0 * np.arctan(fz / (2.0 * fz0)))
    for c in curves:
        assert not c.saturating
        alpha = np.arctan(c.x * d / k)
        ref = np.sin(1.3 * np.arctan(k * alpha / (1.3 * d)))
        np.testing.assert_allclose(c.y, ref, atol=2e-6)


def test_a_surface_that_scales_lmuy_leaves_a_shift_free_curve_unchanged():
    """Without shifts and camber terms LMUY scales the peak D but not the stiffness: in units
    of x = K tan α/(μ Fz) the curve is the same but for α against tan α (the Magic Formula takes
    α, the normalisation tan α: < 0.005 here) — the low-grip margin comes from the shifts."""
    entry = next(e for e in L.LIBRARY if e.file.endswith("PacejkaBook_Defaults.tir"))
    dry = L.normalised_curves(entry, cambers_deg=(0.0,))
    wet = L.normalised_curves(entry, cambers_deg=(0.0,), lmuy=0.3)
    for a, b in zip(dry, wet, strict=True):
        xs = np.linspace(0.0, min(a.x[-1], b.x[-1]), 50)
        np.testing.assert_allclose(np.interp(xs, b.x, b.y), np.interp(xs, a.x, a.y), atol=5e-3)


def test_every_files_curves_lie_within_the_stated_margin_of_the_family():
    curves = L.library_curves()
    assert len(curves) == len(L.LIBRARY) * len(L.LOAD_FACTORS) * len(L.CAMBERS_DEG) * 2
    members = L.FAMILY_MEMBERS
    for k in curves:
        d = min(np.max(np.abs(k.y - magic_formula_normalised(k.x, c, e))) for c, e in members)
        assert d <= L.COVER_MARGIN, (k.file, k.load_factor, k.camber_deg, k.side, d)
    # the estimator's family holds them (and both brush shapes)
    mf = {(s.c, s.e) for s in SHAPE_FAMILY if s.kind == "magic-formula"}
    assert mf == set(members)
    assert {s.kind for s in SHAPE_FAMILY} == {"brush-2", "brush-4", "magic-formula"}


@pytest.mark.slow  # ~20 s: every curve fitted and the cover solved again
def test_family_is_rebuilt_from_the_bundled_files():
    members, categories = L.build_family()
    assert members == L.FAMILY_MEMBERS
    assert categories == L.CATEGORY_MEMBERS


def test_low_grip_sweeps_lie_within_their_margin():
    low = L.low_grip_curves(load_factors=(1.0,), cambers_deg=(0.0,))
    assert low
    for k in low:
        d = min(
            np.max(np.abs(k.y - magic_formula_normalised(k.x, c, e))) for c, e in L.FAMILY_MEMBERS
        )
        assert d <= L.LOW_GRIP_MARGIN, (k.file, d)


def _vehicle_doc(shape: str) -> dict:
    doc = tomllib.loads(data.path("corolla_sim.toml").read_text(encoding="utf-8"))
    doc = copy.deepcopy(doc)
    for axle in ("front", "rear"):
        doc["tyre"][axle]["shape"] = shape
    return doc


@pytest.mark.parametrize("category", ["passenger", "suv", "performance", "racing", "truck"])
def test_a_category_selects_the_members_that_cover_its_files(category):
    v = Vehicle.from_dict(_vehicle_doc(category), source="v.toml")
    ids = shape_ids(v.tyres["front"].shape)
    chosen = [SHAPE_FAMILY[i] for i in ids]
    assert tuple(ids) == shape_members(category)
    assert all(s.kind == "magic-formula" for s in chosen)
    assert 0 < len(chosen) < len(SHAPE_FAMILY) - 2
    # every curve of the category's files lies within the margin of a selected member
    files = {e.file for e in L.LIBRARY if e.category == category}
    for k in (k for k in L.library_curves() if k.file in files):
        d = min(np.max(np.abs(k.y - magic_formula_normalised(k.x, s.c, s.e))) for s in chosen)
        assert d <= L.COVER_MARGIN, (k.file, d)


def test_any_brush_and_magic_formula_keep_their_meaning():
    assert len(shape_ids("any")) == len(SHAPE_FAMILY)
    assert [SHAPE_FAMILY[i].kind for i in shape_ids("brush")] == ["brush-2", "brush-4"]
    assert {SHAPE_FAMILY[i].kind for i in shape_ids("magic-formula")} == {"magic-formula"}
    assert len(shape_ids("magic-formula")) == len(L.FAMILY_MEMBERS)


def test_an_unknown_shape_or_category_names_the_key():
    with pytest.raises(InputError, match=r"shape.*'winter'.*passenger"):
        Vehicle.from_dict(_vehicle_doc("winter"), source="v.toml")
