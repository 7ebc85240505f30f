"""The example a log reader's error gives works on gripsense's own files (issue 45: the MF4
error named channels, ``True_Head``, ``Course``, that no MF4 file of gripsense has)."""

from __future__ import annotations

import re

import pytest

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.canlog import write_can
from gripsense.io.logs.mdf import write_mdf
from tests.conftest import DATA
from tests.io.logs.test_measurement_logs import _epochs

pytest.importorskip("asammdf")
pytest.importorskip("can")
pytest.importorskip("cantools")


def _suggested(err: InputError) -> str:
    m = re.search(r"e\.g\. --columns (\S+)", str(err))
    assert m, str(err)
    return m.group(1)


def test_the_mf4_errors_example_reads_a_simulated_mf4(tmp_path):
    ep = _epochs(20)
    write_mdf(ep, tmp_path / "m.mf4")
    with pytest.raises(InputError, match=r"columns=") as e:  # the Python argument too
        read_log(tmp_path / "m.mf4")
    got = read_log(tmp_path / "m.mf4", columns=_suggested(e.value)).epochs
    assert len(got) == len(ep)
    assert got["heading_deg"].to_numpy() == pytest.approx(ep["heading_deg"].to_numpy(), abs=1e-9)


def test_the_can_errors_example_reads_a_log_of_the_example_dbc(tmp_path):
    ep = _epochs(20)
    write_can(ep, tmp_path / "c.blf", DATA / "formats" / "vehicle.dbc")
    with pytest.raises(InputError) as e:
        read_log(tmp_path / "c.blf", dbc=DATA / "formats" / "vehicle.dbc")
    got = read_log(
        tmp_path / "c.blf", columns=_suggested(e.value), dbc=DATA / "formats" / "vehicle.dbc"
    ).epochs
    assert len(got) == len(ep)
