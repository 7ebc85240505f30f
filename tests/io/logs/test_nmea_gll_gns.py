"""Positions from GLL and GNS (issue 43): logs whose position is only in ``$..GLL`` or ``$..GNS``.

Real files (tests/data/formats/nmea, origins and licences in tests/data/formats/README.md):
GPSD's Ericsson GRU 04 capture (GNS and GLL per second, GGA twice in 70 s), GPSD's depth
sounder log (GLL only) and Signal K's yacht log (instrument bus with a GLL-only GPS). The
reference is pynmea2, an independent decoder, sentence by sentence; which sentence gives an
epoch its position is the documented precedence (GGA with a fix, RMC status A, GNS with a mode
letter other than N, GLL status A and mode not N), applied here to pynmea2's values.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pynmea2
import pytest

from gripsense.io import read_nmea
from gripsense.live import LiveIngest
from tests.nmea_helpers import sentence

DATA = Path(__file__).resolve().parents[2] / "data" / "formats" / "nmea"
ENGINES = ["fast", "reference"]
LOGS = [
    "ericsson-gru04-02-70sec.log",
    "sounder.log",
    "signalk-plaka-head.log",
    "magellan-explorist110.log",
]
POSITION_ORDER = ("GGA", "RMC", "GNS", "GLL")  # docs/ingest.md, NMEA: which position counts


def _reference(path: Path) -> dict[int, tuple[str, float, float, float, float, float]]:
    """1-based line -> (type, lat, lon, alt, satellites, HDOP) of every GGA/RMC/GNS/GLL line
    as pynmea2 decodes it; NaN position where the sentence itself says "no fix"."""
    out = {}
    nan = math.nan
    for i, raw in enumerate(path.read_text(encoding="ascii").splitlines(), start=1):
        if not raw.startswith("$") or raw[3:6] not in POSITION_ORDER:
            continue
        m = pynmea2.parse(raw, check=True)
        k = raw[3:6]
        if k == "GGA":
            ok = int(m.gps_qual or 0) != 0
        elif k == "RMC":
            ok = m.status == "A"
        elif k == "GNS":
            ok = any(c != "N" for c in m.mode_indicator)
        else:  # status A, and a fix mode letter or none (NMEA before 2.3)
            mode = m.faa_mode if len(m.data) > 6 else ""
            ok = m.status == "A" and mode in ("", "A", "D", "P", "R", "F", "E", "M", "S")
        lat, lon = (m.latitude, m.longitude) if ok else (nan, nan)
        alt, n_sats, hdop = nan, nan, nan
        if k in ("GGA", "GNS"):
            alt = float(m.altitude) if ok and m.altitude else nan
            n_sats = float(m.num_sats) if m.num_sats else nan
            hdop = float(m.horizontal_dil if k == "GGA" else m.hdop or nan)
        out[i] = (k, lat, lon, alt, n_sats, hdop)
    return out


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("name", LOGS)
def test_positions_equal_pynmea2_sentence_by_sentence(name, engine):
    path = DATA / name
    log = read_nmea(path, engine=engine)
    ref = _reference(path)
    # every GLL/GNS sentence: its position as pynmea2 reads it (NaN without a fix)
    n = 0
    for key in ("GNS", "GLL"):
        for row in log.sentences[key].itertuples(index=False):
            k, lat, lon, alt, n_sats, hdop = ref[row.line]
            assert k == key
            np.testing.assert_allclose([row.lat_deg, row.lon_deg], [lat, lon], rtol=0, atol=1e-12)
            if key == "GNS":
                np.testing.assert_allclose([row.alt_m, row.n_sats, row.hdop], [alt, n_sats, hdop])
            n += 1
    assert n == sum(1 for k, *_ in ref.values() if k in ("GNS", "GLL")) > 0
    # every epoch: the position of its first sentence in precedence order that has one
    ep = log.epochs
    want = np.full((len(ep), 5), np.nan)
    src: dict[int, str] = {}
    for key in POSITION_ORDER:
        for row in log.sentences[key].itertuples(index=False):
            k, lat, lon, alt, n_sats, hdop = ref[row.line]
            e = row.epoch
            if e not in src and not math.isnan(lat):
                src[e] = key
                want[e, :2] = lat, lon
            if key in ("GGA", "GNS"):  # altitude, satellites, HDOP: GGA's, else GNS's
                want[e, 2:] = np.where(np.isnan(want[e, 2:]), [alt, n_sats, hdop], want[e, 2:])
    got = ep[["lat_deg", "lon_deg", "alt_m", "n_sats", "hdop"]].to_numpy(float)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert len(src) == ep["lat_deg"].notna().sum()
    # (Magellan's eXplorist 110 had no fix: GLL status N, mode V; GGA quality 0; RMC V)
    assert len(src) > 0 or name.startswith("magellan")


@pytest.mark.parametrize("name", LOGS)
def test_every_line_is_counted(name):
    """Nothing lost: each line parsed (GLL and GNS under their types), ignored under its type or
    rejected with a reason; the GLL/GNS counts are the file's own."""
    path = DATA / name
    text = path.read_text(encoding="ascii").splitlines()
    rep = read_nmea(path).report
    assert rep.total_lines == len(text) and rep.balanced and rep.n_rejected == 0
    for key in ("GLL", "GNS"):
        n = sum(1 for ln in text if ln.startswith("$") and ln[3:7] == key + ",")
        assert rep.parsed.get(key, 0) == n
        assert key not in rep.ignored


