"""VBOX .vbo: a real Racelogic file read against the format's description, round trips, and
every kind of bad input as one clear error or a counted line."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.vbo import parse_vbo, read_vbo, write_vbo
from tests.conftest import DATA

SAMPLE = DATA / "formats" / "sample.vbo"
SAMPLE_TEXT = SAMPLE.read_text()


def test_real_sample_against_the_format_description():
    """The Racelogic sample: latitude in minutes north, longitude in minutes **west**
    positive, speed in km/h, time hhmmss.ss UTC on the preamble's date (worked by hand)."""
    log = read_vbo(SAMPLE)
    ep = log.epochs
    assert len(ep) == 6
    # first data row: 019 105633.680 +3119.37247163 +0059.48225769 000.153 218.05 +0155.06
    assert ep["lat_deg"].iloc[0] == pytest.approx(51 + 59.37247163 / 60, abs=1e-12)
    assert ep["lon_deg"].iloc[0] == pytest.approx(-(0 + 59.48225769 / 60), abs=1e-12)
    assert ep["speed_mps"].iloc[0] == pytest.approx(0.153 / 3.6)
    assert ep["course_deg"].iloc[0] == 218.05
    assert ep["alt_m"].iloc[0] == 155.06
    assert ep["n_sats"].iloc[0] == 19 and ep["fix_quality"].iloc[0] == 1
    assert ep["time_utc"].iloc[0] == pd.Timestamp("2013-12-03 10:56:33.680", tz="UTC")
    assert ep["t_s"].iloc[-1] == pytest.approx(0.05)
    # no dual-antenna channel: no heading (and so no yaw rate from it)
    assert ep["heading_deg"].isna().all()
    rep = log.report
    assert rep.format == "VBOX VBO" and rep.balanced
    assert rep.parsed == {"VBO data": 6}
    assert rep.total_lines == len(SAMPLE_TEXT.splitlines())


