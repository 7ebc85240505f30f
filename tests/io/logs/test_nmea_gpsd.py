"""Ingest of real receiver logs checked against GPSD's own decodes and pynmeagps.

Reference: the GPSD project's regression suite (tests/data/gpsd, BSD-2-Clause, see COPYING):
each X.log is a real capture, X.log.chk is what gpsd reported for it (JSON TPV / ATT objects).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from gripsense.io import read_nmea
from tests.conftest import GPSD_LOGS
from tests.nmea_helpers import gpsd_reports

KNOT = 0.514444444  # m/s per knot, the constant gpsd uses (KNOTS_TO_MPS)


def _line_index(log):
    """Map 1-based line number -> (sentence type, row) for every parsed sentence."""
    idx = {}
    for key, frame in log.sentences.items():
        for row in frame.itertuples(index=False):
            idx[row.line] = (key, row)
    return idx


def test_every_line_accounted(gpsd_log):
    data = gpsd_log.read_bytes()
    n_lines = data.count(b"\n") + (0 if data.endswith(b"\n") else 1)
    log = read_nmea(gpsd_log)
    rep = log.report
    assert rep.total_lines == n_lines
    assert rep.n_parsed + rep.n_ignored + rep.n_rejected == n_lines
    assert rep.balanced
    # every parsed sentence is in exactly one epoch
    n_sent = sum(len(f) for f in log.sentences.values())
    assert n_sent == rep.n_parsed
    for f in log.sentences.values():
        assert f["epoch"].between(0, len(log.epochs) - 1).all()


@pytest.mark.parametrize("engine", ["fast", "reference"])
def test_agrees_with_gpsd(gpsd_log, engine):
    chk = gpsd_log.with_suffix(".log.chk")
    reports = gpsd_reports(chk, gpsd_log)
    log = read_nmea(gpsd_log, engine=engine)
    idx = _line_index(log)
    ep = log.epochs
    checked = {
        "latlon": 0,
        "epoch_latlon": 0,
        "speed": 0,
        "track": 0,
        "heading": 0,
        "rot": 0,
        "time": 0,
    }
    for no, trig, rep in reports:
        if no not in idx:
            continue
        key, row = idx[no]
        if rep["class"] == "TPV":
            # gpsd's report for time T and our epoch at time T hold the same position
            e_lat = ep["lat_deg"].iloc[row.epoch]
            e_t = ep["time_utc"].iloc[row.epoch]
            same_t = (
                "time" in rep
                and e_t is not pd.NaT
                and rep["time"][11:23] == (e_t.strftime("%H:%M:%S.%f")[:12])
            )
            if "lat" in rep and same_t and not math.isnan(e_lat):
                assert e_lat == pytest.approx(rep["lat"], abs=6e-10), (no, trig)
                assert ep["lon_deg"].iloc[row.epoch] == pytest.approx(rep["lon"], abs=6e-10)
                checked["epoch_latlon"] += 1
            if key in ("GGA", "RMC") and "lat" in rep:
                # gpsd prints 9 decimals
                assert row.lat_deg == pytest.approx(rep["lat"], abs=6e-10), (no, trig)
                assert row.lon_deg == pytest.approx(rep["lon"], abs=6e-10), (no, trig)
                assert ep["lat_deg"].iloc[row.epoch] == pytest.approx(rep["lat"], abs=6e-10)
                checked["latlon"] += 1
            if key in ("RMC", "VTG") and "speed" in rep and not math.isnan(row.speed_mps):
                assert row.speed_mps == pytest.approx(rep["speed"], abs=6e-4), (no, trig)
                checked["speed"] += 1
            if key in ("RMC", "VTG") and "track" in rep and not math.isnan(row.course_deg):
                assert row.course_deg == pytest.approx(rep["track"], abs=6e-5), (no, trig)
                checked["track"] += 1
            if key in ("GGA", "RMC") and "time" in rep and not math.isnan(row.tod_s):
                hh, mm, ss = rep["time"][11:-1].split(":")
                tod = int(hh) * 3600 + int(mm) * 60 + float(ss)
                assert row.tod_s == pytest.approx(tod, abs=1e-3), (no, trig)
                checked["time"] += 1
        elif rep["class"] == "ATT":
            if key in ("HDT", "THS") and "heading" in rep:
                assert row.heading_deg == pytest.approx(rep["heading"], abs=6e-4), (no, trig)
                checked["heading"] += 1
            if key == "ROT" and "rot" in rep:
                assert row.rot_deg_per_min == pytest.approx(rep["rot"], abs=6e-4), (no, trig)
                checked["rot"] += 1
    # how many of gpsd's reports each log must have been checked against (floor of what it has)
    minimum = {
        "hemi": {"epoch_latlon": 15, "speed": 6, "heading": 4, "time": 20},
        "pypilot": {"rot": 7},
        "quectel-l76k-dual": {"epoch_latlon": 130},
        "rst39": {"latlon": 40, "speed": 4, "heading": 4},
        "saab-r4": {"latlon": 12, "speed": 12, "track": 12, "heading": 12, "rot": 12},
        "skytraq-PX1172RH_DS": {"epoch_latlon": 2, "heading": 1},
        "telit-he910": {"latlon": 188, "epoch_latlon": 373, "speed": 373, "track": 373},
    }.get(gpsd_log.stem, {})
    for k, v in minimum.items():
        assert checked[k] >= v, (k, checked)


def test_gpsd_heading_in_epochs():
    """Epoch heading equals the HDT/THS value of that epoch's line (saab, skytraq, hemi)."""
    for name in ("saab-r4", "skytraq-PX1172RH_DS", "hemi"):
        path = next(p for p in GPSD_LOGS if p.stem == name)
        log = read_nmea(path)
        hdt = log.sentences["HDT"].dropna(subset=["heading_deg"])
        ths = log.sentences["THS"]
        for f in (hdt, ths):
            for row in f.itertuples(index=False):
                src = log.epochs["heading_source"].iloc[row.epoch]
                if src == ("THS" if f is ths else "HDT"):
                    assert log.epochs["heading_deg"].iloc[row.epoch] == row.heading_deg


