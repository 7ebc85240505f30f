"""Drives of vehicle models gripsense did not write, recorded by gripsense's emulated compass
and steering channel: CommonRoad's single-track drift model ``vehicle_dynamics_std`` (TUM,
``commonroad-vehicle-models``; Pacejka lateral and longitudinal tyres with combined slip, wheel
spin, longitudinal load transfer) and its multi-body model ``vehicle_dynamics_mb`` (29 states:
sprung mass with roll and pitch, unsprung masses, suspension springs and dampers, tyre vertical
compliance, wheel spin, per-wheel Pacejka tyres with camber — real lateral load transfer).

It is a truth for accuracy checks whose tyre, load model and integrator share nothing with the
estimator: the tyre is CommonRoad's own Magic Formula (vehicle 2: C 1.35, E ≈ 0, cornering
stiffness |p_ky1| F_z), scaled to the road by its peak coefficient ``p_dy1`` (the stiffness stays,
so on a slippery road the curve peaks at a small slip angle, as a real tyre's does). The model
has no lateral load transfer (one tyre per axle): each wheel of the truth table carries half the
axle. ``commonroad-vehicle-models`` is a test dependency; importing this module without it fails
with a clear message.

Axes: CommonRoad's single-track models integrate x, y in a right-handed ground frame with the yaw
angle counter-clockwise and lateral quantities positive to the left — gripsense's (ISO) axes;
its slip angle is the negative of ISO's. The multi-body model uses SAE-like axes (y right, z
down): its δ, r, lateral velocity and lateral force are the negatives of ISO's, its slip angle
is ISO's.

Road friction: the tyre's peak coefficient ``p_dy1`` is set to μ and the camber-induced vertical
shift ``p_vy1``, ``p_vy3`` scaled with it (as a Magic Formula's λ_μy scales S_Vy; unscaled, the
shift is 2–3 % of the load whatever the road, a third of the grip on μ 0.1).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.data import sample_path
from gripsense.sim.drives import Drive, record_drive
from gripsense.sim.maneuvers import corner_end
from gripsense.sim.vehicle import WHEEL_NAMES, SimParams, SimResult

__all__ = [
    "DrivePlan",
    "commonroad_drive",
    "commonroad_result",
    "commonroad_vehicle",
    "commonroad_vehicle_toml",
    "cr_circle",
    "cr_constant_radius",
    "cr_everyday",
    "cr_ramp_steer",
    "with_corner_exits",
]

G_CR = 9.81
"""CommonRoad's gravity [m/s²]."""


def _params(mu: float):
    try:
        from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
    except ImportError as exc:  # pragma: no cover - the test extra installs it
        raise ImportError(
            "CommonRoad drives need commonroad-vehicle-models: pip install 'gripsense[test]'"
        ) from exc
    p = parameters_vehicle2()
    # the peak scaled to the road, and the camber-induced shift with it (module docstring)
    scale = float(mu) / p.tire.p_dy1
    p.tire.p_vy1 *= scale
    p.tire.p_vy3 *= scale
    p.tire.p_dy1 = float(mu)
    # the longitudinal peak with it (a driven wheel on that road)
    p.tire.p_dx1 = float(mu) * 1.1739 / 1.0489
    return p


