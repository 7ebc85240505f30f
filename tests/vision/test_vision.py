"""Laser camber (geometry built here) and camera slip angle (synthetic road frames).

Command-line checks run the command in the test's process (``tests.cli.inprocess``: the
console script's entry point, its stdout, stderr and exit code), without a console
script's 2–4 s of imports per call, which none of these checks is about."""

from __future__ import annotations

import numpy as np
import pytest

from gripsense.vision.camber_laser import camber_from_lasers

cv2 = pytest.importorskip("cv2", reason="the vision extra (opencv-python-headless) is needed")


@pytest.mark.parametrize("gamma_deg", [-4.0, -1.0, 0.0, 0.5, 3.0])
def test_camber_from_a_tilted_bar(gamma_deg):
    """A bar perpendicular to the wheel plane tilts with the wheel; sensors at ±s/2 along it
    measure vertically down to a flat road from a hub at height h (geometry independent of
    the code: rotate the bar end points)."""
    g = np.deg2rad(gamma_deg)
    h, s = 0.30, 0.25
    # bar direction in (lateral outward, up): (cos γ, sin γ) — top outward = outer end up
    outer = np.array([h]) + (s / 2) * np.sin(g)
    inner = np.array([h]) - (s / 2) * np.sin(g)
    # the lateral spacing along the bar is s; the height difference is s sin γ
    est = camber_from_lasers(outer, inner, s / np.cos(0.0))
    # tangent form: atan(Δd/s) = atan(sin γ) ≈ γ for small γ
    assert np.rad2deg(est[0]) == pytest.approx(np.rad2deg(np.arctan(np.sin(g))), abs=1e-9)
    assert abs(np.rad2deg(est[0]) - gamma_deg) < 0.01


def test_camber_calibration():
    # calibration on a floor at a known 1.0° gives offsets; later readings relative to it
    s = 0.3
    off_o, off_i = 0.3012, 0.2987
    d_o = off_o + 0.0021
    d_i = off_i - 0.0021
    est = camber_from_lasers(
        d_o, d_i, s, offset_outer=off_o, offset_inner=off_i, reference_camber_rad=np.deg2rad(1.0)
    )
    assert np.rad2deg(est) == pytest.approx(1.0 + np.rad2deg(np.arctan(0.0042 / s)))


def texture(n=480, seed=0):
    """Asphalt-like texture: smoothed noise with grains."""
    rng = np.random.default_rng(seed)
    base = cv2.GaussianBlur(rng.random((n, n)).astype(np.float32), (0, 0), 1.2)
    grains = (rng.random((n, n)) > 0.985).astype(np.float32)
    img = base + 0.6 * cv2.GaussianBlur(grains, (0, 0), 0.8)
    return cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX)


def frames(alpha_deg, px_per_frame, n=8, size=200, seed=0, noise=4.0, blur=0.7):
    tex = texture(seed=seed)
    rng = np.random.default_rng(seed + 1)
    a = np.deg2rad(alpha_deg)
    drow, dcol = px_per_frame * np.cos(a), px_per_frame * np.sin(a)
    out = []
    for k in range(n):
        # the ground moves by (drow, dcol) per frame: warpAffine maps dst(x) = src(x − t)
        m = np.float32([[1, 0, k * dcol - 100], [0, 1, k * drow - 100]])
        img = cv2.warpAffine(tex, m, (size, size), flags=cv2.INTER_CUBIC)
        img = cv2.GaussianBlur(img, (0, 0), blur)
        img = img * rng.uniform(0.85, 1.15) + rng.uniform(-10, 10)  # brightness changes
        img = img + rng.normal(0, noise, img.shape)
        out.append(np.clip(img, 0, 255).astype(np.uint8))
    return out


@pytest.mark.parametrize("alpha_deg", [-15.0, -7.5, -2.0, 0.0, 1.0, 4.0, 10.0, 15.0])
def test_camera_slip_angle(alpha_deg):
    from gripsense.vision.slip_camera import slip_from_frames

    res = slip_from_frames(
        frames(alpha_deg, 11.3, seed=int(alpha_deg * 10) % 97), fps=100, mm_per_px=0.5
    )
    ok = res[res["ok"]]
    assert len(ok) >= 5
    assert abs(ok["slip_angle_deg"].median() - alpha_deg) < 0.2
    assert ok["speed_mps"].median() == pytest.approx(11.3 * 0.5e-3 * 100, rel=0.02)


def test_camera_sign_convention_iso():
    """Moving to the left of the heading (ISO α > 0): the ground flows to the image's right."""
    from gripsense.vision.slip_camera import frame_pair_flow

    f = frames(10.0, 8.0, n=2)
    flow = frame_pair_flow(f[0], f[1])
    assert flow["drow"] > 0 and flow["dcol"] > 0  # down (forward travel) and right (leftward)


def test_camera_cli(tmp_path):
    from tests.cli.inprocess import cli

    d = tmp_path / "frames"
    d.mkdir()
    for k, img in enumerate(frames(5.0, 9.0)):
        cv2.imwrite(str(d / f"f{k:03d}.png"), img)
    r = cli(
        "camera-slip",
        str(d),
        "--fps",
        "100",
        "--mm-per-px",
        "0.5",
        "-o",
        str(tmp_path / "slip.csv"),
    )
    assert r.returncode == 0, r.stderr
    assert "median slip angle" in r.stdout and (tmp_path / "slip.png").exists()
    import pandas as pd

    res = pd.read_csv(tmp_path / "slip.csv")
    assert abs(res.loc[res["ok"], "slip_angle_deg"].median() - 5.0) < 0.2


def test_camber_cli(tmp_path):
    import pandas as pd

    from tests.cli.inprocess import cli

    t = np.arange(0, 4, 0.01)
    gamma = np.where(t < 1.0, 0.0, 2.0)  # calibration second on the floor, then 2°
    s = 0.25
    off_o, off_i = 301.2, 298.7  # mm
    d_o = off_o + 1000 * (s / 2) * np.tan(np.deg2rad(gamma))
    d_i = off_i - 1000 * (s / 2) * np.tan(np.deg2rad(gamma))
    f = tmp_path / "laser.csv"
    pd.DataFrame({"t_s": t, "d_outer_mm": d_o, "d_inner_mm": d_i}).to_csv(f, index=False)
    r = cli(
        "camber",
        str(f),
        "--spacing-m",
        str(s),
        "--calibrate-s",
        "1.0",
        "-o",
        str(tmp_path / "c.csv"),
    )
    assert r.returncode == 0, r.stderr
    out = pd.read_csv(tmp_path / "c.csv")
    np.testing.assert_allclose(out["camber_deg"], gamma, atol=1e-9)
    r = cli("camber", str(f), "--spacing-m", "0")
    assert r.returncode == 2 and "spacing_m" in r.stderr
