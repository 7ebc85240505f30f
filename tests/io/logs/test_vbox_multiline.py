"""VBOX files whose ``[column names]`` section spans several lines (issue 43).

VBOX 3i / VBOX Video / VBOX Touch wrap a long channel list over several lines, and some tools
write one name per line. No public file with a wrapped section and a licence that allows
bundling was found, so the tests wrap the section of a real file
(``tests/data/formats/vbox/vb3i_imu_can.vbo``, 49 channels, its bytes otherwise unchanged:
Latin-1, CRLF) and read it against a second, independent reading: the data rows split by hand
in the order of the ``[header]`` section (whose titles are not the column names:
``latitude`` for ``lat``, ``velocity kmh`` for ``velocity``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.vbo import parse_vbo
from tests.conftest import DATA

VB3I = DATA / "formats" / "vbox" / "vb3i_imu_can.vbo"
# the file is GPL-3.0: in the repository, not in the sdist (tests/data/formats/README.md)
pytestmark = pytest.mark.skipif(not VB3I.exists(), reason="copyleft test file not shipped here")
RAW = VB3I.read_bytes().decode("latin-1") if VB3I.exists() else ""
LINES = RAW.split("\r\n")


def _wrapped(per_line: int, lines: list[str] = LINES) -> list[str]:
    """The file's lines with its one [column names] line wrapped to *per_line* names a line."""
    c = lines.index("[column names]") + 1
    names = lines[c].split()
    chunks = [" ".join(names[i : i + per_line]) for i in range(0, len(names), per_line)]
    return lines[:c] + chunks + lines[c + 1 :]


def _write(tmp_path, lines: list[str], name: str = "wrapped.vbo"):
    path = tmp_path / name
    path.write_bytes("\r\n".join(lines).encode("latin-1"))
    return path


def _by_header(lines: list[str]) -> tuple[list[str], np.ndarray]:
    """Second reading: [header] titles (one a line) and the data rows split on white space."""
    h = lines.index("[header]") + 1
    titles = []
    while lines[h].strip():
        titles.append(lines[h].strip())
        h += 1
    d = lines.index("[data]") + 1
    rows = [ln.split() for ln in lines[d:] if ln.strip()]
    assert all(len(r) == len(titles) for r in rows)
    return titles, np.array(rows, dtype=float)


@pytest.mark.parametrize("per_line", [10, 1, 48])
def test_a_wrapped_column_names_section_reads_every_row_by_the_header_order(tmp_path, per_line):
    """Wrapped at 10 names a line (5 lines), one name a line (49) and 48 + 1: every one of the
    100 data rows is read, and the values are those of the header-order hand reading."""
    lines = _wrapped(per_line)
    n_section = -(-49 // per_line)
    assert len(lines) == len(LINES) + n_section - 1
    log = read_log(_write(tmp_path, lines), columns="yaw_rate=YawRate,speed=AvgWhl_V")
    ep, rep = log.epochs, log.report
    titles, a = _by_header(lines)
    assert len(titles) == 49 and a.shape == (100, 49)
    assert len(ep) == 100 and rep.parsed == {"VBO data": 100} and rep.balanced
    assert sum(rep.rejected.values()) == 0
    col = {t: a[:, titles.index(t)] for t in ("latitude", "longitude", "heading", "YawRate")}
    np.testing.assert_allclose(ep["lat_deg"], col["latitude"] / 60, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ep["lon_deg"], -col["longitude"] / 60, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ep["course_deg"], col["heading"], rtol=0, atol=1e-12)
    # YawRate in °/s ([channel units], Latin-1, its blank neighbours kept in place)
    np.testing.assert_allclose(ep["yaw_rate_rps"], np.deg2rad(col["YawRate"]), rtol=1e-12)
    # AvgWhl_V [kph] mapped as speed: the 39th [header] title
    np.testing.assert_allclose(ep["speed_mps"], a[:, titles.index("AvgWhl_V")] / 3.6, rtol=1e-12)
    assert any(f"spans {n_section} lines" in n for n in rep.notes) == (n_section > 1)
    # the unwrapped original reads to the same epochs
    orig = read_log(VB3I, columns="yaw_rate=YawRate,speed=AvgWhl_V").epochs
    pd.testing.assert_frame_equal(ep, orig)
    # the CAN channel named twice is still found at its columns
    assert any("'SteeringWh'" in n and "columns 44 and 49" in n for n in rep.notes)


def test_a_name_with_a_space_split_by_the_wrap(tmp_path):
    """`battery vo` ([header] lists it on one line) with the wrap between its two words: one
    channel, every row read."""
    c = LINES.index("[column names]") + 1
    h = LINES.index("[header]") + 1
    lines = list(LINES)
    lines.insert(h + 49, "battery vo")  # after the 49 titles
    lines[c + 1] = lines[c + 1].rstrip() + " battery vo"
    d = lines.index("[data]") + 1
    for i in range(d, len(lines)):
        if lines[i].strip():
            lines[i] = lines[i].rstrip() + " 12.6"
    names = lines[c + 1].split()
    assert names[-2:] == ["battery", "vo"] and len(names) == 51
    wrapped = [*lines[: c + 1], " ".join(names[:50]), names[50], *lines[c + 2 :]]
    log = read_log(_write(tmp_path, wrapped))
    assert len(log.epochs) == 100 and log.report.balanced
    assert any("'battery vo'" in n for n in log.report.notes)


def test_a_mismatch_is_one_line_naming_file_section_and_counts(tmp_path):
    """A wrapped section that lost a name: one line naming the file, [column names], its
    count (and on how many lines), the rows' and [header]'s counts; on the command line a
    non-zero exit and no traceback. Before issue 43 the first line alone was taken."""
    lines = _wrapped(10)
    c = lines.index("[column names]") + 1
    lines[c + 2] = " ".join(lines[c + 2].split()[1:])  # 'Velocity_Quality' lost
    path = _write(tmp_path, lines, "lost.vbo")
    with pytest.raises(InputError) as e:
        read_log(path)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{path}:{c + 1}: [column names] has 48 names")
    assert "on 5 lines" in msg and "49 fields" in msg and "[header] lists 49" in msg
    from tests.cli.inprocess import cli

    r = cli("ingest", path)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    err = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(err) == 1 and "lost.vbo" in err[0] and "[column names] has 48 names" in err[0]


def test_the_wrapped_file_through_the_command_line_is_quiet(tmp_path):
    from tests.cli.inprocess import cli

    r = cli("ingest", _write(tmp_path, _wrapped(10)))
    assert r.returncode == 0, r.stderr
    assert "100 epochs" in r.stdout and r.stderr.strip() == ""


def test_one_line_sections_are_unchanged():
    """The files read before (one [column names] line) give no note about lines."""
    log = parse_vbo(RAW, "vb3i.vbo")
    assert len(log.epochs) == 100 and not any("spans" in n for n in log.report.notes)
