"""Ingest rules on constructed input: reject reasons, sign conventions, sources, strict mode.

Sentences are built with an independent checksum helper (tests/nmea_helpers.py).
"""

from __future__ import annotations

import gzip
import io
import math

import numpy as np
import pandas as pd
import pytest

from gripsense import InputError, read_nmea
from tests.conftest import GPSD_LOGS
from tests.nmea_helpers import sentence


def test_psat_hpr_with_blank_fields():
    # Hemisphere $PSAT,HPR: time, heading, pitch, roll, type (N = GNSS, G = gyro)
    lines = [
        sentence("PSAT,HPR,123456.70,271.25,-1.50,,N"),
        sentence("GPGGA,123456.70,3500.0000,N,13500.0000,E,4,12,0.8,10.0,M,30.0,M,,"),
        sentence("PSAT,HPR,123456.80,,,,G"),
    ]
    log = read_nmea(lines)
    ep = log.epochs
    assert log.report.parsed == {"GGA": 1, "PSAT,HPR": 2}
    assert len(ep) == 2
    assert ep["heading_deg"].iloc[0] == 271.25 and ep["heading_source"].iloc[0] == "HPR"
    assert ep["pitch_deg"].iloc[0] == -1.5 and math.isnan(ep["roll_deg"].iloc[0])
    assert ep["lat_deg"].iloc[0] == 35.0 and ep["lon_deg"].iloc[0] == 135.0
    assert math.isnan(ep["heading_deg"].iloc[1])  # blank heading is NaN, never 0
    assert ep["t_s"].iloc[1] == pytest.approx(0.1, abs=1e-9)


def test_pashr_fields():
    line = sentence("PASHR,204132.000,010.51,T,+00.39,-00.79,-00.84,0.151,0.075,0.555,1,0")
    ep = read_nmea([line]).epochs
    assert ep["heading_deg"].iloc[0] == 10.51
    assert ep["roll_deg"].iloc[0] == 0.39 and ep["pitch_deg"].iloc[0] == -0.79
    assert ep["heading_source"].iloc[0] == "PASHR"


@pytest.mark.parametrize("engine", ["fast", "reference"])
def test_psti_036_fields(engine):
    """SkyTraq heading receivers (PX1172RH): GPSD's own example sentence (its checksum 4D is
    the one GPSD prints); heading, pitch and roll only with a fixed-RTK baseline (mode R)."""
    lines = [
        "$PSTI,036,054314.000,030521,191.69,-16.35,0.00,R*4D",
        sentence("PSTI,036,054314.100,030521,191.89,-16.30,0.10,F"),
        sentence("PSTI,030,054314.100,A,2447.0,N,12100.0,E,1,0,0,0,030521,R,1,2"),
    ]
    log = read_nmea(lines, engine=engine)
    assert log.report.parsed == {"PSTI,036": 2}
    assert log.report.ignored == {"PSTI,030 (proprietary, not used)": 1}
    ep = log.epochs
    assert ep["heading_deg"].iloc[0] == 191.69 and ep["heading_source"].iloc[0] == "PSTI"
    assert ep["pitch_deg"].iloc[0] == -16.35 and ep["roll_deg"].iloc[0] == 0.0
    assert ep["time_utc"].iloc[0].isoformat().startswith("2021-05-03T05:43:14")
    assert np.isnan(ep["heading_deg"].iloc[1])  # float RTK: not used


def _left_turn(with_rot: bool):
    """A vehicle turning left at 10 deg/s: compass heading falls, NMEA ROT is negative (port)."""
    lines = []
    for k in range(11):
        t = 0.1 * k
        hdg = (5.0 - 10.0 * t) % 360.0  # crosses north: tests unwrapping
        hh = f"1200{t:05.2f}"
        lines.append(sentence(f"GPRMC,{hh},A,3500.0000,N,13500.0000,E,20.0,{hdg:.2f},010120,,,A"))
        lines.append(sentence(f"GPHDT,{hdg:.3f},T"))
        if with_rot:
            lines.append(sentence("GPROT,-600.0,A"))  # 10 deg/s = 600 deg/min to port
    return lines


