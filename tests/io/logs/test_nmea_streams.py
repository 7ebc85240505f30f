"""NMEA streams as receivers and instruments really send them (issue 43).

Real files (tests/data/formats/nmea, origins and licences in tests/data/formats/README.md):
an Ashtech AC12 capture from GPSD's regression suite, the proprietary-sentence samples of
pynmeagps' test data, and a u-blox stream with RTCM3 corrections from pyubx2's test data. The
references are independent decoders: pynmeagps for the sentences, pyubx2 for the RTCM3 frames,
the makers' published example sentences for the proprietary attitude fields.
"""

from __future__ import annotations

import math
from io import BytesIO
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from pynmeagps import NMEAReader
from pyubx2 import NMEA_PROTOCOL, RTCM3_PROTOCOL, UBX_PROTOCOL, UBXReader

from gripsense import InputError, read_nmea
from gripsense.io.logs import read_log
from gripsense.io.logs.nmea.epochs import epoch_boundaries, epoch_boundaries_loop
from gripsense.io.logs.nmea.rtcm import crc24q, split_rtcm
from tests.conftest import GPSD_LOGS
from tests.nmea_helpers import sentence

DATA = Path(__file__).resolve().parents[2] / "data" / "formats" / "nmea"
ENGINES = ["fast", "reference"]


def _no_malformed_proprietary(rep) -> None:
    for r in rep.first_rejects:
        assert not (r.reason == "malformed field" and "PASHR" in r.detail), r


# --- empty sentences do not start or split epochs -------------------------------------------


ORDERS = ["HDT VTG HDT ZDA", "ZDA HDT VTG HDT", "VTG HDT ZDA HDT", "HDT HDT VTG ZDA"]


def _instrument_cycle(n: int, order: str = ORDERS[0]) -> list[str]:
    """A yacht instrument bus: per second an empty $IIHDT,,T twice (no compass), VTG, ZDA."""
    out = []
    for k in range(n):
        t = f"1200{k:02d}.00"
        s = {
            "HDT": sentence("IIHDT,,T"),
            "VTG": sentence(f"IIVTG,{40 + k}.0,T,,M,{5 + k}.0,N,,K,A"),
            "ZDA": sentence(f"IIZDA,{t},27,11,2026,00,00"),
        }
        out += [s[w] for w in order.split()]
    return out


@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("engine", ENGINES)
def test_empty_heading_sent_twice_does_not_split_the_cycle(engine, order):
    """Issue 43: "14500 epochs (7250 without time)" — every VTG was cut off its ZDA time."""
    log = read_nmea(_instrument_cycle(5, order), engine=engine)
    rep, ep = log.report, log.epochs
    assert rep.parsed == {"HDT": 10, "VTG": 5, "ZDA": 5}  # the empty ones are still counted
    assert rep.n_epochs == 5 and rep.epochs_without_time == 0
    assert ep["time_utc"].dt.second.tolist() == [0, 1, 2, 3, 4]
    np.testing.assert_allclose(ep["course_deg"], [40.0, 41.0, 42.0, 43.0, 44.0])
    np.testing.assert_allclose(ep["speed_mps"], np.arange(5, 10) * 1852.0 / 3600.0)
    assert ep["heading_deg"].isna().all()
    # every sentence, the empty ones too, lies in an epoch
    for f in log.sentences.values():
        assert f["epoch"].between(0, len(ep) - 1).all()


def test_hemisphere_empty_heading_still_leads_its_burst():
    """GPSD's Hemisphere capture sends HDT, GGA, VTG[, ZDA], the HDT empty until the compass
    has a heading: the first valid HDT (line 742) belongs to the GGA after it, not to the ZDA
    before it — the empty HDTs before keep marking the bursts."""
    log = read_nmea(next(p for p in GPSD_LOGS if p.stem == "hemi"))
    hdt, gga = log.sentences["HDT"], log.sentences["GGA"]
    row = hdt[hdt["line"] == 742].iloc[0]
    assert row["heading_deg"] == 274.07
    assert row["epoch"] == gga[gga["line"] == 743]["epoch"].iloc[0]
    # every epoch of the capture has its time (97 of 215 had none before issue 43)
    assert log.report.epochs_without_time == 0


