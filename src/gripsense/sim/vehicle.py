"""Planar two-track vehicle model with brush or tabulated (Magic Formula, PAC89) tyres, load
transfer, roll-induced camber and friction patches.

States: world position X, Y (east, north) [m], yaw ψ (counter-clockwise from east) [rad], body
velocities U, V [m/s], yaw rate r [rad/s], and, with a relaxation length, the four lateral tyre
forces (first-order lag, seed 003 eq. 4 / docs/physics.md §9.1: (σ/U) Ḟ + F = F_ss).

Forces (ISO 8855 body axes):

* tyre lateral force from the exact brush model of :mod:`gripsense.physics.brush` (parabolic or
  quartic pressure), with the local road μ, the wheel's load and C = G w l(m)²/2;
  a driven or braked wheel keeps the lateral friction left by its longitudinal force,
  μ_y = √(μ² − (F_x/F_z)²) (friction circle);
* or, per axle, a tyre from a file (:mod:`gripsense.sim.tyres`: Magic Formula ``.tir`` or
  PAC89) with its own load dependence and camber thrust, scaled to the road μ by similarity;
  the wheels lean with the body: inclination γ = k_γ φ, roll φ = (dφ/da_y) a_y (the vehicle
  file's ``roll_gradient_deg_per_g`` and ``roll_camber_gain``), the same for all four wheels;
* locked wheels (straight braking) slide: F = −μ F_z along the wheel's velocity;
* quasi-static loads: longitudinal transfer m a_x h / L and the steady-state lateral transfer of
  docs/physics.md §4.2 (roll-stiffness split and roll-centre heights) with the body's roll
  φ = (dφ/da_y) a_y moving the CG sideways (roll moment m (h − h_ra)(a_y + g φ)), from the
  previous step's accelerations; no aerodynamic drag, no rolling resistance.

Equations: m(U̇ − V r) = ΣF_x, m(V̇ + U r) = ΣF_y, I_z ṙ = Σ(x_i F_y,i − y_i F_x,i).
Integration: fixed-step RK4 (default 2 ms) in one compiled loop; controllers are evaluated once
per step.

This module holds the parameters (:class:`SimParams`, packed for the compiled core) and the
result (:class:`SimResult`); the equations of motion are in :mod:`gripsense.sim.dynamics`, the
drivers (path following, speed) in :mod:`gripsense.sim.control` and the integration in
:mod:`gripsense.sim.integrate` (:func:`~gripsense.sim.integrate.simulate`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.errors import InputError

__all__ = ["DRIVES", "WHEEL_NAMES", "SimParams", "SimResult"]

WHEEL_NAMES = ("front_left", "front_right", "rear_left", "rear_right")
DRIVES = {"front": 0, "rear": 1, "all": 2}


@dataclass(frozen=True)
class SimParams:
    """Parameters of the simulated vehicle (SI).

    Built from a :class:`~gripsense.config.Vehicle` with :meth:`from_vehicle`; the vehicle needs
    a wheelbase and G-or-C tyres for both axles.

    Attributes
    ----------
    mass_kg : float
        Mass [kg].
    yaw_inertia_kgm2 : float
        Yaw inertia [kg m^2].
    l_f : float
        CG to front axle [m].
    l_r : float
        CG to rear axle [m].
    cg_height_m : float
        CG height [m].
    track_front_m : float
        Front track [m].
    track_rear_m : float
        Rear track [m].
    roll_front_fraction : float
        Front share of the roll stiffness [-].
    roll_centre_heights_m : tuple of float
        Front and rear roll-centre heights [m].
    tyres : dict
        Axle → :class:`~gripsense.config.Tyre`.
    relaxation_length_m : float
        Tyre relaxation length (0: no lag) [m].
    drive : str
        Driven axle: ``front``, ``rear`` or ``all``.
    pressure : str
        Pressure shape of the brush tyres.
    sim_tyres : dict
        Axle → :class:`~gripsense.sim.tyres.SimTyre` for axles whose tyres come from a file
        (others are brush tyres).
    roll_gradient_rad_per_g : float
        Body roll per g of lateral acceleration [rad].
    roll_camber_gain : float
        Wheel inclination per radian of body roll [-].
    """

    mass_kg: float
    yaw_inertia_kgm2: float
    l_f: float
    l_r: float
    cg_height_m: float
    track_front_m: float
    track_rear_m: float
    roll_front_fraction: float
    roll_centre_heights_m: tuple[float, float]
    tyres: dict  # axle -> gripsense.config.Tyre
    relaxation_length_m: float = 0.0
    drive: str = "rear"
    pressure: str = "parabolic"
    sim_tyres: dict = field(default_factory=dict)
    roll_gradient_rad_per_g: float = 0.0
    roll_camber_gain: float = 0.0

    @classmethod
    def from_vehicle(
        cls,
        v: Vehicle,
        *,
        yaw_inertia_kgm2: float | None = None,
        relaxation_length_m: float = 0.0,
        drive: str | None = None,
        sim_tyres: dict | None = None,
    ) -> SimParams:
        """Simulation parameters from a vehicle description.

        The yaw inertia defaults to m·l_f·l_r (a common estimate: radius of gyration² ≈ l_f l_r).

        Parameters
        ----------
        v : Vehicle
            Vehicle description (needs a wheelbase).
        yaw_inertia_kgm2 : float, optional
            Yaw inertia [kg m^2]; default m l_f l_r.
        relaxation_length_m : float
            Tyre relaxation length [m].
        drive : str, optional
            Driven axle (default the vehicle file's ``drive``, else ``front``).
        sim_tyres : dict, optional
            Axle → :class:`~gripsense.sim.tyres.SimTyre` (tyres from files; others brush).
        """
        if v.wheelbase_m is None:
            raise InputError(f"{v.source}: [vehicle] wheelbase_m is needed to simulate")
        for axle in ("front", "rear"):
            if axle not in v.tyres:
                raise InputError(f"{v.source}: [tyre.{axle}] is needed to simulate")
        drive = drive or v.drive or "front"
        if drive not in DRIVES:
            raise InputError(f"drive={drive!r}; use one of {sorted(DRIVES)}")
        L = v.wheelbase_m
        l_f = L * (1.0 - v.front_weight_fraction)
        l_r = L - l_f
        kf = (
            v.roll_stiffness_front_fraction
            if v.roll_stiffness_front_fraction is not None
            else v.front_weight_fraction
        )
        rc = v.roll_centre_heights_m or (v.cg_height_m, v.cg_height_m)
        pressures = {t.pressure for t in v.tyres.values()}
        return cls(
            mass_kg=v.mass_kg,
            yaw_inertia_kgm2=yaw_inertia_kgm2 or v.yaw_inertia,
            l_f=l_f,
            l_r=l_r,
            cg_height_m=v.cg_height_m,
            track_front_m=v.track_front_m,
            track_rear_m=v.track_rear_m,
            roll_front_fraction=kf,
            roll_centre_heights_m=(float(rc[0]), float(rc[1])),
            tyres=dict(v.tyres),
            relaxation_length_m=relaxation_length_m,
            drive=drive,
            pressure="quartic" if pressures == {"quartic"} else "parabolic",
            sim_tyres=dict(sim_tyres or {}),
            roll_gradient_rad_per_g=np.deg2rad(v.roll_gradient_deg_per_g),
            roll_camber_gain=v.roll_camber_gain,
        )

    @property
    def wheel_positions(self) -> np.ndarray:
        """(4, 2) wheel positions relative to the CG, x forward, y left [m] (FL, FR, RL, RR)."""
        tf, tr = self.track_front_m / 2, self.track_rear_m / 2
        return np.array([[self.l_f, tf], [self.l_f, -tf], [-self.l_r, tr], [-self.l_r, -tr]])

    def packed(self) -> np.ndarray:
        """Parameters as one float array for the compiled core."""
        m = self.mass_kg
        mf = m * self.l_r / (self.l_f + self.l_r)
        mr = m - mf
        hf, hr = self.roll_centre_heights_m
        tyre_cols = []
        for axle in ("front", "rear"):
            t = self.tyres[axle]
            fixed_c = t.cornering_stiffness_N_per_rad if t.cornering_stiffness_N_per_rad else -1.0
            tyre_cols += [
                t.width_m,
                t.tread_stiffness_N_per_m3 or 0.0,
                fixed_c,
                t.contact_a if t.contact_a is not None else 0.0,
                t.contact_b if t.contact_b is not None else 0.0,
                t.contact_length_m if t.contact_length_m is not None else -1.0,
            ]
        return np.array(
            [
                m,
                self.yaw_inertia_kgm2,
                self.l_f,
                self.l_r,
                self.cg_height_m,
                self.track_front_m,
                self.track_rear_m,
                self.roll_front_fraction,
                hf,
                hr,
                mf,
                mr,
                self.relaxation_length_m,
                DRIVES[self.drive],
                0.0 if self.pressure == "parabolic" else 2.0,
                *tyre_cols,
                self.roll_gradient_rad_per_g,
                self.roll_camber_gain,
            ]
        )

    def tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Tyre tables for the compiled core: front and rear F_0, their peaks, and per axle
        (kind, grid description); a brush axle gets a 2×2×2 dummy table.
        """
        tabs, peaks = [], []
        ax = np.zeros((2, 8))
        for k, axle in enumerate(("front", "rear")):
            t = self.sim_tyres.get(axle)
            if t is None:
                tabs.append(np.zeros((2, 2, 2)))
                peaks.append(np.zeros((2, 2, 2)))
            else:
                tabs.append(np.ascontiguousarray(t.fy))
                peaks.append(np.ascontiguousarray(t.peak))
                ax[k, 0] = 1.0
                ax[k, 1:] = t.axes()
        return tabs[0], tabs[1], peaks[0], peaks[1], ax


@dataclass
class SimResult:
    """Simulated drive.

    Attributes
    ----------
    body : pandas.DataFrame
        At the output rate: ``t_s``, ``x_m``, ``y_m`` (east, north), ``yaw_rad``, ``u_mps``,
        ``v_mps``, ``yaw_rate_rps``, ``ax_mps2``, ``ay_mps2`` (body-axis accelerations),
        ``steer_rad`` (road-wheel angle, front), ``fx_N`` (total longitudinal tyre force).
    wheels : pandas.DataFrame
        Long table per output time and wheel: ``t_s``, ``wheel``, ``mu_true`` (the wheel's
        peak friction at its load and inclination, in the direction of its force: the road μ for
        a brush tyre), ``mu_road`` (road μ at the wheel), ``camber_rad`` (inclination, ISO),
        ``slip_angle_rad``, ``load_N``, ``force_N`` (lateral, wheel axes, ISO sign),
        ``force_ss_N`` (the steady-state force of the slip angle, which ``force_N`` follows
        over the relaxation length), ``speed_mps``.
    params : SimParams
    wall_s : float
        Wall-clock time of the integration [s].
    meta : dict
        Notes on the run (manoeuvre, tyre models).
    """

    body: pd.DataFrame
    wheels: pd.DataFrame
    params: SimParams
    wall_s: float = 0.0
    meta: dict = field(default_factory=dict)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        dur = float(self.body["t_s"].iloc[-1] - self.body["t_s"].iloc[0]) if len(self.body) else 0
        return dur / self.wall_s if self.wall_s > 0 else float("inf")