def test_log_without_gga_or_rmc_is_placed():
    """Before issue 43 these logs had no position at all: GLL and GNS were ignored."""
    for name, n_pos in (("ericsson-gru04-02-70sec.log", 71), ("sounder.log", 122)):
        ep = read_nmea(DATA / name).epochs
        assert ep["lat_deg"].notna().sum() == n_pos == len(ep)
    ep = read_nmea(DATA / "signalk-plaka-head.log").epochs
    assert ep["lat_deg"].notna().sum() == 75  # one GLL per 2-s cycle


# --- validity flags -----------------------------------------------------------------------


def _one(body: str, engine: str) -> pd.Series:
    log = read_nmea([sentence(body)], engine=engine)
    assert log.report.n_parsed == 1, log.report
    return log.epochs.iloc[0]


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(
    ("body", "has_fix", "quality"),
    [
        ("GPGLL,4916.45,N,12311.12,W,225444,A,A", True, 1),
        ("GPGLL,4916.45,N,12311.12,W,225444,A,D", True, 2),
        ("GPGLL,4916.45,N,12311.12,W,225444,A", True, math.nan),  # NMEA 2.0: no mode field
        ("GPGLL,4916.45,N,12311.12,W,225444,V,N", False, 0),
        ("GPGLL,4916.45,N,12311.12,W,225444,V,A", False, 0),
        ("GPGLL,4916.45,N,12311.12,W,225444,A,N", False, 0),
        ("GPGLL,4916.45,N,12311.12,W,225444,A,X", False, 0),  # not a mode letter: no fix
        ("GPGLL,4916.45,N,12311.12,W,225444,N,V", False, 0),  # Magellan eXplorist's "no fix"
        ("GNGNS,225444.00,4916.45,N,12311.12,W,AN,08,1.0,545.4,46.9,,", True, 1),
        ("GNGNS,225444.00,4916.45,N,12311.12,W,NR,08,1.0,545.4,46.9,,", True, 4),
        ("GNGNS,225444.00,4916.45,N,12311.12,W,FA,08,1.0,545.4,46.9,,,V", True, 5),
        ("GNGNS,225444.00,4916.45,N,12311.12,W,NN,00,,545.4,46.9,,", False, 0),
        ("GNGNS,225444.00,4916.45,N,12311.12,W,N,00,,545.4,46.9,,", False, 0),
        ("GNGNS,225444.00,4916.45,N,12311.12,W,,00,,545.4,46.9,,", False, math.nan),
    ],
)
def test_validity_flags(body, has_fix, quality, engine):
    """GLL status V or mode N, GNS mode letters all N: no position (and no altitude); the mode
    letter gives the fix quality on GGA's scale (A 1, D 2, R 4, F 5)."""
    e = _one(body, engine)
    m = pynmea2.parse(sentence(body))
    assert e["time_utc"] is pd.NaT and e["t_s"] == 0.0
    if has_fix:
        assert e["lat_deg"] == pytest.approx(m.latitude, abs=1e-12)
        assert e["lon_deg"] == pytest.approx(m.longitude, abs=1e-12)
    else:
        assert math.isnan(e["lat_deg"]) and math.isnan(e["lon_deg"])
    if body.startswith("GNGNS"):
        assert bool(e["alt_m"] == 545.4) is has_fix
        assert e["n_sats"] == float(m.num_sats)
    np.testing.assert_equal(e["fix_quality"], quality)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(
    ("body", "reason", "detail"),
    [
        ("GNGNS,225444.00,4916.45,N,12311.12,W,AX,08,1.0,545.4,46.9,,", "malformed field", "mode"),
        ("GPGLL,4916.45,N,12311.12,W", "truncated", "GLL has 4 fields, needs 6"),
        ("GPGLL,4916.45,N,12311.12,W,225444,A,A".replace("12311", "12371"), "malformed", "lon"),
    ],
)
def test_bad_gll_gns_are_rejected_with_a_reason(body, reason, detail, engine):
    rep = read_nmea([sentence(body)], engine=engine).report
    assert rep.n_rejected == 1 and rep.balanced
    (r,) = rep.first_rejects
    assert r.reason.startswith(reason) and detail in r.detail, r


