"""NovAtel OEM ASCII logs: real receiver lines from NovAtel's and SwRI's driver test data
(``tests/data/formats/README.md``), checked against a hand parse of the documented field order,
NovAtel's CRC-32 as the OEM7 manual writes it, the receiver's own TIMEA UTC, and a simulated
drive written as NovAtel ASCII against its NMEA."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.errors import InputError
from gripsense.io import read_log, read_nmea
from gripsense.io.logs import detect_format
from gripsense.io.logs.novatel import crc32, gps_to_utc, is_novatel, parse_novatel, write_novatel

DATA = Path(__file__).resolve().parents[2] / "data" / "formats" / "novatel"
STARTUP = DATA / "edie_startup.asc"  # an OEM7 receiver's first 15 s: TIMEA + BESTPOSA at 1 Hz
DRIVERS = DATA / "driver_lines.asc"  # BESTPOS, HEADING2, DUALANTENNAHEADING, INSPVA(S) lines


def _manual_crc(data: bytes) -> int:
    """CRC32Value / CalculateBlockCRC32 of the OEM7 Commands and Logs Reference Manual,
    transcribed bit by bit (polynomial 0xEDB88320, register starting at 0)."""
    crc = 0
    for byte in data:
        temp1 = (crc >> 8) & 0x00FFFFFF
        ulcrc = (crc ^ byte) & 0xFF
        for _ in range(8):
            ulcrc = (ulcrc >> 1) ^ 0xEDB88320 if ulcrc & 1 else ulcrc >> 1
        crc = temp1 ^ ulcrc
    return crc


def _lines(path: Path) -> list[str]:
    return path.read_text(encoding="ascii").splitlines()


def test_every_real_crc_passes_and_equals_the_manuals_algorithm():
    lines = _lines(STARTUP) + _lines(DRIVERS)
    assert len(lines) == 44
    for ln in lines:
        body, _, want = ln[1:].rpartition("*")
        assert _manual_crc(body.encode()) == int(want, 16), ln
        assert crc32(body.encode()) == int(want, 16)


def test_today_a_novatel_log_was_nmea_comments_now_its_own_format():
    """Before the NovAtel reader every line was an NMEA comment ("nothing usable")."""
    nmea = read_nmea(DRIVERS)
    assert nmea.report.n_parsed == 0 and len(nmea.epochs) == 0
    head = DRIVERS.read_bytes()[:65536]
    assert detect_format(head) == "novatel"
    log = read_log(DRIVERS)
    assert log.report.format == "NovAtel ASCII" and log.report.n_parsed == 12
    assert log.report.balanced and log.report.n_rejected == 0


def _hand(path: Path, log: str) -> list[dict]:
    """The documented field order (OEM7 manual, BESTPOS / HEADING2 / DUALANTENNAHEADING),
    split by hand: header ``;`` body ``*`` CRC, header week at 5 and seconds at 6."""
    out = []
    for no, ln in enumerate(_lines(path), 1):
        if not ln.startswith(f"#{log}A,"):
            continue
        head, body = ln[1:].split("*")[0].split(";")
        h, f = head.split(","), body.split(",")
        if f[0] != "SOL_COMPUTED" or h[4] == "UNKNOWN":
            continue
        row = {"line": no, "week": int(h[5]), "seconds": float(h[6])}
        if log == "BESTPOS":
            row |= {"lat_deg": float(f[2]), "lon_deg": float(f[3]), "alt_m": float(f[4]),
                    "n_sats": float(f[14])}  # fmt: skip
        else:
            row |= {"heading_deg": float(f[3]), "heading_acc_deg": float(f[6])}
        out.append(row)
    return out


@pytest.mark.parametrize(
    "path, log",
    [
        (STARTUP, "BESTPOS"),
        (DRIVERS, "BESTPOS"),
        (DRIVERS, "HEADING2"),
        (DRIVERS, "DUALANTENNAHEADING"),
    ],
)
def test_decoded_fields_equal_a_hand_parse(path, log):
    want = pd.DataFrame(_hand(path, log))
    got = read_log(path).sentences[f"NovAtel {log}"]
    assert len(want) > 0 and len(got) == len(want)
    for c in want.columns:
        np.testing.assert_array_equal(got[c].to_numpy(float), want[c].to_numpy(float), err_msg=c)


def test_utc_equals_the_receivers_own_timea():
    """TIMEA carries the receiver's UTC date and time for its GPS week and seconds: every
    BESTPOS epoch's UTC from the leap-second table equals it to its clock's millisecond (2021:
    GPS − UTC = 18 s; a wrong leap second would be 1000 ms off)."""
    utc = {}
    for ln in _lines(STARTUP):
        if (
            ln.startswith("#TIMEA,")
            and ln.split("*")[0].endswith("VALID")
            and ",UNKNOWN," not in ln
        ):
            h, f = ln[1:].split("*")[0].split(";")
            h, f = h.split(","), f.split(",")
            y, mo, d, hh, mm, ms = (int(x) for x in f[4:10])
            stamp = pd.Timestamp(y, mo, d, hh, mm, tz="UTC") + pd.Timedelta(milliseconds=ms)
            utc[float(h[6])] = stamp
    log = read_log(STARTUP)
    pos = log.sentences["NovAtel BESTPOS"]
    t = log.epochs["time_utc"]
    assert len(pos) == len(t) == 12
    matched = 0
    for sec, when in zip(pos["seconds"], t, strict=True):
        if sec in utc:
            # the receiver's UTC milliseconds carry its clock offset while steering (≤ 1 ms)
            assert abs(when - utc[sec]) <= pd.Timedelta(milliseconds=1)
            matched += 1
    assert matched == 12
    assert log.report.ignored["NovAtel TIME"] == 15
    assert log.report.ignored["NovAtel BESTPOS (receiver time unknown)"] == 2


def test_gps_to_utc_across_the_2017_leap_second():
    """GPS week 1930 starts 2017-01-01 00:00:00 GPS; UTC midnight is 18 s into it, the second
    before midnight 16 s into it (GPS − UTC 17 s until then)."""
    t = gps_to_utc(np.array([1930, 1930, 1929]), np.array([18.0, 16.0, 604_799.0]))
    want = pd.to_datetime(["2017-01-01 00:00:00", "2016-12-31 23:59:59", "2016-12-31 23:59:42"])
    np.testing.assert_array_equal(t, (want - pd.Timestamp("1970-01-01")).total_seconds())


def test_a_corrupted_line_is_rejected_with_bad_crc():
    lines = _lines(DRIVERS)
    lines[10] = lines[10].replace("178.347869873", "178.347869874")
    log = parse_novatel("\r\n".join(lines).encode() + b"\r\n", "d.asc")
    r = log.report
    assert r.rejected["bad checksum"] == 1 and r.balanced
    assert r.first_rejects[0].line == 11 and "bad CRC" in r.first_rejects[0].detail
    assert r.parsed["NovAtel HEADING2"] == 1
    with pytest.raises(InputError, match=r"d\.asc: line 11: bad checksum: bad CRC"):
        parse_novatel("\n".join(lines).encode(), "d.asc", strict=True)


def test_abbreviated_short_prompts_nmea_and_damage_are_each_counted():
    good = _lines(DRIVERS)
    text = "\r\n".join(
        [
            "<OK",
            "[COM1]",
            "<HEADING2 COM1 0 39.5 FINESTEERING 1622 422892.200 02040000 f9bf 6521",
            "<     SOL_COMPUTED NARROW_INT 0.927607417 178.347869873 -1.3037414550 0 0.261901051",
            "$GPHDT,178.35,T*0D",  # read by the NMEA reader: no time, so no epoch to join
            "",
            good[4],  # %INSPVASA: a short header, read (INS not aligned: ignored with why)
            good[10],
            good[10].split("*")[0],  # no CRC
            "#HEADING2A,COM1,0,39.5,FINESTEERING;SOL_COMPUTED*00000000",  # CRC bad first
            "garbage",
            good[6][:60],  # the file ends inside a line
        ]
    ).encode()
    r = parse_novatel(text, "m.asc").report
    assert r.balanced and r.total_lines == 12
    assert r.ignored["NovAtel abbreviated ASCII or reply (no CRC: log the ...A form)"] == 3
    assert r.ignored["NovAtel port prompt"] == 1 and r.ignored["(blank)"] == 1
    assert r.ignored["NovAtel INSPVAS (not used: INS status WAITING_AZIMUTH)"] == 1
    assert r.parsed == {"NovAtel HEADING2": 1, "HDT": 1}
    assert "1 NMEA epochs not used: no time of day" in r.notes
    assert r.rejected["missing checksum"] == 1 and r.rejected["bad checksum"] == 1
    assert r.rejected["not NovAtel ASCII"] == 1 and r.rejected["truncated"] == 1


def test_a_line_of_too_few_fields_is_malformed_not_a_traceback():
    msg = "BESTVELA,COM1,0,80.0,FINESTEERING,2200,10.000,02000000,b1f6,16809;SOL_COMPUTED,X,1"
    line = f"#{msg}*{_manual_crc(msg.encode()):08x}"
    r = parse_novatel(line.encode(), "x.asc").report
    assert r.rejected["malformed field"] == 1 and "BESTVEL: 3 fields" in r.first_rejects[0].detail


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    flips=st.lists(st.tuples(st.integers(0, 3000), st.integers(1, 255)), max_size=6),
    cut=st.integers(0, 3005),
)
def test_fuzz_never_a_traceback_and_every_line_counted(flips, cut):
    data = bytearray(DRIVERS.read_bytes()[:cut])
    for at, x in flips:
        if at < len(data):
            data[at] ^= x
    r = parse_novatel(bytes(data), "f.asc").report
    assert r.balanced


def _sim_epochs():
    from gripsense.data import path as data_path

    return read_nmea(data_path("demo/case001.nmea.gz"))


def test_the_same_drive_as_nmea(tmp_path):
    """write_novatel (BESTPOS, BESTVEL, HEADING2 per epoch) → the NMEA epoch table."""
    ref = _sim_epochs().epochs
    write_novatel(ref, tmp_path / "d.asc")
    log = read_log(tmp_path / "d.asc")
    ep = log.epochs
    assert log.report.format == "NovAtel ASCII" and log.report.balanced
    assert log.report.n_rejected == 0 and len(ep) == len(ref)
    assert (ep["time_utc"] == ref["time_utc"]).all()
    for c, tol in (("lat_deg", 1e-10), ("lon_deg", 1e-10), ("alt_m", 1e-4),
                   ("speed_mps", 1e-4), ("course_deg", 1e-6), ("heading_deg", 1e-8)):  # fmt: skip
        np.testing.assert_allclose(ep[c], ref[c], atol=tol, err_msg=c)


def test_a_log_of_bad_crcs_is_still_novatel_each_line_rejected(tmp_path):
    """Recognised by the lines' shape, not their CRCs: a damaged log is not "nothing usable"
    NMEA but NovAtel with every bad line named."""
    bad = [ln[:-8] + "00000000" for ln in _lines(DRIVERS)]
    (tmp_path / "bad.asc").write_text("\r\n".join(bad) + "\r\n")
    r = read_log(tmp_path / "bad.asc").report
    assert r.format == "NovAtel ASCII" and r.rejected["bad checksum"] == 14 and r.balanced


def test_strict_names_the_line_in_one_line(tmp_path):
    from tests.cli.inprocess import cli

    lines = _lines(DRIVERS)
    lines[3] = lines[3].replace("51.15", "51.16")
    (tmp_path / "s.asc").write_text("\r\n".join(lines) + "\r\n")
    r = cli("ingest", tmp_path / "s.asc", "--strict")
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert "s.asc: line 4: bad checksum: bad CRC" in r.stderr


def test_a_log_after_a_port_prompt_on_the_same_line_is_read():
    """NovAtel's console writes ``[USB1]`` before a log's first line (real lines of NovAtel
    EDIE's ``src/decoders/oem/test/resources/BESTUTMBIN.GPS``, MIT): the log is read, the bare
    prompt and the ``<OK`` reply ignored."""
    text = (
        b"<OK\r\n[USB1]#BESTUTMA,USB1,0,73.0,FINESTEERING,2237,270605.000,1a000000,a40a,17007;"
        b"SOL_COMPUTED,WAAS,11,U,5670746.0187,707662.0088,1098.7489,-17.0000,WGS84,0.8816,"
        b'0.6843,1.9549,"131",4.000,0.000,30,9,9,9,0,06,00,03*16afb629\r\n[USB1]\r\n'
        b"[USB1]#HEADING2A,COM1,0,39.5,FINESTEERING;SOL_COMPUTED*00000000\r\n"
        + DRIVERS.read_bytes().splitlines()[10]
    )
    r = parse_novatel(text, "p.asc").report
    assert r.balanced and r.total_lines == 5 and r.junk_prefix_lines == 1
    assert r.ignored["NovAtel BESTUTM"] == 1 and r.ignored["NovAtel port prompt"] == 1
    assert r.rejected["bad checksum"] == 1 and r.parsed == {"NovAtel HEADING2": 1}
    assert is_novatel(text)


def test_inspvax_gives_the_heading_only_without_a_heading_log():
    """The OEM7 manual's INSPVAX example: INS status, position type, lat, lon, height,
    undulation, north/east/up velocity, roll, pitch, azimuth …; its azimuth is the heading of a
    log without HEADING/HEADING2, and a HEADING2 log beats it."""
    ins = (
        b"#INSPVAXA,COM1,0,73.5,FINESTEERING,1695,309428.000,00000040,4e77,43562;"
        b"INS_SOLUTION_GOOD,INS_PSRSP,51.11637873403,-114.03825114994,1063.6093,-16.9000,"
        b"-0.0845,-0.0464,-0.0127,0.138023492,0.069459386,90.000923268,0.9428,0.6688,1.4746,"
        b"0.0430,0.0518,0.0521,0.944295466,0.944567084,1.000131845,3,0*e877c178"
    )
    log = parse_novatel(ins + b"\r\n", "i.asc")
    ep = log.epochs.iloc[0]
    assert log.report.parsed == {"NovAtel INSPVAX": 1}
    assert ep["heading_deg"] == 90.000923268 and "INSPVAX" in log.report.notes[0]
    assert (ep["lat_deg"], ep["lon_deg"]) == (51.11637873403, -114.03825114994)
    assert ep["speed_mps"] == pytest.approx((0.0845**2 + 0.0464**2) ** 0.5, rel=1e-12)
    # moving south-west: north −0.0845, east −0.0464 m/s
    assert ep["course_deg"] == pytest.approx(180 + np.degrees(np.arctan(0.0464 / 0.0845)))
    both = parse_novatel(ins + b"\r\n" + DRIVERS.read_bytes().splitlines()[10], "b.asc")
    assert both.epochs["heading_deg"].dropna().tolist() == [178.347869873]
    assert both.report.notes == []


def test_a_time_out_of_range_is_malformed_and_a_bom_is_no_line():
    msg = (
        "HEADING2A,COM1,0,39.5,FINESTEERING,99999999999,422892.200,02040000,f9bf,6521;"
        "SOL_COMPUTED,NARROW_INT,0.9,178.3,-1.3,0,0.26,0.39"
    )
    line = f"#{msg}*{_manual_crc(msg.encode()):08x}".encode()
    r = parse_novatel(line, "t.asc").report
    assert r.rejected["malformed field"] == 1 and "out of range" in r.first_rejects[0].detail
    r = parse_novatel(b"\xef\xbb\xbf" + DRIVERS.read_bytes(), "t.asc").report
    assert r.n_parsed == 12 and r.n_rejected == 0


@pytest.mark.parametrize("field, value", [(2, "91.0"), (3, "nan"), (4, "inf")])
def test_a_value_no_receiver_gives_is_malformed(field, value):
    line = _lines(DRIVERS)[6]  # BESTPOS: lat, lon, height at body fields 2, 3, 4
    head, body = line[1:].split("*")[0].split(";")
    f = body.split(",")
    f[field] = value
    msg = f"{head};{','.join(f)}"
    r = parse_novatel(f"#{msg}*{_manual_crc(msg.encode()):08x}".encode(), "v.asc").report
    assert r.rejected["malformed field"] == 1 and "outside" in r.first_rejects[0].detail


def test_nmea_on_the_same_port_fills_what_the_novatel_logs_lack():
    """A receiver logging BESTPOSA and BESTVELA at 5 Hz with GPHDT, GPGGA, GPRMC … at 10 Hz on
    one port (no HEADING2): the heading and the rate of turn come from the NMEA at the same UTC
    time, the NMEA epochs between the NovAtel ones are epochs of their own, every line is
    counted by the reader that read it, a rejected NMEA line named by its file line."""
    from gripsense.data import path as data_path

    nmea = gzip.decompress(data_path("demo/case001.nmea.gz").read_bytes()).decode().splitlines()
    ref = read_nmea(data_path("demo/case001.nmea.gz")).epochs
    novatel = write_novatel(ref, None, logs=("BESTPOS", "BESTVEL"))
    per = len(nmea) // len(ref)
    assert per * len(ref) == len(nmea)
    lines = []
    for k in range(len(ref)):
        lines += (novatel[2 * k : 2 * k + 2] if k % 2 == 0 else []) + nmea[k * per : (k + 1) * per]
    lines[5] = lines[5][:-2] + "00"  # a bad NMEA checksum
    log = parse_novatel(("\r\n".join(lines) + "\r\n").encode(), "mixed.asc")
    r, ep = log.report, log.epochs
    assert r.balanced and r.total_lines == len(lines)
    assert r.parsed["NovAtel BESTPOS"] == (len(ref) + 1) // 2 and r.parsed["ROT"] == len(ref)
    assert r.rejected["bad checksum"] == 1 and r.first_rejects[0].line == 6
    assert len(ep) == len(ref) and (ep["time_utc"] == ref["time_utc"]).all()
    ok = ep["heading_deg"].notna().to_numpy()
    assert ok.sum() >= len(ref) - 1
    np.testing.assert_allclose(ep["heading_deg"][ok], ref["heading_deg"][ok], atol=1e-9)
    assert (ep["heading_source"][ok] == ref["heading_source"][ok]).all()
    for c in ("lat_deg", "lon_deg", "speed_mps", "course_deg"):
        np.testing.assert_allclose(ep[c], ref[c], atol=1e-4, err_msg=c)
    rot = (ref["yaw_rate_source"] == "ROT").to_numpy() & (ep["yaw_rate_source"] == "ROT").to_numpy()
    assert rot.sum() >= len(ref) - 2
    np.testing.assert_allclose(ep["yaw_rate_rps"][rot], ref["yaw_rate_rps"][rot])


def test_a_few_novatel_logs_among_more_nmea_are_read_with_it(tmp_path):
    """One BESTVELA per six NMEA sentences: recognised as NovAtel (today: NMEA, the NovAtel
    lines comments), the NMEA read too; a plain NMEA log stays NMEA."""
    from gripsense.data import path as data_path

    nmea = gzip.decompress(data_path("demo/case001.nmea.gz").read_bytes()).decode().splitlines()
    ref = read_nmea(data_path("demo/case001.nmea.gz")).epochs
    vel = write_novatel(ref, None, logs=("BESTVEL",))
    lines = []
    for k in range(len(ref)):
        lines += [vel[k], *nmea[6 * k : 6 * k + 6]]
    (tmp_path / "m.log").write_text("\r\n".join(lines) + "\r\n")
    log = read_log(tmp_path / "m.log")
    assert log.report.format == "NovAtel ASCII + NMEA 0183" and log.report.balanced
    assert log.report.parsed["NovAtel BESTVEL"] == len(ref) and len(log.epochs) == len(ref)
    assert detect_format("\r\n".join(nmea[:600]).encode()) == "nmea"


def _mixed_lines() -> list[str]:
    from gripsense.data import path as data_path

    nmea = gzip.decompress(data_path("demo/case001.nmea.gz").read_bytes()).decode().splitlines()
    nov = write_novatel(read_nmea(data_path("demo/case001.nmea.gz")).epochs[:30], None)
    out = []
    for k in range(30):
        out += nov[3 * k : 3 * k + 3] + nmea[6 * k : 6 * k + 6]
    return out


_MIXED = ("\r\n".join(_mixed_lines()) + "\r\n").encode()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    flips=st.lists(st.tuples(st.integers(0, len(_MIXED) - 1), st.integers(1, 255)), max_size=8),
    start=st.integers(0, len(_MIXED) // 2),
)
def test_fuzz_novatel_with_nmea_every_line_counted(flips, start):
    data = bytearray(_MIXED[start:])
    for at, x in flips:
        if at < len(data):
            data[at] ^= x
    log = parse_novatel(bytes(data), "f.asc")
    assert log.report.balanced
    t = log.epochs["time_utc"].dropna()
    assert t.is_monotonic_increasing
