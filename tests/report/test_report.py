"""Reports and figures: rendered in headless Chromium, compared as images, robust to gaps."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from gripsense import FrictionRun
from gripsense.data import sample_path
from gripsense.estimate.conditions import condition_table, conditions
from gripsense.report import figures as F
from gripsense.report import write_report
from tests.estimate.circle import circle

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

BASELINE = Path(__file__).parent.parent / "data" / "figures"
THESIS = sample_path("corolla_thesis.toml")
CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")
NEEDS_BROWSER = (
    "headless Chromium is needed: `apt-get install chromium chromium-driver` "
    "(make test does this when run as root)"
)


def _result(method="brush-2", mu=0.5, util=0.92):
    epochs, _ = circle(mu=mu, utilisation=util, duration=30.0)
    epochs["lat_deg"] = 33.62 + epochs["t_s"] * 1e-6
    epochs["lon_deg"] = 133.72 + np.sin(epochs["t_s"] / 5) * 1e-4
    res = FrictionRun(THESIS, method=method, calibrate_heading=False).run(epochs)
    return res, epochs


def _open(path: Path):
    if not (CHROMIUM and CHROMEDRIVER):
        pytest.skip(NEEDS_BROWSER)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--window-size=1200,1800",
    ):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    drv = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    drv.get(path.resolve().as_uri())
    return drv


def _check_page(path: Path, tmp_path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    # self-contained: no resource from the network
    assert not re.search(r'(src|href)\s*=\s*["\']https?://', text)
    drv = _open(path)
    try:
        imgs = drv.execute_script(
            "return Array.from(document.images).map(i => [i.complete, i.naturalWidth])"
        )
        assert imgs and all(c and w > 0 for c, w in imgs), imgs
        severe = [e for e in drv.get_log("browser") if e["level"] == "SEVERE"]
        assert not severe, severe
        shot = tmp_path / (path.stem + ".png")
        drv.save_screenshot(str(shot))
    finally:
        drv.quit()
    from matplotlib.image import imread

    img = imread(shot)
    assert img.shape[0] > 500 and img[..., :3].std() > 0.05  # not blank


def test_report_in_browser(tmp_path):
    res, epochs = _result()
    p = write_report(res, tmp_path / "report.html", epochs=epochs)
    _check_page(p, tmp_path)
    html = p.read_text()
    assert "rear_left" in html and "Steady conditions" in html and "Data quality" in html


@pytest.mark.parametrize("method", ["brush-2", "axle-window"])
def test_summary_first_words_not_booleans_in_browser(tmp_path, method):
    """What the page shows first is the compact summary (estimate, measured grip, surface),
    the method and receiver are in the header, details are folded, and no cell says True/False
    — checked on the rendered page, for each kind of result."""
    res, epochs = _result(method=method)
    p = write_report(res, tmp_path / "report.html", epochs=epochs)
    drv = _open(p)
    try:
        first = drv.execute_script(
            "return Array.from(document.querySelectorAll('table')[0].querySelectorAll('th'))"
            ".map(h => h.textContent)"
        )
        cells = drv.execute_script(
            "return Array.from(document.querySelectorAll('td')).map(c => c.textContent.trim())"
        )
        header = drv.execute_script("return document.querySelector('p.meta').textContent")
        folded = drv.execute_script("return document.querySelectorAll('details').length")
        wide = drv.execute_script(  # with the folded tables open: none wider than the window
            "document.querySelectorAll('details').forEach(d => d.open = true);"
            "return Array.from(document.querySelectorAll('table'))"
            ".map(t => t.getBoundingClientRect().right)"
            ".filter(r => r > window.innerWidth);"
        )
    finally:
        drv.quit()
    assert any("estimate" in h for h in first) and any("measured" in h for h in first), first
    assert "True" not in cells and "False" not in cells
    assert f"method {method}" in header and "receiver" in header, header
    assert folded >= 1
    assert wide == [], wide


def test_demo_report_in_browser(tmp_path):
    from gripsense.demo import run_demo, write_demo_report

    df = run_demo()
    p = write_demo_report(df, None, tmp_path / "demo.html")
    _check_page(p, tmp_path)
    text = p.read_text()
    assert "Demo set" in text
    # the drive in detail is run as in the table (with its steering channel): both axles
    head, detail = text.split("One drive in detail: ")
    case = detail[: detail.index("<")]
    assert set(df.loc[df["case"] == case, "axle"]) == {"front", "rear"}
    assert "front" in detail and "rear" in detail
    # the description is the data's (speeds and radii of the bundled cases)
    from gripsense.demo import demo_description

    assert demo_description().replace("'", "&#x27;") in head
    # the header names every receiver of the set, and the one of the drive in detail
    meta = re.search(r"<p class='meta'>gripsense ·(.*?)</p>", text).group(1)
    for rx in df["receiver"].unique():
        assert f"<code>{rx}</code>" in meta, meta
    assert "receivers" in meta and "the drive in detail" in meta, meta
    # columns a reader can check against each other: what the data prove, the true μ and
    # the share proven (their ratio) — not a mean utilisation beside a best-second bound
    table = head[head.index("<table>") :]
    cols = [h for h in re.findall(r"<th[^>]*>(.*?)</th>", table)]
    for c in ("μ true (simulator)", "measured: data prove μ ≥", "share of μ true proven"):
        assert any(x.startswith(c) for x in cols), cols
    assert "utilisation_true" not in cols and "util" not in cols, cols
    # the estimate as the console says it: a value with its range, or only an upper end
    cells = re.findall(r"<td[^>]*>(.*?)</td>", table)
    for r in df.to_dict("records"):
        if r["observable"]:
            assert f"{r['mu']:.2f} [{r['mu_low']:.2f}, {r['mu_high']:.2f}]" in cells
    # no table wider than the page; "what limits the estimate" visible without scrolling
    drv = _open(p)
    try:
        widths = drv.execute_script(
            "const w = document.body.clientWidth;"
            "return Array.from(document.querySelectorAll('table'))"
            ".map(t => [t.getBoundingClientRect().right, w, window.innerWidth]);"
        )
        limited = drv.execute_script(
            "return Array.from(document.querySelectorAll('th'))"
            ".filter(h => h.textContent.includes('what limits the estimate'))"
            ".map(h => h.getBoundingClientRect().right);"
        )
    finally:
        drv.quit()
    assert widths and all(right <= inner for right, _, inner in widths), widths
    assert limited and all(r <= widths[0][2] for r in limited), limited


def test_report_command_round_trip(tmp_path):
    """``friction --report`` and ``report`` in the test's process (``tests.cli.inprocess``:
    the console script's entry point, its stdout, stderr and exit code)."""
    from tests.cli.inprocess import cli
    from tests.cli.test_commands import _circle_nmea

    log = tmp_path / "c.nmea"
    _circle_nmea(log)
    out = tmp_path / "res"
    r = cli(
        "friction",
        str(log),
        "--vehicle",
        str(THESIS),
        "--method",
        "axle-window",
        "-o",
        str(out),
        "--report",
    )
    assert r.returncode == 0, r.stderr
    assert (out / "report.html").exists() and (out / "epochs.parquet").exists()
    assert (out / "ingest.json").exists() and (out / "vehicle.toml").exists()
    r = cli("report", str(out), "-o", str(tmp_path / "again.html"))
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "again.html").read_text()
    assert "axle-window" in text and "lines" in text  # ingest accounting section
    r = cli("report", str(tmp_path))
    assert r.returncode == 2 and "not a result folder" in r.stderr  # no manifest


