"""Vehicle, tyre and antenna descriptions: TOML in, validated, SI out.

Classes here only hold parameters and fill in arguments of the physics functions; they contain
no algorithms (the pvlib ``Location``/``PVSystem`` rule).

TOML layout (units are in the key names; see ``gripsense/data/corolla_thesis.toml``)::

    [vehicle]
    name = "..."
    mass_kg = 1200.0
    front_weight_fraction = 0.6        # or cg_to_front_axle_m (needs wheelbase_m)
    wheelbase_m = 2.6                  # optional; needed to place wheels from [antenna] x_m/y_m
    cg_height_m = 0.55
    track_front_m = 1.50
    track_rear_m = 1.50
    roll_stiffness_front_fraction = 0.6      # optional (docs/physics.md §4.2)
    roll_centre_height_front_m = 0.05        # optional, both or neither
    roll_centre_height_rear_m = 0.10
    steering_ratio = 15.0                    # optional: steering-wheel angle / road-wheel angle
    drive = "front"                          # optional: driven axle, front | rear | all

    [antenna]
    x_m = 0.2                 # antenna position relative to the CG, x forward ...
    y_m = 0.0                 # ... and y left [m]
    heading_offset_deg = 0.0  # compass baseline vs vehicle x axis
    [antenna.wheels]          # or: measured wheel positions relative to the antenna [x, y] (m)
    rear_left = [-0.76, 1.0]

    [tyre.rear]               # and [tyre.front]
    width_m = 0.185
    tread_stiffness_N_per_m3 = 5e7          # or cornering_stiffness_N_per_rad
    contact_length = { a = 0.0104, b = -1.017e-4 }   # l = a sqrt(m) + b m; or { fixed_m = 0.134 }
    pressure = "parabolic"                  # or "quartic"

    [steering]                # optional: what a steering-torque channel needs (§16.3)
    mechanical_trail_m = 0.02
    assist = "linear"                       # or "none"
    assist_gain = 3.0                       # assist torque / column torque
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gripsense.config.receiver import Receiver
from gripsense.config.toml_reader import TomlReader
from gripsense.config.tyre_files import load_mf_tyre
from gripsense.config.vehicle_schema import (
    ANTENNA,
    ASSISTS,
    CALIBRATION,
    CG_HEIGHT_RANGE_FACTORS,
    CONTACT_LENGTH,
    DRIVES,
    PRESSURES,
    SHAPES,
    STEERING_SYSTEM,
    TOP_KEYS,
    TYRE,
    VEHICLE,
)
from gripsense.constants import G0
from gripsense.io.text import read_toml
from gripsense.physics.contact import contact_length_lm

__all__ = ["PLAUSIBLE", "WHEELS", "SteeringSystem", "Tyre", "Vehicle"]

WHEELS = ("front_left", "front_right", "rear_left", "rear_right")
AXLE_OF = {w: w.split("_")[0] for w in WHEELS}

_KEY_OF = {k.name: k for t in (VEHICLE, ANTENNA, TYRE, CONTACT_LENGTH) for k in t.keys}
PLAUSIBLE: dict[str, tuple[float, float]] = {  # type: ignore[assignment]  # every one set
    name: k.plausible
    for name, k in _KEY_OF.items()
    if k.plausible is not None and name != "fixed_m"
} | {
    # the names of the shared ranges (kept for code that reads them)
    "track_m": _KEY_OF["track_front_m"].plausible,
    "roll_centre_height_m": _KEY_OF["roll_centre_height_front_m"].plausible,
    "offset_x_m": _KEY_OF["x_m"].plausible,
    "offset_y_m": _KEY_OF["y_m"].plausible,
    "tyre_width_m": _KEY_OF["width_m"].plausible,
    "contact_length_m": _KEY_OF["fixed_m"].plausible,
}
"""Plausible ranges of the vehicle file's numbers (from :mod:`gripsense.config.vehicle_schema`;
``docs/configuration.md``)."""
MIN_STABILITY_FACTOR = 0.5
"""Smallest track/(2 × CG height): below it the inner wheels would lift under 0.5 g."""


@dataclass(frozen=True)
class Tyre:
    """Tyre of one axle.

    Attributes
    ----------
    width_m : float
        Contact width w [m].
    tread_stiffness_N_per_m3 : float or None
        Tread stiffness G [N/m^3] (brush model).
    cornering_stiffness_N_per_rad : float or None
        Cornering stiffness C [N/rad]; used instead of G when given.
    contact_a, contact_b : float or None
        l–m model coefficients: l = a √m + b m (seed 000, eq. 6.23) [m/kg^0.5], [m/kg].
    contact_length_m : float or None
        Fixed contact length [m], instead of the l–m model.
    pressure : str
        ``parabolic`` or ``quartic``.
    stiffness_uncertainty : float
        Relative 1σ of the cornering stiffness as declared (G or C) [-]; 0.2 by default, 0.05
        for a tyre calibrated on this car (``gripsense stiffness``).
    load_sensitivity : float
        Exponent p of C ∝ Fz^p for a declared C (published Magic Formula files between their
        nominal load and 1.9 times it: −0.8 to 1.4; default 0.5) [-];
        with G and an l–m model the load dependence follows from the contact length instead.
    load_sensitivity_uncertainty : float
        1σ of p [-] (default 0.5).
    shape : str
        What is known of the curve's shape: ``any`` (the family made from real tyres and both
        brush shapes, the default), ``brush``, ``magic-formula`` or a tyre category —
        ``passenger``, ``suv``, ``performance``, ``racing``, ``truck`` (``docs/physics.md``
        §14.3).
    relaxation_length_m : float
        Relaxation length of the lateral force [m] (force lags slip by σ/U).
    camber_thrust_ratio : float
        Camber stiffness over cornering stiffness, |C_γ/C_α| [-] (0.05–0.2 for car tyres).
    friction_load_sensitivity : float
        Exponent η of the peak friction's fall with load, μ ∝ Fz^−η [-]: 0 for a brush tyre;
        published Magic Formula files show 0.08–0.6 between their nominal load and 1.9 times
        it (default 0.2).
    friction_load_sensitivity_uncertainty : float
        1σ of η [-] (default 0.15).
    tyre_set : str
        The name of the tyres fitted (``""``: not named); a calibration learned on another set
        is not applied to them (:func:`gripsense.config.calibration.apply_calibration`).
    shape_members : tuple of int, optional
        The members of the prior family (indices into
        :data:`gripsense.physics.tyre_curves.SHAPE_FAMILY`) a calibration's drives leave
        possible (``docs/physics.md`` §15.10); None: every member the ``shape`` allows.
    shape_evidence : tuple of float, optional
        What a calibration learned of the normalised curve's shape: the deviance of each shape
        of :data:`gripsense.physics.shape_grid.LEARN_GRID` (``docs/physics.md`` §15.10) [-];
        None: nothing learned (the ``shape`` prior alone).
    """

    width_m: float
    tread_stiffness_N_per_m3: float | None = None
    cornering_stiffness_N_per_rad: float | None = None
    contact_a: float | None = None
    contact_b: float | None = None
    contact_length_m: float | None = None
    pressure: str = TYRE["pressure"].default  # "parabolic"
    stiffness_uncertainty: float = TYRE["stiffness_uncertainty"].default  # 0.2
    load_sensitivity: float = TYRE["load_sensitivity"].default  # 0.5
    load_sensitivity_uncertainty: float = TYRE["load_sensitivity_uncertainty"].default  # 0.5
    shape: str = TYRE["shape"].default  # "any"
    relaxation_length_m: float = TYRE["relaxation_length_m"].default  # 0.5
    camber_thrust_ratio: float = TYRE["camber_thrust_ratio"].default  # 0.1
    friction_load_sensitivity: float = TYRE["friction_load_sensitivity"].default  # 0.2
    friction_load_sensitivity_uncertainty: float = TYRE[
        "friction_load_sensitivity_uncertainty"
    ].default  # 0.15
    tyre_set: str = ""
    shape_members: tuple[int, ...] | None = None
    shape_evidence: tuple[float, ...] | None = None

    def contact_length(self, mass_kg) -> np.ndarray:
        """Contact length [m] for the mass the wheel carries [kg].

        Parameters
        ----------
        mass_kg : array_like
            Mass the wheel carries, Fz/g [kg].
        """
        m = np.asarray(mass_kg, dtype=float)
        if self.contact_length_m is not None:
            return np.full(m.shape, self.contact_length_m)
        a, b = self.contact_a, self.contact_b
        assert a is not None and b is not None  # set whenever contact_length_m is not
        return np.asarray(contact_length_lm(m, a, b), dtype=float)

    def cornering_stiffness(self, length_m) -> np.ndarray:
        """C [N/rad]: the given value, or G w l²/2 (seed 000 eq. 9.1).

        Parameters
        ----------
        length_m : array_like
            Contact length [m].
        """
        length = np.asarray(length_m, dtype=float)
        if self.cornering_stiffness_N_per_rad is not None:
            return np.full(length.shape, self.cornering_stiffness_N_per_rad)
        g = self.tread_stiffness_N_per_m3
        assert g is not None  # set whenever cornering_stiffness_N_per_rad is not
        return 0.5 * g * self.width_m * length**2


@dataclass(frozen=True)
class SteeringSystem:
    """The ``[steering]`` table: the steering system between the tyres and a torque channel
    (``docs/physics.md`` §16.3; keys and ranges in :data:`~gripsense.config.vehicle_schema.
    STEERING_SYSTEM`).

    Attributes
    ----------
    mechanical_trail_m : float
        Caster trail t_c [m].
    mechanical_trail_uncertainty_m : float
        Its 1σ [m].
    pneumatic_trail_m : float or None
        The front tyre's pneumatic trail at zero slip t₀ [m]; None: l/6 from the contact length.
    pneumatic_trail_uncertainty : float
        Relative 1σ of t₀ [-].
    kingpin_inertia_kgm2 : float
        I_s of both steered wheels about their axes [kg m²].
    kingpin_damping_Nms : float
        C_s [N m s/rad].
    friction_Nm : float
        Coulomb friction at the steering wheel [N m].
    friction_uncertainty_Nm : float
        Its 1σ [N m].
    column_stiffness_Nm_per_rad : float or None
        k_s of the torque sensor's torsion bar [N m/rad].
    assist : str
        ``none`` or ``linear``.
    assist_gain : float
        Assist torque over column torque [-].
    assist_gain_uncertainty : float
        Relative 1σ of the gain [-].
    torque_scale_uncertainty : float
        Relative 1σ of the torque channel's scale [-].
    torque_offset_uncertainty_Nm : float
        1σ of its offset [N m].
    steering_arm_m : float or None
        Tie-rod lever about the steering axis (for a rack-force channel) [m].
    tyre_file : str or None
        The front tyre's Magic Formula file, when known (its own trail, §16.7).
    calibrated_lever_m, calibrated_lever_uncertainty : float or None
        The lever k (t_c + t₀) learned by ``gripsense calibrate`` [m] and its relative 1σ [-]
        (§16.8; not a vehicle-file key: the calibration file's).
    """

    mechanical_trail_m: float = STEERING_SYSTEM["mechanical_trail_m"].default  # 0.02
    mechanical_trail_uncertainty_m: float = STEERING_SYSTEM[
        "mechanical_trail_uncertainty_m"
    ].default  # 0.01
    pneumatic_trail_m: float | None = None
    pneumatic_trail_uncertainty: float = STEERING_SYSTEM["pneumatic_trail_uncertainty"].default
    kingpin_inertia_kgm2: float = STEERING_SYSTEM["kingpin_inertia_kgm2"].default  # 1.0
    kingpin_damping_Nms: float = STEERING_SYSTEM["kingpin_damping_Nms"].default  # 30
    friction_Nm: float = STEERING_SYSTEM["friction_Nm"].default  # 1.0
    friction_uncertainty_Nm: float = STEERING_SYSTEM["friction_uncertainty_Nm"].default  # 0.5
    column_stiffness_Nm_per_rad: float | None = None
    assist: str = STEERING_SYSTEM["assist"].default  # "none"
    assist_gain: float = STEERING_SYSTEM["assist_gain"].default  # 0
    assist_gain_uncertainty: float = STEERING_SYSTEM["assist_gain_uncertainty"].default  # 0.3
    torque_scale_uncertainty: float = STEERING_SYSTEM["torque_scale_uncertainty"].default
    torque_offset_uncertainty_Nm: float = STEERING_SYSTEM["torque_offset_uncertainty_Nm"].default
    steering_arm_m: float | None = None
    tyre_file: str | None = None
    calibrated_lever_m: float | None = None
    calibrated_lever_uncertainty: float | None = None


@dataclass(frozen=True)
class Vehicle:
    """Vehicle description in SI units (see the module documentation for the TOML layout).

    Attributes
    ----------
    mass_kg : float
    front_weight_fraction : float
        Static fraction of the mass on the front axle, l_r / L [-].
    cg_height_m : float
    track_front_m, track_rear_m : float
    wheel_offsets : dict
        Wheel name -> (dx, dy): position relative to the antenna, x forward, y left [m]. Only
        wheels whose position is known are listed.
    cg_offset : tuple or None
        Position of the CG relative to the antenna (dx, dy) [m], when known.
    heading_offset_rad : float
        Compass baseline offset from the vehicle x axis [rad].
    tyres : dict
        ``front`` / ``rear`` -> :class:`Tyre`.
    wheelbase_m, roll_stiffness_front_fraction, roll_centre_heights_m, steering_ratio
        Optional; None when not given.
    drive : str or None
        Driven axle: ``front``, ``rear`` or ``all`` (None: not declared). On a steered axle the
        measured body-axis force mixes lateral and drive force (``docs/physics.md`` §15).
    yaw_inertia_kgm2 : float or None
        Yaw inertia I_z [kg m^2]; None: the estimate m l_f l_r is used.
    cg_height_range_m : tuple of float
        What the CG height may really be [m] (default 0.7–1.4 × ``cg_height_m``: a guessed
        CG height is more often too low than too high).
    roll_stiffness_front_fraction_range : tuple of float
        What the front roll-stiffness share may really be [-] (default ±0.1).
    roll_gradient_deg_per_g : float
        Body roll per g of lateral acceleration [deg/g] (default 4).
    roll_camber_gain : float
        Wheel inclination per degree of body roll [-] (1: the wheels lean with the body;
        default 0.8).
    steering : SteeringSystem or None
        The ``[steering]`` table, when the file has one (a steering-torque channel needs it).
    receiver : Receiver or None
        The ``[receiver]`` table, when the file has one.
    calibration_file : str or None
        ``[calibration] file``: the vehicle's calibration file (``gripsense calibrate``),
        relative paths from the vehicle file's folder; the estimators take its stiffness.
    name : str
    source : str
        Where the description came from (file path).
    notes : dict
        Free-form notes kept with the description.
    """

    mass_kg: float
    front_weight_fraction: float
    cg_height_m: float
    track_front_m: float
    track_rear_m: float
    wheel_offsets: dict[str, tuple[float, float]]
    tyres: dict[str, Tyre]
    cg_offset: tuple[float, float] | None = None
    heading_offset_rad: float = 0.0
    wheelbase_m: float | None = None
    roll_stiffness_front_fraction: float | None = None
    roll_centre_heights_m: tuple[float, float] | None = None
    steering_ratio: float | None = None
    drive: str | None = None
    yaw_inertia_kgm2: float | None = None
    cg_height_range_m: tuple[float, float] | None = None
    roll_stiffness_front_fraction_range: tuple[float, float] | None = None
    roll_gradient_deg_per_g: float = VEHICLE["roll_gradient_deg_per_g"].default  # 4.0
    roll_camber_gain: float = VEHICLE["roll_camber_gain"].default  # 0.8
    steering: SteeringSystem | None = None
    receiver: Receiver | None = None
    calibration_file: str | None = None
    name: str = "vehicle"
    source: str = ""
    notes: dict = field(default_factory=dict)

    @property
    def axle_masses_kg(self) -> tuple[float, float]:
        """Static (front, rear) axle masses [kg]."""
        f = self.front_weight_fraction
        return self.mass_kg * f, self.mass_kg * (1.0 - f)

    @property
    def yaw_inertia(self) -> float:
        """Yaw inertia [kg m^2]: the declared value, else m l_f l_r (radius of gyration² ≈
        l_f l_r; a 2.6 m wheelbase is assumed when none is declared).
        """
        if self.yaw_inertia_kgm2 is not None:
            return self.yaw_inertia_kgm2
        wb = self.wheelbase_m if self.wheelbase_m is not None else 2.6
        f = self.front_weight_fraction
        return self.mass_kg * (wb * (1 - f)) * (wb * f)

    def static_load(self, axle: str) -> float:
        """Static load of one wheel of *axle* [N].

        Parameters
        ----------
        axle : str
            ``front`` or ``rear``.
        """
        m_f, m_r = self.axle_masses_kg
        return (m_f if axle == "front" else m_r) * G0 / 2.0

    def cornering_stiffness(self, axle: str, load_N) -> np.ndarray:
        """Cornering stiffness of a wheel of *axle* at its load [N/rad]: G w l(m)²/2 with the
        l–m contact length (thesis eq. 9.1, 6.23), or a declared C at the static load scaled by
        (Fz / Fz_static)^p (``docs/physics.md`` §14).

        Parameters
        ----------
        axle : str
            ``front`` or ``rear``.
        load_N : array_like
            Wheel load [N].

        Returns
        -------
        numpy.ndarray
            C [N/rad] (NaN for loads ≤ 0).
        """
        t = self.tyres[axle]
        fz = np.asarray(load_N, dtype=float)
        with np.errstate(invalid="ignore", divide="ignore"):
            if t.cornering_stiffness_N_per_rad is None:
                c = t.cornering_stiffness(t.contact_length(fz / G0))
            else:
                ratio = np.where(fz > 0, fz / self.static_load(axle), np.nan)
                c = t.cornering_stiffness_N_per_rad * ratio**t.load_sensitivity
        return np.where(fz > 0, c, np.nan)

    def track(self, axle: str) -> float:
        """Track width of an axle (``front`` or ``rear``) [m].

        Parameters
        ----------
        axle : str
            ``front`` or ``rear``.
        """
        return self.track_front_m if axle == "front" else self.track_rear_m

    @classmethod
    def from_toml(cls, path: str | Path) -> Vehicle:
        """Read and validate a vehicle description.

        Parameters
        ----------
        path : str or Path
            Vehicle file (TOML).

        Raises
        ------
        InputError
            Naming the file and key, with the expected unit, when something is missing or wrong.
        """
        return cls.from_dict(read_toml(path, "vehicle file"), source=str(path))

    @classmethod
    def from_dict(cls, doc: dict, *, source: str = "<dict>") -> Vehicle:
        """Build from a parsed TOML document (see :meth:`from_toml`).

        Parameters
        ----------
        doc : dict
            Parsed TOML document.
        source : str
            Where it came from, for messages.
        """
        r = TomlReader(doc, source)
        r.known(doc, "", TOP_KEYS)
        veh = r.table("vehicle", required=True)
        v = VEHICLE.read(r, veh)
        mass, wb = v["mass_kg"], v["wheelbase_m"]
        frac = _front_weight_fraction(r, v)
        h, tf, tr = v["cg_height_m"], v["track_front_m"], v["track_rear_m"]
        ssf = min(tf, tr) / (2.0 * h)  # static stability factor: inner wheel lifts at this a_y/g
        if ssf < MIN_STABILITY_FACTOR:
            r.fail(
                "vehicle",
                "cg_height_m",
                f"= {h} m with a {min(tf, tr)} m track: the inner wheels would lift at "
                f"{ssf:.2f} g (track/(2 h) must be ≥ {MIN_STABILITY_FACTOR}); check the CG height "
                "and the track (metres)",
            )
        kf = v["roll_stiffness_front_fraction"]
        if kf is not None and not 0.0 <= kf <= 1.0:
            r.fail("vehicle", "roll_stiffness_front_fraction", f"= {kf}: must be in 0..1")
        hf, hr = v["roll_centre_height_front_m"], v["roll_centre_height_rear_m"]
        if (hf is None) != (hr is None):
            r.fail(
                "vehicle",
                "roll_centre_height_front_m",
                "give both roll-centre heights or "
                "neither (neither: at CG height, the thesis's rigid model)",
            )
        drive = v["drive"]
        if drive is not None and drive not in DRIVES:
            r.fail("vehicle", "drive", f"= {drive!r}: use one of {', '.join(DRIVES)}")
        name = str(v["name"] or Path(source).stem)
        h_range = v["cg_height_range_m"] or tuple(f * h for f in CG_HEIGHT_RANGE_FACTORS)
        kf0 = kf if kf is not None else frac
        k_range = v["roll_stiffness_front_fraction_range"] or (max(kf0 - 0.1, 0), min(kf0 + 0.1, 1))
        steering = None
        ratio = v["steering_ratio"]
        if "steering" in doc:
            steering, ratio = _steering(r, r.table("steering", required=False), ratio)
        receiver = None
        if "receiver" in doc:
            rt = r.table("receiver", required=False)
            receiver = Receiver.from_dict(rt, source=source)
        cal_file = None
        if "calibration" in doc:
            ct = r.table("calibration", required=False)
            r.known(ct, "calibration", CALIBRATION.names)
            cal_file = ct.get("file")
            if not isinstance(cal_file, str) or not cal_file:
                r.fail("calibration", "file", "the path of a calibration file is needed")
            if not Path(cal_file).is_absolute() and Path(source).parent.exists():
                cal_file = str(Path(source).parent / cal_file)

        ant = r.table("antenna", required=True)
        a = ANTENNA.read(r, ant)
        off_deg, ax, ay = a["heading_offset_deg"], a["x_m"], a["y_m"]
        cg = (-ax, -ay) if ax is not None and ay is not None else None
        offsets = _wheel_offsets(r, ant, ax, ay, wb, frac, tf, tr)

        tyres_doc = r.table("tyre", required=True)
        r.known(tyres_doc, "tyre", ("front", "rear"))
        tyres = {}
        for axle in ("front", "rear"):
            if axle not in tyres_doc:
                if any(AXLE_OF[w] == axle for w in offsets):
                    r.fail("tyre", axle, f"missing [tyre.{axle}] for the {axle} wheels")
                continue
            axle_mass = mass * (frac if axle == "front" else 1.0 - frac)
            tyres[axle] = _tyre(r, tyres_doc[axle], f"tyre.{axle}", axle_mass / 2.0)
        offsets = {w: o for w, o in offsets.items() if AXLE_OF[w] in tyres}
        return cls(
            mass_kg=mass,
            front_weight_fraction=frac,
            cg_height_m=h,
            track_front_m=tf,
            track_rear_m=tr,
            wheel_offsets=offsets,
            tyres=tyres,
            cg_offset=cg,
            heading_offset_rad=math.radians(off_deg),
            wheelbase_m=wb,
            roll_stiffness_front_fraction=kf,
            roll_centre_heights_m=(hf, hr) if hf is not None else None,
            steering_ratio=ratio,
            drive=drive,
            yaw_inertia_kgm2=v["yaw_inertia_kgm2"],
            cg_height_range_m=h_range,
            roll_stiffness_front_fraction_range=k_range,
            roll_gradient_deg_per_g=v["roll_gradient_deg_per_g"],
            roll_camber_gain=v["roll_camber_gain"],
            steering=steering,
            receiver=receiver,
            calibration_file=cal_file,
            name=name,
            source=source,
        )


def _front_weight_fraction(r: TomlReader, v: dict) -> float:
    """The static front weight share, given or from the CG's position on the wheelbase."""
    wb, frac, lf = v["wheelbase_m"], v["front_weight_fraction"], v["cg_to_front_axle_m"]
    if frac is None and lf is None:
        r.fail(
            "vehicle",
            "front_weight_fraction",
            "missing; give it (0..1) or cg_to_front_axle_m with wheelbase_m",
        )
    if frac is None:
        if wb is None:
            r.fail("vehicle", "wheelbase_m", "needed with cg_to_front_axle_m [m]")
        if not lf < wb:
            r.fail(
                "vehicle",
                "cg_to_front_axle_m",
                f"= {lf} [m] must be shorter than the wheelbase",
            )
        frac = (wb - lf) / wb
    if not 0.0 < frac < 1.0:
        r.fail("vehicle", "front_weight_fraction", f"= {frac}: must be between 0 and 1")
    return frac


def _wheel_offsets(r: TomlReader, ant: dict, ax, ay, wb, frac, tf, tr) -> dict:
    """Wheel positions relative to the antenna: from the antenna's position relative to the CG
    with wheelbase and tracks, and/or measured (``[antenna.wheels]``).
    """
    explicit = ant.get("wheels", {})
    if not isinstance(explicit, dict):
        r.fail("antenna", "wheels", "must be a table of wheel = [x_m, y_m]")
    offsets: dict[str, tuple[float, float]] = {}
    if (ax is None) != (ay is None):
        r.fail("antenna", "x_m", "give both x_m and y_m (antenna position relative to CG)")
    if ax is not None:
        if wb is not None:
            l_f = wb * (1.0 - frac)
            l_r = wb * frac
            for wname, (x, y) in {
                "front_left": (l_f, tf / 2),
                "front_right": (l_f, -tf / 2),
                "rear_left": (-l_r, tr / 2),
                "rear_right": (-l_r, -tr / 2),
            }.items():
                offsets[wname] = (x - ax, y - ay)
    for wname, xy in explicit.items():
        if wname not in WHEELS:
            r.fail("antenna.wheels", wname, f"unknown wheel; use one of {WHEELS}")
        if (
            not isinstance(xy, list)
            or len(xy) != 2
            or not all(isinstance(v, int | float) for v in xy)
        ):
            r.fail("antenna.wheels", wname, "must be [x_m, y_m] relative to the antenna")
        if abs(xy[0]) > PLAUSIBLE["offset_x_m"][1] or abs(xy[1]) > PLAUSIBLE["offset_y_m"][1]:
            r.fail("antenna.wheels", wname, f"= {xy}: more than 10 m / 3 m from the antenna [m]")
        offsets[wname] = (float(xy[0]), float(xy[1]))
    if not offsets:
        r.fail(
            "antenna",
            "wheels",
            "no wheel position: give [antenna] x_m, y_m with "
            "[vehicle] wheelbase_m, or [antenna.wheels] rear_left = [x, y] ...",
        )
    return offsets


def _steering(r: TomlReader, t: dict, ratio: float | None) -> tuple[SteeringSystem, float | None]:
    """The ``[steering]`` table and the steering ratio it gives or agrees with."""
    v = STEERING_SYSTEM.read(r, t)
    if v["ratio"] is not None:
        if ratio is not None and abs(v["ratio"] - ratio) > 1e-9 * ratio:
            r.fail(
                "steering",
                "ratio",
                f"= {v['ratio']} but [vehicle] steering_ratio = {ratio}; give one of them",
            )
        ratio = v["ratio"]
    if v["assist"] not in ASSISTS:
        r.fail("steering", "assist", f"= {v['assist']!r}: use one of {', '.join(ASSISTS)}")
    if v["assist"] == "none" and v["assist_gain"] > 0:
        r.fail(
            "steering",
            "assist_gain",
            f'= {v["assist_gain"]} with assist = "none"; set assist = "linear" or drop it',
        )
    kw = {k: v[k] for k in STEERING_SYSTEM.names if k in SteeringSystem.__dataclass_fields__}
    if kw["tyre_file"] is not None:
        path = Path(kw["tyre_file"])
        if not path.is_absolute() and Path(r.source).parent.exists():
            path = Path(r.source).parent / path
        if path.suffix.lower() not in (".tir", ".gz") or not path.is_file():
            r.fail(
                "steering",
                "tyre_file",
                f"= {kw['tyre_file']!r}: no Magic Formula .tir file there (a path relative to "
                "the vehicle file, or absolute)",
            )
        load_mf_tyre(path)  # a file that cannot be read is refused here, with its line
        kw["tyre_file"] = str(path)
    return SteeringSystem(**kw), ratio


def _tyre(r: TomlReader, t: dict, where: str, wheel_mass_kg: float) -> Tyre:
    if not isinstance(t, dict):
        r.fail("tyre", where, "must be a table")
    v = TYRE.read(r, t, where)
    w, g, c = v["width_m"], v["tread_stiffness_N_per_m3"], v["cornering_stiffness_N_per_rad"]
    if (g is None) == (c is None):
        r.fail(
            where,
            "tread_stiffness_N_per_m3",
            "give exactly one of tread_stiffness_N_per_m3 "
            "[N/m^3] and cornering_stiffness_N_per_rad [N/rad]",
        )
    cl = t.get("contact_length")
    if not isinstance(cl, dict):
        r.fail(
            where,
            "contact_length",
            "missing; give { a = ..., b = ... } (l = a sqrt(m) + b m) or { fixed_m = ... }",
        )
    lv = CONTACT_LENGTH.read(r, cl, f"{where}.contact_length")
    a, b, fixed = lv["a"], lv["b"], lv["fixed_m"]
    lo, hi = PLAUSIBLE["contact_length_m"]
    if fixed is None and (a is None or b is None):
        r.fail(f"{where}.contact_length", "a", "give both a and b, or fixed_m")
    if fixed is None:
        l0 = float(contact_length_lm(wheel_mass_kg, a, b))
        if not lo <= l0 <= hi:
            r.fail(
                f"{where}.contact_length",
                "a",
                f"gives l = {l0:.3g} m at the static wheel mass {wheel_mass_kg:.0f} kg, outside "
                f"{lo}–{hi} m; check a [m/kg^0.5] and b [m/kg]",
            )
    pressure, shape = v["pressure"], v["shape"]
    if pressure not in PRESSURES:
        r.fail(where, "pressure", f"= {pressure!r}: use 'parabolic' or 'quartic'")
    if shape not in SHAPES:
        r.fail(where, "shape", f"= {shape!r}: use one of {', '.join(SHAPES)}")
    extra = {
        k.name: v[k.name]
        for k in TYRE.keys
        if k.kind == "number" and k.default is not None and not k.required
    }
    return Tyre(
        shape=shape,
        tyre_set=v["tyre_set"],
        **extra,
        width_m=w,
        tread_stiffness_N_per_m3=g,
        cornering_stiffness_N_per_rad=c,
        contact_a=a,
        contact_b=b,
        contact_length_m=fixed,
        pressure=pressure,
    )