def test_saab_rot_sign():
    """Saab R4 sends $HEROT; the epoch's ROT is that value and yaw rate its ISO counterpart."""
    log = read_nmea(next(p for p in GPSD_LOGS if p.stem == "saab-r4"))
    ep = log.epochs
    assert (ep["yaw_rate_source"] == "ROT").all()
    np.testing.assert_allclose(
        ep["yaw_rate_rps"], -ep["rot_deg_per_min"] * math.pi / 10800.0, atol=0
    )


# ---------------------------------------------------------------------------------------------
# Differential test against pynmeagps (an independent parser), every sentence of every log.

pynmeagps = pytest.importorskip("pynmeagps")


def _pyn(line: str):
    return pynmeagps.NMEAReader.parse(line, validate=pynmeagps.VALCKSUM)


def _num(x):
    return float("nan") if x in ("", None) else float(x)


def _eq(a, b, tol):
    if math.isnan(a) and math.isnan(_num(b)):
        return True
    return abs(a - _num(b)) <= tol


@pytest.mark.parametrize("path", GPSD_LOGS, ids=lambda p: p.stem)
def test_against_pynmeagps(path):
    log = read_nmea(path)
    lines = path.read_bytes().split(b"\n")
    n = 0
    for key, frame in log.sentences.items():
        for row in frame.itertuples(index=False):
            raw = lines[row.line - 1].rstrip(b"\r")
            start = max(raw.rfind(b"$"), 0)
            text = raw[start:].decode("ascii")
            msg = _pyn(text)
            if key == "GGA":
                assert _eq(row.lat_deg, msg.lat, 1e-9) and _eq(row.lon_deg, msg.lon, 1e-9), text
                assert _eq(row.alt_m, msg.alt, 1e-9) and _eq(row.hdop, msg.HDOP, 1e-9), text
                assert _eq(row.fix_quality, msg.quality, 0) and _eq(row.n_sats, msg.numSV, 0), text
            elif key == "RMC":
                assert _eq(row.lat_deg, msg.lat, 1e-9) and _eq(row.lon_deg, msg.lon, 1e-9), text
                spd = _num(msg.spd) * 1852 / 3600
                assert (math.isnan(row.speed_mps) and math.isnan(spd)) or abs(
                    row.speed_mps - spd
                ) < 1e-12, text
                assert _eq(row.course_deg, msg.cog, 1e-12), text
                if msg.date not in ("", None):
                    assert row.day == (msg.date - __import__("datetime").date(1970, 1, 1)).days
            elif key == "VTG":
                if row.mode != "N":
                    assert _eq(row.course_deg, msg.cogt, 1e-12), text
                    spd = _num(msg.sogn) * 1852 / 3600
                    if not math.isnan(spd):
                        assert abs(row.speed_mps - spd) < 1e-12, text
            elif key == "HDT":
                assert _eq(row.heading_deg, msg.headingT, 1e-12), text
            elif key == "THS":
                assert _eq(row.heading_deg, msg.headt, 1e-12), text
            elif key == "ROT":
                assert _eq(row.rot_deg_per_min, msg.rot, 1e-12), text
            elif key == "ZDA":
                t = msg.time
                tod = t.hour * 3600 + t.minute * 60 + t.second + t.microsecond / 1e6
                assert abs(row.tod_s - tod) < 1e-6, text
                d = __import__("datetime").date(int(msg.year), int(msg.month), int(msg.day))
                assert row.day == (d - __import__("datetime").date(1970, 1, 1)).days
            elif key == "PASHR":
                assert _eq(row.heading_deg, msg.trueHdg, 1e-12), text
                assert _eq(row.roll_deg, msg.roll, 1e-12), text
                assert _eq(row.pitch_deg, msg.pitch, 1e-12), text
            n += 1
    assert n == log.report.n_parsed