@pytest.mark.parametrize("with_rot", [True, False])
def test_left_turn_sign(with_rot):
    ep = read_nmea(_left_turn(with_rot)).epochs
    assert len(ep) == 11
    expected = math.radians(10.0)  # ISO 8855: counter-clockwise (left) positive
    np.testing.assert_allclose(ep["yaw_rate_rps"], expected, rtol=1e-6)
    assert (ep["yaw_rate_source"] == ("ROT" if with_rot else "heading")).all()
    if with_rot:
        assert (ep["rot_deg_per_min"] < 0).all()


def test_rot_unit_trap():
    # 0.2778 rad/s is 955 deg/min (docs/physics.md section 3.2)
    ep = read_nmea(
        [
            sentence("GPRMC,120000.00,A,3500.0,N,13500.0,E,1.0,0.0,010120,,,A"),
            sentence("GPROT,-955.0,A"),
        ]
    ).epochs
    assert ep["yaw_rate_rps"].iloc[0] == pytest.approx(0.2778, abs=1e-4)


def test_invalid_flags_give_nan():
    lines = [
        sentence("GPRMC,120000.00,V,3500.0,N,13500.0,E,1.0,10.0,010120,,,N"),
        sentence("GNTHS,123.4,V"),
        sentence("GPROT,12.0,V"),
        sentence("GPVTG,10.0,T,,M,1.0,N,1.852,K,N"),
    ]
    ep = read_nmea(lines).epochs
    assert len(ep) == 1
    for c in ("lat_deg", "speed_mps", "course_deg", "heading_deg", "rot_deg_per_min"):
        assert math.isnan(ep[c].iloc[0]), c


def test_vtg_kmh_fallback():
    ep = read_nmea([sentence("GPVTG,10.0,T,,M,,N,36.0,K,A")]).epochs
    assert ep["speed_mps"].iloc[0] == pytest.approx(10.0)


@pytest.mark.parametrize(
    ("line", "bucket", "kind"),
    [
        ("", "ignored", "(blank)"),
        ("# comment", "ignored", "(comment)"),
        ('{"class":"VERSION"}', "rejected", "not NMEA"),
        ("hello", "rejected", "not NMEA"),
        ("$gpgga,1*00", "rejected", "not NMEA"),
        ("$GPHDT,274.07,T", "rejected", "missing checksum"),
        ("$GPGGA,120000.00,3500.0", "rejected", "truncated"),
        ("$GPHDT,274.07,T*0", "rejected", "truncated"),
        ("$GPHDT,274.07,T*04", "rejected", "bad checksum"),
        ("$GPHDT,274.07,T*0G", "rejected", "bad checksum"),
        (sentence("GPHDT,27x.07,T"), "rejected", "malformed field"),
        (
            sentence("GPGGA,126000.00,3500.0,N,13500.0,E,1,08,1.0,1.0,M,,M,,"),
            "rejected",
            "malformed field",
        ),
        (
            sentence("GPGGA,120000.00,3500.0,,13500.0,E,1,08,1.0,1.0,M,,M,,"),
            "rejected",
            "malformed field",
        ),
        (
            sentence("GPRMC,120000.00,A,3500.0,N,13500.0,E,1.0,10.0,320120,,,A"),
            "rejected",
            "malformed field",
        ),
        (sentence("GPZDA,120000.00,29,02,2021,00,00"), "rejected", "malformed field"),
        (sentence("GPGGA,120000.00,3500.0,N"), "rejected", "truncated"),
        (sentence("GPGSV,1,1,00"), "ignored", "GSV"),
        (sentence("PSTI,030,1"), "ignored", "PSTI,030 (proprietary, not used)"),
        (sentence("PSAT,GBS,1"), "ignored", "PSAT,GBS (proprietary, not used)"),
        (sentence("AIVDM,1,1,,B,13aGhtw0R", "!"), "ignored", "VDM"),
        ("\x00\xff" + sentence("GPHDT,274.07,T"), "parsed", "HDT"),
    ],
)
@pytest.mark.parametrize("engine", ["fast", "reference"])
def test_line_buckets(line, bucket, kind, engine):
    log = read_nmea([line.encode("latin-1")], engine=engine)
    rep = log.report
    assert rep.total_lines == 1 and rep.balanced
    counts = {"parsed": rep.parsed, "ignored": rep.ignored, "rejected": rep.rejected}[bucket]
    assert counts.get(kind) == 1, rep
    if bucket == "rejected":
        assert rep.first_rejects[0].line == 1 and rep.first_rejects[0].reason == kind
        assert rep.first_rejects[0].detail