def _epochs(n: int = 50, rate: float = 10.0, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    return pd.DataFrame(
        {
            "time_utc": pd.Timestamp("2026-03-01 23:59:57", tz="UTC") + pd.to_timedelta(t, "s"),
            "t_s": t,
            "lat_deg": 35.5 + rng.normal(0, 1e-4, n),
            "lon_deg": -120.25 + rng.normal(0, 1e-4, n),  # west: negative here, positive in .vbo
            "alt_m": 12.0 + rng.normal(0, 1, n),
            "n_sats": np.full(n, 14.0),
            "speed_mps": rng.uniform(5, 30, n),
            "course_deg": rng.uniform(0, 360, n),
            "heading_deg": rng.uniform(0, 360, n),
            "yaw_rate_rps": rng.normal(0, 0.3, n),
        }
    )


def test_round_trip_to_the_format_resolution_across_midnight(tmp_path):
    ep = _epochs()
    steer = pd.DataFrame({"t_s": ep["t_s"], "road_wheel_deg": np.linspace(-2, 3, len(ep))})
    write_vbo(ep, tmp_path / "d.vbo", steer=steer)
    log = read_vbo(tmp_path / "d.vbo", columns="steer=RoadWheelAngle")
    got = log.epochs
    # the file's resolutions: 1e-8 minute, 0.001 km/h, 0.01° course, 0.001° heading
    np.testing.assert_allclose(got["lat_deg"], ep["lat_deg"], atol=1e-9)
    np.testing.assert_allclose(got["lon_deg"], ep["lon_deg"], atol=1e-9)
    np.testing.assert_allclose(got["speed_mps"], ep["speed_mps"], atol=0.0005 / 3.6 + 1e-12)
    np.testing.assert_allclose(got["course_deg"], ep["course_deg"], atol=0.005 + 1e-9)
    np.testing.assert_allclose(got["heading_deg"], ep["heading_deg"], atol=0.0005 + 1e-9)
    np.testing.assert_allclose(got["yaw_rate_rps"], ep["yaw_rate_rps"], atol=np.deg2rad(5e-4))
    np.testing.assert_allclose(np.rad2deg(got["steer_rad"]), steer["road_wheel_deg"], atol=1e-5)
    assert (got["yaw_rate_source"] == "VBOX").all() and (got["heading_source"] == "VBOX").all()
    # the time of day rolls over midnight onto the next date
    assert (got["time_utc"] - ep["time_utc"]).abs().max() < pd.Timedelta("1ms")
    assert got["time_utc"].iloc[-1].date() == dt.date(2026, 3, 2)
    assert log.report.balanced


def test_short_and_non_numeric_rows_are_counted_with_their_line(tmp_path):
    lines = SAMPLE_TEXT.splitlines()
    k = lines.index("[data]")
    lines[k + 2] = lines[k + 2][:40]  # cut short
    lines[k + 3] = lines[k + 3].replace("197.16", "19?.16")  # not a number
    log = parse_vbo("\n".join(lines), "bad.vbo")
    rep = log.report
    assert rep.rejected["truncated"] == 1 and rep.rejected["malformed field"] == 1
    assert [r.line for r in rep.first_rejects] == [k + 3, k + 4]  # 1-based
    assert rep.balanced and len(log.epochs) == 4
    with pytest.raises(InputError, match=rf"bad.vbo:{k + 3}: truncated"):
        parse_vbo("\n".join(lines), "bad.vbo", strict=True)


@pytest.mark.parametrize("section", ["[column names]", "[data]"])
def test_a_missing_section_is_one_clear_error(section):
    text = SAMPLE_TEXT.replace(section, "")
    with pytest.raises(InputError, match=rf"x.vbo: .*no \{section[:-1]}\] section"):
        parse_vbo(text, "x.vbo")


def test_a_file_without_header_section_is_read():
    """[header] is optional (some loggers write only [column names] and [data])."""
    lines = SAMPLE_TEXT.splitlines()
    h0 = lines.index("[header]")
    h1 = next(i for i in range(h0 + 1, len(lines)) if lines[i].startswith("["))
    log = parse_vbo("\n".join(lines[:h0] + lines[h1:]) + "\n", "x.vbo")
    assert len(log.epochs) == 6 and log.report.balanced
    assert log.epochs["speed_mps"].iloc[0] == pytest.approx(0.153 / 3.6)  # km/h by default


def test_a_mapped_channel_without_a_unit_names_the_channel_and_the_fix(tmp_path):
    ep = _epochs(5)
    steer = pd.DataFrame({"t_s": ep["t_s"], "road_wheel_deg": np.ones(5)})
    write_vbo(ep, tmp_path / "d.vbo", steer=steer)
    text = (tmp_path / "d.vbo").read_text().replace("[channel units]\ndeg\n", "[channel units]\n")
    with pytest.raises(InputError, match=r"'RoadWheelAngle' \(steer\): it has no unit.*:deg"):
        parse_vbo(text, "d.vbo", columns="steer=RoadWheelAngle")
    # the unit given in --columns is enough
    got = parse_vbo(text, "d.vbo", columns="steer=RoadWheelAngle:deg").epochs
    np.testing.assert_allclose(got["steer_rad"], np.deg2rad(1.0))
    with pytest.raises(InputError, match="no such column; the file has"):
        parse_vbo(text, "d.vbo", columns="steer=Steer")


def test_content_not_the_suffix_decides(tmp_path):
    import gzip

    (tmp_path / "drive.txt").write_bytes(SAMPLE.read_bytes())
    (tmp_path / "drive.log.gz").write_bytes(gzip.compress(SAMPLE.read_bytes()))
    for name in ("drive.txt", "drive.log.gz"):
        log = read_log(tmp_path / name)
        assert log.report.format == "VBOX VBO" and len(log.epochs) == 6
        assert log.report.channels["speed_mps"] == pytest.approx(100.0)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    cut=st.integers(0, len(SAMPLE_TEXT)),
    junk=st.text(min_size=0, max_size=30),
    at=st.integers(0, len(SAMPLE_TEXT)),
)
def test_fuzz_never_a_traceback(cut, junk, at):
    """Any cut or insertion: a log with every line accounted for, or one InputError."""
    text = SAMPLE_TEXT[:at] + junk + SAMPLE_TEXT[at:cut] if cut > at else SAMPLE_TEXT[:cut]
    try:
        log = parse_vbo(text, "f.vbo")
    except InputError:
        return
    assert log.report.balanced
    assert log.report.total_lines == len(text.splitlines())


