"""The tyre-curve family made from real tyres: published tyre property files, their normalised
lateral curves, and the compact set of Magic Formula shapes that covers them
(``docs/physics.md`` §14.3).

Each file of :data:`LIBRARY` (bundled under ``gripsense/data/tyres``, origin and licence in
``tyres/library/SOURCES.md``) is read with the project's own readers
(:func:`gripsense.config.tyre_files.load_tyre_model`) and its pure lateral force evaluated —
Magic Formula 5.2 / 6.1 / 6.2 and PAC2002 as the files are, PAC89 for Project Chrono's HMMWV —
at 0.5–1.5 × its nominal load and inclination −3…+3°. Each curve is taken from its zero-force
slip α₀ on both sides and normalised (§14): F/(μFz) against x = K tan|α − α₀|/(μFz), with K the
slope dF/dα at α₀ and μFz the branch's peak at that load and inclination. Every normalised curve
is fitted with the Magic Formula's normalised shape f(x) = sin(C_s atan(x/C_s − E(x/C_s −
atan(x/C_s)))) (:func:`~gripsense.physics.tyre_curves.magic_formula_normalised`), and the
family is the smallest set of those fitted shapes (greedy cover) such that every curve of every
file lies within :data:`COVER_MARGIN` of a member, in F/(μFz), from x = 0 to the file's largest
slip (:func:`build_family`).

What the files do not cover — low-grip surfaces (wet, snow, ice), worn or winter tyres — is
measured, not assumed: the same sweeps with the files' LMUY scaled so that the nominal μ is
0.3–0.5 (:func:`low_grip_distance`). In the Magic Formula LMUY scales the peak D (and the
vertical shifts) but not the cornering stiffness, so the normalised shape moves only through
the shifts and camber terms; real low-grip surfaces are not so kind, which the stated margin
does not capture.

The family is computed once, by :func:`build_family`, and stored here as constants
(:data:`FAMILY_MEMBERS`); ``tests/physics/test_tyre_library.py`` rebuilds it from the files and
checks it is the same. Nothing is read at import.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from gripsense.physics.tyre_family import (
    CATEGORIES,
    CATEGORY_MEMBERS,
    FAMILY_MEMBERS,
    category_members,
)

__all__ = [
    "CAMBERS_DEG",
    "CATEGORIES",
    "CATEGORY_MEMBERS",
    "COVER_MARGIN",
    "FAMILY_MEMBERS",
    "FIT_STEP",
    "LIBRARY",
    "LOAD_FACTORS",
    "LOW_GRIP_MARGIN",
    "LOW_GRIP_MUS",
    "PEAK_X_MAX",
    "LibraryTyre",
    "NormalisedCurve",
    "build_family",
    "category_members",
    "coverage_table",
    "curve_distance",
    "fit_shape",
    "fit_shapes",
    "library_curves",
    "low_grip_curves",
    "normalised_curves",
    "peak_x",
    "plot_family",
]


LOAD_FACTORS = (0.5, 0.75, 1.0, 1.25, 1.5)
"""Loads of the sweeps, as multiples of each file's nominal load FNOMIN [-]."""

CAMBERS_DEG = (-3.0, -1.5, 0.0, 1.5, 3.0)
"""Inclinations of the sweeps [deg]."""

SLIP_MAX = 0.42
"""Largest slip from the zero-force slip that is evaluated [rad] (24°: inside every file's
ALPMIN/ALPMAX)."""

COVER_MARGIN = 0.035
"""Every normalised curve of every file lies within this of a family member, in F/(μ Fz) [-]."""

LOW_GRIP_MUS = (0.3, 0.5)
"""Road friction of the low-grip sweeps (the files' LMUY scaled) [-]."""

LOW_GRIP_MARGIN = 0.05
"""Every low-grip curve lies within this of a family member, in F/(μ Fz) [-]."""


@dataclass(frozen=True)
class LibraryTyre:
    """A bundled tyre property file.

    Attributes
    ----------
    file : str
        Path relative to the ``gripsense.data`` folder.
    category : str
        One of :data:`CATEGORIES`.
    label : str
        What the tyre is (size, vehicle, source).
    """

    file: str
    category: str
    label: str


