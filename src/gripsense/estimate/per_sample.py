"""Per-sample estimators: μ of each wheel and sample from the brush model (thesis ch. 4, 6, 10;
``docs/physics.md`` §1, §11).

Each wheel carries its load's share of the axle force; μ follows from the brush model of the
chosen pressure shape (§1.3, §2.3) with κ_β, the slide point and a first-order σ_μ from the
noise model (§1.4). A flag says why μ is not reported: ``no_solution`` (r ≥ 1, or force and slip
angle of inconsistent sign), ``full_sliding``, ``ill_conditioned`` (σ_μ/μ above
``max_rel_sigma``), besides the kinematics' own (:data:`~gripsense.estimate.wheels.FLAGS`).

Why most samples are ``ill_conditioned``: at everyday lateral acceleration the whole difference
between μ = 0.9 and μ = ∞ lies in a few hundredths of a degree of slip angle (§1.4). The
``utilisation`` column, |F|/Fz, is what the data prove in every case: μ ≥ utilisation.
"""

from __future__ import annotations

import numpy as np

from gripsense.config import Vehicle
from gripsense.estimate.options import FrictionOptions
from gripsense.estimate.wheels import FLAGS
from gripsense.physics import brush

__all__ = ["PRESSURE_MODELS", "brush_stage"]

PRESSURE_MODELS = {
    "thesis-2": ("parabolic", "thesis"),
    "thesis-4": ("quartic", "thesis"),
    "brush-2": ("parabolic", "exact"),
    "brush-4": ("quartic", "exact"),
    "brush": (None, "exact"),
    "thesis": (None, "thesis"),
}
"""Per-sample method → (pressure shape, brush model); ``None``: the tyre description's shape."""


def brush_stage(
    frame: dict,
    vehicle: Vehicle,
    pressure: str | None,
    model: str,
    options: FrictionOptions,
) -> None:
    """μ of one wheel's samples from the brush model, with σ_μ and the estimator's flags
    (in place: ``mu``, ``mu_sigma``, ``kappa_beta``, ``slide_point_m``, ``force_ratio``,
    ``flag``).

    Parameters
    ----------
    frame : dict
        One wheel of :func:`gripsense.estimate.wheels.wheel_kinematics`.
    vehicle : Vehicle
        Vehicle description (the wheel's tyre).
    pressure : str or None
        Pressure shape (``parabolic``, ``quartic``; None: the tyre description's).
    model : str
        ``exact`` (brush) or ``thesis`` (the thesis's approximation).
    options : FrictionOptions
        ``max_rel_sigma`` and the noise model.
    """
    nz = options.noise
    tyre = vehicle.tyres[frame["_axle"]]
    force, alpha = frame["force_N"], frame["slip_angle_rad"]
    fz, c, length = (
        frame["load_N"],
        frame["cornering_stiffness_N_per_rad"],
        frame["contact_length_m"],
    )
    inv = brush.invert(force, alpha, fz, c, pressure=pressure or tyre.pressure, model=model)
    mu_raw, status, kap = inv["mu"], inv["status"], inv["kappa_beta"]
    # first-order uncertainty (docs/physics.md §1.4): T ∝ C tanβ, κ_F = 1 − κ_β
    sig_v_rel, sig_f_rel = frame["_sig_v_rel"], frame["_sig_f_rel"]
    sig_r = np.deg2rad(nz.yaw_rate_dps)
    sig_alpha = np.sqrt(
        np.deg2rad(nz.heading_deg) ** 2
        + sig_v_rel**2
        + (sig_r * frame["_dx"] / np.maximum(np.abs(frame["_u"]), 1e-9)) ** 2
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        sig_tan_rel = sig_alpha / np.abs(np.sin(alpha) * np.cos(alpha))
    sig_c_rel = np.hypot(
        nz.tread_stiffness_rel,
        2.0 * nz.contact_length_rel if tyre.cornering_stiffness_N_per_rad is None else 0.0,
    )
    with np.errstate(invalid="ignore"):
        rel = np.sqrt(kap**2 * (sig_tan_rel**2 + sig_c_rel**2) + (1.0 - kap) ** 2 * sig_f_rel**2)
        mu_sigma = mu_raw * rel
    code = np.zeros(alpha.size, dtype=np.int8)
    sign_bad = force * alpha > 0  # ISO: F ≈ −C α
    conds = [
        ("ill_conditioned", ~(rel <= options.max_rel_sigma)),
        ("full_sliding", status == brush.FULL_SLIDING),
        ("no_solution", (status == brush.NO_SOLUTION) | (status == brush.INVALID) | sign_bad),
    ]
    for name, m in conds:  # later entries take precedence; the kinematics' flags above all
        code[m] = FLAGS.index(name)
    flag = np.where(frame["flag"] == 0, code, frame["flag"])
    ok = flag == 0
    frame.update(
        flag=flag,
        mu=np.where(ok, mu_raw, np.nan),
        mu_sigma=np.where(ok, mu_sigma, np.nan),
        kappa_beta=kap,
        slide_point_m=inv["xi"] * length,
        force_ratio=inv["ratio"],
    )