# --- real files as they come (issue 43) --------------------------------------------------------

VB3I = DATA / "formats" / "vbox" / "vb3i_imu_can.vbo"
# the file is GPL-3.0: in the repository, not in the sdist (tests/data/formats/README.md)
needs_vb3i = pytest.mark.skipif(not VB3I.exists(), reason="copyleft test file not shipped here")
"""A real VBOX 3i file with an IMU and a CAN module (Racelogic-VBO-Converter's example, its
first 100 rows; tests/data/formats/README.md): Latin-1 ``°``, blank unit lines, a CAN channel
named twice in [column names]."""


def _field(text: str, row: int, column: str, k: int = 1) -> float:
    """The value of a column in a data row, read from the text by hand (k-th of that name)."""
    lines = text.splitlines()
    cols = lines[lines.index("[column names]") + 1].split()
    j = [i for i, c in enumerate(cols) if c == column][k - 1]
    return float(lines[lines.index("[data]") + 1 + row].split()[j])


@needs_vb3i
def test_real_vbox3i_with_modules_reads_its_latin1_units_in_place():
    """Through read_log (the path of every command): YawRate is in °/s (byte 0xB0 in the
    file; the blank unit of Veh_VoG_QF keeps its place) and AvgWhl_V in kph."""
    text = VB3I.read_bytes().decode("latin-1")
    assert b"\xb0/s" in VB3I.read_bytes()
    log = read_log(VB3I, columns="yaw_rate=YawRate,speed=AvgWhl_V")
    ep, rep = log.epochs, log.report
    assert len(ep) == 100 and rep.parsed == {"VBO data": 100} and rep.balanced
    yaw = [_field(text, i, "YawRate") for i in range(3)]  # -0.43, -0.52, -0.12 deg/s
    np.testing.assert_allclose(ep["yaw_rate_rps"].iloc[:3], np.deg2rad(yaw), rtol=1e-12)
    # the standard channels against the format description, by hand
    assert ep["lat_deg"].iloc[0] == pytest.approx(52 + 21.68909263 / 60, abs=1e-12)  # 3141.69 min
    assert ep["lon_deg"].iloc[0] == pytest.approx(-(1 + 39.51333601 / 60), abs=1e-12)
    assert ep["time_utc"].iloc[0] == pd.Timestamp("2016-03-01 14:26:19.860", tz="UTC")
    assert ep["fix_quality"].iloc[0] == 1  # Solution_Type +00001: GNSS


@needs_vb3i
def test_real_file_steering_wheel_channel_named_twice(tmp_path):
    """SteeringWh is columns 44 and 49 of [column names]; the same values: the first is read
    and said; different values: one line naming both columns and the mapping that chooses."""
    log = read_vbo(VB3I)
    assert log.report.steering["channel"] == "SteeringWh"
    assert log.report.steering["key"] == "steering_wheel"  # ° (Degrees), cut by VBOX
    assert any("'SteeringWh'" in n and "columns 44 and 49" in n for n in log.report.notes)
    raw = VB3I.read_bytes().decode("latin-1")
    lines = raw.split("\r\n")
    k = lines.index("[data]") + 1
    fields = lines[k].split(" ")
    assert fields[48] == "+0.000000E+00"
    fields[48] = "+4.500000E+01"  # the second SteeringWh: 45 deg in the first row
    lines[k] = " ".join(fields)
    (tmp_path / "twice.vbo").write_bytes("\r\n".join(lines).encode("latin-1"))
    with pytest.raises(InputError, match=r"'SteeringWh'.*columns 44 and 49.*SteeringWh\[2\]"):
        read_log(tmp_path / "twice.vbo", columns="steering_wheel=SteeringWh")
    # found by its name (not mapped): not used, and said
    found = read_log(tmp_path / "twice.vbo")
    assert found.report.steering == {} and "steering_wheel_rad" not in found.epochs
    assert any("columns 44 and 49) with different values: not used" in n for n in
               found.report.notes)  # fmt: skip
    got = read_log(tmp_path / "twice.vbo", columns="steering_wheel=SteeringWh[2]").epochs
    assert got["steering_wheel_rad"].iloc[0] == pytest.approx(np.deg2rad(45.0))
    assert got["steering_wheel_rad"].iloc[1] == 0.0