LIBRARY: tuple[LibraryTyre, ...] = (
    LibraryTyre("tyres/PacejkaBook_Defaults.tir", "passenger", "205/60R15, MF 6.1 (MFeval)"),
    LibraryTyre("tyres/Sedan_Pac02Tire.tir", "passenger", "sedan, PAC2002 (Chrono)"),
    LibraryTyre("tyres/library/car205_60R19.tir", "passenger", "205/60R19, MF 6.2 (Simscape)"),
    LibraryTyre("tyres/library/mf_185_80R14.tir", "passenger", "185/80R14 van, PAC2002 (Chrono)"),
    LibraryTyre("tyres/MagicFormula61_Paramerters.tir", "performance", "255/55, MF 6.1 (MFeval)"),
    LibraryTyre("tyres/library/suv_Pac02Tire.tir", "suv", "Nissan Patrol, PAC2002 (Chrono)"),
    LibraryTyre("tyres/library/HMMWV_Pac02Tire.tir", "suv", "HMMWV, PAC2002 (Chrono)"),
    LibraryTyre("tyres/HMMWV_Pac89Tire.json", "suv", "HMMWV, PAC89 (Chrono)"),
    LibraryTyre(
        "tyres/library/MagicFormula52_Paramerters.tir", "suv", "235/85 light truck, MF 5.2 (MFeval)"
    ),
    LibraryTyre("tyres/library/car235_80R17.tir", "suv", "235/80R17, MF 6.2 (Simscape)"),
    LibraryTyre("tyres/library/FSAE_Defaults.tir", "racing", "Formula Student, MF 6.1 (MFeval)"),
    LibraryTyre(
        "tyres/library/335_65R22_5_G275MSA_40psi.tir", "truck", "335/65R22.5 40 psi, MF 5.2"
    ),
    LibraryTyre(
        "tyres/library/335_65R22_5_G275MSA_60psi.tir", "truck", "335/65R22.5 60 psi, PAC2002"
    ),
    LibraryTyre(
        "tyres/library/335_65R22_5_G275MSA_70psi.tir", "truck", "335/65R22.5 70 psi, MF 5.2"
    ),
    LibraryTyre(
        "tyres/library/335_65R22_5_G275MSA_95psi.tir", "truck", "335/65R22.5 95 psi, MF 5.2"
    ),
)
"""The bundled files, each with its category (``tyres/library/SOURCES.md``)."""


@dataclass(frozen=True)
class NormalisedCurve:
    """One normalised lateral curve of one file.

    Attributes
    ----------
    file : str
        The file (:attr:`LibraryTyre.file`).
    load_factor : float
        Load over the file's nominal load [-].
    camber_deg : float
        Inclination [deg].
    side : int
        +1: slip above the zero-force slip, −1: below.
    x : numpy.ndarray
        Normalised slip K tan|α − α₀|/(μ Fz) [-].
    y : numpy.ndarray
        F/(μ Fz) [-] (peak 1).
    saturating : bool
        The force still rises at the largest slip evaluated (:data:`SLIP_MAX`): μFz is the
        force there, not a peak.
    """

    file: str
    load_factor: float
    camber_deg: float
    side: int
    x: np.ndarray
    y: np.ndarray
    saturating: bool


def _force_function(entry: LibraryTyre, lmuy: float = 1.0):
    """(F(fz, α, γ) with positive force for positive slip [N], nominal load [N])."""
    from gripsense.config.tyre_files import load_tyre_model
    from gripsense.data import path as data_path
    from gripsense.io.tyres.tir import read_tir
    from gripsense.physics.magic_formula import MFTyre

    path = data_path(entry.file)
    if path.suffix == ".tir":
        tir = read_tir(path)
        params: dict = dict(tir.parameters())
        scale = params.get("LMUY", 1.0)
        params["LMUY"] = (float(scale) if isinstance(scale, (int, float)) else 1.0) * lmuy
        tyre = MFTyre(params, name=tir.name)

        def force(fz, alpha, gamma):
            return -tyre.forces(fz, 0.0, alpha, gamma, combined=False).fy

        return force, float(tyre.params["FNOMIN"])
    if lmuy != 1.0:
        raise ValueError(f"{entry.file}: LMUY scaling needs a Magic Formula file")
    model = load_tyre_model(path)

    def force_iso(fz, alpha, gamma):
        return -np.asarray(model.fy_iso(fz, alpha, gamma), dtype=float)

    return force_iso, float(model.fz_nominal)