def test_leap_february_date_ok():
    log = read_nmea([sentence("GPZDA,120000.00,29,02,2020,00,00")])
    assert str(log.epochs["time_utc"].iloc[0]) == "2020-02-29 12:00:00+00:00"


def test_strict_names_file_line_reason(tmp_path):
    p = tmp_path / "drive.nmea"
    p.write_text(sentence("GPHDT,1.0,T") + "\n" + "$GPHDT,2.0,T*00\n")
    with pytest.raises(InputError, match=r"drive\.nmea:2: bad checksum"):
        read_nmea(p, strict=True)
    assert read_nmea(p).report.rejected["bad checksum"] == 1


def test_sources_agree(tmp_path):
    path = next(p for p in GPSD_LOGS if p.stem == "saab-r4")
    data = path.read_bytes()
    gz = tmp_path / "saab.log.gz"
    gz.write_bytes(gzip.compress(data))
    ref = read_nmea(path)
    others = [
        read_nmea(gz),
        read_nmea(str(path)),
        read_nmea(io.BytesIO(data)),
        read_nmea(io.StringIO(data.decode("latin-1"))),
        read_nmea(data.decode("latin-1").splitlines()),
        read_nmea(data.splitlines(keepends=True)),
    ]
    for o in others:
        assert o.report.total_lines == ref.report.total_lines
        assert o.report.parsed == ref.report.parsed
        assert o.epochs.equals(ref.epochs)


def test_binary_starting_like_gzip_is_read_as_it_is():
    """A receiver stream whose first bytes are gzip's magic (UBX can be) is not an error: its
    lines are read and accounted for, and the notes say why it was not decompressed."""
    good = sentence("GPHDT,1.0,T")
    data = b"\x1f\x8b!\x00\x00q\x01\xcb\n" + good.encode() + b"\n"
    log = read_nmea(data)
    assert log.report.total_lines == 2
    assert log.report.parsed == {"HDT": 1} and log.report.n_rejected == 1
    assert any("not a gzip stream" in n for n in log.report.notes)


def test_damaged_gzip_file_is_one_clear_error(tmp_path):
    """A file named .gz whose stream cannot be decompressed from its start is an error that
    names the file (not a table of rejected binary lines)."""
    good = gzip.compress((sentence("GPHDT,1.0,T") + "\n").encode() * 50)
    p = tmp_path / "drive.nmea.gz"
    p.write_bytes(good[:10] + bytes(40) + good[50:])
    with pytest.raises(InputError, match=r"drive\.nmea\.gz: named gzip but cannot be decompressed"):
        read_nmea(p)


def test_missing_file_and_bad_source():
    with pytest.raises(InputError, match="no such file"):
        read_nmea("/nonexistent/drive.nmea")
    with pytest.raises(InputError, match="not supported"):
        read_nmea(12345)
    with pytest.raises(InputError, match="engine"):
        read_nmea([], engine="turbo")


def test_empty_input():
    log = read_nmea([])
    assert log.report.total_lines == 0 and len(log.epochs) == 0


def test_crlf_and_no_final_newline():
    a = sentence("GPHDT,1.0,T")
    b = sentence("GPHDT,2.0,T")
    log = read_nmea((a + "\r\n" + b).encode())
    assert log.report.parsed == {"HDT": 2} and log.report.total_lines == 2