def test_empty_sentence_does_not_replace_a_value():
    """An empty GGA after a good one in the same epoch leaves the position alone."""
    lines = [
        sentence("GPGGA,120000.00,3500.0000,N,13500.0000,E,1,08,0.9,10.0,M,30.0,M,,"),
        sentence("GPGGA,,,,,,0,,,,M,,M,,"),
        sentence("GPRMC,120000.00,A,3500.0000,N,13500.0000,E,10.0,90.0,271126,,,A"),
    ]
    ep = read_nmea(lines).epochs
    assert len(ep) == 1
    assert ep["lat_deg"].iloc[0] == 35.0 and ep["alt_m"].iloc[0] == 10.0


def test_log_of_only_empty_sentences_is_one_epoch_without_values():
    log = read_nmea([sentence("IIHDT,,T")] * 3 + [sentence("GPVTG,,T,,M,,N,,K,N")])
    assert log.report.n_epochs == 1 and log.report.n_parsed == 4
    assert (
        log.epochs.drop(columns=["time_utc", "heading_source", "yaw_rate_source"])
        .isna()
        .all(axis=None)
    )


@pytest.mark.parametrize("seed", range(20))
def test_epoch_rule_with_empty_sentences_compiled_equals_loop(seed):
    rng = np.random.default_rng(seed)
    n = 80
    kind = rng.integers(0, 5, n)
    tod = np.where(rng.random(n) < 0.4, rng.integers(0, 4, n).astype(float), np.nan)
    empty = rng.random(n) < 0.3
    np.testing.assert_array_equal(
        epoch_boundaries(kind, tod, empty), epoch_boundaries_loop(kind, tod, empty)
    )


# --- proprietary sentences --------------------------------------------------------------------


@pytest.mark.parametrize("engine", ENGINES)
def test_ashtech_ac12_capture_has_no_malformed_proprietary_sentence(engine):
    """GPSD's Ashtech AC12 capture: $PASHR,POS / SAT / XMG are well-formed, counted as
    proprietary sentences gripsense does not use; before issue 43 they were *malformed*."""
    log = read_nmea(DATA / "ashtech-ac12.log", engine=engine)
    rep = log.report
    assert rep.ignored["PASHR,POS (proprietary, not used)"] == 5
    assert rep.ignored["PASHR,SAT (proprietary, not used)"] == 4
    assert rep.ignored["PASHR,XMG (proprietary, not used)"] == 4
    assert rep.rejected["malformed field"] == 0
    assert rep.balanced
    _no_malformed_proprietary(rep)
    # its fixes are read as GPSD reads them: the RMC at 18:35:30 is 20°37.7601' N 87°04.0737' W
    rmc = log.sentences["RMC"]
    row = rmc[np.isclose(rmc["tod_s"], 18 * 3600 + 35 * 60 + 30)].iloc[0]
    assert row["lat_deg"] == pytest.approx(20 + 37.7601 / 60, abs=1e-9)
    assert row["lon_deg"] == pytest.approx(-(87 + 4.0737 / 60), abs=1e-9)


