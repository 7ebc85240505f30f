"""Real files as ``gripsense simulate`` writes them, made once per test session.

One small scenario (a 35 km/h circle of 25 m on μ 0.5, about 28 s of driving, near the front
axle's limit) with a steering channel (angle at 20 Hz, column torque and assist at 100 Hz in the
same CSV, as ``simulate`` writes them), simulated per log format on first use
(:func:`gripsense.sim.scenario.run_scenario`, the code behind ``gripsense simulate``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest

SCENARIO = """
[scenario]
vehicle = "corolla_sim.toml"
seed = 5
[road]
mu = 0.5
[gnss]
rate_hz = 10
noise = "v100"
[steering]
rate_hz = 20
torque = true
assist_channel = true
[accelerometer]
rate_hz = 50
[[case]]
maneuver = "circle"
speed_kmh = 35
radius_m = 25
laps = 1
"""


@dataclass(frozen=True)
class Simulated:
    """One simulated drive: its folder and its row of ``cases.csv``."""

    folder: Path
    case: pd.Series

    @property
    def log(self) -> Path:
        return self.folder / self.case["log"]

    @property
    def steer(self) -> Path:
        return self.folder / self.case["steer"]

    @property
    def accel(self) -> Path:
        return self.folder / self.case["accel"]

    @property
    def vehicle(self) -> Path:
        return self.folder / self.case["vehicle_file"]

    @property
    def columns(self) -> str | None:
        c = self.case.get("columns")
        return c if isinstance(c, str) else None


_CACHE: dict[str, Simulated] = {}


def simulate(base: Path, fmt: str = "nmea") -> Simulated:
    """The scenario simulated in *fmt* under *base* (once per session and format)."""
    from gripsense.sim.scenario import run_scenario

    if fmt not in _CACHE:
        base.mkdir(parents=True, exist_ok=True)
        sc = base / "scenario.toml"
        sc.write_text(SCENARIO)
        out = base / f"sim-{fmt}"
        cases = run_scenario(sc, out, fmt=fmt)
        _CACHE[fmt] = Simulated(out, cases.iloc[0])
    return _CACHE[fmt]


@pytest.fixture(scope="session")
def simulated(tmp_path_factory):
    """``simulated(fmt)`` -> :class:`Simulated` (made on first use in the session)."""
    base = tmp_path_factory.getbasetemp() / "simulated"
    return lambda fmt="nmea": simulate(base, fmt)
