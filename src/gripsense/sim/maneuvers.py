"""Manoeuvres: controller settings, duration and initial state for :func:`simulate`.

Each builder returns a :class:`Maneuver`; :func:`run` simulates it. Speeds in m/s, angles in
rad (the ``*_kmh`` / ``*_deg`` arguments of the scenario files are converted at the edge).
Thesis experiments (seed 000): 2016 — 20–40 km/h × fixed steering 5–35° (ch. 7);
2018 — 20–50 km/h × radius 20–40 m, 5 laps each (ch. 11).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gripsense.sim import control as C
from gripsense.sim.integrate import simulate
from gripsense.sim.vehicle import SimParams, SimResult

__all__ = [
    "Maneuver",
    "braking",
    "circle",
    "constant_radius",
    "corner_end",
    "everyday",
    "fixed_steer",
    "ramp_steer",
    "run",
    "sine_with_dwell",
    "slalom",
    "thesis_grid_2016",
    "thesis_grid_2018",
    "with_corner_exits",
]


@dataclass
class Maneuver:
    """A manoeuvre ready to simulate.

    Attributes
    ----------
    name : str
        Label.
    controller : numpy.ndarray
        Packed controller settings of the integrator.
    duration_s : float
        Simulated time [s].
    initial : dict
        Initial state (speed, position, heading).
    steer_table : tuple of numpy.ndarray, optional
        Time [s] and road-wheel angle [rad] of an open-loop steer input.
    settle_s : float
        Initial transient, not part of the intended test [s].
    info : dict
        Parameters of the manoeuvre, for the case table.
    """

    name: str
    controller: np.ndarray
    duration_s: float
    initial: dict
    steer_table: tuple[np.ndarray, np.ndarray] | None = None
    settle_s: float = 0.0  # initial transient, not part of the intended test
    info: dict = field(default_factory=dict)


def _ctrl(**kw) -> np.ndarray:
    c = np.zeros(C.N_CTRL)
    c[C.C_KP] = 3000.0  # speed controller gain [N per m/s]
    c[C.C_FXMAX] = 6000.0  # [N]
    c[C.C_LOOK] = 6.0  # pure-pursuit look-ahead [m]
    for k, v in kw.items():
        c[getattr(C, k)] = v
    return c


def circle(
    speed_mps: float,
    radius_m: float,
    *,
    laps: float = 5.0,
    left: bool = True,
    lead_s: float = 6.0,
    settle_s: float = 6.0,
    params: SimParams | None = None,
) -> Maneuver:
    """Steady circle at constant speed: a straight lead-in of *lead_s* (which also lets the
    heading offset be calibrated), then the circle, followed with pure pursuit.
    """
    sgn = 1.0 if left else -1.0
    lap_s = 2 * np.pi * radius_m / speed_mps
    look = float(np.clip(0.6 * speed_mps, 4.0, 0.5 * radius_m))
    x_in = speed_mps * lead_s  # where the circle starts (tangent to the lead-in line)
    ctrl = _ctrl(
        C_STEER_MODE=C.STEER_CIRCLE,
        C_CX=x_in,
        C_CY=sgn * radius_m,
        C_R=radius_m,
        C_DIR=sgn,
        C_LOOK=look,
        C_SPEED_MODE=C.SPEED_HOLD,
        C_V=speed_mps,
        C_T_LEAD=lead_s,
    )
    init = {"u_mps": speed_mps}
    if params is not None:  # rear axle on the line
        init["x_m"] = params.l_r
    return Maneuver(
        f"circle v={speed_mps * 3.6:.0f}km/h R={radius_m:.0f}m",
        ctrl,
        lead_s + settle_s + laps * lap_s,
        init,
        settle_s=lead_s + settle_s,
        info={
            "maneuver": "circle",
            "speed_mps": speed_mps,
            "radius_m": radius_m,
            "laps": laps,
            "left": left,
            "lead_s": lead_s,
        },
    )


def constant_radius(
    radius_m: float,
    speed_start_mps: float,
    speed_end_mps: float,
    *,
    accel_mps2: float = 0.1,
    lead_s: float = 6.0,
    settle_s: float = 6.0,
    params: SimParams | None = None,
) -> Maneuver:
    """ISO 4138 steady-state circular driving, constant-radius method with the speed rising:
    a straight lead-in, the circle at *speed_start_mps*, then the speed raised slowly
    (quasi-steady, *accel_mps2*) to *speed_end_mps* — the axles climb their curves to the limit
    (beyond it the car leaves the circle).

    Parameters
    ----------
    radius_m : float
        Radius [m].
    speed_start_mps, speed_end_mps : float
        Speed at the start and the end of the sweep [m/s].
    accel_mps2 : float
        Speed increase per second [m/s²] (ISO 4138: slow enough to be quasi-steady).
    lead_s : float
        Straight lead-in (heading calibration) [s].
    settle_s : float
        Time on the circle before the speed rises [s].
    params : SimParams, optional
        The vehicle (puts the rear axle on the lead-in line).

    Returns
    -------
    Maneuver
        The manoeuvre.
    """
    m = circle(speed_start_mps, radius_m, laps=0.0, lead_s=lead_s, settle_s=settle_s,
               params=params)  # fmt: skip
    m.controller[C.C_SPEED_MODE] = C.SPEED_RAMP
    m.controller[C.C_ACCEL] = accel_mps2
    m.controller[C.C_V_END] = max(speed_end_mps, speed_start_mps)
    m.controller[C.C_T_BRAKE] = lead_s + settle_s
    sweep = max(speed_end_mps - speed_start_mps, 0.0) / accel_mps2
    m.duration_s = lead_s + settle_s + sweep
    m.name = (
        f"constant radius R={radius_m:.0f}m {speed_start_mps * 3.6:.0f}->"
        f"{speed_end_mps * 3.6:.0f}km/h"
    )
    m.info = {
        "maneuver": "constant_radius",
        "radius_m": radius_m,
        "speed_start_mps": speed_start_mps,
        "speed_end_mps": speed_end_mps,
        "accel_mps2": accel_mps2,
    }
    return m


def everyday(
    speed_mps: float,
    *,
    seed: int = 0,
    curves: int = 12,
    hold_s: float = 8.0,
    max_steer_deg: float = 2.2,
    lead_s: float = 6.0,
) -> Maneuver:
    """Everyday driving: after a straight, a sequence of steady curves of random direction and
    road-wheel angle (0.4 to *max_steer_deg*), each held for *hold_s* and entered over 2 s —
    the moderate cornering from which ``gripsense calibrate`` learns the tyres' stiffness.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    seed : int
        Random seed of the curves.
    curves : int
        Number of curves.
    hold_s : float
        Time in each curve [s].
    max_steer_deg : float
        Largest road-wheel angle [deg].
    lead_s : float
        Straight at the start (heading calibration) [s].

    Returns
    -------
    Maneuver
        The manoeuvre.
    """
    rng = np.random.default_rng(seed)
    levels = rng.uniform(0.4, max_steer_deg, curves) * rng.choice([-1.0, 1.0], curves)
    t, v = [0.0, lead_s], [0.0, 0.0]
    for lv in np.deg2rad(levels):
        t += [t[-1] + 2.0, t[-1] + 2.0 + hold_s]
        v += [lv, lv]
    t.append(t[-1] + 2.0)
    v.append(0.0)
    ctrl = _ctrl(C_STEER_MODE=C.STEER_TABLE, C_SPEED_MODE=C.SPEED_HOLD, C_V=speed_mps)
    return Maneuver(
        f"everyday v={speed_mps * 3.6:.0f}km/h seed={seed} {curves}x{hold_s:g}s "
        f"≤{max_steer_deg:.1f}deg",
        ctrl,
        t[-1],
        {"u_mps": speed_mps},
        (np.array(t), np.array(v)),
        lead_s,
        {
            "maneuver": "everyday",
            "speed_mps": speed_mps,
            "seed": seed,
            "curves": curves,
            "hold_s": hold_s,
            "max_steer_deg": max_steer_deg,
        },
    )


def corner_end(unwind: float = 0.4, other_way: float = 0.7) -> tuple[tuple[float, float], ...]:
    """The end a driver gives a corner, as targets over the corner's last and how long each is
    held: the wheel unwound by *unwind* (2 s), turned back in (3 s), an S-bend into a corner the
    other way at *other_way* (5 s), the exit to a straight (3 s).

    Parameters
    ----------
    unwind : float
        Share of the corner unwound in the reversal [-].
    other_way : float
        The opposite corner over the last one [-].

    Returns
    -------
    tuple of (float, float)
        (target over the corner's last [-], hold [s]) in order.
    """
    return ((1.0 - unwind, 2.0), (1.0, 3.0), (-other_way, 5.0), (0.0, 3.0))


def with_corner_exits(
    m: Maneuver,
    result: SimResult,
    *,
    unwind: float = 0.4,
    rate_rad_s: float = np.deg2rad(4.0),
    other_way: float = 0.7,
) -> Maneuver:
    """A simulated manoeuvre replayed open-loop with the corner's end a driver adds: at its last
    steer a steering reversal (the wheel unwound by *unwind* of its angle, held 2 s, turned back
    in and held 3 s), an S-bend into a corner the other way at *other_way* of the angle (held
    5 s), the corner exit to the straight and 3 s straight. The steering rate of each change is
    *rate_rad_s* (road wheel); the speed is held at the manoeuvre's last.

    Parameters
    ----------
    m : Maneuver
        The manoeuvre as simulated (closed- or open-loop).
    result : SimResult
        Its simulation: the steer history replayed.
    unwind : float
        Share of the angle unwound in the reversal [-].
    rate_rad_s : float
        Road-wheel steering rate of the changes [rad/s].
    other_way : float
        The opposite corner's angle over the last one [-].

    Returns
    -------
    Maneuver
        The open-loop manoeuvre (its first part the original's steer history).
    """
    b = result.body
    t = b["t_s"].to_numpy(float)
    d = b["steer_rad"].to_numpy(float)
    d_end = float(np.median(d[t >= t[-1] - 1.0]))
    tt, dd = [float(t[-1])], [d_end]
    for share, hold in corner_end(unwind, other_way):
        target = share * d_end
        tt.append(tt[-1] + max(abs(target - dd[-1]) / rate_rad_s, 0.1))
        dd.append(target)
        tt.append(tt[-1] + hold)
        dd.append(target)
    ctrl = m.controller.copy()
    ctrl[C.C_STEER_MODE] = C.STEER_TABLE
    if int(ctrl[C.C_SPEED_MODE]) == C.SPEED_RAMP and ctrl[C.C_V_END] <= 0.0:
        ctrl[C.C_V_END] = float(b["u_mps"].iloc[-1])
    return Maneuver(
        m.name + " + corner exits",
        ctrl,
        tt[-1],
        m.initial,
        (np.concatenate([t, tt[1:]]), np.concatenate([d, dd[1:]])),
        m.settle_s,
        {**m.info, "corner_exits": True},
    )


def sine_with_dwell(
    speed_mps: float,
    *,
    amplitude_rad: float = np.deg2rad(4.0),
    frequency_hz: float = 0.7,
    dwell_s: float = 0.5,
    lead_s: float = 6.0,
    after_s: float = 4.0,
) -> Maneuver:
    """Sine with dwell (the transient of FMVSS 126 / UN R140, ISO 3888-like in its demand): a
    straight, one 0.7 Hz sine period of the road-wheel angle with a dwell at the second peak,
    then straight again.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    amplitude_rad : float
        Road-wheel angle amplitude [rad].
    frequency_hz : float
        Frequency of the sine [Hz].
    dwell_s : float
        Dwell at the second (opposite) peak [s].
    lead_s : float
        Straight before the manoeuvre (heading calibration) [s].
    after_s : float
        Straight after it [s].

    Returns
    -------
    Maneuver
        The manoeuvre.
    """
    period = 1.0 / frequency_hz
    t1 = np.linspace(0.0, 0.75 * period, 76)
    t3 = np.linspace(0.75 * period, period, 26)
    t = np.concatenate(
        [[0.0], lead_s + t1, lead_s + dwell_s + t3, [lead_s + dwell_s + period + after_s]]
    )
    v = np.concatenate(
        [
            [0.0],
            amplitude_rad * np.sin(2 * np.pi * frequency_hz * t1),
            amplitude_rad * np.sin(2 * np.pi * frequency_hz * t3),
            [0.0],
        ]
    )
    ctrl = _ctrl(C_STEER_MODE=C.STEER_TABLE, C_SPEED_MODE=C.SPEED_HOLD, C_V=speed_mps)
    return Maneuver(
        f"sine with dwell v={speed_mps * 3.6:.0f}km/h {np.rad2deg(amplitude_rad):.1f}deg",
        ctrl,
        float(t[-1]),
        {"u_mps": speed_mps},
        (t, v),
        lead_s,
        {"maneuver": "sine_with_dwell", "speed_mps": speed_mps, "amplitude_rad": amplitude_rad},
    )


def fixed_steer(
    speed_mps: float, steer_rad: float, *, duration_s: float = 30.0, settle_s: float = 6.0
) -> Maneuver:
    """Constant road-wheel angle at constant speed (the thesis's 2016 experiments)."""
    ctrl = _ctrl(C_STEER_MODE=C.STEER_TABLE, C_SPEED_MODE=C.SPEED_HOLD, C_V=speed_mps)
    table = (np.array([0.0, 1.0]), np.array([steer_rad, steer_rad]))
    return Maneuver(
        f"steer {np.rad2deg(steer_rad):.0f}° v={speed_mps * 3.6:.0f}km/h",
        ctrl,
        settle_s + duration_s,
        {"u_mps": speed_mps},
        table,
        settle_s,
        {"maneuver": "fixed_steer", "speed_mps": speed_mps, "steer_rad": steer_rad},
    )


def ramp_steer(
    speed_mps: float,
    *,
    rate_rad_s: float = np.deg2rad(1.0),
    max_steer_rad: float = np.deg2rad(25.0),
    hold_s: float = 3.0,
) -> Maneuver:
    """ISO 4138 ramp steer: straight for *hold_s*, then the road-wheel angle ramps up slowly at
    constant speed to *max_steer_rad* — through the linear range to the limit.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    rate_rad_s : float
        Road-wheel steering rate [rad/s].
    max_steer_rad : float
        Road-wheel angle at the end [rad].
    hold_s : float
        Straight before the ramp (heading calibration) [s].

    Returns
    -------
    Maneuver
        The manoeuvre.
    """
    t_end = hold_s + max_steer_rad / rate_rad_s
    table = (np.array([0.0, hold_s, t_end]), np.array([0.0, 0.0, max_steer_rad]))
    ctrl = _ctrl(
        C_STEER_MODE=C.STEER_TABLE, C_SPEED_MODE=C.SPEED_HOLD, C_V=speed_mps, C_FXMAX=8000.0
    )
    return Maneuver(
        f"ramp steer v={speed_mps * 3.6:.0f}km/h {np.rad2deg(rate_rad_s):.1f}deg/s to "
        f"{np.rad2deg(max_steer_rad):.1f}deg",
        ctrl,
        t_end,
        {"u_mps": speed_mps},
        table,
        hold_s,
        {
            "maneuver": "ramp_steer",
            "speed_mps": speed_mps,
            "rate_rad_s": rate_rad_s,
            "max_steer_rad": max_steer_rad,
        },
    )


def slalom(
    speed_mps: float,
    *,
    amplitude_rad: float = np.deg2rad(3.0),
    period_s: float = 3.0,
    cycles: int = 5,
) -> Maneuver:
    """Sinusoidal steering at constant speed.

    Parameters
    ----------
    speed_mps : float
        Speed [m/s].
    amplitude_rad : float
        Road-wheel angle amplitude [rad].
    period_s : float
        Period of the sine [s].
    cycles : int
        Number of periods.

    Returns
    -------
    Maneuver
        The manoeuvre.
    """
    t = np.linspace(0.0, cycles * period_s, 50 * cycles + 1)
    table = (t, amplitude_rad * np.sin(2 * np.pi * t / period_s))
    ctrl = _ctrl(C_STEER_MODE=C.STEER_TABLE, C_SPEED_MODE=C.SPEED_HOLD, C_V=speed_mps)
    return Maneuver(
        f"slalom v={speed_mps * 3.6:.0f}km/h {np.rad2deg(amplitude_rad):.1f}deg T={period_s:g}s "
        f"x{cycles}",
        ctrl,
        cycles * period_s,
        {"u_mps": speed_mps},
        table,
        0.0,
        {
            "maneuver": "slalom",
            "speed_mps": speed_mps,
            "amplitude_rad": amplitude_rad,
            "period_s": period_s,
            "cycles": cycles,
        },
    )


def braking(speed_mps: float, *, cruise_s: float = 3.0) -> Maneuver:
    """Straight line at speed, then all wheels locked until standstill (thesis ch. 8)."""
    ctrl = _ctrl(
        C_STEER_MODE=C.STEER_LINE,
        C_R=0.0,
        C_LOOK=8.0,
        C_SPEED_MODE=C.SPEED_BRAKE_LOCK,
        C_V=speed_mps,
        C_T_BRAKE=cruise_s,
    )
    dur = cruise_s + speed_mps / (0.1 * 9.81) + 2.0  # enough even for μ = 0.1
    return Maneuver(
        f"locked braking from {speed_mps * 3.6:.0f}km/h",
        ctrl,
        dur,
        {"u_mps": speed_mps},
        None,
        0.0,
        {"maneuver": "braking", "speed_mps": speed_mps, "brake_at_s": cruise_s},
    )


def thesis_grid_2018(
    params: SimParams | None = None,
    *,
    speeds_kmh=(20, 30, 40, 50),
    radii_m=(20, 25, 30, 35, 40),
    laps: float = 5.0,
) -> list[Maneuver]:
    """The 2018 experiments: circles at 20–50 km/h × radius 20–40 m, 5 laps each."""
    return [circle(v / 3.6, r, laps=laps, params=params) for v in speeds_kmh for r in radii_m]


def thesis_grid_2016(
    *, speeds_kmh=(20, 30, 40), steer_deg=(5, 10, 15, 20, 25, 30, 35), duration_s: float = 30.0
) -> list[Maneuver]:
    """The 2016 experiments: 20–40 km/h × fixed steering 5–35° (road-wheel angle here)."""
    return [
        fixed_steer(v / 3.6, np.deg2rad(d), duration_s=duration_s)
        for v in speeds_kmh
        for d in steer_deg
    ]


def run(
    params: SimParams,
    m: Maneuver,
    *,
    mu: float = 0.9,
    patches=None,
    dt: float = 0.002,
    output_hz: float = 100.0,
) -> SimResult:
    """Simulate a manoeuvre."""
    res = simulate(
        params,
        m.controller,
        m.duration_s,
        mu=mu,
        patches=patches,
        initial=m.initial,
        steer_table=m.steer_table,
        dt=dt,
        output_hz=output_hz,
    )
    res.meta.update(m.info, name=m.name, settle_s=m.settle_s, mu_road=mu)
    return res
