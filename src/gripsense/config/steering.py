"""The seed-003 car and steering system: parameters only (the model is
:mod:`gripsense.physics.steering_system`, the identification :mod:`gripsense.identify.steering`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from gripsense.config.toml_reader import TomlReader
from gripsense.io.text import read_toml

__all__ = ["SteeringCar"]

_KEYS = {
    "car": ("name", "mass_kg", "yaw_inertia_kgm2", "lf_m", "lr_m"),
    "steering": (
        "kingpin_inertia_kgm2",
        "kingpin_damping_Nms",
        "ks1_Nm_per_rad",
        "ks2_Nm_per_rad",
        "trail_m",
        "steering_ratio",
        "wheel_inertia_kgm2",
        "wheel_damping_Nms",
    ),
    "tyre": (
        "cornering_stiffness_front_N_per_rad",
        "cornering_stiffness_rear_N_per_rad",
        "lateral_stiffness_N_per_m",
    ),
    "test": ("speed_mps", "release_angle_deg", "step_stop_deg", "reference_steer_rate_dps"),
}


@dataclass(frozen=True)
class SteeringCar:
    """Parameters of the seed-003 model (SI; kingpin-referred unless said otherwise).

    Attributes
    ----------
    mass_kg, yaw_inertia_kgm2 : float
        m, I.
    lf_m, lr_m : float
        CG to front and rear axle.
    speed_mps : float
        Constant forward speed V.
    kingpin_inertia_kgm2 : float
        I_s: both steered wheels and knuckles about their kingpins.
    kingpin_damping_Nms : float
        C_s: equivalent viscous friction about the kingpins [N m s/rad].
    ks1_Nm_per_rad : float
        k_s1: steering stiffness computable from drawings [N m/rad].
    ks2_Nm_per_rad : float
        k_s2: the part that is not (joints, play); ``inf`` for rigid.
    trail_m : float
        ξ: kingpin-to-force-point distance (mechanical + pneumatic trail) per front wheel [m].
    cornering_stiffness_front_N_per_rad, cornering_stiffness_rear_N_per_rad : float
        K_i per tyre [N/rad] (the seed's "cornering power", per degree in its text).
    tyre_lateral_stiffness_N_per_m : float
        k_y: lateral stiffness of the tyre carcass [N/m]; relaxation length K_i/k_y.
    steering_ratio : float
        N = steering-wheel angle / kingpin angle.
    wheel_inertia_kgm2, wheel_damping_Nms : float
        Steering-wheel side inertia and damping at the steering wheel (the seed's C_h = 0.38).
    reference_steer_rate_dps : float
        Steering-wheel rate the yaw gains are normalised to (seed eq. 7: 70) [deg/s].
    step_stop_deg : float
        Steering-wheel angle of the step-steer stopper [deg].
    release_angle_deg : float
        Steering-wheel angle held before the hands-off release [deg].
    """

    mass_kg: float
    yaw_inertia_kgm2: float
    lf_m: float
    lr_m: float
    speed_mps: float
    kingpin_inertia_kgm2: float
    kingpin_damping_Nms: float
    ks1_Nm_per_rad: float
    ks2_Nm_per_rad: float
    trail_m: float
    cornering_stiffness_front_N_per_rad: float
    cornering_stiffness_rear_N_per_rad: float
    tyre_lateral_stiffness_N_per_m: float
    steering_ratio: float
    wheel_inertia_kgm2: float
    wheel_damping_Nms: float
    reference_steer_rate_dps: float = 70.0
    step_stop_deg: float = 90.0
    release_angle_deg: float = 30.0

    @property
    def ks(self) -> float:
        """Series stiffness k_s = k_s1 k_s2/(k_s1 + k_s2) (eq. 6) [N m/rad]."""
        k1, k2 = self.ks1_Nm_per_rad, self.ks2_Nm_per_rad
        return k1 if math.isinf(k2) else k1 * k2 / (k1 + k2)

    @property
    def ih(self) -> float:
        """Steering-wheel inertia referred to the kingpin, I_sw N² [kg m^2]."""
        return self.wheel_inertia_kgm2 * self.steering_ratio**2

    @property
    def ch(self) -> float:
        """Steering-wheel damping referred to the kingpin, C_h N² [N m s/rad]."""
        return self.wheel_damping_Nms * self.steering_ratio**2

    def with_ks(self, ks: float) -> SteeringCar:
        """The same car with total stiffness ``ks`` (k_s2 from eq. 6; ``inf`` when ks ≥ k_s1).

        Parameters
        ----------
        ks : float
            Total steering stiffness k_s [N m/rad].
        """
        k1 = self.ks1_Nm_per_rad
        k2 = math.inf if ks >= k1 else ks * k1 / (k1 - ks)
        return replace(self, ks2_Nm_per_rad=k2)

    def with_cs(self, cs: float) -> SteeringCar:
        """The same car with kingpin damping ``cs``.

        Parameters
        ----------
        cs : float
            Kingpin damping C_s [N m s/rad].
        """
        return replace(self, kingpin_damping_Nms=float(cs))

    @classmethod
    def from_toml(cls, path: str | Path) -> SteeringCar:
        """Read ``[car]``, ``[steering]``, ``[tyre]`` and ``[test]`` tables (see
        ``gripsense/data/of18_steering.toml``); errors name the file, table and key.

        Parameters
        ----------
        path : str or Path
            Car file with [car], [steering], [tyre] and [test] tables.
        """
        doc = read_toml(path, "steering car file")
        r = TomlReader(doc, str(path))
        r.known(doc, "", _KEYS)
        car, st, ty, te = (r.table(n, True) for n in ("car", "steering", "tyre", "test"))
        for name, t in zip(("car", "steering", "tyre", "test"), (car, st, ty, te), strict=True):
            r.known(t, name, _KEYS[name])
        ks2 = r.num(st, "steering", "ks2_Nm_per_rad", unit="N·m/rad", positive=True, required=False)
        return cls(
            mass_kg=r.num(car, "car", "mass_kg", unit="kg", positive=True),
            yaw_inertia_kgm2=r.num(car, "car", "yaw_inertia_kgm2", unit="kg·m²", positive=True),
            lf_m=r.num(car, "car", "lf_m", unit="m", positive=True),
            lr_m=r.num(car, "car", "lr_m", unit="m", positive=True),
            speed_mps=r.num(te, "test", "speed_mps", unit="m/s", positive=True),
            kingpin_inertia_kgm2=r.num(
                st, "steering", "kingpin_inertia_kgm2", unit="kg·m²", positive=True
            ),
            kingpin_damping_Nms=r.num(
                st,
                "steering",
                "kingpin_damping_Nms",
                unit="N·m·s/rad",
                positive=True,
                required=False,
            )
            or 50.0,
            ks1_Nm_per_rad=r.num(st, "steering", "ks1_Nm_per_rad", unit="N·m/rad", positive=True),
            ks2_Nm_per_rad=math.inf if ks2 is None else ks2,
            trail_m=r.num(st, "steering", "trail_m", unit="m", positive=True),
            cornering_stiffness_front_N_per_rad=r.num(
                ty, "tyre", "cornering_stiffness_front_N_per_rad", unit="N/rad", positive=True
            ),
            cornering_stiffness_rear_N_per_rad=r.num(
                ty, "tyre", "cornering_stiffness_rear_N_per_rad", unit="N/rad", positive=True
            ),
            tyre_lateral_stiffness_N_per_m=r.num(
                ty, "tyre", "lateral_stiffness_N_per_m", unit="N/m", positive=True
            ),
            steering_ratio=r.num(st, "steering", "steering_ratio", unit="-", positive=True),
            wheel_inertia_kgm2=r.num(
                st, "steering", "wheel_inertia_kgm2", unit="kg·m²", positive=True
            ),
            wheel_damping_Nms=r.num(
                st, "steering", "wheel_damping_Nms", unit="N·m·s/rad", positive=True
            ),
            reference_steer_rate_dps=r.num(
                te, "test", "reference_steer_rate_dps", unit="deg/s", positive=True, required=False
            )
            or 70.0,
            step_stop_deg=r.num(
                te, "test", "step_stop_deg", unit="deg", positive=True, required=False
            )
            or 90.0,
            release_angle_deg=r.num(
                te, "test", "release_angle_deg", unit="deg", positive=True, required=False
            )
            or 30.0,
        )