# --- precedence -----------------------------------------------------------------------------

T = "120000.00"
GGA_FIX = f"GPGGA,{T},4800.000,N,01100.000,E,1,10,0.8,500.0,M,47.0,M,,"
GGA_NOFIX = f"GPGGA,{T},,,,,0,00,,,M,,M,,"
RMC_A = f"GPRMC,{T},A,4800.500,N,01100.500,E,10.0,90.0,271126,,,A"
GNS = f"GNGNS,{T},4801.000,N,01101.000,E,AA,14,0.6,510.0,47.0,,"
GLL = f"GNGLL,4802.000,N,01102.000,E,{T},A,A"


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(
    ("bodies", "source"),
    [
        ((GLL, GNS, RMC_A, GGA_FIX), GGA_FIX),
        ((GLL, GNS, RMC_A, GGA_NOFIX), RMC_A),
        ((GGA_NOFIX, GLL, GNS), GNS),
        ((GLL, GNS.replace(",AA,", ",NN,")), GLL),
        ((GGA_NOFIX, GLL), GLL),
    ],
)
def test_position_precedence(bodies, source, engine):
    """One epoch (one time): GGA with a fix > RMC status A > GNS > GLL; the position is taken
    from one sentence (latitude and longitude together)."""
    log = read_nmea([sentence(b) for b in bodies], engine=engine)
    assert log.report.n_epochs == 1
    e = log.epochs.iloc[0]
    m = pynmea2.parse(sentence(source))
    assert (e["lat_deg"], e["lon_deg"]) == pytest.approx((m.latitude, m.longitude), abs=1e-12)
    alt = {GGA_FIX: 500.0}.get(source, 510.0 if GNS in bodies else math.nan)
    np.testing.assert_equal(e["alt_m"], alt)


def test_gll_time_joins_the_epoch_as_ggas_does():
    """GLL's time (field 5) and GNS's (field 1) group the burst and are the epoch's time; with
    a ZDA's date the epoch is dated."""
    bodies = [
        "GNVTG,90.0,T,,M,10.0,N,18.5,K,A",
        f"GNGNS,{T},4801.000,N,01101.000,E,AA,14,0.6,510.0,47.0,,",
        f"GNGLL,4801.000,N,01101.000,E,{T},A,A",
        f"GNZDA,{T},27,11,2026,00,00",
        "GNVTG,91.0,T,,M,10.0,N,18.5,K,A",
        "GNGLL,4801.010,N,01101.000,E,120001.00,A,A",
    ]
    log = read_nmea([sentence(b) for b in bodies])
    ep = log.epochs
    assert log.report.n_epochs == 2 and log.report.epochs_without_time == 0
    assert [t.isoformat() for t in ep["time_utc"]] == [
        "2026-11-27T12:00:00+00:00",
        "2026-11-27T12:00:01+00:00",
    ]
    assert ep["course_deg"].tolist() == [90.0, 91.0]
    assert ep["lat_deg"].iloc[1] == pytest.approx(48 + 1.01 / 60, abs=1e-12)


# --- live ---------------------------------------------------------------------------------


@pytest.mark.parametrize("name", LOGS)
def test_live_equals_batch(name):
    """``gripsense live`` reads the same tables: random chunk boundaries give the batch
    reader's epochs and line accounting on a GLL/GNS log."""
    data = (DATA / name).read_bytes()
    batch = read_nmea(data)
    rng = np.random.default_rng(43)
    live = LiveIngest(max_lines=200)
    out, i = [], 0
    while i < len(data):
        n = int(rng.integers(1, 3000))
        out.append(live.feed(data[i : i + n]))
        i += n
    out.append(live.finish())
    ep = pd.concat([o for o in out if len(o)], ignore_index=True)
    pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)
    rep = live.report
    assert (rep.total_lines, rep.parsed, rep.ignored, rep.n_epochs) == (
        batch.report.total_lines,
        batch.report.parsed,
        batch.report.ignored,
        batch.report.n_epochs,
    )
    assert ep["lat_deg"].notna().sum() > 0 or name.startswith("magellan")  # (no fix)