def commonroad_vehicle_toml(
    *,
    stiffness_error: float = 0.0,
    stiffness_uncertainty: float = 0.15,
    name: str = "CommonRoad vehicle 2 (single-track drift model)",
) -> str:
    """The vehicle file a user would write for CommonRoad's vehicle 2, as text: its mass, yaw
    inertia, CG position and height, tracks and wheel radius; per axle the cornering stiffness
    at the static load as measured (|p_ky1| F_z per wheel), the default load sensitivity and
    shape.

    Parameters
    ----------
    stiffness_error : float
        Relative error of the declared cornering stiffness [-].
    stiffness_uncertainty : float
        Declared 1σ of the stiffness [-].
    name : str
        The vehicle's ``name``.

    Returns
    -------
    str
        The TOML text (antenna as in the bundled sedan).
    """
    from pathlib import Path

    p = _params(1.0)
    wb = p.a + p.b
    base = Path(sample_path("corolla_sim.toml")).read_text(encoding="utf-8")
    lines, skip = [], False
    vals = {
        "name": f'"{name}"',
        "mass_kg": f"{p.m:.3f}",
        "front_weight_fraction": f"{p.b / wb:.5f}",
        "wheelbase_m": f"{wb:.5f}",
        "cg_height_m": f"{p.h_cg:.4f}",
        "track_front_m": f"{p.T_f:.4f}",
        "track_rear_m": f"{p.T_r:.4f}",
        "drive": '"rear"',
    }
    for line in base.splitlines():
        head = line.strip()
        if head.startswith("["):
            skip = head.startswith("[tyre")
        if skip or head.startswith("#"):
            continue
        key = head.split("=")[0].strip()
        if key in vals:
            line = f"{key} = {vals[key]}"
        lines.append(line)
    lines.insert(lines.index("[vehicle]") + 1, f"yaw_inertia_kgm2 = {p.I_z:.2f}")
    c_norm = abs(p.tire.p_ky1)
    for axle, share in (("front", p.b / wb), ("rear", p.a / wb)):
        fz = p.m * G0 * share / 2.0
        lines += [
            "",
            f"[tyre.{axle}]",
            "width_m = 0.205",
            f"cornering_stiffness_N_per_rad = {c_norm * fz * (1.0 + stiffness_error):.0f}",
            f"stiffness_uncertainty = {stiffness_uncertainty}",
            "contact_length = { fixed_m = 0.14 }",
        ]
    return "\n".join(lines) + "\n"


def commonroad_vehicle(
    *, stiffness_error: float = 0.0, stiffness_uncertainty: float = 0.15
) -> Vehicle:
    """The vehicle file a user would write for CommonRoad's vehicle 2
    (:func:`commonroad_vehicle_toml`), read.

    Parameters
    ----------
    stiffness_error : float
        Relative error of the declared cornering stiffness [-].
    stiffness_uncertainty : float
        Declared 1σ of the stiffness [-].

    Returns
    -------
    Vehicle
        The description (antenna as in the bundled sedan).
    """
    import tomllib

    text = commonroad_vehicle_toml(
        stiffness_error=stiffness_error, stiffness_uncertainty=stiffness_uncertainty
    )
    return Vehicle.from_dict(tomllib.loads(text), source="CommonRoad vehicle 2 (as a user would)")


@dataclasses.dataclass
class DrivePlan:
    """Targets of a drive as functions of time.

    Attributes
    ----------
    duration_s : float
        Length of the drive [s].
    settle_s : float
        Start of the intended test [s].
    target : callable
        t → (yaw rate [rad/s] or None, road-wheel angle [rad] or None, speed [m/s]).
    """

    duration_s: float
    settle_s: float
    target: Callable[[float], tuple[float | None, float | None, float]]
    # t -> (yaw rate [rad/s] or None, steer [rad] or None, speed [m/s])


def cr_circle(speed_mps: float, radius_m: float, *, steady_s: float = 25.0) -> DrivePlan:
    """A steady circle: 6 s straight (heading calibration), 3 s turn-in, *steady_s* on the
    circle at constant speed (yaw rate v/R held by the driver).

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    radius_m : float
        Radius [m].
    steady_s : float
        Time on the circle after the turn-in [s].

    Returns
    -------
    DrivePlan
        The drive's targets.
    """
    r_target = speed_mps / radius_m

    def target(t):
        return r_target * float(np.clip((t - 6.0) / 3.0, 0.0, 1.0)), None, speed_mps

    return DrivePlan(duration_s=9.0 + steady_s, settle_s=9.0, target=target)


def cr_constant_radius(
    radius_m: float, v_start_mps: float, v_end_mps: float, *, accel_mps2: float = 0.1
) -> DrivePlan:
    """ISO 4138 constant radius, speed rising: 6 s straight, 3 s turn-in at *v_start_mps*, then
    the speed raised slowly (quasi-steady) on the circle to *v_end_mps*.

    Parameters
    ----------
    radius_m : float
        Radius [m].
    v_start_mps, v_end_mps : float
        Speed at the start and at the end of the sweep [m/s].
    accel_mps2 : float
        Rate of the speed increase [m/s²].

    Returns
    -------
    DrivePlan
        The drive's targets.
    """
    t_sweep = (v_end_mps - v_start_mps) / accel_mps2

    def target(t):
        v = v_start_mps + accel_mps2 * float(np.clip(t - 11.0, 0.0, t_sweep))
        return v / radius_m * float(np.clip((t - 6.0) / 3.0, 0.0, 1.0)), None, v

    return DrivePlan(duration_s=11.0 + t_sweep + 1.0, settle_s=9.0, target=target)


