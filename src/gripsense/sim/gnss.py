"""Dual-antenna GNSS-compass emulator: a simulated drive -> NMEA 0183 lines.

The antenna sits at a given point of the body. At the receiver rate it reports, in one burst per
epoch (Hemisphere order: ``HDT, GGA, VTG, RMC, ROT, $PSAT,HPR``), with valid checksums and the
receiver's UTC time:

* true heading = vehicle heading + mounting offset + noise (HDT, HPR);
* position of the antenna + DGPS error (GGA, RMC); velocity of the antenna + noise gives speed
  and course over ground (RMC, VTG);
* rate of turn, NMEA sign (positive to starboard) [deg/min] + noise (ROT).

Noise defaults (:class:`CompassNoise`, the ``v100`` receiver of :data:`gripsense.config.RECEIVERS`)
are close to the thesis's receiver, a Hemisphere V100
(Table 13: true-heading accuracy < 0.75°, position 1 m with DGPS): heading 0.3° white + 0.4°
slowly varying (Gauss–Markov, 20 s) — 0.5° rms in all; position 0.7 m Gauss–Markov (60 s) +
0.3 m white per axis; velocity 0.05 m/s white per component; rate of turn 0.3°/s; latency 0;
mounting offset 0.5°. ``CompassNoise.none()`` gives exact values (to the printed digits).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config.receiver import EXACT, RECEIVERS, Receiver, receiver_from
from gripsense.sim.vehicle import SimResult

__all__ = ["CompassLog", "CompassNoise", "emulate_compass", "format_sentence"]

WGS84_A = 6378137.0
WGS84_E2 = 6.69437999014e-3
KNOT = 1852.0 / 3600.0
# Kochi University of Technology, where the thesis measured (seed 000)
DEFAULT_ORIGIN = (33.6200, 133.7195, 10.0)
DEFAULT_START = dt.datetime(2018, 2, 8, 4, 0, 0, tzinfo=dt.UTC)
SENTENCES = ("HDT", "GGA", "VTG", "RMC", "ROT", "HPR")


@dataclass(frozen=True)
class CompassNoise:
    """Noise model of the emulated receiver (1 σ values; see the module documentation), built
    from the one receiver description (:meth:`from_receiver`, :meth:`preset`) plus what only an
    installation has (latency, mounting offset).

    Attributes
    ----------
    heading_white_deg : float
        White heading noise [deg].
    heading_slow_deg : float
        Slowly varying (Gauss–Markov) heading error [deg].
    heading_slow_tau_s : float
        Its correlation time [s].
    position_slow_m : float
        Slowly varying position error [m].
    position_slow_tau_s : float
        Its correlation time [s].
    position_white_m : float
        White position noise [m].
    velocity_mps : float
        Noise of each velocity component [m/s].
    yaw_rate_dps : float
        Rate-of-turn noise [deg/s].
    latency_s : float
        Delay of the heading behind the velocity [s].
    mounting_offset_deg : float
        Antenna baseline offset from the vehicle axis [deg].
    """

    heading_white_deg: float = 0.3
    heading_slow_deg: float = 0.4
    heading_slow_tau_s: float = 20.0
    position_slow_m: float = 0.7
    position_slow_tau_s: float = 60.0
    position_white_m: float = 0.3
    velocity_mps: float = 0.05
    yaw_rate_dps: float = 0.3
    latency_s: float = 0.0
    mounting_offset_deg: float = 0.5

    @classmethod
    def from_receiver(cls, receiver: Receiver, mounting_offset_deg: float = 0.5) -> CompassNoise:
        """The emulator of a receiver (:class:`gripsense.config.Receiver`).

        Parameters
        ----------
        receiver : Receiver
            The receiver.
        mounting_offset_deg : float
            Mounting offset [deg].
        """
        return cls(
            heading_white_deg=receiver.heading_white_deg,
            heading_slow_deg=receiver.heading_slow_deg,
            heading_slow_tau_s=receiver.heading_slow_tau_s,
            position_slow_m=receiver.position_slow_m,
            position_white_m=receiver.position_white_m,
            velocity_mps=receiver.velocity_mps,
            yaw_rate_dps=receiver.yaw_rate_dps,
            mounting_offset_deg=mounting_offset_deg,
        )

    @classmethod
    def none(cls, mounting_offset_deg: float = 0.0) -> CompassNoise:
        """No noise (and no mounting offset unless given).

        Parameters
        ----------
        mounting_offset_deg : float
            Mounting offset kept [deg].
        """
        return cls.from_receiver(EXACT, mounting_offset_deg)

    @classmethod
    def rtk(cls, mounting_offset_deg: float = 0.5) -> CompassNoise:
        """An RTK-class dual-antenna receiver: heading 0.05° white + 0.05° slow, cm position.

        Parameters
        ----------
        mounting_offset_deg : float
            Mounting offset [deg].
        """
        return cls.from_receiver(RECEIVERS["rtk"], mounting_offset_deg)

    @classmethod
    def preset(cls, name: str | Path | Receiver, mounting_offset_deg: float = 0.5) -> CompassNoise:
        """A receiver as ``--receiver`` names it: a class of :data:`gripsense.config.RECEIVERS`
        (``v100``, ``white-0.3`` without slow error, ``rtk``), a TOML file with a
        ``[receiver]`` table, or ``none`` (:meth:`none`: no noise).

        Parameters
        ----------
        name : str or Path or Receiver
            The receiver.
        mounting_offset_deg : float
            Mounting offset [deg].
        """
        rec = EXACT if str(name) == EXACT.name else receiver_from(name)
        return cls.from_receiver(rec, mounting_offset_deg)

    def scaled(self, k: float) -> CompassNoise:
        """All random terms multiplied by *k* (latency and mounting offset kept).

        Parameters
        ----------
        k : float
            Factor on every noise term [-].
        """
        return replace(
            self,
            heading_white_deg=k * self.heading_white_deg,
            heading_slow_deg=k * self.heading_slow_deg,
            position_slow_m=k * self.position_slow_m,
            position_white_m=k * self.position_white_m,
            velocity_mps=k * self.velocity_mps,
            yaw_rate_dps=k * self.yaw_rate_dps,
        )


OLD_NOISE_KEYS = {
    "heading_gm_deg": "heading_slow_deg",
    "heading_gm_tau_s": "heading_slow_tau_s",
    "position_gm_m": "position_slow_m",
    "position_gm_tau_s": "position_slow_tau_s",
    "rot_dps": "yaw_rate_dps",
}
"""The emulator's former names (before 0.9) → the receiver's names (deprecated in scenarios)."""


@dataclass
class CompassLog:
    """Emulator output.

    Attributes
    ----------
    lines : list of str
        NMEA sentences (no line terminators).
    antenna : pandas.DataFrame
        True antenna motion per epoch: ``t_s``, ``heading_deg`` (vehicle heading, compass),
        ``course_deg``, ``speed_mps``, ``yaw_rate_rps`` (ISO), ``lat_deg``, ``lon_deg``.
    truth : pandas.DataFrame
        Per epoch and wheel: ``t_s``, ``wheel``, ``mu_true``, ``slip_angle_rad``, ``load_N``,
        ``force_N``, ``speed_mps`` (from the simulator).
    epochs : pandas.DataFrame or None
        What the receiver measured, as an epoch table (``time_utc``, ``t_s``, ``lat_deg``,
        ``lon_deg``, ``alt_m``, ``n_sats``, ``speed_mps``, ``course_deg``, ``heading_deg``,
        ``yaw_rate_rps``): the same drive for the other log formats
        (:func:`gripsense.io.logs.write_log`).
    """

    lines: list[str]
    antenna: pd.DataFrame
    truth: pd.DataFrame
    epochs: pd.DataFrame | None = None

    def write(self, path, *, crlf: bool = True) -> None:
        """Write the sentences to a file (gzip-compressed when the name ends in .gz).

        Parameters
        ----------
        path : str or Path
            Output file (.gz: compressed).
        crlf : bool
            End lines with CR LF as NMEA does.
        """
        from gripsense.io.logs import write_nmea_lines

        write_nmea_lines(self.lines, path, crlf=crlf)


def format_sentence(body: str) -> str:
    """``$body*hh`` with the NMEA 0183 XOR checksum."""
    cs = 0
    for ch in body.encode("ascii"):
        cs ^= ch
    return f"${body}*{cs:02X}"


def _gauss_markov(n: int, step_s: float, sigma: float, tau: float, rng) -> np.ndarray:
    if sigma == 0 or n == 0:
        return np.zeros(n)
    a = np.exp(-step_s / tau)
    e = rng.normal(0.0, sigma * np.sqrt(1 - a * a), n)
    out = np.empty(n)
    out[0] = rng.normal(0.0, sigma)
    for k in range(1, n):
        out[k] = a * out[k - 1] + e[k]
    return out


def _ddmm(value: float, pos: str, neg: str, deg_width: int) -> tuple[str, str]:
    h = pos if value >= 0 else neg
    v = abs(value)
    d = int(v)
    m = (v - d) * 60.0
    if round(m, 7) >= 60.0:
        d, m = d + 1, 0.0
    return f"{d:0{deg_width}d}{m:010.7f}", h


def emulate_compass(
    result: SimResult,
    antenna_xy: tuple[float, float],
    *,
    rate_hz: float = 10.0,
    noise: CompassNoise | None = None,
    sentences: tuple[str, ...] = SENTENCES,
    origin: tuple[float, float, float] = DEFAULT_ORIGIN,
    start: dt.datetime = DEFAULT_START,
    seed: int = 0,
    talker: str = "GP",
) -> CompassLog:
    """Emulate a dual-antenna GNSS compass on a simulated drive.

    Parameters
    ----------
    result : SimResult
        The drive (its output rate must be a multiple of *rate_hz*).
    antenna_xy : (float, float)
        Antenna position relative to the CG, x forward, y left [m].
    rate_hz : float
        Receiver output rate [Hz].
    noise : CompassNoise
        Default: :class:`CompassNoise` defaults (Hemisphere V100-like).
    sentences : tuple of str
        Any of ``HDT, GGA, VTG, RMC, ROT, HPR`` in burst order.
    origin : (lat_deg, lon_deg, alt_m)
        World origin of the simulation (x east, y north).
    start : datetime
        UTC time of t = 0.
    seed : int
        Random seed (the same seed gives the same log).
    talker : str
        Talker ID of the standard sentences.

    Returns
    -------
    CompassLog
    """
    noise = noise or CompassNoise()
    unknown = set(sentences) - set(SENTENCES)
    if unknown:
        raise ValueError(f"unknown sentences {sorted(unknown)}; use {SENTENCES}")
    rng = np.random.default_rng(seed)
    b = result.body
    out_hz = result.meta.get("output_hz", 100.0)
    step = round(out_hz / rate_hz)
    lag = round(noise.latency_s * out_hz)
    idx_t = np.arange(lag, len(b), step)  # time tags
    idx_v = idx_t - lag  # measured values (latency)
    t = b["t_s"].to_numpy()[idx_t]
    tru = _antenna_truth(b, idx_v, antenna_xy)
    m = _measure(tru, noise, 1.0 / rate_hz, rng)
    lat0, lon0, alt0 = origin
    lat, lon = _lat_lon(m["pn"], m["pe"], lat0, lon0)
    lat_true, lon_true = _lat_lon(tru["ny"], tru["ex"], lat0, lon0)
    m.update(lat=lat, lon=lon)
    lines = _sentences(t, m, start, sentences, talker, alt0)
    antenna = pd.DataFrame(
        {
            "t_s": t,
            "heading_deg": tru["heading"],
            "course_deg": tru["course"],
            "speed_mps": tru["speed"],
            "yaw_rate_rps": tru["r"],
            "lat_deg": lat_true,
            "lon_deg": lon_true,
        }
    )
    w = result.wheels
    tw = w["t_s"].to_numpy()
    keep = np.isin(np.round(tw, 6), np.round(b["t_s"].to_numpy()[idx_v], 6))
    truth = w[keep].reset_index(drop=True)
    if lag:
        truth["t_s"] = truth["t_s"] + lag / out_hz
    n = t.size
    measured = pd.DataFrame(
        {
            "time_utc": pd.DatetimeIndex([start + dt.timedelta(seconds=float(x)) for x in t]),
            "t_s": t,
            "lat_deg": lat,
            "lon_deg": lon,
            "alt_m": np.full(n, float(alt0)),
            "n_sats": np.full(n, 12.0),
            "speed_mps": m["speed"],
            "course_deg": m["course"],
            "heading_deg": np.mod(m["hdg"], 360.0),
            "yaw_rate_rps": -np.deg2rad(m["rot"] / 60.0),
        }
    )
    return CompassLog(lines=lines, antenna=antenna, truth=truth, epochs=measured)


def _antenna_truth(
    b: pd.DataFrame, idx: np.ndarray, antenna_xy: tuple[float, float]
) -> dict[str, np.ndarray]:
    """The antenna's true position (``ex`` east, ``ny`` north [m]), velocity (``ve``, ``vn``
    [m/s]), heading, course [deg], speed [m/s] and the yaw rate ``r`` [rad/s] at the body
    table's rows *idx* (``docs/physics.md`` §3.1, rigid body).
    """
    xa, ya = antenna_xy
    psi = b["yaw_rad"].to_numpy()[idx]
    X, Y = b["x_m"].to_numpy()[idx], b["y_m"].to_numpy()[idx]
    U, V = b["u_mps"].to_numpy()[idx], b["v_mps"].to_numpy()[idx]
    r = b["yaw_rate_rps"].to_numpy()[idx]
    # antenna position and velocity in the world (x east, y north)
    ex = X + xa * np.cos(psi) - ya * np.sin(psi)
    ny = Y + xa * np.sin(psi) + ya * np.cos(psi)
    ua, va = U - r * ya, V + r * xa
    ve = ua * np.cos(psi) - va * np.sin(psi)
    vn = ua * np.sin(psi) + va * np.cos(psi)
    return {
        "ex": ex,
        "ny": ny,
        "ve": ve,
        "vn": vn,
        "r": r,
        "heading": np.mod(90.0 - np.rad2deg(psi), 360.0),
        "course": np.mod(np.rad2deg(np.arctan2(ve, vn)), 360.0),
        "speed": np.hypot(ve, vn),
    }


def _measure(
    tru: dict[str, np.ndarray], noise: CompassNoise, step_s: float, rng: np.random.Generator
) -> dict[str, np.ndarray]:
    """What the receiver reports of the truth (:func:`_antenna_truth`): heading ``hdg`` [deg],
    position ``pe``/``pn`` [m], course [deg], speed [m/s] and rate of turn ``rot`` [deg/min],
    with the noise's offsets, white and Gauss–Markov errors (drawn in this order from *rng*).
    """
    n = tru["r"].size
    hdg = (
        tru["heading"]
        + noise.mounting_offset_deg
        + rng.normal(0, noise.heading_white_deg, n)
        + _gauss_markov(n, step_s, noise.heading_slow_deg, noise.heading_slow_tau_s, rng)
    )
    pe = (
        tru["ex"]
        + _gauss_markov(n, step_s, noise.position_slow_m, noise.position_slow_tau_s, rng)
        + rng.normal(0, noise.position_white_m, n)
    )
    pn = (
        tru["ny"]
        + _gauss_markov(n, step_s, noise.position_slow_m, noise.position_slow_tau_s, rng)
        + rng.normal(0, noise.position_white_m, n)
    )
    ve_m = tru["ve"] + rng.normal(0, noise.velocity_mps, n)
    vn_m = tru["vn"] + rng.normal(0, noise.velocity_mps, n)
    rot = -np.rad2deg(tru["r"]) * 60.0 + rng.normal(0, noise.yaw_rate_dps * 60.0, n)
    return {
        "hdg": hdg,
        "pe": pe,
        "pn": pn,
        "course": np.mod(np.rad2deg(np.arctan2(ve_m, vn_m)), 360.0),
        "speed": np.hypot(ve_m, vn_m),
        "rot": rot,
    }


def _lat_lon(
    north: np.ndarray, east: np.ndarray, lat0: float, lon0: float
) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude [deg] of local north/east offsets [m] from (*lat0*, *lon0*)
    (WGS 84's radii of curvature at *lat0*).
    """
    s2 = np.sin(np.deg2rad(lat0)) ** 2
    r_n = WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * s2) ** 1.5
    r_e = WGS84_A / np.sqrt(1 - WGS84_E2 * s2)
    return lat0 + np.rad2deg(north / r_n), lon0 + np.rad2deg(
        east / (r_e * np.cos(np.deg2rad(lat0)))
    )


