"""The vehicle file's keys, once: unit, default, plausible range and meaning of every key of
``[vehicle]``, ``[antenna]``, ``[tyre.front]``/``[tyre.rear]`` (with ``contact_length``) and
``[calibration]`` (:mod:`gripsense.config.schema`). Reading (:meth:`gripsense.config.Vehicle.
from_dict`), the dataclasses' defaults, ``docs/configuration.md`` and the templates come from
here.
"""

from __future__ import annotations

from gripsense.config.schema import REQUIRED, Key, Table
from gripsense.physics.tyre_family import CATEGORIES as TYRE_CATEGORIES

__all__ = [
    "ANTENNA",
    "ASSISTS",
    "CALIBRATION",
    "CG_HEIGHT_RANGE_FACTORS",
    "CONTACT_LENGTH",
    "DRIVES",
    "PRESSURES",
    "SHAPES",
    "STEERING_SYSTEM",
    "TOP_KEYS",
    "TYRE",
    "VEHICLE",
]

TOP_KEYS = ("vehicle", "antenna", "tyre", "steering", "receiver", "calibration")
ASSISTS = ("none", "linear")
SHAPES = ("any", "brush", "magic-formula", *TYRE_CATEGORIES)
"""``shape``: any (the family made from real tyres and both brush shapes), brush, magic-formula
(the real tyres' shapes) or a tyre category (its files' shapes; ``docs/physics.md`` §14.3)."""
DRIVES = ("front", "rear", "all")
PRESSURES = ("parabolic", "quartic")
CG_HEIGHT_RANGE_FACTORS = (0.7, 1.4)
"""Default of ``cg_height_range_m`` as multiples of ``cg_height_m``: a guessed CG height is more
often too low than too high."""

_CG = (0.05, 3.0)
_TRACK = (0.5, 3.5)
_ROLL_CENTRE = (-0.5, 3.0)

VEHICLE = Table(
    "vehicle",
    (
        Key("name", "", "label (default: the file's name)", kind="text"),
        Key("mass_kg", "kg", "total mass", REQUIRED, (50.0, 60000.0), positive=True),
        Key(
            "front_weight_fraction",
            "-",
            "static share of the mass on the front axle, l_r / L (or cg_to_front_axle_m)",
        ),
        Key(
            "cg_to_front_axle_m",
            "m",
            "CG to front axle, instead of front_weight_fraction (needs wheelbase_m)",
            positive=True,
        ),
        Key(
            "wheelbase_m",
            "m",
            "wheelbase (places the wheels from [antenna] x_m, y_m)",
            None,
            (0.5, 10.0),
        ),
        Key("cg_height_m", "m", "CG height", REQUIRED, _CG),
        Key("track_front_m", "m", "front track", REQUIRED, _TRACK),
        Key("track_rear_m", "m", "rear track", REQUIRED, _TRACK),
        Key(
            "roll_stiffness_front_fraction",
            "-",
            "front share of the roll stiffness, 0..1 (default: the weight share; physics §4.2)",
        ),
        Key(
            "roll_centre_height_front_m",
            "m",
            "front roll-centre height (both or neither; "
            "neither: at CG height, the thesis's rigid model)",
            None,
            _ROLL_CENTRE,
        ),
        Key("roll_centre_height_rear_m", "m", "rear roll-centre height", None, _ROLL_CENTRE),
        Key("steering_ratio", "-", "steering-wheel angle / road-wheel angle", None, (1.0, 40.0)),
        Key("drive", "", f"driven axle: {' | '.join(DRIVES)}", kind="other"),
        Key("yaw_inertia_kgm2", "kg m^2", "yaw inertia I_z (default: m l_f l_r)", None, (5.0, 2e6)),
        Key(
            "cg_height_range_m",
            "m",
            "[low, high] the CG height may really be (default "
            f"{CG_HEIGHT_RANGE_FACTORS[0]:g}–{CG_HEIGHT_RANGE_FACTORS[1]:g} × cg_height_m)",
            plausible=_CG,
            kind="range",
        ),
        Key(
            "roll_stiffness_front_fraction_range",
            "-",
            "[low, high] the front roll-stiffness share may really be (default ±0.1)",
            plausible=(0.0, 1.0),
            kind="range",
        ),
        Key("roll_gradient_deg_per_g", "deg/g", "body roll per g", 4.0, (0.0, 15.0)),
        Key(
            "roll_camber_gain",
            "-",
            "wheel inclination per degree of roll (1: with the body)",
            0.8,
            (0.0, 1.5),
        ),
    ),
    "the vehicle",
)