def cr_ramp_steer(
    speed_mps: float, *, rate_deg_s: float = 0.5, max_steer_deg: float = 6.0
) -> DrivePlan:
    """ISO 4138 ramp steer: constant speed, the steering wheel turned slowly at a constant rate
    after 6 s straight, until *max_steer_deg* at the road wheels.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    rate_deg_s : float
        Road-wheel steering rate [deg/s].
    max_steer_deg : float
        Largest road-wheel angle [deg].

    Returns
    -------
    DrivePlan
        The drive's targets.
    """
    dur = 6.0 + max_steer_deg / rate_deg_s

    def target(t):
        return None, math.radians(rate_deg_s * max(t - 6.0, 0.0)), speed_mps

    return DrivePlan(duration_s=dur, settle_s=6.0, target=target)


def cr_everyday(speed_mps: float, *, seed: int = 0, **kwargs) -> DrivePlan:
    """Everyday driving (:func:`gripsense.sim.maneuvers.everyday`: steady curves of random
    direction and road-wheel angle, each entered over 2 s, after a straight) at constant speed.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    seed : int
        Random seed of the curves.
    **kwargs
        ``curves``, ``hold_s``, ``max_steer_deg``, ``lead_s`` of
        :func:`~gripsense.sim.maneuvers.everyday`.

    Returns
    -------
    DrivePlan
        The drive's targets.
    """
    from gripsense.sim.maneuvers import everyday

    m = everyday(speed_mps, seed=seed, **kwargs)
    assert m.steer_table is not None  # an everyday drive is steered by a table
    t_tab, steer_tab = m.steer_table

    def target(t):
        return None, float(np.interp(t, t_tab, steer_tab)), speed_mps

    return DrivePlan(duration_s=m.duration_s, settle_s=m.settle_s, target=target)


def with_corner_exits(
    plan: DrivePlan, *, unwind: float = 0.4, other_way: float = 0.7, change_s: float = 1.2
) -> DrivePlan:
    """A plan followed by the corner's end a driver adds
    (:func:`gripsense.sim.maneuvers.corner_end`, as :func:`gripsense.sim.maneuvers.
    with_corner_exits` does for gripsense's simulator), on the plan's last yaw rate or steer
    and at its last speed.

    Parameters
    ----------
    plan : DrivePlan
        The plan.
    unwind : float
        Share unwound in the reversal [-].
    other_way : float
        The opposite corner over the last one [-].
    change_s : float
        Time of a change by the whole last target [s].

    Returns
    -------
    DrivePlan
        The longer plan.
    """
    t_end = plan.duration_s
    r_end, d_end, v_end = plan.target(t_end)
    knots_t, knots_s = [t_end], [1.0]
    for share, hold in corner_end(unwind, other_way):
        knots_t.append(knots_t[-1] + max(abs(share - knots_s[-1]) * change_s, 0.2))
        knots_s.append(share)
        knots_t.append(knots_t[-1] + hold)
        knots_s.append(share)
    kt, ks = np.array(knots_t), np.array(knots_s)

    def target(t):
        if t <= t_end:
            return plan.target(t)
        share = float(np.interp(t, kt, ks))
        return (
            None if r_end is None else r_end * share,
            None if d_end is None else d_end * share,
            v_end,
        )

    return DrivePlan(duration_s=float(kt[-1]), settle_s=plan.settle_s, target=target)