def test_figures_with_missing_channels_and_no_valid_mu(tmp_path):
    """No ROT, no steering, no positions, zero valid μ: every figure still draws."""
    res, epochs = _result(method="axle-window", mu=0.9, util=0.2)
    assert res.wheels["mu"].isna().all()
    bare = epochs.drop(columns=["lat_deg", "lon_deg"])
    conds = conditions(res.wheels)
    ct = condition_table(res.wheels, conds, res.windows)
    figs = [
        F.trajectory(bare, conds),
        F.mu_vs_utilisation(res.wheels, res.windows),
        F.mu_vs_radius(ct),
        F.mu_vs_yaw_rate(ct),
    ]
    figs += [F.condition_figure(res.wheels, t0, t1) for t0, t1 in conds[:1]]
    assert all(f.axes for f in figs)
    p = write_report(res, tmp_path / "r.html", epochs=bare)
    text = p.read_text()
    assert "no value" in text and "the data prove μ ≥" in text
    assert ">True<" not in text and ">False<" not in text  # words, not booleans
    empty = res.wheels.iloc[:0]
    assert conditions(empty) == []
    F.mu_vs_utilisation(empty)


def _compare(fig, name: str, tmp_path: Path, tol: float = 8.0) -> None:
    """Image comparison with a tolerance (RMS over pixel values 0–255, matplotlib's measure).

    Baselines in tests/data/figures/ were rendered once from the same synthetic drive; set
    GRIPSENSE_UPDATE_BASELINES=1 to regenerate them after an intended change."""
    import matplotlib.pyplot as plt
    from matplotlib.testing.compare import compare_images

    out = tmp_path / name
    fig.savefig(out, dpi=60)
    plt.close(fig)  # the test's own figure (the report closes its own)
    base = BASELINE / name
    if os.environ.get("GRIPSENSE_UPDATE_BASELINES") == "1":
        shutil.copyfile(out, base)
    err = compare_images(str(base), str(out), tol=tol)
    assert err is None, err


def test_condition_figure_image(tmp_path):
    res, _ = _result()
    t0, t1 = conditions(res.wheels)[0]
    _compare(F.condition_figure(res.wheels, t0, t1, title="condition 1"), "condition.png", tmp_path)


def test_mu_vs_utilisation_image(tmp_path):
    res, _ = _result()
    _compare(F.mu_vs_utilisation(res.wheels), "mu_vs_utilisation.png", tmp_path)


def test_condition_table_values():
    res, epochs = _result()
    conds = conditions(res.wheels)
    assert len(conds) == 1  # one steady circle
    ct = condition_table(res.wheels, conds)
    rl = ct.set_index("wheel").loc["rear_left"]
    _, truth = circle(mu=0.5, utilisation=0.92, duration=30.0)
    from tests.estimate.circle import RL

    # the wheel's own speed from the circle's geometry: U_L = U_A − r y_L, V_L = U_L tan α_L
    beta_a = np.deg2rad(epochs["heading_deg"].iloc[0] - epochs["course_deg"].iloc[0])
    u_l = truth["speed"] * np.cos(beta_a) - truth["r"] * RL[1]
    v_wheel = u_l / np.cos(truth["alpha_rear_left"])
    assert rl["mu"] == pytest.approx(0.5, rel=1e-6)
    assert rl["ay_g"] == pytest.approx(0.92 * 0.5, rel=1e-6)
    assert rl["speed_kmh"] == pytest.approx(v_wheel * 3.6, rel=1e-6)
    assert rl["radius_m"] == pytest.approx(v_wheel / truth["r"], rel=1e-6)
