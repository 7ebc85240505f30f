"""Ashtech binary records (``$PASHR,MCA,`` / ``$PASHR,PBN,`` …) inside an NMEA stream (issue 43).

The real excerpt is GPSD's Magellan/Ashtech AC12 capture (``ashtech-ac12.log``): 12 MCA and 4
PBN records between GGA/RMC/ZDA/GSV and the ASCII ``$PASHR`` sentences; their binary bytes hold
CR, LF and ``$``. Before the fix they were read as lines: 8 *not NMEA* and 13 *missing
checksum* rejections out of 21 line pieces. The reference here is an independent cut written
from the Ashtech manuals' layout (header, fixed-length structure, CR LF; MCA: XOR checksum,
PBN: sum of big-endian 16-bit words), not the reader's scanner.
"""

from __future__ import annotations

import re
import struct
from itertools import pairwise
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense import InputError, read_nmea
from gripsense.io.logs.nmea.rtcm import RtcmStream, split_rtcm
from gripsense.live import LiveIngest

DATA = Path(__file__).parents[2] / "data" / "formats" / "nmea"
AC12 = DATA / "ashtech-ac12.log"
SIZE = {b"MCA": 37, b"PBN": 56}  # Ashtech DG14/DG16 and Z-Family manuals: structure + checksum


def _manual_checksum(kind: bytes, body: bytes) -> bool:
    if kind == b"MCA":
        x = 0
        for b in body[:-1]:
            x ^= b
        return x == body[-1]
    words = struct.unpack(f">{len(body) // 2 - 1}H", body[:-2])
    return sum(words) & 0xFFFF == struct.unpack(">H", body[-2:])[0]


def _records(data: bytes) -> list[tuple[int, int, bytes]]:
    """(start, end, id) of every binary record, found by the manuals' layout."""
    out = []
    for m in re.finditer(rb"\$PASHR,(MCA|PBN),", data):
        a = m.start()
        e = a + 11 + SIZE[m.group(1)] + 2
        if data[e - 2 : e] == b"\r\n" and _manual_checksum(m.group(1), data[a + 11 : e - 2]):
            out.append((a, e, m.group(1)))
    return out


def _without(data: bytes, recs) -> bytes:
    keep, pos = [], 0
    for a, e, _ in recs:
        keep.append(data[pos:a])
        pos = e
    return b"".join(keep) + data[pos:]


def test_real_capture_records_are_counted_not_rejected():
    data = AC12.read_bytes()
    recs = _records(data)
    assert [r[2] for r in recs].count(b"MCA") == 12 and [r[2] for r in recs].count(b"PBN") == 4
    # their bytes hold what breaks line splitting
    assert any(b"\r" in data[a + 11 : e - 2] for a, e, _ in recs)
    log = read_nmea(AC12)
    rep = log.report
    assert rep.ignored["Ashtech binary MCA"] == 12
    assert rep.ignored["Ashtech binary PBN"] == 4
    assert sum(rep.rejected.values()) == 0, rep.first_rejects
    assert rep.balanced
    # nothing lost: every other line of the file is read as it is without the records
    text_lines = _without(data, recs).count(b"\n")
    assert rep.total_lines == text_lines + len(recs)
    assert any("16 Ashtech binary records" in n for n in rep.notes)
    # the sentence after each PBN (a ZDA) is whole: the same sentences as the file without them
    ref = read_nmea(_without(data, recs))
    assert ref.report.parsed == rep.parsed
    pd.testing.assert_frame_equal(ref.epochs, log.epochs)


def test_line_numbers_are_the_files():
    """A rejected sentence after the records names its line in the file (records hold LFs)."""
    data = AC12.read_bytes()
    lines = data.split(b"\n")
    k = max(i for i, ln in enumerate(lines) if ln.startswith(b"$GPZDA"))
    lines[k] = lines[k].replace(b"*", b"*0")[:-1] + b"\r"  # its checksum no longer matches
    rep = read_nmea(b"\n".join(lines)).report
    assert rep.rejected["bad checksum"] == 1
    assert rep.first_rejects[0].line == k + 1


