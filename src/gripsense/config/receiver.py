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

from gripsense.config.toml_reader import TomlReader
from gripsense.errors import InputError
from gripsense.io.text import read_toml

__all__ = ["EXACT", "RECEIVERS", "RECEIVER_KEYS", "Receiver", "receiver_from"]

RECEIVER_KEYS = (
    "name",
    "heading_white_deg",
    "heading_slow_deg",
    "velocity_mps",
    "yaw_rate_dps",
    "heading_slow_tau_s",
    "position_slow_m",
    "position_white_m",
)
# key → (unit, plausible range)
_RANGES = {
    "heading_white_deg": ("deg", (0.0, 10.0)),
    "heading_slow_deg": ("deg", (0.0, 10.0)),
    "velocity_mps": ("mps", (0.0, 5.0)),
    "yaw_rate_dps": ("dps", (0.0, 20.0)),
    "heading_slow_tau_s": ("s", (0.5, 3600.0)),
    "position_slow_m": ("m", (0.0, 100.0)),
    "position_white_m": ("m", (0.0, 100.0)),
}


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
    heading_white_deg: float = 0.3
    heading_slow_deg: float = 0.4
    velocity_mps: float = 0.05
    yaw_rate_dps: float = 0.3
    heading_slow_tau_s: float = 20.0
    position_slow_m: float = 0.7
    position_white_m: float = 0.3

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
        r = TomlReader({table: t}, source)
        r.known(t, table, RECEIVER_KEYS)
        kw = {"name": str(t.get("name", Path(source).stem))}
        for key, (unit, plausible) in _RANGES.items():
            v = r.num(t, table, key, unit=unit, required=False, plausible=plausible)
            if v is not None:
                kw[key] = v
        return cls(**kw)


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