def normalised_curves(
    entry: LibraryTyre,
    *,
    load_factors=LOAD_FACTORS,
    cambers_deg=CAMBERS_DEG,
    lmuy: float = 1.0,
    n: int = 211,
) -> list[NormalisedCurve]:
    """The normalised pure lateral curves of one file (``docs/physics.md`` §14.3).

    Parameters
    ----------
    entry : LibraryTyre
        The file.
    load_factors : sequence of float
        Loads as multiples of the file's nominal load [-].
    cambers_deg : sequence of float
        Inclinations [deg].
    lmuy : float
        Factor on the file's LMUY (peak friction scaling; Magic Formula files only) [-].
    n : int
        Slip points per branch, 0 … :data:`SLIP_MAX` from the zero-force slip.

    Returns
    -------
    list of NormalisedCurve
        Two per load and inclination (both sides of the zero-force slip).
    """
    force, fz0 = _force_function(entry, lmuy)
    t = np.linspace(0.0, SLIP_MAX, n)
    out = []
    for lf in load_factors:
        fz = lf * fz0
        for cam in cambers_deg:
            g = np.deg2rad(cam)
            # zero-force slip: the sign change nearest zero on a fine grid, then two secant steps
            a = np.linspace(-0.1, 0.1, 2001)
            fa = force(np.full_like(a, fz), a, np.full_like(a, g))
            k = np.nonzero(np.diff(np.sign(fa)) != 0)[0]
            i = k[np.argmin(np.abs(a[k]))]
            a0 = a[i] - fa[i] * (a[i + 1] - a[i]) / (fa[i + 1] - fa[i])
            h = 1e-6
            fp, fm, f0 = (
                float(force(np.array([fz]), np.array([a0 + d]), np.array([g]))[0])
                for d in (h, -h, 0.0)
            )
            slope = (fp - fm) / (2 * h)
            a0 -= f0 / slope
            for side in (1, -1):
                alpha = a0 + side * t
                f = side * force(np.full_like(t, fz), alpha, np.full_like(t, g))
                j = int(np.argmax(f))
                peak = float(f[j])
                x = slope * np.tan(t) / peak
                out.append(
                    NormalisedCurve(
                        entry.file, float(lf), float(cam), side, x, f / peak, j == n - 1
                    )
                )
    return out


@cache
def library_curves() -> tuple[NormalisedCurve, ...]:
    """Every normalised curve of every file of :data:`LIBRARY` (computed once)."""
    return tuple(c for e in LIBRARY for c in normalised_curves(e))


def curve_distance(curve: NormalisedCurve, c: float, e: float) -> float:
    """Largest |F/(μFz) − f(x)| between a normalised curve and the Magic Formula shape (C_s, E)
    over the curve's slip range (``docs/physics.md`` §14.3).

    Parameters
    ----------
    curve : NormalisedCurve
        The curve.
    c : float
        Shape factor C_s [-].
    e : float
        Curvature factor E [-].

    Returns
    -------
    float
        The distance [-].
    """
    from gripsense.physics.tyre_curves import magic_formula_normalised

    return float(np.max(np.abs(curve.y - magic_formula_normalised(curve.x, c, e))))


FIT_STEP = (0.02, 0.02)
"""Grid step of the fitted (C_s, E) [-]: the fits are the grid's minimax shapes."""

PEAK_X_MAX = 7.5
"""Largest normalised slip of a member's peak [-]: the files' curves are evaluated up to x ≈ 2.7–7.5
(:data:`SLIP_MAX`); a curve still rising there (:attr:`NormalisedCurve.saturating`) says its peak
lies beyond, not where — a member peaking far beyond every file's data would be extrapolation."""