def test_junk_before_a_record_is_a_line_of_its_own():
    """Bytes before a record on the same line (a receiver's stray byte) are rejected as a line,
    and the record after them is still cut out and counted: two units, nothing lost."""
    data = AC12.read_bytes()
    a, e, kind = _records(data)[0]
    for junk in (b"\x00", b"xy"):
        rep = read_nmea(junk + data[a:e]).report
        assert rep.ignored[f"Ashtech binary {kind.decode()}"] == 1
        assert rep.rejected["not NMEA"] == 1 and sum(rep.rejected.values()) == 1
        assert rep.total_lines == 2 and rep.balanced


def test_damaged_record_is_one_bad_checksum_and_strict_names_it():
    data = bytearray(AC12.read_bytes())
    a, _e, _ = _records(bytes(data))[0]  # an MCA
    data[a + 20] ^= 0x01
    data = bytes(data)
    rep = read_nmea(data).report
    assert rep.ignored["Ashtech binary MCA"] == 11
    assert rep.rejected["bad checksum"] == 1 and sum(rep.rejected.values()) == 1
    bad = rep.first_rejects[0]
    assert bad.line == data[:a].count(b"\n") + 1
    assert bad.detail.startswith(f"byte {a}: Ashtech binary MCA record (37-byte structure)")
    with pytest.raises(InputError, match=rf"byte {a}: Ashtech binary MCA .*strict"):
        read_nmea(data, strict=True)


def test_ascii_pashr_and_a_truncated_record_stay_text():
    """``$PASHR,PBN`` in ASCII form is a sentence; a record cut short by the end of the file is
    not a record (its bytes are rejected as lines, never silently dropped)."""
    data = AC12.read_bytes()
    a, _e, _ = _records(data)[3]  # the first PBN
    cut = data[: a + 30]
    text, frames = split_rtcm(cut)
    assert text[a - len(cut) :] == cut[a:]  # the record's bytes stay in the text
    assert frames is None or frames.end.max() <= a
    rep = read_nmea(cut).report
    assert "Ashtech binary PBN" not in rep.ignored
    assert sum(rep.rejected.values()) >= 1 and rep.balanced
    ascii_pbn = b"$PASHR,PBN,1234,+1234567.89,-1234567.89,+1234567.89,,,,,,,,*00\r\n"
    text, frames = split_rtcm(ascii_pbn)
    assert frames is None and text == ascii_pbn


def _live(data: bytes, cuts):
    live = LiveIngest()
    out = []
    for a, b in pairwise([0, *sorted(set(cuts)), len(data)]):
        out.append(live.feed(data[a:b]))
    out.append(live.finish())
    got = [o for o in out if len(o)]
    return (pd.concat(got, ignore_index=True) if got else pd.DataFrame()), live.report


def _same_as_batch(data: bytes, ep, rep) -> None:
    batch = read_nmea(data, decompress=False)
    b = batch.report
    assert (rep.total_lines, rep.parsed, rep.ignored, rep.rejected, rep.notes, rep.unit) == (
        b.total_lines,
        b.parsed,
        b.ignored,
        b.rejected,
        b.notes,
        b.unit,
    )
    assert [(r.line, r.reason, r.detail) for r in rep.first_rejects] == [
        (r.line, r.reason, r.detail) for r in b.first_rejects
    ]
    assert rep.n_epochs == b.n_epochs
    pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)


def _damaged() -> bytes:
    data = bytearray(AC12.read_bytes())
    a, _, _ = _records(bytes(data))[5]
    data[a + 15] ^= 0x10
    return bytes(data)


@pytest.mark.parametrize("which", ["real", "damaged"])
def test_live_whole_and_byte_by_byte_equal_batch(which):
    data = AC12.read_bytes() if which == "real" else _damaged()
    _same_as_batch(data, *_live(data, []))
    _same_as_batch(data, *_live(data, range(1, len(data))))


@pytest.mark.parametrize("which", ["real", "damaged"])
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_live_random_chunks_equal_batch(which, data):
    raw = AC12.read_bytes() if which == "real" else _damaged()
    # cuts anywhere, and inside the records' headers ("$PAS|HR,MCA,")
    heads = [a + j for a, _, _ in _records(raw) for j in range(1, 12)]
    cuts = data.draw(st.lists(st.integers(1, len(raw) - 1) | st.sampled_from(heads), max_size=40))
    _same_as_batch(raw, *_live(raw, cuts))