def _with_channel(text: str, title: str, name: str, values: list[str]) -> str:
    """The sample with one more channel: its title in [header], its name in [column names],
    a value at the end of each data row."""
    lines = text.splitlines()
    h = lines.index("[header]") + 1
    while lines[h].strip():
        h += 1
    lines.insert(h, title)
    c = lines.index("[column names]") + 1
    lines[c] = lines[c].rstrip() + " " + name
    d = lines.index("[data]") + 1
    rows = [i for i in range(d, len(lines)) if lines[i].strip()]
    for i, v in zip(rows, values, strict=True):
        lines[i] = lines[i].rstrip() + " " + v
    return "\n".join(lines) + "\n"


def test_a_channel_name_with_a_space_is_read_as_header_lists_it(tmp_path):
    """`battery vo` in [column names] is one channel ([header] lists it on one line): every row
    is read, and the notes say so; without a [header] to tell, one line and no epochs."""
    text = _with_channel(SAMPLE_TEXT, "battery vo", "battery vo", ["12.6"] * 6)
    log = parse_vbo(text, "space.vbo")
    assert len(log.epochs) == 6 and log.report.balanced
    assert log.epochs["speed_mps"].iloc[0] == pytest.approx(0.153 / 3.6)
    assert any("'battery vo'" in n for n in log.report.notes)
    # a title that the name cuts (VBOX cuts names to ten characters)
    text = _with_channel(SAMPLE_TEXT, "battery voltage", "battery vo", ["12.6"] * 6)
    assert len(parse_vbo(text, "space.vbo").epochs) == 6
    lines = text.splitlines()
    h0 = lines.index("[header]")
    h1 = lines.index("[channel units]") if "[channel units]" in lines else h0 + 1
    no_header = "\n".join(lines[:h0] + lines[h1:])
    with pytest.raises(
        InputError, match=r"^space.vbo:\d+: \[column names\] has \d+ names but the rows"
    ):
        parse_vbo(no_header, "space.vbo")


def test_the_space_in_a_name_through_the_command_line(tmp_path):
    """Today's failure was "parsed 0", exit 0: now the file is read, and a file whose names
    cannot be told apart is one line and a non-zero exit."""
    from tests.cli.inprocess import cli

    text = _with_channel(SAMPLE_TEXT, "battery vo", "battery vo", ["12.6"] * 6)
    (tmp_path / "ok.vbo").write_text(text)
    r = cli("ingest", tmp_path / "ok.vbo")
    assert r.returncode == 0, r.stderr
    assert "6 epochs" in r.stdout and "'battery vo' holds a space" in r.stdout
    assert r.stderr.strip() == ""  # nothing on stderr
    bad = text.replace("battery vo\n", "battery\nvo\n", 1)  # [header] lists two channels
    (tmp_path / "bad.vbo").write_text(bad)
    r = cli("ingest", tmp_path / "bad.vbo")
    assert r.returncode != 0
    assert "Traceback" not in r.stderr
    err = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(err) == 1 and "[column names] has" in err[0] and "bad.vbo" in err[0]


