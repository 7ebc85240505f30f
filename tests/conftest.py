from __future__ import annotations

from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
GPSD = DATA / "gpsd"
GPSD_LOGS = sorted(GPSD.glob("*.log"))


@pytest.fixture(params=GPSD_LOGS, ids=lambda p: p.stem)
def gpsd_log(request) -> Path:
    return request.param
