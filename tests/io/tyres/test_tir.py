"""`.tir` reader/writer: real files (MFeval examples, Project Chrono), round trip, errors, units."""

from __future__ import annotations

import gzip
import io
from pathlib import Path

import pytest

from gripsense.errors import InputError
from gripsense.io.tyres.tir import TirError, TirFile, read_tir, write_tir

TIR_DIR = Path(__file__).parents[2] / "data" / "tyre" / "tir"
TIR_FILES = sorted(TIR_DIR.glob("*.tir"))


def test_shared_files_present():
    assert len(TIR_FILES) == 9


@pytest.mark.parametrize("path", TIR_FILES, ids=lambda p: p.name)
def test_round_trip_is_byte_identical(path, tmp_path):
    tir = read_tir(path)
    out = write_tir(tir, tmp_path / path.name)
    assert out.read_bytes() == path.read_bytes()


@pytest.mark.parametrize("path", TIR_FILES, ids=lambda p: p.name)
def test_changed_values_survive_a_round_trip(path, tmp_path):
    """Every numeric value perturbed, written, read back: all values equal (bit for bit)."""
    tir = read_tir(path)
    changed = {}
    for i, key in enumerate(tir.keys()):
        v = tir[key]
        if isinstance(v, float):
            changed[key] = v * (1 + 1e-7 * (i + 1)) + 1e-300
        elif isinstance(v, int) and key not in ("FITTYP",):
            changed[key] = v + 1
        elif isinstance(v, str):
            changed[key] = v + "x"
    for k, v in changed.items():
        tir.set(k, v)
    again = read_tir(write_tir(tir, tmp_path / path.name))
    for k, v in changed.items():
        assert again[k] == v, k
    # untouched layout: the same number of lines, comments kept
    assert again.to_text().count(tir.newline) == path.read_bytes().decode("latin-1").count(
        tir.newline
    )


def test_line_endings_tabs_and_case(tmp_path):
    mf61 = read_tir(TIR_DIR / "MagicFormula61_Paramerters.tir")  # tab separated, CRLF
    assert mf61.newline == "\r\n"
    assert mf61["pdy1"] == mf61["PDY1"] == pytest.approx(1.0184)
    assert mf61.get("TyreSide") == "RIGHT"
    fsae = read_tir(TIR_DIR / "FSAE_Defaults.tir")  # '!' comments
    assert fsae["FITTYP"] == 61
    lf = read_tir(io.StringIO("[model]\nfittyp = 61\n"))
    assert lf.newline == "\n" and lf["FITTYP"] == 61 and lf.section_of("fittyp") == "MODEL"


def test_shape_table_and_empty_strings_kept():
    feda = read_tir(TIR_DIR / "335_65R22_5_G275MSA_40psi.tir")
    assert feda["TEST_NUMBER"] == ""
    rows = feda.table("SHAPE")
    assert rows[0].split() == ["1.00", "0.00"]
    assert feda.section_of("FNOMIN") == "VERTICAL"


def test_units_are_converted_to_si():
    text = "\n".join(
        [
            "[UNITS]",
            "LENGTH = 'mm'",
            "FORCE = 'kN'",
            "ANGLE = 'deg'",
            "PRESSURE = 'bar'",
            "[DIMENSION]",
            "UNLOADED_RADIUS = 300",
            "[VERTICAL]",
            "FNOMIN = 4.0",
            "VERTICAL_STIFFNESS = 200 $kN/mm",
            "[SLIP_ANGLE_RANGE]",
            "ALPMAX = 15",
            "[OPERATING_CONDITIONS]",
            "NOMPRES = 2.2",
            "[LATERAL_COEFFICIENTS]",
            "PDY1 = 1.1",
            "",
        ]
    )
    p = read_tir(io.StringIO(text)).parameters()
    assert p["UNLOADED_RADIUS"] == pytest.approx(0.3)
    assert p["FNOMIN"] == pytest.approx(4000.0)
    assert p["VERTICAL_STIFFNESS"] == pytest.approx(200e3 / 1e-3)
    assert p["ALPMAX"] == pytest.approx(0.2617993877991494)
    assert p["NOMPRES"] == pytest.approx(220000.0)
    assert p["PDY1"] == 1.1  # coefficients are dimensionless: untouched


def test_fortran_exponents_and_unquoted_words():
    t = read_tir(
        io.StringIO("[MODEL]\nTYRESIDE = LEFT\n[LATERAL_COEFFICIENTS]\nPDY2 = 1.5D-03 $c\n")
    )
    assert t["PDY2"] == pytest.approx(1.5e-3)
    assert t["TYRESIDE"] == "LEFT"


def test_gzip_and_binary_streams(tmp_path):
    src = TIR_DIR / "FSAE_Defaults.tir"
    gz = tmp_path / "f.tir.gz"
    gz.write_bytes(gzip.compress(src.read_bytes()))
    assert read_tir(gz)["FNOMIN"] == read_tir(io.BytesIO(src.read_bytes()))["FNOMIN"] == 1000


def test_errors_name_line_and_key(tmp_path):
    with pytest.raises(TirError, match=r"line 2 \(PDY1\)"):
        read_tir(io.StringIO("[LATERAL_COEFFICIENTS]\nPDY1 = 1.0x\n"))
    with pytest.raises(TirError, match="unterminated"):
        read_tir(io.StringIO("[MODEL]\nTYRESIDE = 'LEFT\n"))
    with pytest.raises(TirError, match="line 1"):
        read_tir(io.StringIO("hello world\n[MODEL]\nA = 1\n"))
    with pytest.raises(TirError, match="not a known unit"):
        read_tir(io.StringIO("[UNITS]\nLENGTH = 'furlong'\n[X]\nA=1\n")).parameters()
    with pytest.raises(InputError, match="no such file"):
        read_tir(tmp_path / "missing.tir")


def test_from_sections_writes_a_readable_file(tmp_path):
    t = TirFile.from_sections(
        {
            "MODEL": {"FITTYP": 61, "TYRESIDE": "LEFT"},
            "LATERAL_COEFFICIENTS": {"PCY1": 1.3, "PDY1": -0.9871234567891234},
        },
        comments={"PCY1": "Shape factor"},
        header=["written by a test"],
    )
    back = read_tir(write_tir(t, tmp_path / "x.tir"))
    assert back["PDY1"] == -0.9871234567891234
    assert back["TYRESIDE"] == "LEFT"
    assert back.sections["LATERAL_COEFFICIENTS"] == {"PCY1": 1.3, "PDY1": -0.9871234567891234}