ANTENNA = Table(
    "antenna",
    (
        Key(
            "x_m",
            "m",
            "antenna position relative to the CG, x forward (with y_m)",
            None,
            (-10.0, 10.0),
        ),
        Key("y_m", "m", "antenna position relative to the CG, y left", None, (-3.0, 3.0)),
        Key(
            "heading_offset_deg",
            "deg",
            "compass baseline vs the vehicle's x axis",
            0.0,
            (-180.0, 180.0),
        ),
        Key(
            "wheels",
            "m",
            "[antenna.wheels] rear_left = [x, y] …: measured wheel positions "
            "relative to the antenna (instead of x_m, y_m with wheelbase_m)",
            kind="other",
        ),
    ),
    "where the compass sits",
)

TYRE = Table(
    "tyre.front / tyre.rear",
    (
        Key("width_m", "m", "contact width w", REQUIRED, (0.03, 1.0)),
        Key(
            "tread_stiffness_N_per_m3",
            "N/m^3",
            "tread stiffness G of the brush model (or cornering_stiffness_N_per_rad)",
            None,
            (1e5, 1e10),
        ),
        Key(
            "cornering_stiffness_N_per_rad",
            "N/rad",
            "cornering stiffness C at the static load (instead of G)",
            None,
            (1e3, 2e6),
        ),
        Key(
            "contact_length",
            "",
            "{ a = …, b = … } (l = a √m + b m) or { fixed_m = … }",
            REQUIRED,
            kind="other",
        ),
        Key("pressure", "", f"pressure shape: {' | '.join(PRESSURES)}", "parabolic", kind="other"),
        Key(
            "stiffness_uncertainty",
            "-",
            "relative 1σ of the declared stiffness (0.05 for a tyre calibrated on this car)",
            0.2,
            (0.0, 1.0),
        ),
        Key("load_sensitivity", "-", "exponent p of C ∝ Fz^p for a declared C", 0.5, (0.0, 1.5)),
        Key("load_sensitivity_uncertainty", "-", "1σ of p", 0.5, (0.0, 1.0)),
        Key(
            "shape",
            "",
            "what is known of the curve's shape: any | brush | magic-formula, or the tyre's "
            f"category ({' | '.join(TYRE_CATEGORIES)}: the shapes of its real tyres)",
            "any",
            kind="other",
        ),
        Key(
            "relaxation_length_m",
            "m",
            "relaxation length (force lags slip by σ/U)",
            0.5,
            (0.0, 3.0),
        ),
        Key("camber_thrust_ratio", "-", "|C_γ / C_α|", 0.1, (0.0, 1.0)),
        Key("friction_load_sensitivity", "-", "exponent η of μ ∝ Fz^−η", 0.2, (-0.5, 1.0)),
        Key("friction_load_sensitivity_uncertainty", "-", "1σ of η", 0.15, (0.0, 1.0)),
        Key(
            "tyre_set",
            "",
            'name of the tyres fitted (e.g. "winter 2026"): a calibration learned on another '
            "set is not applied to them",
            "",
            kind="text",
        ),
    ),
    "the tyre of one axle",
)

