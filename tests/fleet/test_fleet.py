"""Fleet map on a real Dask LocalCluster: a synthetic road network with known surfaces."""

from __future__ import annotations

import json
import re
import tempfile
from pathlib import Path

import h3
import numpy as np
import pandas as pd
import pytest

import gripsense
from gripsense.fleet import run_fleet
from gripsense.sim.fleet_data import Site, write_fleet
from tests.report.test_report import _open

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

SIM_VEHICLE = Path(gripsense.__file__).parent / "data" / "corolla_sim.toml"
SITES = [
    Site("dry", 33.620, 133.7195, 30.0, 0.9),
    Site("wet", 33.625, 133.7195, 30.0, 0.5),
    Site("snow", 33.630, 133.7195, 30.0, 0.25),
]


def _truth(cell: str) -> float:
    lat = h3.cell_to_latlng(cell)[0]
    return min(SITES, key=lambda s: abs(s.lat_deg - lat)).mu


@pytest.fixture(scope="module")
def fleet_logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet")
    write_fleet(d / "logs", SIM_VEHICLE, SITES, n_vehicles=2)
    # the fleet's vehicle file: tyres calibrated on the car (G to 5 %, no camber thrust)
    text = SIM_VEHICLE.read_text().replace(
        'pressure = "parabolic"',
        'pressure = "parabolic"\nstiffness_uncertainty = 0.05\ncamber_thrust_ratio = 0.0',
    )
    (d / "vehicle.toml").write_text(text)
    (d / "logs" / "car01" / "broken.nmea").write_text("garbage\n$GPGGA,bad*00\n")
    (d / "logs" / "car02" / "empty.nmea").write_bytes(b"")
    return d


@pytest.fixture(scope="module")
def fleet_run(fleet_logs):
    return run_fleet(
        [str(fleet_logs / "logs" / "**" / "*.nmea*")],
        fleet_logs / "out2",
        vehicle=fleet_logs / "vehicle.toml",
        receiver="rtk",
        workers=2,
    )


def test_cells_recover_the_road_surfaces(fleet_run):
    c = fleet_run.cells
    assert len(c) >= 9
    truth = np.array([_truth(x) for x in c["cell"]])
    est = c["status"] == "estimate"
    # a value only where a window neared the limit with enough change in it; measured grip in
    # every cell
    assert est.mean() > 0.3 and (c["grip_used_lower"] > 0).all()
    assert np.all(np.abs(c.loc[est, "mu"] - truth[est]) < 0.05)
    covered = (c.loc[est, "mu_low"] <= truth[est]) & (truth[est] <= c.loc[est, "mu_high"])
    assert covered.mean() >= 0.8
    assert np.all(c["grip_used_lower"] <= truth + 0.01)  # model-free: never above the truth
    assert set(c.loc[est, "surface"]) <= {"DRY", "WET", "SNOW"}
    assert c["n_vehicles"].max() == 2


def test_bad_logs_are_listed_not_fatal(fleet_run):
    p = pd.read_csv(fleet_run.paths["problems"])
    assert sorted(Path(x).name for x in p["log"]) == ["broken.nmea", "empty.nmea"]
    assert all(p["problem"].str.len() > 0)
    assert (fleet_run.logs["problem"].fillna("") == "").sum() == 6
    gj = json.loads(fleet_run.paths["geojson"].read_text())
    assert len(gj["features"]) == fleet_run.cells["cell"].nunique()