def _pynmeagps(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    for raw in path.read_bytes().splitlines():
        msg = NMEAReader.parse(raw)
        out.setdefault(msg.identity, []).append(msg)
    return out


@pytest.mark.parametrize("engine", ENGINES)
def test_trimble_sentences_read_as_pynmeagps_reads_them(engine):
    """pynmeagps' Trimble samples: $PTNL,AVR gives the heading (yaw of a fixed-RTK vector),
    every other well-formed proprietary sentence is counted, none is malformed."""
    path = DATA / "pynmeagps-trimble.log"
    log = read_nmea(path, engine=engine)
    rep = log.report
    assert sum(rep.rejected.values()) == 0
    assert rep.parsed["PTNL,AVR"] == 2
    ref = _pynmeagps(path)["PTNLAVR"]
    avr = log.sentences["PTNL,AVR"]
    np.testing.assert_allclose(avr["heading_deg"], [m.yaw for m in ref])
    for got, m in zip(avr["pitch_deg"], ref, strict=True):
        assert (math.isnan(got) and m.tilt == "") or got == pytest.approx(m.tilt)
    for got, m in zip(avr["roll_deg"], ref, strict=True):
        assert (math.isnan(got) and m.roll == "") or got == pytest.approx(m.roll)
    ep = log.epochs
    assert (ep["heading_source"].iloc[avr["epoch"]] == "AVR").all()
    unused = {k for k in rep.ignored if k.endswith("(proprietary, not used)")}
    assert {"PTNL,GGK (proprietary, not used)", "PASHR,ARR (proprietary, not used)"} <= unused


def test_trimble_avr_heading_only_from_a_fixed_rtk_vector():
    # Trimble's own example sentence (its manual prints the checksum as *00), then the same
    # with quality 2 (float RTK)
    lines = [
        sentence("PTNL,AVR,181059.6,+149.4688,Yaw,+0.0134,Tilt,,,60.191,3,2.5,6"),
        sentence("PTNL,AVR,181059.8,+149.4700,Yaw,+0.0134,Tilt,,,60.191,2,2.5,6"),
    ]
    ep = read_nmea(lines).epochs
    assert ep["heading_deg"].iloc[0] == pytest.approx(149.4688)
    assert math.isnan(ep["heading_deg"].iloc[1])


@pytest.mark.parametrize("engine", ENGINES)
def test_septentrio_hrp_and_its_mode(engine):
    """pynmeagps' Septentrio X5 sample has mode 0 (no attitude): counted, no heading; the
    reference guide's example (mode 2, fixed ambiguities) gives heading and pitch."""
    path = DATA / "pynmeagps-septentriox5.log"
    log = read_nmea(path, engine=engine)
    assert log.report.parsed == {"PSSN,HRP": 1}
    assert log.report.ignored == {
        "PSSN,SNC (proprietary, not used)": 2,
        "PSSN,TFM (proprietary, not used)": 1,
    }
    ref = _pynmeagps(path)["PSSNHRP"][0]
    assert int(ref.attmode) == 0 and math.isnan(log.epochs["heading_deg"].iloc[0])
    ok = read_nmea(
        ["$PSSN,HRP,142657.80,061222,152.236,,-0.708,0.084,,0.181,21,2,2.400,E*23"],
        engine=engine,
    ).epochs
    assert ok["heading_deg"].iloc[0] == 152.236 and ok["pitch_deg"].iloc[0] == -0.708
    assert math.isnan(ok["roll_deg"].iloc[0]) and ok["heading_source"].iloc[0] == "PSSN"
    assert ok["time_utc"].iloc[0].isoformat().startswith("2022-12-06T14:26:57.8")


@pytest.mark.parametrize("engine", ENGINES)
def test_ashtech_hpr(engine):
    """$PASHR,HPR as a ProFlex/SP receiver sends it (a public ROS driver's recorded sentence):
    heading 302.15390, pitch 1.90221, no roll, fixed ambiguities (0)."""
    line = "$PASHR,HPR,021745.90,302.15390,1.90221,,0.0065,0.0000,0,2,0.900,1.2*11"
    float_amb = sentence("PASHR,HPR,021746.00,302.2,1.9,,0.0065,0.0000,1,2,0.900,1.2")
    log = read_nmea([line, float_amb], engine=engine)
    assert log.report.parsed == {"PASHR,HPR": 2}
    ep = log.epochs
    assert ep["heading_deg"].iloc[0] == 302.1539 and ep["pitch_deg"].iloc[0] == 1.90221
    assert ep["heading_source"].iloc[0] == "PASHR" and math.isnan(ep["roll_deg"].iloc[0])
    assert math.isnan(ep["heading_deg"].iloc[1])  # float ambiguities: not a heading


@pytest.mark.parametrize("engine", ENGINES)
def test_furuno_satellite_compass_attitude(engine):
    """pynmeagps' Furuno samples: $PFEC,GPatt (yaw, pitch, roll of a satellite compass) read
    as pynmeagps reads it; $PFEC,GPhve (heave) counted as not used."""
    path = DATA / "pynmeagps-furuno.log"
    log = read_nmea(path, engine=engine)
    assert log.report.parsed == {"PFEC,GPatt": 1}
    assert log.report.ignored == {"PFEC,GPhve (proprietary, not used)": 1}
    assert log.report.n_rejected == 0
    ref = _pynmeagps(path)["PFECGPatt"][0]
    ep = log.epochs
    assert ep["heading_deg"].iloc[0] == pytest.approx(ref.yaw)
    assert ep["pitch_deg"].iloc[0] == pytest.approx(ref.pitch)
    assert ep["roll_deg"].iloc[0] == pytest.approx(ref.roll)
    assert ep["heading_source"].iloc[0] == "GPatt"


def test_oxts_pashr_with_time_first_is_still_read():
    line = sentence("PASHR,204132,010.51,T,+00.39,-00.79,-00.84,0.151,0.075,0.555,1,0")
    ep = read_nmea([line]).epochs
    assert ep["heading_deg"].iloc[0] == 10.51 and ep["heading_source"].iloc[0] == "PASHR"


# --- RTCM3 between the sentences --------------------------------------------------------------


def _pyubx2_frames(path: Path) -> list[str]:
    r = UBXReader(
        BytesIO(path.read_bytes()),
        protfilter=UBX_PROTOCOL | NMEA_PROTOCOL | RTCM3_PROTOCOL,
        quitonerror=0,
    )
    return [p.identity for raw, p in r if raw[:1] == b"\xd3"]


@pytest.mark.parametrize("engine", ENGINES)
def test_rtcm3_frames_between_sentences_are_counted_as_rtcm(engine):
    """A u-blox stream with RTCM3 output (pyubx2's test data, its UBX frame cut out): the
    frames are counted under their message numbers as pyubx2 decodes them; before issue 43
    their bytes were 9 *not NMEA* lines."""
    path = DATA / "pyubx2-nmea-rtcm3.log"
    log = read_nmea(path, engine=engine)
    rep = log.report
    ref = _pyubx2_frames(path)
    assert len(ref) == 7
    got = {k[6:]: v for k, v in rep.ignored.items() if k.startswith("RTCM3 ")}
    assert got == {m: ref.count(m) for m in ref}
    assert rep.n_rejected == 0 and rep.balanced
    assert rep.unit == "lines and frames"
    assert rep.parsed == {"RMC": 1, "GLL": 1}  # (GLL read since issue 43, too)
    # the RMC is on line 11 of the file (the frames hold line-end bytes)
    data = path.read_bytes()
    line = data[: data.index(b"$GNRMC")].count(b"\n") + 1
    assert log.sentences["RMC"]["line"].tolist() == [line]
    # the GLL (084158.00) and the RMC (084159.00, dated 080222) are two epochs
    times = [t.isoformat() for t in log.epochs["time_utc"]]
    assert times == ["2022-02-08T08:41:58+00:00", "2022-02-08T08:41:59+00:00"]


def test_rtcm3_frame_with_a_bad_crc_is_one_rejected_frame(tmp_path):
    """pyubx2's copy of the stream with one byte of the 1005 frame changed."""
    path = DATA / "pyubx2-mixed-rtcm3-badcrc.log"
    for log in (read_log(path), read_nmea(path)):
        rep = log.report
        assert rep.rejected["bad checksum"] == 1 and rep.balanced
        assert "RTCM3 1005" not in rep.ignored and rep.ignored["RTCM3 1077"] == 1
        bad = next(r for r in rep.first_rejects if r.reason == "bad checksum")
        assert "RTCM3 frame (message 1005" in bad.detail and "CRC-24Q" in bad.detail
    with pytest.raises(InputError, match=r"byte 52: RTCM3 frame .*strict"):
        read_nmea(path, strict=True)


def test_ubx_stream_with_rtcm3_counts_the_frames():
    """The same stream with its UBX frame goes to the UBX reader, whose NMEA part counts the
    RTCM3 frames instead of *not NMEA* lines."""
    rep = read_log(DATA / "pyubx2-mixed-rtcm3.log").report
    assert rep.parsed == {"GLL": 1, "RMC": 1, "UBX NAV-PVT": 1}
    assert sum(v for k, v in rep.ignored.items() if k.startswith("RTCM3")) == 7
    assert rep.n_rejected == 0 and rep.balanced


def test_crc24q_matches_the_standards_check_value():
    # CRC-24Q (RTCM 10403.3; the "CRC-24/LTE-A" parameters): check value of "123456789"
    assert crc24q(b"123456789") == 0xCDE703


def test_pure_nmea_is_not_scanned_and_binary_is_not_taken_for_rtcm():
    data = b"".join(s.encode() + b"\r\n" for s in _instrument_cycle(3))
    text, frames = split_rtcm(data)
    assert frames is None and text is data
    junk = bytes(np.random.default_rng(1).integers(0, 256, 4000, dtype=np.uint8))
    _, frames = split_rtcm(junk.replace(b"\xd3", b"\xd2"))
    assert frames is None


# --- line ends, checksums ---------------------------------------------------------------------


@pytest.mark.parametrize("eol", [b"\r\n", b"\n", b"\r"])
def test_line_ends(eol):
    lines = _instrument_cycle(3)
    log = read_nmea(eol.join(s.encode() for s in lines) + eol)
    assert log.report.total_lines == len(lines)
    assert log.report.n_parsed == len(lines) and log.report.n_epochs == 3


def test_lower_case_checksum():
    s = sentence("GPHDT,274.07,T")
    lower = s[:-2] + s[-2:].lower()
    assert read_nmea([lower]).epochs["heading_deg"].iloc[0] == 274.07


# --- several talkers, one instant -------------------------------------------------------------


@pytest.mark.parametrize("engine", ENGINES)
def test_several_talkers_of_one_instant_are_one_epoch(engine):
    """GPSD's Telit PLS83-W capture sends $GPGGA and $GAGGA, $GPVTG and $GAVTG, $GPRMC and
    $GARMC for each second: one epoch per second (before issue 43: two per second, at the same
    time, half of them without speed)."""
    log = read_nmea(DATA / "telit-pls83-w.log", engine=engine)
    ep = log.epochs
    rmc = log.sentences["RMC"]
    assert len(ep) == rmc["tod_s"].nunique() == 10
    assert ep["time_utc"].is_unique and ep["time_utc"].is_monotonic_increasing
    assert ep["speed_mps"].notna().all() and ep["lat_deg"].notna().all()
    # both talkers' sentences of a second are in that second's epoch
    for k in ("GGA", "RMC"):
        f = log.sentences[k]
        assert (ep["time_utc"].iloc[f["epoch"]].dt.second.to_numpy() == f["tod_s"] % 60).all()
    assert any("several talkers" in n for n in log.report.notes)


# --- a talker that sends no checksums ---------------------------------------------------------


@pytest.mark.parametrize("engine", ENGINES)
def test_log_without_any_checksum_is_read_unverified_and_says_so(engine):
    """GPSD's HP 58534A capture has no checksum on any line ("everything ignored" by GPSD;
    before issue 43 all its sentences were rejected as *missing checksum*)."""
    log = read_nmea(DATA / "hp58534a.log", engine=engine)
    rep = log.report
    assert rep.parsed == {"GGA": 2, "VTG": 2, "ZDA": 1} and rep.n_rejected == 0
    assert any("read unverified" in n for n in rep.notes)
    ep = log.epochs
    # $GPGGA,222449,3349.0337,S,01843.9282,E,… and $GPVTG,318.0,T,…,000.0,N,0000.1,K,A
    assert ep["lat_deg"].iloc[0] == pytest.approx(-(33 + 49.0337 / 60), abs=1e-12)
    assert ep["lon_deg"].iloc[0] == pytest.approx(18 + 43.9282 / 60, abs=1e-12)
    assert ep["course_deg"].iloc[0] == 318.0 and ep["speed_mps"].iloc[0] == 0.0
    assert ep["time_utc"].iloc[0].isoformat().startswith("2010-10-25T22:24:49")


def test_missing_checksum_among_checksummed_lines_is_still_rejected():
    lines = [sentence("GPHDT,274.07,T"), "$GPHDT,274.1,T", sentence("GPHDT,274.2,T")]
    rep = read_nmea(lines).report
    assert rep.rejected["missing checksum"] == 1 and rep.parsed == {"HDT": 2}


def test_without_checksums_fast_equals_reference_and_the_checksummed_read():
    """The GPSD logs with every '*hh' cut off: both tokenizers agree line by line and read
    the values the checksummed logs give."""
    import re

    from gripsense.io.logs.nmea.fast import tokenize_fast
    from gripsense.io.logs.nmea.reference import tokenize_reference
    from tests.io.logs.test_nmea_fuzz import assert_same_tokens

    for p in GPSD_LOGS:
        data = p.read_bytes()
        bare = re.sub(rb"\*[0-9A-Fa-f]{2}(\r?)$", rb"\1", data, flags=re.M)
        assert_same_tokens(
            tokenize_fast(bare, no_checksum=True), tokenize_reference(bare, no_checksum=True)
        )
        a, b = read_nmea(data), read_nmea(bare)
        if not a.report.n_rejected:  # (binary between the lines reads differently unchecked)
            assert a.epochs.equals(b.epochs), p.name
            assert a.report.parsed == b.report.parsed


@pytest.mark.parametrize("engine", ENGINES)
def test_signalk_yacht_log_one_epoch_per_cycle(engine):
    """The issue's own file: Signal K's sample yacht log (plaka.log, first 1200 lines). Per
    2-second cycle: VHW, VPW, VTG, MWV, VWT, an empty $IIHDT,,T, WCV, XTE, ZDA (no date), DBT,
    GLL, GSV, HDM, a second empty $IIHDT,,T, MWD, VDR. Before issue 43 the second HDT split
    every cycle: twice the epochs, half of them without time.

    Since GLL is read (its time groups the burst as GGA's does): in 17 of the 75 cycles the
    GLL's fix time is one second after the ZDA's (the plotter's clock lags), and the GLL starts
    an epoch of its own there — as a GGA with that time would."""
    path = DATA / "signalk-plaka-head.log"
    log = read_nmea(path, engine=engine)
    rep, ep = log.report, log.epochs
    zda, vtg, gll = log.sentences["ZDA"], log.sentences["VTG"], log.sentences["GLL"]
    text = path.read_text().splitlines()
    # the times as the file writes them (ZDA field 1, GLL field 5), cycle by cycle
    t_zda = [ln.split(",")[1] for ln in text if ln.startswith("$GPZDA")]
    t_gll = [ln.split(",")[5] for ln in text if ln.startswith("$GPGLL")]
    late = [a != b for a, b in zip(t_zda, t_gll, strict=True)]
    assert len(late) == 75 and sum(late) == 17
    assert rep.n_epochs == len(zda) + sum(late) and rep.epochs_without_time == 0
    assert rep.parsed["HDT"] == 2 * len(zda)
    # each cycle's GLL is in its ZDA's epoch where their times agree, else in one of its own
    z_ep, g_ep = zda["epoch"].to_numpy(), gll["epoch"].to_numpy()
    assert ((g_ep == z_ep) == ~np.array(late)).all()
    # each VTG (no time of its own) is in a timed epoch of its cycle: that of the ZDA after it,
    # or that of the last timed sentence (ZDA or GLL) before it — one VTG per epoch
    timed = pd.concat([zda[["line", "epoch"]], gll[["line", "epoch"]]]).sort_values("line")
    for row in vtg.itertuples(index=False):
        nxt = next(i for i in range(row.line, len(text)) if "ZDA," in text[i]) + 1
        before = timed.loc[timed["line"] < row.line, "epoch"]
        allowed = {zda.loc[zda["line"] == nxt, "epoch"].iloc[0], *before.tail(1)}
        assert row.epoch in allowed, row
    assert vtg["epoch"].is_unique and ep["speed_mps"].notna().sum() == 75
    assert ep["t_s"].notna().all() and ep["lat_deg"].notna().sum() == 75
    # the log has no date (its ZDA date fields are empty): t_s, no time_utc
    assert not rep.has_date and ep["time_utc"].isna().all()


@pytest.mark.parametrize("engine", ENGINES)
def test_no_fix_placeholder_position_is_not_malformed(engine):
    """GPSD's MediaTek MT3301 capture (power-up to first fix): without a fix the receiver
    sends 8960.000000,N (89° 60') with GGA quality 0 / RMC status V. Those are well-formed
    sentences saying "no fix" — parsed, without a position — not 43 *malformed* lines."""
    log = read_nmea(DATA / "mtk-3301.log", engine=engine)
    rep = log.report
    assert rep.rejected["malformed field"] == 0
    assert rep.parsed["GGA"] == rep.parsed["RMC"] == 11
    ep = log.epochs
    no_fix = ep["fix_quality"] == 0
    assert no_fix.sum() == 7 and ep.loc[no_fix, "lat_deg"].isna().all()
    # the first fixes, near where the file's header says it was made (52.21N 6.88E)
    assert (ep.loc[~no_fix, "lat_deg"] - 52.21).abs().max() < 0.02
    assert (ep.loc[~no_fix, "lon_deg"] - 6.88).abs().max() < 0.02
    # its last GGA: 5212.981832,N,00653.104686,E
    assert ep["lat_deg"].iloc[-1] == pytest.approx(52 + 12.981832 / 60, abs=1e-12)
    assert ep["lon_deg"].iloc[-1] == pytest.approx(6 + 53.104686 / 60, abs=1e-12)
    # a fixed GGA with minute 60 stays malformed
    bad = sentence("GPGGA,120000.00,8960.0000,N,00000.0000,E,1,08,0.9,10.0,M,30.0,M,,")
    assert read_nmea([bad], engine=engine).report.rejected["malformed field"] == 1


@pytest.mark.parametrize("path", sorted(DATA.glob("*.log")), ids=lambda p: p.stem)
def test_real_files_fast_equals_reference(path):
    a, b = read_nmea(path, engine="fast"), read_nmea(path, engine="reference")
    assert a.report == b.report and a.report.balanced
    assert a.epochs.equals(b.epochs)
    for k in a.sentences:
        assert a.sentences[k].equals(b.sentences[k]), k


def _pyn_num(x) -> float:
    return float("nan") if x in ("", None) else float(x)


def _same(a: float, b, tol: float = 1e-9) -> bool:
    b = _pyn_num(b)
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol


@pytest.mark.parametrize(
    "path",
    [p for p in sorted(DATA.glob("*.log")) if p.stem != "hp58534a"],  # (pynmeagps wants *hh)
    ids=lambda p: p.stem,
)
def test_every_parsed_sentence_as_pynmeagps_decodes_it(path):
    """Each parsed sentence of each bundled file, decoded by pynmeagps (checksum checked) from
    the file's own line: the same values (the line numbers are the file's, also where RTCM3
    frames with line-end bytes were cut out)."""
    from pynmeagps import VALCKSUM

    log = read_nmea(path)
    lines = path.read_bytes().split(b"\n")
    n = 0
    for key, frame in log.sentences.items():
        for row in frame.itertuples(index=False):
            raw = lines[row.line - 1].rstrip(b"\r")
            text = raw[max(raw.rfind(b"$"), 0) :]
            m = NMEAReader.parse(text, validate=VALCKSUM)
            if key in ("GGA", "RMC", "GLL", "GNS") and not math.isnan(row.lat_deg):
                assert _same(row.lat_deg, m.lat) and _same(row.lon_deg, m.lon), text
            if key == "RMC" and not math.isnan(row.speed_mps):
                assert _same(row.speed_mps, _pyn_num(m.spd) * 1852 / 3600, 1e-12), text
            elif key == "VTG" and row.mode != "N":
                assert _same(row.course_deg, m.cogt, 1e-12), text
            elif key == "HDT":
                assert _same(row.heading_deg, m.headingT, 1e-12), text
            elif key == "PTNL,AVR" and not math.isnan(row.heading_deg):
                assert _same(row.heading_deg, m.yaw, 1e-12), text
            elif key == "PSSN,HRP" and not math.isnan(row.heading_deg):
                assert _same(row.heading_deg, m.hdg, 1e-12), text
            elif key == "PFEC,GPatt":
                assert _same(row.heading_deg, m.yaw, 1e-12), text
            if "tod_s" in frame.columns and not math.isnan(row.tod_s):
                t = m.time if hasattr(m, "time") else m.utctime if hasattr(m, "utctime") else m.utc
                tod = t.hour * 3600 + t.minute * 60 + t.second + t.microsecond / 1e6
                assert abs(row.tod_s - tod) < 1e-6, text
            n += 1
    assert n == log.report.n_parsed