CONTACT_LENGTH = Table(
    "tyre.*.contact_length",
    (
        Key("a", "m/kg^0.5", "l–m model: l = a √m + b m (seed 000 eq. 6.23)"),
        Key("b", "m/kg", "l–m model's second coefficient"),
        Key("fixed_m", "m", "a fixed contact length instead", None, (0.02, 0.6)),
    ),
    "the contact length",
)

CALIBRATION = Table(
    "calibration",
    (
        Key(
            "file",
            "",
            "the vehicle's calibration file (gripsense calibrate), relative to the vehicle file",
            REQUIRED,
            kind="text",
        ),
    ),
    "what the car's own driving taught",
)

STEERING_SYSTEM = Table(
    "steering",
    (
        Key(
            "ratio",
            "-",
            "steering-wheel angle / road-wheel angle (the same as [vehicle] steering_ratio)",
            None,
            (3.0, 40.0),
        ),
        Key(
            "mechanical_trail_m",
            "m",
            "caster trail: the steering axis meets the ground this far ahead of the contact centre",
            0.02,
            (-0.05, 0.12),
        ),
        Key("mechanical_trail_uncertainty_m", "m", "1σ of the caster trail", 0.01, (0.0, 0.05)),
        Key(
            "pneumatic_trail_m",
            "m",
            "front tyre's pneumatic trail at zero slip (default: l/6 from the contact length)",
            None,
            (0.003, 0.12),
        ),
        Key(
            "pneumatic_trail_uncertainty",
            "-",
            "relative 1σ of the pneumatic trail at zero slip (a tyre_file's too: on the car, "
            "roll camber and toe add to it)",
            0.3,
            (0.0, 1.0),
        ),
        Key(
            "kingpin_inertia_kgm2",
            "kg m^2",
            "I_s: both steered wheels and knuckles about their axes (seed 003)",
            1.0,
            (0.0, 50.0),
        ),
        Key(
            "kingpin_damping_Nms",
            "N m s/rad",
            "C_s: viscous damping about the steering axes (seed 003)",
            30.0,
            (0.0, 2000.0),
        ),
        Key(
            "friction_Nm",
            "N m",
            "Coulomb friction of the steering, at the steering wheel",
            1.0,
            (0.0, 20.0),
        ),
        Key("friction_uncertainty_Nm", "N m", "1σ of the friction", 0.5, (0.0, 20.0)),
        Key(
            "column_stiffness_Nm_per_rad",
            "N m/rad",
            "k_s: the torsion bar of the torque sensor, at the steering wheel (seed 003)",
            None,
            (10.0, 1e5),
        ),
        Key(
            "assist",
            "",
            f"power steering: {' | '.join(ASSISTS)} (an assist channel replaces the description)",
            "none",
            kind="other",
        ),
        Key(
            "assist_gain",
            "-",
            'assist torque / column torque, for assist = "linear"',
            0.0,
            (0.0, 30.0),
        ),
        Key("assist_gain_uncertainty", "-", "relative 1σ of the assist gain", 0.3, (0.0, 1.0)),
        Key(
            "torque_scale_uncertainty",
            "-",
            "relative 1σ of the torque channel's scale",
            0.03,
            (0.0, 0.5),
        ),
        Key(
            "torque_offset_uncertainty_Nm",
            "N m",
            "1σ of the torque channel's offset (at the steering wheel)",
            0.2,
            (0.0, 10.0),
        ),
        Key(
            "steering_arm_m",
            "m",
            "tie-rod lever about the steering axis (turns a rack force into the axes' moment)",
            None,
            (0.03, 0.5),
        ),
        Key(
            "tyre_file",
            "",
            "the front tyre's Magic Formula file (.tir), when known: its own trail shape and "
            "zero-slip trail replace the family's (docs/physics.md §16.7)",
            kind="text",
        ),
    ),
    "the steering system (what a steering-torque channel needs; docs/physics.md §16.3)",
)