def _with_external_cluster(tmp: Path, fn):
    """Run fn(scheduler address) against `dask scheduler` + 2 `dask worker` processes."""
    import subprocess
    import sys
    import time

    dask_cli = [sys.executable, "-m", "dask"]
    sched_file = tmp / "scheduler.json"
    procs = [
        subprocess.Popen(
            [*dask_cli, "scheduler", "--host", "127.0.0.1", "--port", "0",
             "--dashboard-address", ":0", "--scheduler-file", str(sched_file)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )
    ]  # fmt: skip
    try:
        # wait until the scheduler has written its file whole (it exists, empty, for a moment)
        deadline, address = time.monotonic() + 600, ""
        while not address and time.monotonic() < deadline:
            try:
                address = json.loads(sched_file.read_text())["address"]
            except (OSError, ValueError, KeyError):
                time.sleep(0.2)
        assert address.startswith("tcp://127.0.0.1:"), address
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [*dask_cli, "worker", address, "--nthreads", "1", "--host", "127.0.0.1",
                     "--dashboard-address", ":0"],
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                )
            )  # fmt: skip
        from dask.distributed import Client

        with Client(address, timeout=600) as c:
            c.wait_for_workers(2, timeout=600)
        return fn(address)
    finally:
        for p in procs[::-1]:
            p.terminate()
        for p in procs:
            p.wait(timeout=120)


def test_same_results_with_1_worker_and_an_explicit_scheduler(
    fleet_logs, fleet_run, tmp_path, monkeypatch
):
    from dask.distributed import LocalCluster

    pattern = [str(fleet_logs / "logs" / "**" / "*.nmea*")]
    veh = fleet_logs / "vehicle.toml"
    system_tmp = tmp_path / "tmp"  # the system's temporary folder, as the run sees it
    system_tmp.mkdir()
    with monkeypatch.context() as m:
        m.setattr(tempfile, "tempdir", str(system_tmp))
        m.setenv("TMPDIR", str(system_tmp))
        one = run_fleet(pattern, fleet_logs / "out1", vehicle=veh, receiver="rtk", workers=1)
    # the cluster's spill folders went with it (Dask's default left "dask-scratch-space")
    assert list(system_tmp.iterdir()) == []
    with LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
    ) as cl:
        assert cl.scheduler_address.startswith("tcp://127.0.0.1:")
        sch = run_fleet(
            pattern,
            fleet_logs / "out3",
            vehicle=veh,
            receiver="rtk",
            scheduler=cl.scheduler_address,
        )
    # an explicitly started `dask scheduler` and two `dask worker` processes on loopback
    ext = _with_external_cluster(
        fleet_logs,
        lambda address: run_fleet(
            pattern, fleet_logs / "out4", vehicle=veh, receiver="rtk", scheduler=address
        ),
    )
    cols = ["mu", "mu_sigma", "mu_low", "mu_high", "grip_used_lower", "n_estimates", "n_passes",
            "n_statements"]  # fmt: skip
    ref = fleet_run.cells.sort_values(["cell", "bucket"]).reset_index(drop=True)
    for other in (one, sch, ext):
        o = other.cells.sort_values(["cell", "bucket"]).reset_index(drop=True)
        assert list(o["cell"]) == list(ref["cell"])
        assert list(o["status"]) == list(ref["status"]) and list(o["passes"]) == list(ref["passes"])
        np.testing.assert_allclose(
            o[cols].to_numpy(float), ref[cols].to_numpy(float), rtol=1e-12, equal_nan=True
        )