def test_video_variant_sections_and_latin1_and_null_units(tmp_path):
    """A VBOX Video file's [AVI] and [laptiming] sections (a Latin-1 ``¬`` in the start line),
    ``(null)`` as the unit of a unitless channel and a unit in Latin-1 ``°``."""
    text = _with_channel(SAMPLE_TEXT, "lap_number", "lap_number", ["1"] * 6)
    text = _with_channel(text, "Steering angle", "RoadWheelAngle", ["+2.0"] * 6)
    text = text.replace("[channel units]\n", "[channel units]\n(null)\n°\n", 1).replace(
        "[column names]",
        "[AVI]\nVBOX0135_\nmp4\n\n[laptiming]\n"
        "Start  +3119.372 +0059.482 +3119.380 +0059.490 ¬  Start / Finish\n\n[column names]",
        1,
    )
    (tmp_path / "video.vbo").write_bytes(text.encode("latin-1"))
    log = read_log(tmp_path / "video.vbo")
    assert len(log.epochs) == 6 and log.report.balanced
    assert log.report.steering["channel"] == "RoadWheelAngle"
    np.testing.assert_allclose(log.epochs["steer_rad"], np.deg2rad(2.0))


def test_decimal_commas_are_read_as_points():
    """A file converted with a decimal comma (``+3119,37247163``): the same epochs as the
    original, and a note."""
    lines = SAMPLE_TEXT.splitlines()
    k = lines.index("[data]") + 1
    comma = lines[:k] + [ln.replace(".", ",") for ln in lines[k:]]
    log = parse_vbo("\n".join(comma) + "\n", "comma.vbo")
    ref = read_vbo(SAMPLE).epochs
    assert len(log.epochs) == 6 and log.report.balanced
    np.testing.assert_array_equal(log.epochs["lat_deg"], ref["lat_deg"])
    np.testing.assert_array_equal(log.epochs["speed_mps"], ref["speed_mps"])
    assert any("decimal commas" in n for n in log.report.notes)


def _rows(first: str, n: int, step: float) -> list[str]:
    """*n* rows: the first row's fields, its time (2nd field, hhmmss.ss) advanced by *step*."""
    f = first.split(" ")
    out = []
    for i in range(n):
        g = list(f)
        g[1] = f"{float(f[1]) + i * step:09.2f}"
        out.append(" ".join(g))
    return out


def test_vbox_sport_layout_battery_vo(tmp_path):
    """The layout of the issue's VBOX Sport file (github.com/b-stead/vbox, DA500.vbo; no
    licence, so its structure is replicated here with our own numbers): 14 channels in
    [header], `battery vo` in [column names] (15 words), units for the 5 module channels with
    a blank one (`batt.flags`), a Latin-1 `°` in [comments], [data] right after the names."""
    head = [
        "File created on 23/04/2018 at 09:20:26", "", "[header]",
        "satellites", "time", "latitude", "longitude", "velocity kmh", "heading", "height",
        "long accel g", "lat accel g", "temperatur", "battery vo", "batt.flags", "batt.ai",
        "batt.soc", "", "[channel units]", "degC", "v", "", "mA", "%", "", "[comments]",
        "VBSp V01.01 Build 0218", " Elevation mask = 7°", "  VBOX Sport", "",
        "[column names]",
        "sats time lat long velocity heading height GPS-Longacc GPS-Latacc temperatur "
        "battery vo batt.flags batt.ai batt.soc",
        "[data]",
    ]  # fmt: skip
    first = (
        "011 101500.00 +03000.00000 +00030.00000 012.600 090.00 +00010.00 +00.00 +00.01 "
        "+2.00000E+01 +3.80000E+00 +4.00000E+05 -1.00000E+02 +8.00000E+01"
    )
    rows = _rows(first, 10, 0.05)
    (tmp_path / "sport.vbo").write_bytes(("\r\n".join(head + rows) + " \r\n").encode("latin-1"))
    log = read_log(tmp_path / "sport.vbo")
    ep = log.epochs
    assert len(ep) == 10 and log.report.parsed == {"VBO data": 10} and log.report.balanced
    assert ep["lat_deg"].iloc[0] == pytest.approx(50.0) and ep["lon_deg"].iloc[0] == -0.5
    assert ep["speed_mps"].iloc[0] == pytest.approx(12.6 / 3.6)
    assert (ep["t_s"].diff().dropna().round(6) == 0.05).all()
    assert any("'battery vo' holds a space" in n for n in log.report.notes)


