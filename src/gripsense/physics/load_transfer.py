"""Static axle loads, lateral load transfer and the lateral force an axle carries.

Sign convention: ISO 8855, lateral acceleration a_y > 0 in a left turn, which moves load to the
right (outer) wheels.

References: docs/physics.md §4.2 (general steady-state formula), §4.3 (thesis eqs. 6.21/6.22 as a
special case), §4.4 (what the lateral force is).
"""

from __future__ import annotations

from gripsense._arrays import as_float_array, restore

__all__ = [
    "axle_lateral_force",
    "lateral_load_transfer",
    "static_axle_masses",
    "thesis_load_transfer",
    "wheel_loads",
]

from gripsense.constants import G0


def static_axle_masses(mass_kg: float, front_fraction: float) -> tuple[float, float]:
    """Static axle masses (front, rear) = (m f, m (1 − f)) [kg]; f = l_r/L. docs/physics.md §4.2.

    Parameters
    ----------
    mass_kg : float
        Vehicle mass [kg].
    front_fraction : float
        Static front weight fraction l_r/L [-].
    """
    return mass_kg * front_fraction, mass_kg * (1.0 - front_fraction)


def lateral_load_transfer(
    lateral_accel,
    mass_kg: float,
    cg_height_m: float,
    axle_masses_kg: tuple[float, float],
    tracks_m: tuple[float, float],
    roll_centre_heights_m: tuple[float, float] | None = None,
    roll_stiffness_front_fraction: float | None = None,
    roll_gradient_rad_per_g: float = 0.0,
):
    """Steady-state lateral load transfer per axle, ΔFz_i [N] (to the right wheels for a_y > 0).

    ΔFz_i = (1 / t_i) · [ a_y m_i⁰ h_i + (K_φi / ΣK_φ) · m · (h − h_ra) · a_y (1 + φ_g) ],
    h_ra = Σ m_i⁰ h_i / m, with the body's roll φ = φ_g a_y/g moving the CG sideways.

    Parameters
    ----------
    lateral_accel : array_like
        a_y of the CG, ISO (left positive) [m/s^2].
    mass_kg : float
        Total mass m [kg].
    cg_height_m : float
        CG height h [m].
    axle_masses_kg : (float, float)
        Static front and rear axle masses m_f⁰, m_r⁰ [kg].
    tracks_m : (float, float)
        Front and rear track t_f, t_r [m].
    roll_centre_heights_m : (float, float) or None
        Roll-centre heights h_f, h_r [m]. None: at CG height (rigid, no-roll vehicle) — the
        thesis model, ΔFz_i = m_i⁰ a_y h / t_i.
    roll_stiffness_front_fraction : float or None
        K_φf / ΣK_φ [-]. None: equal to the weight split.
    roll_gradient_rad_per_g : float
        Body roll per g of lateral acceleration φ_g [rad] (0: the CG does not move sideways).

    Returns
    -------
    (dfz_front, dfz_rear) : tuple of array_like
        [N]. Moment balance: Σ ΔFz_i t_i = m a_y h (+ m (h − h_ra) a_y φ_g).

    References
    ----------
    docs/physics.md §4.2 (simplified: no sprung/unsprung split).
    """
    ay = as_float_array(lateral_accel, "lateral_accel")
    mf, mr = axle_masses_kg
    tf, tr = tracks_m
    hf, hr = roll_centre_heights_m if roll_centre_heights_m is not None else (cg_height_m,) * 2
    kf = (
        roll_stiffness_front_fraction
        if roll_stiffness_front_fraction is not None
        else (mf / (mf + mr))
    )
    h_ra = (mf * hf + mr * hr) / mass_kg
    arm = mass_kg * (cg_height_m - h_ra)
    roll = 1.0 + roll_gradient_rad_per_g
    dfz_f = ay / tf * (mf * hf + kf * arm * roll)
    dfz_r = ay / tr * (mr * hr + (1.0 - kf) * arm * roll)
    return restore(dfz_f, lateral_accel), restore(dfz_r, lateral_accel)


def thesis_load_transfer(axle_lateral_force_N, cg_height_m: float, half_track_m: float):
    """Thesis eqs. (6.21)/(6.22): Δm = F_c h /(2 b g), returned as a force ΔFz = F_c h/(2b) [N].

    Equals the rigid-vehicle transfer m_i⁰ a_y h / t only when F_c is the **axle's** lateral
    force m_i⁰ a_y (docs/physics.md §4.3); with the thesis's per-wheel F_c it is half of that.

    Parameters
    ----------
    axle_lateral_force_N : array_like
        F_c [N].
    cg_height_m : float
        h [m] (thesis: 0.75, estimated by eye).
    half_track_m : float
        b, "distance from CG to tyre, y" [m] (thesis: 0.55).
    """
    fc = as_float_array(axle_lateral_force_N, "axle_lateral_force_N")
    return restore(fc * cg_height_m / (2.0 * half_track_m), axle_lateral_force_N)


def wheel_loads(axle_mass_kg: float, dfz):
    """(left, right) wheel loads Fz = m_i⁰ g/2 ∓ ΔFz [N] (ΔFz > 0 loads the right wheel).

    Parameters
    ----------
    axle_mass_kg : float
        Static axle mass m_i⁰ [kg].
    dfz : array_like
        Load transfer of the axle, ΔFz [N] (:func:`lateral_load_transfer`).

    References
    ----------
    docs/physics.md §4.2: Fz,outer/inner = m_i⁰ g/2 ± ΔFz_i.
    """
    d = as_float_array(dfz, "dfz")
    half = 0.5 * axle_mass_kg * G0
    return restore(half - d, dfz), restore(half + d, dfz)


def axle_lateral_force(axle_mass_kg: float, lateral_accel):
    """Lateral force the axle carries in steady state, F = m_i⁰ a_y [N] (ISO sign).

    With no yaw acceleration the rear axle carries m a_y l_f/L = (static rear-axle mass) · a_y.

    Parameters
    ----------
    axle_mass_kg : float
        Static axle mass m_i⁰ [kg].
    lateral_accel : array_like
        Lateral acceleration of the CG, ISO [m/s^2].

    References
    ----------
    docs/physics.md §4.4.
    """
    ay = as_float_array(lateral_accel, "lateral_accel")
    return restore(axle_mass_kg * ay, lateral_accel)