def _sentences(
    t: np.ndarray,
    m: dict[str, np.ndarray],
    start: dt.datetime,
    sentences: tuple[str, ...],
    talker: str,
    alt0: float,
) -> list[str]:
    """The NMEA lines of every epoch (times *t* [s] after *start*) in burst order, from the
    measured values *m* (:func:`_measure` with ``lat``/``lon``).
    """
    hdg, course, speed, rot = m["hdg"], m["course"], m["speed"], m["rot"]
    lines: list[str] = []
    for k in range(t.size):
        when = start + dt.timedelta(seconds=float(t[k]))
        hms = when.strftime("%H%M%S") + f".{when.microsecond // 10000:02d}"
        date = when.strftime("%d%m%y")
        la, ns = _ddmm(m["lat"][k], "N", "S", 2)
        lo, ew = _ddmm(m["lon"][k], "E", "W", 3)
        kn = speed[k] / KNOT
        for sname in sentences:
            if sname == "HDT":
                lines.append(format_sentence(f"{talker}HDT,{np.mod(hdg[k], 360.0):.3f},T"))
            elif sname == "GGA":
                lines.append(
                    format_sentence(
                        f"{talker}GGA,{hms},{la},{ns},{lo},{ew},2,12,0.8,{alt0:.3f},M,30.000,M,1.0,"
                        "0001"
                    )
                )
            elif sname == "VTG":
                lines.append(
                    format_sentence(
                        f"{talker}VTG,{course[k]:.3f},T,,M,{kn:.4f},N,{speed[k] * 3.6:.4f},K,D"
                    )
                )
            elif sname == "RMC":
                lines.append(
                    format_sentence(
                        f"{talker}RMC,{hms},A,{la},{ns},{lo},{ew},{kn:.4f},{course[k]:.3f},{date},,,D"
                    )
                )
            elif sname == "ROT":
                lines.append(format_sentence(f"{talker}ROT,{rot[k]:.2f},A"))
            elif sname == "HPR":
                lines.append(format_sentence(f"PSAT,HPR,{hms},{np.mod(hdg[k], 360.0):.3f},0.00,,N"))
    return lines