def test_stream_scanner_holds_a_cut_header():
    """A piece ending in ``$PASHR,MC`` keeps those bytes until the rest arrives."""
    data = AC12.read_bytes()
    a, e, _ = _records(data)[0]
    s = RtcmStream()
    text, frames = s.feed(data[: a + 9])
    assert frames is None and s.held == 9 and not text.endswith(b"$")
    _text2, frames = s.feed(data[a + 9 : e + 5])
    assert frames is not None and frames.start.tolist() == [a] and frames.end.tolist() == [e]


# the structure sizes and checksums of the Ashtech manuals (Z-Family Technical Reference: MPC
# 95 bytes, XOR; DG14/DG16 and G12: SNV 132, SAL 70; ProMark 800: SNG 82, SNW 76 — 16-bit sums)
MANUAL = {"MPC": (95, "xor"), "SNV": (132, "sum"), "SAL": (70, "sum"), "SNG": (82, "sum"),
          "SNW": (76, "sum"), "MCA": (37, "xor"), "PBN": (56, "sum")}  # fmt: skip


def _record(kind: str, rng, *, comma: bool = False, damage: bool = False) -> bytes:
    size, algo = MANUAL[kind]
    body = bytearray(rng.integers(0, 256, size, dtype="uint8").tobytes())
    body[1:3] = b"\r\n"  # binary bytes that look like a line end, and a "$"
    body[5] = ord("$")
    if algo == "xor":
        x = 0x2C if comma else 0
        for b in body[:-1]:
            x ^= b
        body[-1] = x
    else:
        words = struct.unpack(f">{size // 2 - 1}H", bytes(body[:-2]))
        body[-2:] = struct.pack(">H", sum(words) & 0xFFFF)
    if damage:
        body[10] ^= 0x40
    return b"$PASHR," + kind.encode() + b"," + bytes(body) + b"\r\n"


@pytest.mark.parametrize("kind", sorted(MANUAL))
def test_every_documented_record_type_is_cut_and_counted(kind):
    """Records of each documented type, built from the manuals' layout, between the real
    capture's sentences: counted under their id, the sentences read as without them; one with
    a damaged checksum is one *bad checksum*."""
    import numpy as np

    rng = np.random.default_rng(len(kind) * 43 + ord(kind[0]))
    data = _without(AC12.read_bytes(), _records(AC12.read_bytes()))  # its sentences only
    base = read_nmea(data).report
    recs = [_record(kind, rng) for _ in range(3)]
    if kind == "MPC":
        recs.append(_record(kind, rng, comma=True))
    at = dict(zip([15, 25, 35, 45, 55], [*recs, _record(kind, rng, damage=True)], strict=False))
    out = []
    assert data.count(b"\n") > max(at)
    for i, ln in enumerate(data.splitlines(keepends=True)):
        out += [at[i], ln] if i in at else [ln]
    rep = read_nmea(b"".join(out)).report
    assert rep.ignored[f"Ashtech binary {kind}"] == len(recs)
    assert rep.rejected["bad checksum"] == 1 and sum(rep.rejected.values()) == 1
    assert rep.parsed == base.parsed
    assert rep.total_lines == base.total_lines + len(recs) + 1 and rep.balanced


def test_a_record_whose_bytes_read_as_a_sentence_is_still_a_record():
    """A record's binary bytes can by chance form a whole sentence (printable, ``*hh`` with the
    right NMEA checksum before its CR LF): it is still the record its Ashtech checksum says, in
    batch (which looks for records only when a line says it must) as live."""
    import numpy as np

    rng = np.random.default_rng(7)
    printable = np.frombuffer(b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefxyz.,-+ ", dtype=np.uint8)
    while True:
        body = bytearray(rng.choice(printable, 37).astype(np.uint8).tobytes())
        body[34] = ord("*")
        x = 0
        for b in b"PASHR,MCA," + bytes(body[:34]):
            x ^= b
        body[35:37] = f"{x:02X}".encode()
        a = 0
        for b in body[:36]:
            a ^= b
        if a == body[36]:
            break
    rec = b"$PASHR,MCA," + bytes(body) + b"\r\n"
    data = _without(AC12.read_bytes(), _records(AC12.read_bytes()))
    lines = data.splitlines(keepends=True)
    data = b"".join([*lines[:30], rec, *lines[30:]])
    rep = read_nmea(data).report
    assert rep.ignored["Ashtech binary MCA"] == 1
    assert "PASHR,MCA (proprietary, not used)" not in rep.ignored
    _same_as_batch(data, *_live(data, range(0, len(data), 17)))
