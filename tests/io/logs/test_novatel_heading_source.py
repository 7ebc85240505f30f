"""NovAtel headings name the log that gave them (issue 43): ``heading_source`` is ``HEADING2``,
``DUALANTENNAHEADING``, ``HEADING``, ``INSPVA``, ``INSPVAS`` or ``INSPVAX`` — before, every
NovAtel heading said ``channel`` (the category of a channel the user mapped), because the
categories lived in the NMEA reader. The reference is a hand parse of the real receiver lines
(``driver_lines.asc``, see ``tests/data/formats/README.md``): the log name and the heading field
of the OEM7 manual's field order, matched by the header's GPS week and seconds.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import gripsense.io.logs.sources as sources
from gripsense.io import read_nmea
from gripsense.io.logs.novatel import parse_novatel
from gripsense.io.logs.sources import HEADING_SOURCES
from tests.io.logs.test_novatel import _manual_crc

DRIVERS = Path(__file__).resolve().parents[2] / "data" / "formats" / "novatel" / "driver_lines.asc"
# body field of the heading: HEADING/HEADING2/DUALANTENNAHEADING (sol, pos type, length,
# heading …) and INSPVA/INSPVAS (week, seconds, lat, lon, height, vn, ve, vu, roll, pitch, azimuth)
HEADING_FIELD = {"HEADING2": 3, "DUALANTENNAHEADING": 3, "INSPVA": 10, "INSPVAS": 10}


def _hand(line: str) -> tuple[str, float, float, float]:
    """Log name (without the A suffix), GPS week, seconds and heading of one ASCII line."""
    head, body = line.lstrip("#%").split("*")[0].split(";")
    h = head.split(",")
    name = h[0][:-1]
    week, sec = (float(h[1]), float(h[2])) if line.startswith("%") else (float(h[5]), float(h[6]))
    return name, week, sec, float(body.split(",")[HEADING_FIELD[name]])


def test_dual_antenna_headings_name_their_log():
    lines = DRIVERS.read_text(encoding="ascii").splitlines()
    ref = [_hand(ln) for ln in lines if ln[1:].startswith(("HEADING2A", "DUALANTENNAHEADINGA"))]
    assert {r[0] for r in ref} == {"HEADING2", "DUALANTENNAHEADING"}
    ep = parse_novatel(DRIVERS.read_bytes(), "d.asc").epochs
    got = ep[ep["heading_deg"].notna()]
    assert len(got) == len({(r[1], r[2]) for r in ref})  # each pair of lines is one epoch
    for name, _, _, hdg in ref:
        row = got[np.isclose(got["heading_deg"], hdg, atol=1e-9)]
        assert len(row) == 1 and row["heading_source"].iloc[0] == name
    assert "channel" not in set(got["heading_source"].astype(str))


@pytest.mark.parametrize("name", ["INSPVA", "INSPVAS"])
def test_ins_azimuth_names_its_log(name):
    """A log without HEADING/HEADING2: the INS azimuth is the heading, named after its log. The
    real INSPVAA line of SwRI's driver tests (INS_ALIGNMENT_COMPLETE); INSPVAS: the same body under
    the short header, its CRC by the manual's algorithm."""
    lines = DRIVERS.read_text(encoding="ascii").splitlines()
    line = next(ln for ln in lines if ln.startswith("#INSPVAA") and "WAITING" not in ln)
    if name == "INSPVAS":
        head, body = line[1:].split("*")[0].split(";")
        h = head.split(",")
        msg = f"INSPVASA,{h[5]},{h[6]};{body}"
        line = f"%{msg}*{_manual_crc(msg.encode()):08x}"
    _, _, _, azimuth = _hand(line)
    log = parse_novatel((line + "\r\n").encode(), "i.asc")
    ep = log.epochs
    assert log.report.parsed == {f"NovAtel {name}": 1}
    assert len(ep) == 1
    assert ep["heading_deg"].iloc[0] == pytest.approx(azimuth, abs=1e-9)
    assert ep["heading_source"].iloc[0] == name


def test_the_manuals_inspvax_example_names_inspvax():
    ins = (
        b"#INSPVAXA,COM1,0,73.5,FINESTEERING,1695,309428.000,00000040,4e77,43562;"
        b"INS_SOLUTION_GOOD,INS_PSRSP,51.11637873403,-114.03825114994,1063.6093,-16.9000,"
        b"-0.0845,-0.0464,-0.0127,0.138023492,0.069459386,90.000923268,0.9428,0.6688,1.4746,"
        b"0.0430,0.0518,0.0521,0.944295466,0.944567084,1.000131845,3,0*e877c178"
    )
    ep = parse_novatel(ins + b"\r\n", "x.asc").epochs
    assert ep["heading_source"].tolist() == ["INSPVAX"]


def test_an_epoch_without_heading_has_no_source():
    bestpos = DRIVERS.read_text(encoding="ascii").splitlines()[0]
    ep = parse_novatel((bestpos + "\r\n").encode(), "b.asc").epochs
    assert ep["heading_deg"].isna().all() and ep["heading_source"].isna().all()


def test_one_list_of_categories_for_every_reader():
    """NMEA and NovAtel tables carry the same categories, from a module that imports no other
    gripsense module (both rooms import it; it imports neither)."""
    nmea = read_nmea(["$GPHDT,274.07,T*03"]).epochs
    nov = parse_novatel(DRIVERS.read_bytes(), "d.asc").epochs
    assert list(nmea["heading_source"].cat.categories) == HEADING_SOURCES
    assert list(nov["heading_source"].cat.categories) == HEADING_SOURCES
    assert nmea["heading_source"].iloc[0] == "HDT"
    tree = ast.parse(Path(sources.__file__).read_text(encoding="utf-8"))
    imported = [
        n.module if isinstance(n, ast.ImportFrom) else a.name
        for n in ast.walk(tree)
        if isinstance(n, ast.Import | ast.ImportFrom)
        for a in (n.names if isinstance(n, ast.Import) else [n])
    ]
    assert not [m for m in imported if m and m.startswith("gripsense")]
    assert len(set(HEADING_SOURCES)) == len(HEADING_SOURCES)
