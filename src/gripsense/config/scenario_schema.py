"""The scenario file's tables (``gripsense simulate``; :mod:`gripsense.sim.scenario`), once:
``[scenario]``, ``[road]``, ``[gnss]``, ``[accelerometer]`` and ``[steering]``. The
manoeuvres' own keys (``[[case]]``, ``[[grid]]``) are the arguments of
:mod:`gripsense.sim.maneuvers` and are checked there.
"""

from __future__ import annotations

from gripsense.config.receiver import RECEIVER
from gripsense.config.schema import Key, Table

__all__ = ["ACCELEROMETER", "GNSS", "ROAD", "SCENARIO", "SCENARIO_TABLES", "STEERING_CHANNEL"]

SCENARIO = Table(
    "scenario",
    (
        Key("name", "", "label", kind="text"),
        Key(
            "vehicle", "", "the vehicle file (next to the scenario, or a bundled name)", kind="text"
        ),
        Key("seed", "-", "random seed of the emulated sensors", 0),
        Key("drive", "", "driven axle for the simulator: front / rear / all", kind="other"),
        Key("relaxation_length_m", "m", "tyre relaxation length of the simulator (0: none)", 0.0),
        Key(
            "tyre",
            "",
            '"brush", a .tir / .json file, or { front = …, rear = … }',
            "brush",
            kind="other",
        ),
    ),
    "the scenario",
)
ROAD = Table(
    "road",
    (
        Key("mu", "-", "road μ outside the patches", 0.9),
        Key(
            "patches",
            "",
            "[{ x_m = [min, max], y_m = [min, max], mu = … }, …]: later wins",
            kind="other",
        ),
    ),
    "the road",
)
GNSS = Table(
    "gnss",
    (
        Key("rate_hz", "Hz", "receiver rate", 10.0),
        Key(
            "noise",
            "",
            "the receiver: v100 / white-0.3 / rtk / none / a [receiver] file",
            "v100",
            kind="text",
        ),
        *(
            Key(k.name, k.unit, k.doc, k.default, k.plausible)
            for k in RECEIVER.keys
            if k.kind == "number"
        ),
        Key("position_slow_tau_s", "s", "correlation time of the slow position error", 60.0),
        Key("latency_s", "s", "delay of the heading behind the velocity", 0.0),
        Key("mounting_offset_deg", "deg", "antenna baseline offset from the vehicle axis", 0.5),
    ),
    "the emulated compass: the receiver's keys override its class (none given: the class)",
)
ACCELEROMETER = Table(
    "accelerometer",
    (
        Key("rate_hz", "Hz", "output rate", 50.0),
        Key("pitch_deg", "deg", "sensor pitch (nose up)", 0.0),
        Key("roll_deg", "deg", "sensor roll", 0.0),
        Key("noise_g", "g", "white noise per axis, 1σ", 0.01),
    ),
    "the emulated accelerometer (the braking test's CSV)",
)
STEERING_CHANNEL = Table(
    "steering",
    (
        Key("rate_hz", "Hz", "output rate", 50.0),
        Key("noise_deg", "deg", "white noise of the road-wheel angle, 1σ", 0.05),
        Key("scale_error", "-", "relative scale error of the channel", 0.03),
        Key("offset_deg", "deg", "offset of the road-wheel angle", 0.0),
        Key(
            "torque",
            "",
            "also the column torque, torque_Nm (true | false; the vehicle file's [steering])",
            False,
            kind="other",
        ),
        Key("torque_rate_hz", "Hz", "output rate of the torque", 100.0),
        Key("torque_noise_Nm", "N m", "white noise of the torque sensor, 1σ", 0.05),
        Key("torque_scale_error", "-", "relative scale error of the torque sensor", 0.0),
        Key("torque_offset_Nm", "N m", "offset of the torque sensor", 0.0),
        Key(
            "assist_channel",
            "",
            "also the power steering's assist torque, assist_Nm (true | false)",
            False,
            kind="other",
        ),
    ),
    "the emulated steering channel (and torque)",
)
SCENARIO_TABLES = (SCENARIO, ROAD, GNSS, ACCELEROMETER, STEERING_CHANNEL)
"""The single tables of a scenario file (besides ``[[case]]`` and ``[[grid]]``)."""
