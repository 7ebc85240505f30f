"""FrictionRun: one entry point from a log to a typed result, and results that every consumer
reads the same way whatever the method."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from gripsense import AxleFriction, FrictionResult, FrictionRun, InputError, WheelFriction
from gripsense.demo import demo_dir
from gripsense.estimate.results import ESTIMATE_COLUMNS, UNIT_COLUMNS

DEMO = demo_dir()
VEHICLE = DEMO / "vehicle.toml"
LOG = DEMO / "case022.nmea.gz"  # near-limit dry circle


@pytest.fixture(scope="module")
def results():
    return {m: FrictionRun(VEHICLE, method=m).run_log(LOG) for m in ("brush-2", "axle-window")}


def test_each_method_returns_its_own_type(results):
    assert type(results["brush-2"]) is WheelFriction and results["brush-2"].unit == "wheel"
    assert type(results["axle-window"]) is AxleFriction and results["axle-window"].unit == "axle"
    for r in results.values():
        assert isinstance(r, FrictionResult)
        assert r.epochs is not None and len(r.epochs) > 100  # run_log keeps what it read
        acc = r.ingest
        n = sum(sum(acc[k].values()) for k in ("parsed", "ignored", "rejected"))
        assert n == acc["total_lines"] > 1000


def test_results_are_immutable(results):
    r = results["brush-2"]
    with pytest.raises(AttributeError):
        r.meta = {}
    r2 = r.replace(meta={"method": "x"})
    assert r2.meta == {"method": "x"} and r.meta["method"] == "brush-2"
    assert type(r2) is WheelFriction


@pytest.mark.parametrize("method", ["brush-2", "axle-window"])
def test_consumers_see_the_same_columns(results, method):
    r = results[method]
    est = r.estimates()
    assert list(est.columns) == ESTIMATE_COLUMNS and len(est)
    # every estimate points at an epoch of the drive and lies within it in time
    t = r.epochs["t_s"].to_numpy()
    e = est["epoch"].to_numpy(int)
    assert (est["t_start"].to_numpy() >= t.min() - 1e-9).all()
    assert np.abs(t[e] - 0.5 * (est["t_start"] + est["t_end"]).to_numpy()).max() < 0.2
    # a value carries a 1σ; a non-value carries none
    obs = est["observable"].to_numpy(bool)
    assert np.isfinite(est.loc[obs, "mu_sigma"]).all()
    assert est.loc[~obs, "mu"].isna().all()
    ut = r.unit_table()
    assert list(ut.columns) == UNIT_COLUMNS and set(ut["unit"]) == set(r.summary[r.unit])


@pytest.mark.parametrize("method", ["brush-2", "axle-window"])
def test_files_round_trip(results, method, tmp_path):
    r = results[method]
    paths = r.to_files(tmp_path / "out")
    back = FrictionResult.from_files(tmp_path / "out")
    assert type(back) is type(r)
    pd.testing.assert_frame_equal(back.wheels, r.wheels)
    assert back.explain() == r.explain()
    assert back.vehicle.mass_kg == r.vehicle.mass_kg
    man = json.loads(paths["manifest"].read_text())
    assert man["inputs"] == [] and sorted(man["files"]) == sorted(
        p.name for k, p in paths.items() if k != "manifest"
    )


def test_reused_folder_reads_only_its_own_files(results, tmp_path):
    """axle-window then brush-2 into the same folder: the report must not see the old
    windows.parquet (issue: stale files read back)."""
    out = tmp_path / "out"
    results["axle-window"].to_files(out)
    assert (out / "windows.parquet").exists()
    results["brush-2"].to_files(out, overwrite=True)
    assert not (out / "windows.parquet").exists()  # listed in the old manifest: removed
    back = FrictionResult.from_files(out)
    assert type(back) is WheelFriction


def test_run_log_errors_are_clear(tmp_path):
    empty = tmp_path / "empty.nmea"
    empty.write_text("hello\nworld\n")
    with pytest.raises(InputError, match="no epochs"):
        FrictionRun(VEHICLE).run_log(empty)
    with pytest.raises(InputError, match="no such file"):
        FrictionRun(VEHICLE).run_log(tmp_path / "missing.nmea")
    with pytest.raises(InputError, match="receiver"), pytest.warns(DeprecationWarning):
        FrictionRun(VEHICLE, noise="nonsense")


def test_tyre_fit_plugs_back_into_its_model():
    """pvlib's convention: a fit's parameters are the model function's keyword arguments."""
    from gripsense.identify.tyre_fit import fit_pac94
    from gripsense.physics.magic_formula.pac94 import pac94_lateral
    from gripsense.sim.tyre_data import PAC94_EXAMPLE, rig_samples

    d = rig_samples(
        lambda fz, a, g: pac94_lateral(PAC94_EXAMPLE, fz, a, g),
        1500,
        rng=np.random.default_rng(2),
    )
    fit = fit_pac94(d.alpha_rad, d.gamma_rad, d.fz_N, d.fy_N)
    al = np.deg2rad(np.linspace(-8, 8, 17))
    direct = pac94_lateral(fz=4000.0, alpha=al, gamma=0.0, **fit.model_kwargs)
    np.testing.assert_allclose(direct, fit.predict(4000.0, al), rtol=1e-12)


def test_tyre_model_registry_reads_every_file_type(tmp_path):
    from gripsense.config.tyre_files import TYRE_FILE_TYPES, load_tyre_model
    from tests.conftest import DATA

    assert set(TYRE_FILE_TYPES) >= {".tir", ".json"}
    tir = load_tyre_model(DATA / "tyre" / "tir" / "MagicFormula61_Paramerters.tir")
    pac89 = load_tyre_model(DATA / "tyre" / "tir" / "HMMWV_Pac89Tire.json")
    for m in (tir, pac89):
        _, fy = m.forces(np.array([4000.0]), 0.0, np.deg2rad([4.0]), 0.0)
        assert np.isfinite(fy).all() and abs(fy[0]) > 1000
    with pytest.raises(InputError, match="unknown model file type"):
        load_tyre_model(tmp_path / "x.xlsx")