def test_units_one_line_per_column_as_racebobo_writes_them(tmp_path):
    """A converter (Racebobo) writes one [channel units] line per column, blank for most: the
    9th of 10 is `rpm`, and the blank 10th (event1) ends the section with the separator. A
    steering angle in that layout keeps its place (here the 9th)."""
    text = SAMPLE_TEXT.replace("Event 1 time\n", "Steering angle\nEvent 1 time\n", 1)
    text = text.replace("[channel units]\n", "[channel units]\n" + "\n" * 8 + "deg\n\n", 1)
    lines = text.splitlines()
    c = lines.index("[column names]") + 1
    lines[c] = lines[c].replace("event-1", "RoadWheelAngle event-1")
    assert "RoadWheelAngle event-1" in lines[c]
    d = lines.index("[data]") + 1
    for i in range(d, len(lines)):
        if lines[i].strip():
            f = lines[i].split()
            lines[i] = " ".join([*f[:8], "+1.50", *f[8:]])
    log = parse_vbo("\n".join(lines) + "\n", "racebobo.vbo")
    assert len(log.epochs) == 6 and log.report.steering["channel"] == "RoadWheelAngle"
    np.testing.assert_allclose(log.epochs["steer_rad"], np.deg2rad(1.5))


def test_the_format_descriptions_example_without_a_final_line_end():
    """The example of Racelogic's format description (VBox II, 2 Hz), pasted without a final
    line end: its last row has every field whole (`000.072` is one character shorter than
    `+000.000` before it: no sign), so it is read, not rejected as cut off."""
    text = "\n".join(
        [
            "File created on 31/07/2006 at 09:55:20", "", "[header]", "satellites", "time",
            "latitude", "longitude", "velocity kmh", "heading", "height",
            "vertical velocity kmh", "trigger event time in clock counts", "",
            "[channel units]", "", "[comments]", "(c) 2001 2003 Racelogic",
            "VBox II Version 4.5a", "Log Rate (Hz) : 02.00", "", "[column names]",
            "sats time lat long velocity heading height vertvel event1", "", "[data]",
            "137 162235.40 +03119.09973 +00058.49277 000.140 321.85 +00152.58 +000.000 00000",
            "137 162235.90 +03119.09973 +00058.49277 000.220 065.93 +00152.58 +000.000 00000",
            "137 162236.40 +03119.09973 +00058.49277 000.250 356.43 +00152.59 000.072 00000",
        ]
    )  # fmt: skip
    log = parse_vbo(text, "vbox2.vbo")
    ep = log.epochs
    assert len(ep) == 3 and log.report.rejected["truncated"] == 0 and log.report.balanced
    # sats 137 = 9 satellites + 128 (DGPS); 3119.09973 min = 51°59.09973' N; 58.49277' W
    assert ep["n_sats"].iloc[0] == 9 and ep["fix_quality"].iloc[0] == 2
    assert ep["lat_deg"].iloc[2] == pytest.approx(51 + 59.09973 / 60, abs=1e-12)
    assert ep["lon_deg"].iloc[2] == pytest.approx(-58.49277 / 60, abs=1e-12)
    assert ep["time_utc"].iloc[2] == pd.Timestamp("2006-07-31 16:22:36.40", tz="UTC")
    # cut inside its last field, the row is rejected
    cut = parse_vbo(text[:-2], "vbox2.vbo")
    assert len(cut.epochs) == 2 and cut.report.rejected["truncated"] == 1