def _simulate(plan: DrivePlan, mu: float, out_hz: float = 100.0) -> SimResult:
    from scipy.integrate import solve_ivp
    from vehiclemodels.init_std import init_std
    from vehiclemodels.utils import tire_model
    from vehiclemodels.vehicle_dynamics_std import vehicle_dynamics_std

    p = _params(mu)
    v0 = plan.target(0.0)[2]
    x0 = init_std([0.0, 0.0, 0.0, v0, 0.0, 0.0, 0.0], p)

    def control(t, x):
        r_t, d_t, v_t = plan.target(t)
        if d_t is not None:
            steer_rate = 8.0 * (d_t - x[2])
        else:  # a driver holding the yaw rate: the steer follows the yaw-rate error (integral)
            steer_rate = 0.6 * (r_t - x[5])
        return [steer_rate, 2.0 * (v_t - x[3])]

    def f(t, x):
        return vehicle_dynamics_std(list(x), control(t, x), p)

    t_out = np.arange(0.0, plan.duration_s + 1e-9, 1.0 / out_hz)
    sol = solve_ivp(
        f, (0.0, t_out[-1]), x0, t_eval=t_out, method="LSODA", rtol=1e-7, atol=1e-9, max_step=0.01
    )
    if sol.status != 0:  # pragma: no cover
        raise RuntimeError(f"CommonRoad integration failed: {sol.message}")
    X, Y, delta, v, psi, r, beta = (sol.y[k] for k in range(7))
    u_b, v_b = v * np.cos(beta), v * np.sin(beta)
    ve, vn = v * np.cos(beta + psi), v * np.sin(beta + psi)
    ae, an = np.gradient(ve, t_out), np.gradient(vn, t_out)
    ax = ae * np.cos(psi) + an * np.sin(psi)
    ay = -ae * np.sin(psi) + an * np.cos(psi)
    n = t_out.size
    wb = p.a + p.b
    fz_f, fz_r = p.m * G_CR * p.b / wb, p.m * G_CR * p.a / wb
    a_f = np.arctan2(v * np.sin(beta) + r * p.a, v * np.cos(beta)) - delta
    a_r = np.arctan2(v * np.sin(beta) - r * p.b, v * np.cos(beta))
    f_f = np.array([tire_model.formula_lateral(a, 0.0, fz_f, p.tire)[0] for a in a_f])
    f_r = np.array([tire_model.formula_lateral(a, 0.0, fz_r, p.tire)[0] for a in a_r])
    body = pd.DataFrame(
        {
            "t_s": t_out,
            "x_m": X,
            "y_m": Y,
            "yaw_rad": psi,
            "u_mps": u_b,
            "v_mps": v_b,
            "yaw_rate_rps": r,
            "ax_mps2": ax,
            "ay_mps2": ay,
            "steer_rad": delta,
            "fx_N": np.zeros(n),
        }
    )
    rows = []
    for name in WHEEL_NAMES:
        front = name.startswith("front")
        rows.append(
            pd.DataFrame(
                {
                    "t_s": t_out,
                    "wheel": name,
                    "mu_true": np.full(n, float(mu)),
                    "mu_road": np.full(n, float(mu)),
                    "camber_rad": np.zeros(n),
                    "slip_angle_rad": -(a_f if front else a_r),
                    "load_N": np.full(n, (fz_f if front else fz_r) / 2.0),
                    "force_N": (f_f if front else f_r) / 2.0,
                    "speed_mps": v,
                }
            )
        )
    wheels = pd.concat(rows, ignore_index=True).sort_values(["t_s", "wheel"], kind="stable")
    wheels["wheel"] = pd.Categorical(wheels["wheel"], categories=list(WHEEL_NAMES))
    params = SimParams.from_vehicle(commonroad_vehicle())
    return SimResult(
        body=body,
        wheels=wheels.reset_index(drop=True),
        params=params,
        meta={"output_hz": out_hz, "model": "CommonRoad vehicle_dynamics_std, vehicle 2"},
    )