def peak_x(c, e):
    """Normalised slip of the peak of the Magic Formula shape (C_s, E): C_s atan(u) = π/2 with
    u = x/C_s − E (x/C_s − atan(x/C_s)) (``docs/physics.md`` §14), solved by bisection.

    Parameters
    ----------
    c : array_like
        Shape factor C_s, 1 < C_s ≤ 2 [-].
    e : array_like
        Curvature factor E ≤ 1 [-].

    Returns
    -------
    numpy.ndarray
        x of the peak [-] (inf where C_s ≤ 1: no peak).
    """
    c, e = np.broadcast_arrays(np.asarray(c, dtype=float), np.asarray(e, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore"):
        u_star = np.where(c > 1.0, np.tan(np.pi / (2.0 * c)), np.inf)
    lo, hi = np.zeros(c.shape), np.full(c.shape, 1e4)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        b = mid / c
        u = b - e * (b - np.arctan(b))
        below = u < u_star
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return np.where(np.isfinite(u_star), 0.5 * (lo + hi), np.inf)


def fit_shapes(curves) -> np.ndarray:
    """The Magic Formula normalised shape closest to each curve: the (C_s, E) on a grid of
    step :data:`FIT_STEP` (C_s 1–2, E −3…1, peak at most :data:`PEAK_X_MAX`) with the smallest
    largest deviation, found coarse to fine (``docs/physics.md`` §14.3).

    Parameters
    ----------
    curves : sequence of NormalisedCurve
        The curves (all of one length).

    Returns
    -------
    numpy.ndarray
        Shape (n, 3): C_s [-], E [-] and the largest |Δ F/(μFz)| over each curve [-].
    """
    from gripsense.physics.tyre_curves import magic_formula_normalised

    x = np.array([k.x for k in curves])
    y = np.array([k.y for k in curves])
    sc, se = FIT_STEP

    def worst(c, e):
        w = np.max(np.abs(y - magic_formula_normalised(x, c[:, None], e[:, None])), axis=1)
        return np.where(peak_x(c, e) <= PEAK_X_MAX, w, np.inf)

    n = x.shape[0]
    best_c, best_e, best = np.full(n, 1.5), np.zeros(n), np.full(n, np.inf)
    for c in np.arange(10, 21) / 10.0:  # coarse: C_s 1.0–2.0 by 0.1, E −3…1 by 0.2
        for e in np.arange(-15, 6) / 5.0:
            w = worst(np.full(n, c), np.full(n, e))
            better = w < best
            best_c, best_e, best = (
                np.where(better, c, best_c),
                np.where(better, e, best_e),
                np.minimum(w, best),
            )
    c0, e0 = best_c.copy(), best_e.copy()
    best[:] = np.inf
    for dc in range(-5, 6):  # fine: ±0.1 in C_s, ±0.2 in E around the coarse best
        for de in range(-10, 11):
            c = np.clip(np.round(c0 / sc + dc) * sc, 1.0, 2.0)
            e = np.clip(np.round(e0 / se + de) * se, -3.0, 1.0)
            w = worst(c, e)
            better = w < best
            best_c, best_e, best = (
                np.where(better, c, best_c),
                np.where(better, e, best_e),
                np.minimum(w, best),
            )
    return np.column_stack([np.round(best_c, 2), np.round(best_e, 2), best])


def fit_shape(curve: NormalisedCurve) -> tuple[float, float, float]:
    """The Magic Formula normalised shape closest to one curve (:func:`fit_shapes`).

    Parameters
    ----------
    curve : NormalisedCurve
        The curve.

    Returns
    -------
    c, e, error : float
        C_s [-], E [-] and the largest |Δ F/(μFz)| over the curve [-].
    """
    c, e, err = fit_shapes([curve])[0]
    return float(c), float(e), float(err)


def low_grip_curves(
    mu_targets=LOW_GRIP_MUS,
    *,
    load_factors=(0.5, 1.0, 1.5),
    cambers_deg=(-3.0, 0.0, 3.0),
    n: int = 211,
) -> list[NormalisedCurve]:
    """The Magic Formula files' normalised curves on low-grip surfaces: LMUY scaled so that μ
    at the nominal load and zero inclination is each target (``docs/physics.md`` §14.3).

    Parameters
    ----------
    mu_targets : sequence of float
        Road friction levels [-].
    load_factors : sequence of float
        Loads as multiples of each file's nominal load [-].
    cambers_deg : sequence of float
        Inclinations [deg].
    n : int
        Slip points per branch.

    Returns
    -------
    list of NormalisedCurve
        The curves (PAC89 files, which have no LMUY, left out).
    """
    out: list[NormalisedCurve] = []
    t = np.linspace(0.0, SLIP_MAX, n)
    for entry in LIBRARY:
        if not entry.file.endswith(".tir"):
            continue
        force, fz0 = _force_function(entry)
        mu0 = float(np.max(force(np.full_like(t, fz0), t, np.zeros_like(t)))) / fz0
        for mu in mu_targets:
            out += normalised_curves(
                entry, load_factors=load_factors, cambers_deg=cambers_deg, lmuy=mu / mu0, n=n
            )
    return out


def _distances(curves, members) -> np.ndarray:
    """|Δ F/(μFz)| of every curve (rows) to every member (columns), largest over the curve."""
    from gripsense.physics.tyre_curves import magic_formula_normalised

    x = np.array([k.x for k in curves])
    y = np.array([k.y for k in curves])
    d = np.empty((len(curves), len(members)))
    for j, (c, e) in enumerate(members):
        d[:, j] = np.max(np.abs(y - magic_formula_normalised(x, c, e)), axis=1)
    return d


def _cover(d: np.ndarray, margins: np.ndarray, cands, what) -> list:
    """Greedy set cover: the fewest candidates (columns) within each row's margin."""
    ok = d <= margins[:, None]
    left = np.ones(d.shape[0], dtype=bool)
    chosen = []
    while left.any():
        gain = ok[left].sum(axis=0)
        j = int(np.argmax(gain))  # ties: the first candidate in (C_s, E) order
        if gain[j] == 0:
            bad = sorted({what[i] for i in np.nonzero(left)[0]})
            raise ValueError(f"no fitted shape covers {', '.join(bad[:3])} within the margin")
        chosen.append(cands[j])
        left &= ~ok[:, j]
    return chosen


def build_family(
    curves=None,
    low=None,
    *,
    margin: float = COVER_MARGIN,
    low_margin: float = LOW_GRIP_MARGIN,
) -> tuple[tuple[tuple[float, float], ...], dict[str, tuple[tuple[float, float], ...]]]:
    """The compact family (``docs/physics.md`` §14.3): every curve is fitted with the Magic
    Formula's normalised shape, the fits (C_s, E) rounded to 0.02 are the candidates, and the
    family is the fewest candidates (greedy set cover) such that every curve of every file lies
    within *margin* of a member and every low-grip curve within *low_margin*. Each category's
    members are then the fewest family members that cover that category's curves alike.

    Parameters
    ----------
    curves : sequence of NormalisedCurve, optional
        The files' curves (default: :func:`library_curves`).
    low : sequence of NormalisedCurve, optional
        The low-grip curves (default: :func:`low_grip_curves`).
    margin : float
        Largest |Δ F/(μFz)| a member may leave on a file's curve [-].
    low_margin : float
        Largest |Δ F/(μFz)| on a low-grip curve [-].

    Returns
    -------
    members : tuple of (float, float)
        The family's (C_s, E), sorted.
    categories : dict
        Category → its members' (C_s, E), sorted.
    """
    curves = list(library_curves() if curves is None else curves)
    low = list(low_grip_curves() if low is None else low)
    every = curves + low
    fits = {
        (float(np.round(c / 0.02) * 0.02), float(np.round(e / 0.02) * 0.02))
        for c, e, _ in fit_shapes(every)  # every curve at once: 15 × faster than one by one
    }
    cands = sorted((round(c, 2), round(e, 2)) for c, e in fits)
    d = _distances(every, cands)
    margins = np.array([margin] * len(curves) + [low_margin] * len(low))
    what = [k.file for k in every]
    members = sorted(_cover(d, margins, cands, what))
    cat_of = {e.file: e.category for e in LIBRARY}
    cols = [cands.index(m) for m in members]
    categories = {}
    for cat in CATEGORIES:
        rows = np.array([cat_of[k.file] == cat for k in every])
        if rows.any():
            got = _cover(
                d[rows][:, cols],
                margins[rows],
                members,
                [w for w, r in zip(what, rows, strict=True) if r],
            )
            categories[cat] = tuple(sorted(got))
    return tuple(members), categories


def coverage_table(curves=None) -> list[dict]:
    """Per file: category, load range, the fitted (C_s, E) ranges, the largest fit error and
    the largest distance of its curves to the nearest family member (``docs/physics.md`` §14.3).

    Parameters
    ----------
    curves : sequence of NormalisedCurve, optional
        The curves (default: :func:`library_curves`).

    Returns
    -------
    list of dict
        One row per file of :data:`LIBRARY`.
    """
    curves = list(library_curves() if curves is None else curves)
    d = _distances(curves, FAMILY_MEMBERS).min(axis=1)
    rows = []
    for entry in LIBRARY:
        idx = [i for i, k in enumerate(curves) if k.file == entry.file]
        fits = fit_shapes([curves[i] for i in idx])
        peaks = [float(curves[i].x[np.argmax(curves[i].y)]) for i in idx]
        rows.append(
            {
                "file": entry.file.rsplit("/", 1)[-1],
                "category": entry.category,
                "label": entry.label,
                "loads": (
                    min(curves[i].load_factor for i in idx),
                    max(curves[i].load_factor for i in idx),
                ),
                "c": (float(fits[:, 0].min()), float(fits[:, 0].max())),
                "e": (float(fits[:, 1].min()), float(fits[:, 1].max())),
                "fit_error": float(fits[:, 2].max()),
                "x_peak": (min(peaks), max(peaks)),
                "saturating": sum(curves[i].saturating for i in idx),
                "curves": len(idx),
                "distance": float(d[idx].max()),
            }
        )
    return rows


def plot_family(path) -> None:
    """Draw every file's normalised curves, coloured by category, over the family's members
    (``docs/physics.md`` §14.3; ``python -m gripsense.config.tyre_library FILE.png``).

    Parameters
    ----------
    path : str or Path
        The figure's file (PNG).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gripsense.physics.tyre_curves import BOX_FAMILY, normalised_force

    colours = dict(zip(CATEGORIES, ("C0", "C1", "C2", "C3", "C7"), strict=True))
    cat_of = {e.file: e.category for e in LIBRARY}
    x = np.linspace(0.0, 8.0, 401)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for k in library_curves():
        axes[0].plot(k.x, k.y, color=colours[cat_of[k.file]], lw=0.4, alpha=0.5)
    for cat in CATEGORIES:
        axes[0].plot([], [], color=colours[cat], label=cat)
    axes[0].set_title(f"{len(LIBRARY)} tyre files: 0.5–1.5 × load, ±3° inclination, both sides")
    for s in BOX_FAMILY:
        axes[1].plot(x, normalised_force(x, s), color="0.75", lw=0.8)
    for c, e in FAMILY_MEMBERS:
        axes[1].plot(x, _mf(x, c, e), color="C3", lw=1.0)
    axes[1].plot([], [], color="C3", label=f"made from the files ({len(FAMILY_MEMBERS)})")
    axes[1].plot([], [], color="0.75", label="the earlier box of constants")
    axes[1].set_title(f"the family: within {COVER_MARGIN} of every curve")
    for ax in axes:
        ax.set_xlim(0, 8)
        ax.set_ylim(0, 1.05)
        ax.set_xlabel("x = K tan|α − α₀| / (μ Fz)")
        ax.legend(loc="lower right", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("F / (μ Fz)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _mf(x, c, e):
    """:func:`gripsense.physics.tyre_curves.magic_formula_normalised` (imported late)."""
    from gripsense.physics.tyre_curves import magic_formula_normalised

    return magic_formula_normalised(x, c, e)


if __name__ == "__main__":  # pragma: no cover - writes the docs' figure
    import sys

    plot_family(sys.argv[1] if len(sys.argv) > 1 else "docs/figures/tyre_family.png")