# --- the fleet ------------------------------------------------------------------------------


def _positions_moved(lines: list[str], to: str) -> str:
    """The demo drive with its positions moved from GGA into GNS (mode DD: differential, as
    the GGA's quality 2) or GLL (status A, mode D), and RMC's position fields emptied: the
    same numbers, in the sentences of a receiver without GGA."""
    out = []
    for ln in lines:
        f = ln[1 : ln.index("*")].split(",")
        if f[0].endswith("GGA"):
            t, lat, ns, lon, ew, _q, sats, hdop, alt = f[1:10]
            if to == "GNS":
                body = f"GNGNS,{t},{lat},{ns},{lon},{ew},DD,{sats},{hdop},{alt},30.000,1.0,0001"
            else:
                body = f"GPGLL,{lat},{ns},{lon},{ew},{t},A,D"
            out.append(sentence(body))
        elif f[0].endswith("RMC"):
            f[3:7] = ["", "", "", ""]
            out.append(sentence(",".join(f)))
        else:
            out.append(ln)
    return "\n".join(out) + "\n"


@pytest.mark.parametrize("to", ["GNS", "GLL"])
def test_fleet_places_a_log_whose_positions_are_in_gns_or_gll(tmp_path, to):
    """The fleet's task on the demo drive and on the same drive with its positions in GNS or
    GLL only: the same rows (cells, windows, numbers). Before issue 43: "no position fix in
    the log (GGA/RMC)"."""
    import gzip

    import gripsense
    from gripsense.config import Vehicle
    from gripsense.fleet.tasks import process_log

    data = Path(gripsense.__file__).parent / "data"
    lines = gzip.decompress((data / "demo" / "case001.nmea.gz").read_bytes()).decode()
    lines = lines.splitlines()
    vehicle = Vehicle.from_toml(data / "corolla_sim.toml")
    a, b = tmp_path / "gga.nmea", tmp_path / f"{to}.nmea"
    a.write_text("\n".join(lines) + "\n")
    b.write_text(_positions_moved(lines, to))
    assert read_nmea(b).report.parsed.get("GGA", 0) == 0
    rows_a = process_log(str(a), vehicle, vehicle_id="car")
    rows_b = process_log(str(b), vehicle, vehicle_id="car")
    assert len(rows_a) > 0
    pd.testing.assert_frame_equal(rows_a.drop(columns="log"), rows_b.drop(columns="log"))


@pytest.mark.parametrize("engine", ENGINES)
def test_gns_per_constellation_sentences_join_the_combined_one(engine):
    """NMEA 4.x: the combined ``$GNGNS`` with the position, then ``$GPGNS`` / ``$GLGNS`` with
    null position fields and their own satellites: one epoch per time, the combined
    sentence's position, altitude, satellites and HDOP."""
    bodies = []
    for k in range(2):
        t = f"12000{k}.00"
        bodies += [
            f"GNGNS,{t},48{k:02d}.000,N,01101.000,E,AAN,14,0.6,51{k}.0,47.0,,,V",
            f"GPGNS,{t},,,,,A,08,0.9,,,,,V",
            f"GLGNS,{t},,,,,A,06,1.1,,,,,V",
        ]
    log = read_nmea([sentence(b) for b in bodies], engine=engine)
    assert log.report.n_epochs == 2 and log.report.parsed == {"GNS": 6}
    ep = log.epochs
    assert ep["lat_deg"].tolist() == [48.0, 48 + 1 / 60]
    assert ep["alt_m"].tolist() == [510.0, 511.0]
    assert ep["n_sats"].tolist() == [14.0, 14.0] and ep["hdop"].tolist() == [0.6, 0.6]


@pytest.mark.parametrize("name", ["sounder.log", "ericsson-gru04-02-70sec.log"])
def test_replay_is_paced_by_gll_and_gns_times(name):
    """``gripsense live --replay`` paces a log by its sentences' times: a GLL-only log (time in
    field 5) and a GNS log (field 1) carry their times as pynmea2 reads them."""
    from gripsense.live.sources import _pieces

    pieces = _pieces((DATA / name).read_bytes())
    n = 0
    for line, tod in pieces:
        text = line.decode("ascii").strip()
        if text[3:7] in ("GLL,", "GNS,"):
            t = pynmea2.parse(text).timestamp
            assert tod == pytest.approx(t.hour * 3600 + t.minute * 60 + t.second, abs=1e-9)
            n += 1
    assert n == sum(1 for ln, _ in pieces if ln[3:7] in (b"GLL,", b"GNS,")) > 70