def _mb_wheels(p, x: np.ndarray) -> dict:
    """Per-wheel loads, slips, camber and combined-slip forces of CommonRoad's multi-body model
    at the states *x* (29 × n), as ``vehicle_dynamics_mb`` computes them (its own tyre
    functions, its SAE-like axes).
    """
    from vehiclemodels.utils import tire_model as tm

    roll, v_y, r, delta, u = x[6], x[10], x[5], x[2], x[3]
    out = {}
    geo = {
        "front_left": (13, 16, 14, 0.5 * p.T_f, p.a, p.D_f, p.E_f, 1.0, 23),
        "front_right": (13, 16, 14, -0.5 * p.T_f, p.a, p.D_f, p.E_f, -1.0, 24),
        "rear_left": (18, 21, 19, 0.5 * p.T_r, -p.b, p.D_r, p.E_r, 1.0, 25),
        "rear_right": (18, 21, 19, -0.5 * p.T_r, -p.b, p.D_r, p.E_r, -1.0, 26),
    }
    for name, (i_roll, i_z, i_rr, half_t, lx, d_k, e_k, side, i_w) in geo.items():
        fz = (x[i_z] + p.R_w * (np.cos(x[i_roll]) - 1) - half_t * np.sin(x[i_roll])) * p.K_zt
        front = name.startswith("front")
        vx_w = u + half_t * r
        alpha = np.arctan((v_y + lx * r - x[i_rr] * (p.R_w - x[i_z])) / vx_w)
        if front:
            u_w = vx_w * np.cos(delta) + (v_y + p.a * r) * np.sin(delta)
            alpha = alpha - delta
        else:
            u_w = vx_w
        kappa = 1.0 - p.R_w * x[i_w] / np.maximum(u_w, 1e-3)
        z_s = ((p.h_s - p.R_w + x[i_z] - x[11]) / np.cos(roll) - p.h_s + p.R_w + lx * x[8]
               + side * 0.5 * (roll - x[i_roll]) * (p.T_f if front else p.T_r))  # fmt: skip
        gamma = roll + side * (d_k * z_s + e_k * z_s**2)
        fy = np.empty(u.size)
        mu_y = np.empty(u.size)
        for k in range(u.size):  # CommonRoad's tyre functions are scalar (math module)
            f0y, mu_y[k] = tm.formula_lateral(alpha[k], gamma[k], fz[k], p.tire)
            fy[k] = tm.formula_lateral_comb(kappa[k], alpha[k], gamma[k], mu_y[k], fz[k], f0y,
                                            p.tire)  # fmt: skip
        out[name] = {"load": fz, "alpha": alpha, "gamma": gamma, "fy": fy, "mu": mu_y}
    return out


def _simulate_mb(plan: DrivePlan, mu: float, out_hz: float = 100.0) -> SimResult:
    from scipy.integrate import solve_ivp
    from vehiclemodels.init_mb import init_mb
    from vehiclemodels.vehicle_dynamics_mb import vehicle_dynamics_mb

    p = _params(mu)
    v0 = plan.target(0.0)[2]
    x0 = init_mb([0.0, 0.0, 0.0, v0, 0.0, 0.0, 0.0], p)

    def control(t, x):  # in ISO axes, returned in CommonRoad's (δ, r flip sign)
        r_t, d_t, v_t = plan.target(t)
        if d_t is not None:
            steer_rate = 8.0 * (d_t + x[2])
        else:  # a driver holding the yaw rate (integral action on the steer)
            steer_rate = 0.6 * (r_t + x[5])
        return [-steer_rate, 2.0 * (v_t - x[3])]

    def f(t, x):
        return vehicle_dynamics_mb(list(x), control(t, x), p)

    def spun(t, x):  # the car has left the test: body slip beyond 15° (a spin)
        return 0.26 - abs(math.atan2(x[10], max(x[3], 0.1)))

    lift_load = 0.05 * p.m * G_CR / 4.0

    def lifts(t, x):  # a wheel leaves the road (the model's tyres do not: its loads go < 0)
        return (
            min(
                (x[iz] + p.R_w * (math.cos(x[ir]) - 1) - s * 0.5 * tr * math.sin(x[ir])) * p.K_zt
                for iz, ir, tr in ((16, 13, p.T_f), (21, 18, p.T_r))
                for s in (1.0, -1.0)
            )
            - lift_load
        )

    spun.terminal = lifts.terminal = True  # type: ignore[attr-defined]  # solve_ivp's event flag
    t_out = np.arange(0.0, plan.duration_s + 1e-9, 1.0 / out_hz)
    sol = solve_ivp(
        f, (0.0, t_out[-1]), x0, t_eval=t_out, method="LSODA", rtol=1e-6, atol=1e-8,
        max_step=0.01, events=(spun, lifts),
    )  # fmt: skip
    if sol.status == -1:  # pragma: no cover
        raise RuntimeError(f"CommonRoad integration failed: {sol.message}")
    x, t_out = sol.y, sol.t  # up to a spin or a lifting wheel, if the plan ends in one
    psi, r, delta, u, v_y = -x[4], -x[5], -x[2], x[3], -x[10]
    ve = u * np.cos(psi) - v_y * np.sin(psi)
    vn = u * np.sin(psi) + v_y * np.cos(psi)
    ae, an = np.gradient(ve, t_out), np.gradient(vn, t_out)
    n = t_out.size
    body = pd.DataFrame(
        {
            "t_s": t_out,
            "x_m": x[0],
            "y_m": -x[1],
            "yaw_rad": psi,
            "u_mps": u,
            "v_mps": v_y,
            "yaw_rate_rps": r,
            "ax_mps2": ae * np.cos(psi) + an * np.sin(psi),
            "ay_mps2": -ae * np.sin(psi) + an * np.cos(psi),
            "steer_rad": delta,
            "fx_N": np.zeros(n),
        }
    )
    w = _mb_wheels(p, x)
    speed = np.hypot(u, v_y)
    rows = [
        pd.DataFrame(
            {
                "t_s": t_out,
                "wheel": name,
                "mu_true": w[name]["mu"],
                "mu_road": np.full(n, float(mu)),
                "camber_rad": w[name]["gamma"],
                "slip_angle_rad": w[name]["alpha"],
                "load_N": w[name]["load"],
                "force_N": -w[name]["fy"],
                "speed_mps": speed,
            }
        )
        for name in WHEEL_NAMES
    ]
    wheels = pd.concat(rows, ignore_index=True).sort_values(["t_s", "wheel"], kind="stable")
    wheels["wheel"] = pd.Categorical(wheels["wheel"], categories=list(WHEEL_NAMES))
    return SimResult(
        body=body,
        wheels=wheels.reset_index(drop=True),
        params=SimParams.from_vehicle(commonroad_vehicle()),
        meta={"output_hz": out_hz, "model": "CommonRoad vehicle_dynamics_mb, vehicle 2"},
    )