# --- epoch grouping on real receiver orders ------------------------------------------------


def test_hemisphere_heading_joins_following_fix():
    """Hemisphere sends HDT, GGA, VTG[, ZDA] per epoch: HDT belongs to the GGA after it."""
    log = read_nmea(next(p for p in GPSD_LOGS if p.stem == "hemi"))
    hdt, gga = log.sentences["HDT"], log.sentences["GGA"]
    gga_epoch_by_line = dict(zip(gga["line"], gga["epoch"], strict=True))
    for row in hdt.itertuples(index=False):
        nxt = row.line + 1  # the GGA line follows the HDT line in this log
        # (an empty $GPHDT,,T carries nothing and joins the epoch before it instead)
        if nxt in gga_epoch_by_line and not math.isnan(row.heading_deg):
            assert row.epoch == gga_epoch_by_line[nxt]


def test_saab_heading_joins_preceding_fix():
    """Saab R4 sends ZDA, GLL, GGA, VTG, RMC, DTM, HDT, ROT: HDT and ROT join that RMC."""
    log = read_nmea(next(p for p in GPSD_LOGS if p.stem == "saab-r4"))
    rmc = log.sentences["RMC"]
    for key in ("HDT", "ROT"):
        f = log.sentences[key]
        for row in f.itertuples(index=False):
            prev = rmc[rmc["line"] < row.line].iloc[-1]
            assert row.epoch == prev["epoch"]
    assert len(log.epochs) == 12 and log.report.epochs_without_time == 0


def test_lines_at_is_split_lines():
    from gripsense.io.logs.nmea.tokens import lines_at, split_lines

    for data in (b"", b"a", b"a\n", b"a\nb", b"\n\nx\r\n\ny", b"$GP\n\n\n"):
        lines = split_lines(data)
        assert lines_at(data, range(len(lines))) == dict(enumerate(lines))
        assert lines_at(data, [len(lines) - 1, 0] if lines else []) == (
            {0: lines[0], len(lines) - 1: lines[-1]} if lines else {}
        )


def test_dates_carry_across_midnight_both_ways():
    """An epoch's date is its own, else carried from the nearest earlier dated epoch (before
    the first date: from the first one), counting midnight roll-overs in between; without any
    date the times stay continuous (t_s) and time_utc is NaT."""

    def gga(t):
        return sentence(f"GPGGA,{t},3500.0000,N,13500.0000,E,1,12,0.8,10.0,M,30.0,M,,")

    rmc = sentence("GPRMC,000002.00,A,3500.0,N,13500.0,E,1.0,0.0,010125,,,A")
    lines = [gga("235958.00"), gga("235959.00"), gga("000001.00"), rmc, gga("000003.00")]
    ep = read_nmea(lines).epochs
    want = pd.to_datetime(
        [
            "2024-12-31 23:59:58",
            "2024-12-31 23:59:59",
            "2025-01-01 00:00:01",
            "2025-01-01 00:00:02",
            "2025-01-01 00:00:03",
        ],
        utc=True,
    )
    assert list(ep["time_utc"]) == list(want)
    np.testing.assert_allclose(ep["t_s"], [0.0, 1.0, 3.0, 4.0, 5.0])
    later = [sentence("GPRMC,235959.00,A,3500.0,N,13500.0,E,1.0,0.0,311224,,,A")]
    ep = read_nmea([*later, gga("000000.50"), gga("235959.50")]).epochs
    assert str(ep["time_utc"].iloc[1]) == "2025-01-01 00:00:00.500000+00:00"
    # a fall of more than 12 h again: the next day
    assert str(ep["time_utc"].iloc[2]) == "2025-01-01 23:59:59.500000+00:00"
    undated = read_nmea([gga("235959.00"), gga("000001.00")])
    assert not undated.report.has_date and ep["time_utc"].notna().all()
    assert undated.epochs["time_utc"].isna().all()
    np.testing.assert_allclose(undated.epochs["t_s"], [0.0, 2.0])
