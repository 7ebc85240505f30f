"""The seed-003 car and steering system: parameters only (the model is
:mod:`gripsense.physics.steering_system`, the identification :mod:`gripsense.identify.steering`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from gripsense.config.schema import REQUIRED, Key, Table
from gripsense.config.toml_reader import TomlReader
from gripsense.io.text import read_toml

__all__ = ["STEERING_TABLES", "SteeringCar"]

_NMS = "N·m·s/rad"
CAR = Table(
    "car",
    (
        Key("name", "", "label (default: the file's name)", kind="text"),
        Key("mass_kg", "kg", "mass m", REQUIRED, positive=True),
        Key("yaw_inertia_kgm2", "kg·m²", "yaw inertia I", REQUIRED, positive=True),
        Key("lf_m", "m", "CG to front axle", REQUIRED, positive=True),
        Key("lr_m", "m", "CG to rear axle", REQUIRED, positive=True),
    ),
    "the car of a steering-system file (seed 003)",
)
STEERING = Table(
    "steering",
    (
        Key(
            "kingpin_inertia_kgm2",
            "kg·m²",
            "I_s: steered wheels and knuckles about their kingpins",
            REQUIRED,
            positive=True,
        ),
        Key(
            "kingpin_damping_Nms",
            _NMS,
            "C_s: viscous friction about the kingpins (the identification's start)",
            50.0,
            positive=True,
        ),
        Key(
            "ks1_Nm_per_rad",
            "N·m/rad",
            "k_s1: steering stiffness from drawings",
            REQUIRED,
            positive=True,
        ),
        Key(
            "ks2_Nm_per_rad",
            "N·m/rad",
            "k_s2: the part that is not (joints, play); absent: rigid",
            None,
            positive=True,
        ),
        Key(
            "trail_m",
            "m",
            "ξ: kingpin-to-force-point distance per front wheel",
            REQUIRED,
            positive=True,
        ),
        Key(
            "steering_ratio",
            "-",
            "steering-wheel angle / road-wheel angle N",
            REQUIRED,
            positive=True,
        ),
        Key(
            "wheel_inertia_kgm2",
            "kg·m²",
            "steering-wheel inertia (at the wheel)",
            REQUIRED,
            positive=True,
        ),
        Key(
            "wheel_damping_Nms",
            _NMS,
            "steering-wheel damping (at the wheel)",
            REQUIRED,
            positive=True,
        ),
    ),
    "the steering system",
)
TYRES = Table(
    "tyre",
    (
        Key(
            "cornering_stiffness_front_N_per_rad",
            "N/rad",
            "K per front tyre",
            REQUIRED,
            positive=True,
        ),
        Key(
            "cornering_stiffness_rear_N_per_rad",
            "N/rad",
            "K per rear tyre",
            REQUIRED,
            positive=True,
        ),
        Key(
            "lateral_stiffness_N_per_m",
            "N/m",
            "k_y: the tyre's lateral stiffness",
            REQUIRED,
            positive=True,
        ),
    ),
    "the tyres of a steering-system file",
)
TEST = Table(
    "test",
    (
        Key("speed_mps", "m/s", "constant forward speed V", REQUIRED, positive=True),
        Key("release_angle_deg", "deg", "steering-wheel angle released from", 30.0, positive=True),
        Key(
            "step_stop_deg",
            "deg",
            "steering-wheel angle of the step's stopper",
            90.0,
            positive=True,
        ),
        Key(
            "reference_steer_rate_dps",
            "deg/s",
            "steering-wheel rate the yaw gain refers to",
            70.0,
            positive=True,
        ),
    ),
    "the tests of a steering-system file",
)
STEERING_TABLES = (CAR, STEERING, TYRES, TEST)
"""The tables of a steering-system file (``gripsense/data/of18_steering.toml``)."""


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
    reference_steer_rate_dps: float = TEST["reference_steer_rate_dps"].default  # 70
    step_stop_deg: float = TEST["step_stop_deg"].default  # 90
    release_angle_deg: float = TEST["release_angle_deg"].default  # 30

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
        r.known(doc, "", [t.name for t in STEERING_TABLES])
        v: dict = {}
        for t in STEERING_TABLES:
            v |= t.read(r, r.table(t.name, True))
        # the file's keys are the fields, but for the label, k_y's name and a rigid k_s2
        v.pop("name")
        v["tyre_lateral_stiffness_N_per_m"] = v.pop("lateral_stiffness_N_per_m")
        if v["ks2_Nm_per_rad"] is None:
            v["ks2_Nm_per_rad"] = math.inf
        return cls(**v)