def commonroad_result(plan: DrivePlan, mu: float, *, model: str = "std") -> SimResult:
    """Simulate *plan* with one of CommonRoad's models (the truth per wheel as it computes it).

    Parameters
    ----------
    plan : DrivePlan
        :func:`cr_circle`, :func:`cr_constant_radius` or :func:`cr_ramp_steer`.
    mu : float
        Road friction [-].
    model : {"std", "mb"}
        The single-track drift model or the multi-body model.

    Returns
    -------
    SimResult
        The drive (its ``params`` describe the vehicle as :func:`commonroad_vehicle` does).
    """
    simulate = {"std": _simulate, "mb": _simulate_mb}.get(model)
    if simulate is None:
        raise ValueError(f"model={model!r}: use 'std' or 'mb'")
    return simulate(plan, mu)


def commonroad_drive(
    plan: DrivePlan,
    mu: float,
    *,
    model: str = "std",
    receiver: str = "white-0.3",
    seed: int = 0,
    steer_scale_error: float = 0.03,
    **where,
) -> Drive:
    """Simulate *plan* with one of CommonRoad's models on a road of friction *mu* and record it
    with the emulated compass and steering channel (the truth per wheel as the model computes
    it).

    Parameters
    ----------
    plan : DrivePlan
        :func:`cr_circle`, :func:`cr_constant_radius` or :func:`cr_ramp_steer`.
    mu : float
        Road friction (the tyre's lateral peak coefficient at zero camber) [-].
    model : {"std", "mb"}
        The single-track drift model ``vehicle_dynamics_std`` or the multi-body model
        ``vehicle_dynamics_mb``.
    receiver : str
        Receiver preset.
    seed : int
        Random seed of the receiver and steering noise.
    steer_scale_error : float
        Scale error of the steering channel [-].
    **where
        ``origin`` and ``start`` of :func:`~gripsense.sim.drives.record_drive` (where and when
        the drive is).

    Returns
    -------
    Drive
        The recording and the truth.
    """
    return record_drive(
        commonroad_result(plan, mu, model=model), commonroad_vehicle(), plan.settle_s,
        receiver=receiver, seed=seed, steer_scale_error=steer_scale_error, **where,
    )  # fmt: skip