def test_map_page_in_headless_chromium(fleet_run, tmp_path):
    page = fleet_run.paths["map"]
    text = page.read_text(encoding="utf-8")
    assert "https://unpkg" not in text and "cdn" not in text.lower().split("attribution")[0]
    drv = _open(page)
    try:
        n_paths = drv.execute_script(
            "return document.querySelectorAll('path.leaflet-interactive').length"
        )
        assert n_paths == fleet_run.cells["cell"].nunique()
        severe = [e for e in drv.get_log("browser") if e["level"] == "SEVERE"]
        assert not severe, severe
        drv.execute_script(
            "document.querySelector('path.leaflet-interactive')"
            ".dispatchEvent(new MouseEvent('click', {bubbles: true}))"
        )
        popup = drv.execute_script(
            "const p = document.querySelector('.leaflet-popup-content');"
            " return p ? p.textContent : ''"
        )
        assert "cell" in popup and "passes" in popup and "its statement" in popup
        # bounded ranges filled in a surface colour, one-sided ones hatched, slippery ones
        # with a thick border: as the cells state them
        styles = drv.execute_script(
            "return [...document.querySelectorAll('path.leaflet-interactive')]"
            ".map(p => [p.getAttribute('fill'), p.getAttribute('stroke-width')])"
        )
        latest = fleet_run.cells.sort_values("bucket").groupby("cell").tail(1)
        one_sided = (latest["status"] == "measured grip only") & (latest["grip_used_lower"] > 0)
        assert sum(f.startswith("url(#hatch-") for f, _ in styles) == one_sided.sum()
        assert sum(f.startswith("#") and f != "#888888" for f, _ in styles) == (
            latest["status"].isin(["estimate", "range"]).sum()
        )
        assert sum(w == "4" for _, w in styles) == (latest["slippery"] == "slippery").sum() > 0
        shot = tmp_path / "map.png"
        drv.save_screenshot(str(shot))
    finally:
        drv.quit()
    from matplotlib.image import imread

    img = imread(shot)
    # not a blank page: hexagons drawn (grey where only measured grip is known)
    assert img[..., :3].std() > 0.02


def test_cli(fleet_logs):
    from tests.cli.test_commands import run

    out = fleet_logs / "cli"
    r = run(
        "fleet",
        str(fleet_logs / "logs" / "car02" / "*.nmea*"),
        "--vehicle",
        str(SIM_VEHICLE),
        "--receiver",
        "rtk",
        "--workers",
        "1",
        "-o",
        str(out),
    )
    assert r.returncode == 0, r.stderr
    assert "4 logs: 3 used, 1 with problems" in r.stdout
    # piped (a log file, a CI job): progress as plain lines, the last one saying all is done
    done = re.findall(r"tasks: (\d+) of (\d+) done", r.stdout)
    assert done and done[-1][0] == done[-1][1], r.stdout
    assert "killing" not in r.stdout + r.stderr and "Worker process" not in r.stderr
    assert (out / "map.html").exists() and (out / "cells.parquet").exists()
    r = run(
        "fleet",
        str(fleet_logs / "nothing" / "*.nmea"),
        "--vehicle",
        str(SIM_VEHICLE),
        "-o",
        str(out),
    )
    assert r.returncode == 2 and "no file matches this pattern" in r.stderr


def test_a_batch_runs_numba_on_its_own_thread_and_restores_the_count(fleet_logs, tmp_path):
    """A fleet task runs numba's parallel loops on its own thread only (two workers on two
    cores would otherwise each wake a second thread on the other's core): it gives the
    caller's thread count back, and the rows it writes equal ``process_log``'s run with
    numba's threads."""
    import numba

    from gripsense.fleet.tasks import process_batch

    log = max((fleet_logs / "logs" / "car01").glob("*.nmea*"), key=lambda p: p.stat().st_size)
    item = [(str(log), str(fleet_logs / "vehicle.toml"), "car01")]
    before = numba.get_num_threads()
    kw = {"method": "axle-window", "h3_res": 11, "since": None, "receiver": "rtk"}
    rec = process_batch(item, str(tmp_path / "a"), **kw)
    assert numba.get_num_threads() == before
    assert rec[0]["problem"] == "" and rec[0]["rows"] > 0
    a = pd.read_parquet(next((tmp_path / "a").rglob("*.parquet")))
    from gripsense.config import Vehicle
    from gripsense.fleet.tasks import process_log, tyres_digest

    rows = process_log(
        str(log), Vehicle.from_toml(fleet_logs / "vehicle.toml"), vehicle_id="car01",
        method="axle-window", h3_res=11, since=None, receiver="rtk",
        tyres=tyres_digest(fleet_logs / "vehicle.toml"),
    )  # fmt: skip
    pd.testing.assert_frame_equal(
        a.reset_index(drop=True), rows.drop(columns="vehicle").reset_index(drop=True)
    )
