"""Slip angle from a downward-looking camera on the wheel (seed 002 §2.1, Fig. 2).

The seed measures the direction of the road texture's flow in the video: a reference block at
the image centre is compared with blocks along the search area, the best-correlated positions
are found, and a linear regression of them gives the streamline direction — which runs
**opposite** to the direction of travel. Here, on consecutive frames:

1. **block matching** (the seed's step <1>–<5>): the centre block of frame k is located in frame
   k+1 by normalised cross-correlation (OpenCV ``matchTemplate``) → integer displacement;
2. **sub-pixel refinement**: pyramidal Lucas–Kanade on up to 300 corners of frame k, seeded with
   the block-matching displacement; the median of the tracked flows (outliers beyond 3 MAD
   dropped) is the pair's flow. Phase correlation (``phaseCorrelate``) is a second opinion;
3. **outlier rejection and quality**: the block-matching peak, the fraction of corners tracked
   and the agreement of the three estimates give a per-pair quality; pairs that disagree or
   score low are flagged.

Image convention: camera looking down, not mirrored, image **top = wheel forward**, image left =
wheel left. The ground's flow (drow, dcol) then equals the wheel's velocity (v_x, v_y) in
pixels: slip angle α = atan2(dcol, drow) (ISO 8855: positive when the wheel moves to the left
of its heading), ground speed = |flow| · mm-per-px · fps.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.errors import InputError

__all__ = ["SLIP_COLUMNS", "frame_pair_flow", "slip_from_frames"]

SLIP_COLUMNS = [
    "pair",
    "t_s",
    "slip_angle_rad",
    "slip_angle_deg",
    "speed_mps",
    "quality",
    "response",
    "ok",
]
"""Columns of :func:`slip_from_frames`."""


def _cv2():
    try:
        import cv2
    except ImportError:  # pragma: no cover - depends on the install
        raise InputError(
            "the camera slip angle needs OpenCV: pip install 'gripsense[vision]'"
        ) from None
    return cv2


def frame_pair_flow(a: np.ndarray, b: np.ndarray, *, block: int = 64, search: int = 48) -> dict:
    """Ground flow between two grey frames (see the module documentation).

    Parameters
    ----------
    a : numpy.ndarray
        Earlier frame (grey).
    b : numpy.ndarray
        Later frame (grey).
    block : int
        Side of the centre block matched [px].
    search : int
        Search range of the block match [px].

    Returns
    -------
    dict
        ``drow``, ``dcol`` [px] (refined), ``ncc`` (block-matching peak), ``response``
        (phase correlation), ``agree`` (block match and phase correlation within 1.5 px).
    """
    cv2 = _cv2()
    a = a.astype(np.float32)
    b = b.astype(np.float32)
    h, w = a.shape
    r0, c0 = h // 2 - block // 2, w // 2 - block // 2
    tmpl = a[r0 : r0 + block, c0 : c0 + block]
    rs, cs = max(r0 - search, 0), max(c0 - search, 0)
    area = b[rs : min(r0 + block + search, h), cs : min(c0 + block + search, w)]
    res = cv2.matchTemplate(area, tmpl, cv2.TM_CCOEFF_NORMED)
    _, ncc, _, loc = cv2.minMaxLoc(res)
    drow_i = loc[1] + rs - r0
    dcol_i = loc[0] + cs - c0
    win = cv2.createHanningWindow((w, h), cv2.CV_32F)
    (dx, dy), response = cv2.phaseCorrelate(a, b, win)

    # seeded Lucas–Kanade on corners; frames normalised first (LK assumes constant brightness,
    # a road under changing light or exposure does not keep it)
    def norm8(x):
        return np.clip((x - x.mean()) / (x.std() + 1e-6) * 40.0 + 128.0, 0, 255).astype(np.uint8)

    a8 = norm8(a)
    b8 = norm8(b)
    pts = cv2.goodFeaturesToTrack(a8, maxCorners=300, qualityLevel=0.01, minDistance=5, blockSize=7)
    tracked = 0.0
    drow, dcol = float(drow_i), float(dcol_i)
    if pts is not None and len(pts) >= 5:
        guess = pts + np.array([dcol_i, drow_i], dtype=np.float32)
        nxt, st, _ = cv2.calcOpticalFlowPyrLK(
            a8,
            b8,
            pts,
            guess.copy(),
            winSize=(21, 21),
            maxLevel=2,
            criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 40, 0.001),
            flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
        )
        good = st.ravel() == 1
        # keep corners whose target stays inside the frame
        inside = (
            (nxt[:, 0, 0] > 2)
            & (nxt[:, 0, 0] < w - 3)
            & (nxt[:, 0, 1] > 2)
            & (nxt[:, 0, 1] < h - 3)
        )
        good &= inside
        tracked = float(good.mean())
        if good.sum() >= 5:
            f = (nxt - pts)[good, 0, :]
            med = np.median(f, axis=0)
            mad = np.median(np.abs(f - med), axis=0) * 1.4826 + 1e-3
            keep = np.all(np.abs(f - med) <= 3 * mad, axis=1)
            dcol, drow = np.median(f[keep], axis=0).astype(float)
    agree = (
        abs(drow - drow_i) <= 1.5
        and abs(dcol - dcol_i) <= 1.5
        and abs(dy - drow) <= 1.5
        and abs(dx - dcol) <= 1.5
    )
    return {
        "drow": float(drow),
        "dcol": float(dcol),
        "ncc": float(ncc),
        "response": float(response),
        "tracked": tracked,
        "agree": bool(agree),
    }


def slip_from_frames(
    frames, *, fps: float, mm_per_px: float | None = None, min_quality: float = 0.5
) -> pd.DataFrame:
    """Slip angle per consecutive frame pair.

    Parameters
    ----------
    frames : iterable of 2-D arrays, a folder of images, or a video file path
        Grey or colour frames (converted to grey).
    fps : float
        Frame rate [1/s].
    mm_per_px : float or None
        Ground scale; with it the ground speed is given.
    min_quality : float
        Pairs whose quality is below this, or whose three flow estimates disagree by more
        than 1.5 px, are flagged ``ok = False``.

    Returns
    -------
    pandas.DataFrame
        ``pair``, ``t_s``, ``slip_angle_rad``, ``slip_angle_deg``, ``speed_mps`` (NaN without
        a scale), ``quality`` (block-matching peak × fraction of corners tracked),
        ``response`` (phase correlation), ``ok``.
    """
    if not (np.isfinite(fps) and fps > 0):  # the frame interval 1/fps times every pair
        raise InputError(f"fps = {fps}: give the camera's frame rate, > 0 [1/s]")
    cv2 = _cv2()
    imgs = list(_load(frames, cv2))
    if len(imgs) < 2:
        raise InputError("slip_from_frames: need at least two frames")
    rows = []
    for k in range(len(imgs) - 1):
        f = frame_pair_flow(imgs[k], imgs[k + 1])
        alpha = float(np.arctan2(f["dcol"], f["drow"]))
        px = float(np.hypot(f["drow"], f["dcol"]))
        q = f["ncc"] * f["tracked"]
        rows.append(
            {
                "pair": k,
                "t_s": (k + 0.5) / fps,
                "slip_angle_rad": alpha,
                "slip_angle_deg": float(np.rad2deg(alpha)),
                "speed_mps": px * mm_per_px * 1e-3 * fps if mm_per_px else np.nan,
                "quality": q,
                "response": f["response"],
                "ok": bool(f["agree"] and q >= min_quality and px > 0.5),
            }
        )
    return pd.DataFrame(rows, columns=SLIP_COLUMNS)


def _load(frames, cv2):
    if isinstance(frames, str | Path):
        p = Path(frames)
        if p.is_dir():
            files = sorted(
                f
                for f in p.iterdir()
                if f.suffix.lower() in (".png", ".jpg", ".jpeg", ".bmp", ".tif")
            )
            if not files:
                raise InputError(f"{p}: no image files (.png, .jpg, .bmp, .tif)")
            for f in files:
                img = cv2.imread(str(f), cv2.IMREAD_GRAYSCALE)
                if img is None:
                    raise InputError(f"{f}: cannot be read as an image")
                yield img
            return
        cap = cv2.VideoCapture(str(p))
        if not cap.isOpened():
            raise InputError(f"{p}: not a folder of images nor a readable video")
        while True:
            ok, img = cap.read()
            if not ok:
                break
            yield cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        return
    for img in frames:
        img = np.asarray(img)
        yield img if img.ndim == 2 else cv2.cvtColor(img.astype(np.uint8), cv2.COLOR_BGR2GRAY)
