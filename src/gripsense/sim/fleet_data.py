"""A synthetic fleet: several vehicles driving the curves of a small road network whose road
surfaces (dry, wet, snow …) are known, recorded by emulated GNSS compasses.

:func:`write_fleet` (the fleet tests): each *site* is a curve (driven as a circle) at its own
geographic origin with one road μ; one vehicle file for all vehicles, each driving every site at
a speed near its grip limit there (utilisation ``util``), because μ is observable from cornering
only near the limit (docs/friction.md); the truth per site is returned. A mixed fleet with its
own calibrations on a road network: :mod:`gripsense.fleet.network`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from gripsense.config import Vehicle
from gripsense.constants import G0
from gripsense.errors import InputError
from gripsense.sim import maneuvers as M
from gripsense.sim.gnss import CompassNoise, emulate_compass
from gripsense.sim.vehicle import SimParams

__all__ = ["Site", "write_fleet"]


@dataclass(frozen=True)
class Site:
    """A curve of the network: centre of its lead-in (lat, lon), radius and road μ."""

    name: str
    lat_deg: float
    lon_deg: float
    radius_m: float
    mu: float


def write_fleet(
    outdir: str | Path,
    vehicle_toml: str | Path,
    sites: list[Site],
    *,
    n_vehicles: int = 3,
    util: tuple[float, ...] = (0.95,),
    laps: float = 2.0,
    noise: CompassNoise | None = None,
    seed: int = 0,
) -> pd.DataFrame:
    """Simulate and write ``outdir/<vehicle>/<site>_<k>.nmea.gz``; return the truth table
    (vehicle, site, log, mu, speed).
    """
    outdir = Path(outdir)
    veh = Vehicle.from_toml(vehicle_toml)
    params = SimParams.from_vehicle(veh, drive="front")
    if veh.cg_offset is None:
        raise InputError(f"{vehicle_toml}: [antenna] x_m and y_m are needed to simulate its logs")
    antenna = (-veh.cg_offset[0], -veh.cg_offset[1])
    noise = noise or CompassNoise.rtk()
    rows = []
    k = 0
    for v in range(n_vehicles):
        vdir = outdir / f"car{v + 1:02d}"
        vdir.mkdir(parents=True, exist_ok=True)
        for s in sites:
            for u in util:
                speed = float(np.sqrt(u * s.mu * G0 * s.radius_m))
                m = M.circle(speed, s.radius_m, laps=laps, left=bool((v + k) % 2), params=params)
                res = M.run(params, m, mu=s.mu)
                log = emulate_compass(
                    res, antenna, noise=noise, seed=seed + k, origin=(s.lat_deg, s.lon_deg, 10.0)
                )
                name = f"{s.name}_{k:03d}.nmea.gz"
                log.write(vdir / name)
                rows.append(
                    {
                        "vehicle": vdir.name,
                        "site": s.name,
                        "log": str(vdir / name),
                        "mu": s.mu,
                        "speed_mps": speed,
                        "util": u,
                    }
                )
                k += 1
    return pd.DataFrame(rows)


# --- a road network driven by a mixed fleet (issue 42's benchmark) -----------------------------
