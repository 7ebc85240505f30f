from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
GPSD = DATA / "gpsd"
GPSD_LOGS = sorted(GPSD.glob("*.log"))


@pytest.fixture(params=GPSD_LOGS, ids=lambda p: p.stem)
def gpsd_log(request) -> Path:
    return request.param


@pytest.fixture(scope="session", autouse=True)
def system_tmp(tmp_path_factory) -> Iterator[Path]:
    """The system's temporary folder, as every program the suite starts sees it: a folder of
    the session's own (Chromium's profiles, Dask's spill folders, the console script's and the
    libraries' temporary files land there, not in /tmp), removed with pytest's own folders.
    """
    d = tmp_path_factory.mktemp("system-tmp")
    old_env, old = os.environ.get("TMPDIR"), tempfile.tempdir
    os.environ["TMPDIR"] = str(d)
    tempfile.tempdir = str(d)
    try:
        yield d
    finally:
        tempfile.tempdir = old
        if old_env is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = old_env
