"""The steering-torque channel of a simulated drive: the truth tyres' aligning moments, the
seed-003 steering balance and a column torque sensor.

Per front wheel the aligning moment of the truth tyre (``docs/physics.md`` §16.4):

* a tyre from a ``.tir`` file: the file's tabulated M_z(α, Fz, γ), scaled to the road by the
  force's similarity (:meth:`gripsense.sim.tyres.SimTyre.aligning`), and by F_ss/F_0 where a
  driven wheel's friction circle reduces its lateral force;
* the brush tyre (parabolic pressure): the closed form of §16.1 at the utilisation of the
  steady-state force, u = |F_ss|/(μ F_z), with the wheel's own contact half-length;

then delayed like the force, over the relaxation length (a first-order lag of time constant
σ/|U|). A drive of another vehicle model (CommonRoad's) gets an aligning moment added: a
``.tir`` file's own trail at the wheel's utilisation and load (:meth:`gripsense.sim.tyres.
SimTyre.trail_by_utilisation`), M_z = −t F_y.

The steering moment M_s = Σ (t_c F_y − M_z) and seed 003's eq. (3) with the assist, the
kingpins' inertia and damping and a Dahl friction give the column torque
(:func:`gripsense.physics.steering_balance.column_torque`); the sensor adds its scale error,
offset and white noise.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from numba import njit

from gripsense.config.vehicle import SteeringSystem
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.physics.steering_balance import column_torque, dahl_friction, steering_moment
from gripsense.sim.tyres import SimTyre
from gripsense.sim.vehicle import SimResult

__all__ = ["aligning_moments", "emulate_torque"]

FRONT = ("front_left", "front_right")


@njit(cache=True)
def _lag_loop(x: np.ndarray, k: np.ndarray) -> np.ndarray:  # pragma: no cover
    y = np.empty_like(x)
    y[0] = x[0]
    for i in range(1, x.size):
        y[i] = y[i - 1] + k[i] * (x[i] - y[i - 1])
    return y


def _lag(x: np.ndarray, t: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """First-order lag y' = (x − y)/τ, exact for x held over each step (τ ≤ 0: no lag)."""
    if x.size == 0:
        return x
    dt = np.diff(t, prepend=t[0])
    tau = np.broadcast_to(tau, x.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(tau > 0, 1.0 - np.exp(-dt / np.where(tau > 0, tau, 1.0)), 1.0)
    return _lag_loop(np.ascontiguousarray(x, float), np.ascontiguousarray(k, float))


def aligning_moments(
    result: SimResult, wheels: tuple[str, ...] = FRONT, *, trail_tyre: SimTyre | None = None
) -> pd.DataFrame:
    """Aligning moment of each truth tyre along a simulated drive.

    Parameters
    ----------
    result : SimResult
        A simulated drive (gripsense's simulator, or another model's wheel table).
    wheels : tuple of str
        The wheels (default the front ones).
    trail_tyre : SimTyre, optional
        Add this ``.tir`` tyre's trail at each wheel's utilisation and load instead of the
        truth tyre's own moment (for a vehicle model without an aligning moment).

    Returns
    -------
    pandas.DataFrame
        Per output time (rows) and wheel (columns): M_z [N m], ISO (negative for a positive
        force below the peak).

    Raises
    ------
    InputError
        When the truth tyre has no aligning moment (a PAC89 file, a quartic-pressure brush).
    """
    p = result.params
    w = result.wheels
    t = result.body["t_s"].to_numpy(float)
    out = {}
    for name in wheels:
        axle = name.split("_")[0]
        r = w[w["wheel"] == name]
        alpha = r["slip_angle_rad"].to_numpy(float)
        fz = r["load_N"].to_numpy(float)
        f_ss = r["force_ss_N" if "force_ss_N" in r else "force_N"].to_numpy(float)
        sim_tyre = p.sim_tyres.get(axle)
        if trail_tyre is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                u = np.abs(f_ss) / (r["mu_true"].to_numpy(float) * fz)
            u = np.where(fz > 0, np.nan_to_num(u, nan=1.0), 1.0)
            mz_ss = -trail_tyre.trail_by_utilisation(u, fz) * f_ss
        elif sim_tyre is not None:
            if sim_tyre.mz is None:
                raise InputError(
                    f"{sim_tyre.name}: the truth tyre has no aligning moment; a steering-torque "
                    "channel needs a .tir tyre or the brush tyre"
                )
            mz0, f0 = sim_tyre.aligning(
                alpha, fz, r["camber_rad"].to_numpy(float), r["mu_road"].to_numpy(float)
            )
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(np.abs(f0) > 1.0, np.clip(f_ss / f0, 0.0, 1.0), 1.0)
            mz_ss = mz0 * scale
        else:
            tyre = p.tyres[axle]
            if tyre.pressure != "parabolic":
                raise InputError(
                    "the brush tyre's aligning moment is written for a parabolic pressure; "
                    'a steering-torque channel needs pressure = "parabolic" or a .tir tyre'
                )
            mu = r["mu_true"].to_numpy(float)
            with np.errstate(divide="ignore", invalid="ignore"):
                u = np.clip(np.abs(f_ss) / (mu * fz), 0.0, 1.0)
            u = np.where(fz > 0, u, 1.0)
            lam = 1.0 - (1.0 - u) ** (1.0 / 3.0)
            half = 0.5 * tyre.contact_length(np.maximum(fz, 0.0) / G0)
            trail = half * (1.0 - lam) ** 3 / (3.0 - 3.0 * lam + lam**2)
            mz_ss = -trail * f_ss
        sigma = p.relaxation_length_m
        speed = np.abs(r["speed_mps"].to_numpy(float))
        tau = np.where(speed > 0.5, sigma / np.maximum(speed, 0.5), 0.0) if sigma > 0 else 0.0 * t
        out[name] = _lag(mz_ss, t, tau)
    return pd.DataFrame(out, index=pd.Index(t, name="t_s"))


def emulate_torque(
    result: SimResult,
    steering: SteeringSystem,
    ratio: float,
    *,
    rate_hz: float = 100.0,
    noise_Nm: float = 0.05,
    scale_error: float = 0.0,
    offset_Nm: float = 0.0,
    assist_channel: bool = False,
    seed: int = 0,
    trail_tyre: SimTyre | None = None,
) -> pd.DataFrame:
    """The column torque sensor of a simulated drive (and the assist torque, if asked).

    Parameters
    ----------
    result : SimResult
        A drive of gripsense's simulator.
    steering : SteeringSystem
        The truth steering system (caster trail, kingpin inertia and damping, friction at the
        steering wheel, assist gain).
    ratio : float
        Steering ratio [-].
    rate_hz : float
        Sample rate of the channel [Hz] (the simulator output rate must be a multiple).
    noise_Nm : float
        White noise of the sensor [N m], 1σ.
    scale_error : float
        Relative scale error: the channel reads (1 + scale_error) × the torque [-].
    offset_Nm : float
        Zero offset of the sensor [N m].
    assist_channel : bool
        Also write the assist torque the power steering reports (``assist_Nm``, at the steering
        wheel; noise-free).
    seed : int
        Random seed.
    trail_tyre : SimTyre, optional
        The aligning moment added to another vehicle model's forces (:func:`aligning_moments`).

    Returns
    -------
    pandas.DataFrame
        ``t_s`` and ``torque_Nm`` (ISO: positive steers left), ``assist_Nm`` when asked; the
        columns :func:`gripsense.io.sensors.steer.read_steer_csv` maps by themselves.
    """
    b = result.body
    t = b["t_s"].to_numpy(float)
    mz = aligning_moments(result, trail_tyre=trail_tyre)
    w = result.wheels
    m_s = np.zeros(t.size)
    for name in FRONT:
        fy = w.loc[w["wheel"] == name, "force_N"].to_numpy(float)
        m_s += steering_moment(fy, mz[name].to_numpy(), steering.mechanical_trail_m)
    delta = b["steer_rad"].to_numpy(float)
    rate = np.gradient(delta, t)
    acc = np.gradient(rate, t)
    yaw_acc = np.gradient(b["yaw_rate_rps"].to_numpy(float), t)
    friction = dahl_friction(delta, steering.friction_Nm * ratio)
    gain = steering.assist_gain if steering.assist == "linear" else 0.0
    col = column_torque(
        m_s, rate, acc, friction, ratio=ratio, assist_gain=gain,
        kingpin_inertia_kgm2=steering.kingpin_inertia_kgm2,
        kingpin_damping_Nms=steering.kingpin_damping_Nms, yaw_accel_rps2=yaw_acc,
    )  # fmt: skip
    step = max(round(result.meta.get("output_hz", 100.0) / rate_hz), 1)
    rng = np.random.default_rng(seed)
    sel = slice(None, None, step)
    reading = col[sel] * (1.0 + scale_error) + offset_Nm
    reading = reading + rng.normal(0.0, noise_Nm, reading.size)
    out = pd.DataFrame({"t_s": t[sel], "torque_Nm": reading})
    if assist_channel:
        out["assist_Nm"] = gain * col[sel]
    return out
