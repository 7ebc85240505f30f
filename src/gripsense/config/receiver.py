"""The GNSS compass as its user describes it: heading and velocity noise, yaw-rate noise.

Named classes (``--receiver v100|white-0.3|rtk``) or a ``[receiver]`` table in the vehicle
file or a file of its own::

    [receiver]
    name = "my compass"
    heading_white_deg = 0.3     # independent from sample to sample [deg], 1 σ
    heading_slow_deg = 0.4      # slowly varying error (multipath, τ ≈ 20 s) [deg], 1 σ
    velocity_mps = 0.05         # each horizontal velocity component [m/s], 1 σ
    yaw_rate_dps = 0.3          # rate of turn [deg/s], 1 σ
    heading_slow_tau_s = 20.0   # correlation time of the slow heading error [s] (optional)
    position_slow_m = 0.7       # slowly varying position error per axis [m] (optional)
    position_white_m = 0.3      # white position noise per axis [m] (optional)

The one description of a receiver: the estimators' noise model
(:meth:`gripsense.estimate.NoiseModel.for_vehicle`) and the simulator's compass emulator
(:meth:`gripsense.sim.CompassNoise.from_receiver`) are both built from it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gripsense.config.schema import Key, Table
from gripsense.config.toml_reader import TomlReader
from gripsense.errors import InputError
from gripsense.io.text import read_toml

__all__ = ["EXACT", "RECEIVER", "RECEIVERS", "RECEIVER_KEYS", "Receiver", "receiver_from"]

RECEIVER = Table(
    "receiver",
    (
        Key("name", "", "label (default: the file's name)", kind="text"),
        Key(
            "heading_white_deg",
            "deg",
            "heading error independent from sample to sample, 1σ",
            0.3,
            (0.0, 10.0),
        ),
        Key(
            "heading_slow_deg",
            "deg",
            "slowly varying heading error (multipath), 1σ",
            0.4,
            (0.0, 10.0),
        ),
        Key("velocity_mps", "mps", "each horizontal velocity component, 1σ", 0.05, (0.0, 5.0)),
        Key("yaw_rate_dps", "dps", "rate of turn, 1σ", 0.3, (0.0, 20.0)),
        Key(
            "heading_slow_tau_s",
            "s",
            "correlation time of the slow heading error",
            20.0,
            (0.5, 3600.0),
        ),
        Key(
            "position_slow_m",
            "m",
            "slowly varying position error per axis, 1σ (simulator)",
            0.7,
            (0.0, 100.0),
        ),
        Key(
            "position_white_m",
            "m",
            "white position noise per axis, 1σ (simulator)",
            0.3,
            (0.0, 100.0),
        ),
    ),
    "the GNSS compass (defaults: the v100 class)",
)
RECEIVER_KEYS = RECEIVER.names


@dataclass(frozen=True)
class Receiver:
    """Measurement noise of a GNSS compass (1 σ values).

    Attributes
    ----------
    name : str
        Label.
    heading_white_deg : float
        Heading error independent from sample to sample [deg].
    heading_slow_deg : float
        Slowly varying heading error (multipath; correlation time ~20 s) [deg].
    velocity_mps : float
        Each horizontal velocity component [m/s].
    yaw_rate_dps : float
        Rate of turn [deg/s].
    heading_slow_tau_s : float
        Correlation time of the slowly varying heading error (a Gauss–Markov process) [s].
    position_slow_m : float
        Slowly varying position error per horizontal axis (Gauss–Markov, 60 s) [m] (the
        simulator's; the estimators use velocity and heading only).
    position_white_m : float
        White position noise per horizontal axis [m] (the simulator's).
    """

    name: str = "v100"
    heading_white_deg: float = RECEIVER["heading_white_deg"].default  # 0.3
    heading_slow_deg: float = RECEIVER["heading_slow_deg"].default  # 0.4
    velocity_mps: float = RECEIVER["velocity_mps"].default  # 0.05
    yaw_rate_dps: float = RECEIVER["yaw_rate_dps"].default  # 0.3
    heading_slow_tau_s: float = RECEIVER["heading_slow_tau_s"].default  # 20.0
    position_slow_m: float = RECEIVER["position_slow_m"].default  # 0.7
    position_white_m: float = RECEIVER["position_white_m"].default  # 0.3

    @classmethod
    def from_dict(cls, t: dict, *, source: str = "<dict>", table: str = "receiver") -> Receiver:
        """A receiver from a ``[receiver]`` table.

        Parameters
        ----------
        t : dict
            The table.
        source : str
            File name, for messages.
        table : str
            Table name, for messages.

        Returns
        -------
        Receiver
            The receiver (keys not given keep the V100-class defaults).
        """
        v = RECEIVER.read(TomlReader({table: t}, source), t, table)
        return cls(**{**v, "name": str(v["name"] or Path(source).stem)})

    def at_least_as_good_as(self, other: Receiver) -> bool:
        """Whether this receiver's data are at least as good as *other*'s in every component the
        estimators use: white and slow heading error, velocity and yaw-rate noise each no larger,
        and, where both have a slow heading error, the same correlation time.

        Two receivers need not be ordered: a precise compass with a slow heading error is not
        better data than a noisier one without, on a steady window, where the white noise
        averages and the slow error does not (``rtk`` against ``white-0.3``, docs/physics.md
        §15.11).

        Parameters
        ----------
        other : Receiver
            The receiver compared with.

        Returns
        -------
        bool
            True where no noise component is larger than *other*'s (and, where both have a
            slow heading error, its correlation time is the same).
        """
        if self.heading_slow_deg > 0 and other.heading_slow_deg > 0:
            if self.heading_slow_tau_s != other.heading_slow_tau_s:
                return False
        return all(getattr(self, k) <= getattr(other, k) for k in _NOISE_COMPONENTS)


_NOISE_COMPONENTS = ("heading_white_deg", "heading_slow_deg", "velocity_mps", "yaw_rate_dps")


RECEIVERS = {
    "v100": Receiver("v100", 0.3, 0.4, 0.05, 0.3),
    "white-0.3": Receiver("white-0.3", 0.3, 0.0, 0.05, 0.3),
    "rtk": Receiver("rtk", 0.05, 0.05, 0.02, 0.1, position_slow_m=0.02, position_white_m=0.01),
}
"""Named receiver classes: a Hemisphere V100-class dual-antenna compass (≈ 0.5° heading with a
slow error, 1 m DGPS position), a 0.3° compass without slow error, and an RTK-class compass
(0.05°, cm position)."""

EXACT = Receiver("none", 0.0, 0.0, 0.0, 0.0, position_slow_m=0.0, position_white_m=0.0)
"""No noise at all: the simulator's ``receiver = "none"`` (exact values to the printed digits);
not a receiver an estimate can be made for."""


def receiver_from(spec: str | Path | Receiver) -> Receiver:
    """A receiver from a name of :data:`RECEIVERS`, a TOML file with a ``[receiver]`` table, or
    a :class:`Receiver`.

    Parameters
    ----------
    spec : str or Path or Receiver
        What the user gave (``--receiver``).

    Returns
    -------
    Receiver
        The receiver.
    """
    if isinstance(spec, Receiver):
        return spec
    if str(spec) in RECEIVERS:
        return RECEIVERS[str(spec)]
    path = Path(spec)
    if path.suffix.lower() != ".toml":
        raise InputError(
            f"receiver {str(spec)!r}: use one of {', '.join(RECEIVERS)} or a .toml file with a "
            "[receiver] table"
        )
    doc = read_toml(path, "receiver file")
    TomlReader(doc, str(path)).known(doc, "", ("receiver",))
    if not isinstance(doc.get("receiver"), dict):
        raise InputError(f"{path}: missing table [receiver]")
    return Receiver.from_dict(doc["receiver"], source=str(path))
