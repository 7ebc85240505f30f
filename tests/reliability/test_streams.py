"""Streams read once, never forever: a log from a pipe, a FIFO or stdin gives what the file
gives; every read is bounded by ``--max-lines`` / ``--max-bytes`` (a pipe beyond them is one
error naming the limit; a file's rest is counted); a device file is refused in one line; a gzip
bomb costs neither memory nor minutes (issue 40, "Streams read twice or forever").

The inputs are real: simulated drives in every format (``gripsense simulate``), real pipes
(``os.pipe``), FIFOs (``os.mkfifo``) fed by a writer thread, ``/dev/zero``, real gzip files.
"""

from __future__ import annotations

import gzip
import os
import re
import resource
import subprocess
import sys
import threading
import tracemalloc
import zlib
from pathlib import Path

import pytest

from gripsense.errors import InputError
from gripsense.io.logs import read_log
from gripsense.io.logs.nmea import read_nmea
from gripsense.io.text import read_bytes, read_toml
from gripsense.io.tyres.tir import MAX_TIR_BYTES, read_tir
from tests.conftest import DATA
from tests.io.simulated import simulated  # noqa: F401  (real files of `gripsense simulate`)

GRIPSENSE = [str(Path(sys.executable).parent / "gripsense")]
TIR = DATA / "tyre" / "tir" / "MagicFormula61_Paramerters.tir"
# a bound on a read that must end: far above the time it takes, and a thread that does not
# finish by then has hung (the old code's FIFO)
HANG_S = 600.0


def _writer(fd: int, data: bytes | None = None, *, endless: bytes = b"", cap: int = 0):
    """A thread writing *data* (or *endless* repeated up to *cap* bytes) to *fd*, then closing
    it; a reader that stops early ends it (broken pipe)."""

    def run() -> None:
        try:
            with os.fdopen(fd, "wb", buffering=0) as f:
                if data is not None:
                    f.write(data)
                    return
                sent = 0
                while sent < cap:
                    f.write(endless)
                    sent += len(endless)
        except (BrokenPipeError, OSError):
            pass

    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t


def _in_thread(fn):
    """Run *fn* in a thread; its result (or exception), or ``"hung"`` when it does not end
    within :data:`HANG_S`."""
    box: dict = {}

    def run() -> None:
        try:
            box["value"] = fn()
        except BaseException as e:  # handed to the test
            box["error"] = e

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(HANG_S)
    if t.is_alive():
        return "hung"
    if "error" in box:
        raise box["error"]
    return box["value"]


def _error(fn, *args) -> InputError | str:
    """The InputError *fn* raises (``"no error"`` when it returns)."""
    try:
        fn(*args)
    except InputError as e:
        return e
    return "no error"


def _log(sim, fmt: str) -> tuple[Path, dict]:
    s = sim(fmt)
    return s.log, ({"columns": s.columns} if fmt == "mf4" else {})


def _same(a, b) -> None:
    ra, rb = a.report, b.report
    assert ra.total_lines == rb.total_lines
    assert (ra.parsed, ra.ignored, ra.rejected) == (rb.parsed, rb.ignored, rb.rejected)
    assert ra.balanced and ra.n_epochs == rb.n_epochs
    assert a.epochs.equals(b.epochs)


# --- read once --------------------------------------------------------------------------


@pytest.mark.parametrize("fmt", ["nmea-plain", "nmea", "ubx", "vbo", "mf4"])
def test_a_log_from_a_pipe_is_the_log_from_its_file(simulated, tmp_path, fmt):  # noqa: F811
    """``gripsense ingest <(cat log)``: the format sniff does not eat what the reader reads
    (the old code lost the first 64 KiB of a pipe and still said balanced)."""
    path, kw = _log(simulated, fmt.split("-")[0])
    if fmt == "nmea-plain":  # 83 KB of text: more than the sniff's 64 KiB
        plain = tmp_path / "drive.nmea"
        plain.write_bytes(gzip.decompress(path.read_bytes()))
        path = plain
    data = path.read_bytes()
    assert len(data) > 65536 or fmt in ("nmea", "vbo")
    ref = read_log(path, **kw)
    r, w = os.pipe()
    _writer(w, data)
    try:
        got = _in_thread(lambda: read_log(f"/dev/fd/{r}", **kw))
    finally:
        os.close(r)
    assert got != "hung"
    _same(got, ref)


def test_calibrate_reads_a_pipe_once(tmp_path):
    """``gripsense calibrate <(cat log)``: the log is hashed and read from one read of the
    pipe — the drive's sums and SHA-256 are those of its file (the old code hashed the pipe
    first and then read an empty log)."""
    from gripsense import FrictionRun
    from gripsense.pipeline import log_drive_sums
    from gripsense.sim import maneuvers as M
    from gripsense.sim.drives import simulate_drive, truth_vehicle, user_vehicle

    d = simulate_drive("sedan", "mf-book", M.everyday(60 / 3.6, seed=100), 0.9, seed=100)
    log = tmp_path / "everyday.nmea.gz"
    log.write_bytes(gzip.compress(("\n".join(d.lines) + "\n").encode("ascii")))
    run = FrictionRun(user_vehicle(truth_vehicle("sedan"), "mf-book"))
    ref = log_drive_sums(log, run)
    assert ref
    r, w = os.pipe()
    _writer(w, log.read_bytes())
    try:
        got = _in_thread(lambda: log_drive_sums(f"/dev/fd/{r}", run))
    finally:
        os.close(r)
    assert got != "hung"
    assert [(s.axle, s.sha256, s.bins) for s in got] == [(s.axle, s.sha256, s.bins) for s in ref]


@pytest.mark.parametrize("fmt", ["nmea", "ubx"])
def test_a_named_pipe_is_read_once_as_a_stream(simulated, tmp_path, fmt):  # noqa: F811
    """A FIFO (``mkfifo``) fed by a writer: read once, the same as its file — the old code
    opened it twice and waited forever for a second writer."""
    path, kw = _log(simulated, fmt)
    ref = read_log(path, **kw)
    fifo = tmp_path / "live.fifo"
    os.mkfifo(fifo)

    def write() -> None:
        try:
            with open(fifo, "wb") as f:
                f.write(path.read_bytes())
        except BrokenPipeError:
            pass

    t = threading.Thread(target=write, daemon=True)
    t.start()
    got = _in_thread(lambda: read_log(fifo, **kw))
    if got == "hung":  # release the reader blocked in open() before failing
        fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
    assert got != "hung", "reading a FIFO did not end"
    t.join(HANG_S)
    _same(got, ref)


@pytest.mark.parametrize("stdin", ["-", "/dev/stdin"])
def test_stdin_through_the_command(simulated, tmp_path, stdin):  # noqa: F811
    """``… | gripsense ingest -`` (or ``/dev/stdin``): the same accounting as the file."""
    path, _ = _log(simulated, "ubx")
    ref = read_log(path).report
    proc = subprocess.run(
        [*GRIPSENSE, "ingest", stdin],
        input=path.read_bytes(),
        capture_output=True,
        timeout=HANG_S,
        cwd=tmp_path,
    )
    out = proc.stdout.decode()
    assert proc.returncode == 0, proc.stderr.decode()
    assert f"= {ref.total_lines} lines and frames; balanced: yes" in out
    assert f"{ref.n_epochs} epochs" in out


# --- devices ------------------------------------------------------------------------------


def _limited(cmd: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """*cmd* with 3 GB of address space and :data:`HANG_S` seconds (the old code read
    ``/dev/zero`` until memory ran out)."""

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    return subprocess.run(cmd, capture_output=True, timeout=HANG_S, cwd=cwd, preexec_fn=limit)


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null", "/dev/urandom"])
def test_a_device_is_refused_in_one_line(tmp_path, device):
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    proc = _limited([*GRIPSENSE, "ingest", device], tmp_path)
    err = proc.stderr.decode().strip()
    assert proc.returncode == 2, err
    assert err.count("\n") == 0 and "Traceback" not in err
    assert err.startswith(f"error: {device}: is a character device") and "regular file" in err


@pytest.mark.parametrize(
    "reader",
    [
        lambda p: read_nmea(p),
        lambda p: read_log(p),
        lambda p: read_tir(p),
        lambda p: read_toml(p, "vehicle file"),
        lambda p: read_bytes(p, "steering CSV"),
    ],
    ids=["read_nmea", "read_log", "read_tir", "read_toml", "read_bytes"],
)
def test_every_reader_refuses_a_device(reader):
    result = _in_thread(lambda: _error(reader, "/dev/zero"))
    assert result != "hung"
    assert "/dev/zero: is a character device" in str(result)


def test_a_dangling_link_is_named(tmp_path):
    link = tmp_path / "drive.nmea"
    link.symlink_to(tmp_path / "gone.nmea")
    with pytest.raises(InputError, match=r"drive\.nmea: a link to nothing"):
        read_log(link)


# --- bounded reads ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("endless", "limit", "flag"),
    [
        (bytes(1 << 16), {"max_bytes": 1 << 20}, "--max-bytes"),  # /dev/zero through a pipe
        (b"$GPHDT,274.07,T*03\r\n" * 3000, {"max_lines": 10_000}, "--max-lines"),
        (b"$GPHDT,274.07,T*03\r\n" * 3000, {"max_bytes": 1 << 20}, "--max-bytes"),
    ],
    ids=["zeros-bytes", "lines-lines", "lines-bytes"],
)
def test_an_endless_pipe_stops_at_the_limit(endless, limit, flag):
    """A pipe that never ends (``cat /dev/zero |``, ``yes '$GPHDT…' |``): the read stops at
    the limit with one error naming it and the option that raises it; memory stays near the
    limit. The writer stops after 64 × the limit, so the old code (which read on) ends too and
    fails the test instead of hanging."""
    cap = 64 * max(limit.get("max_bytes", 0), 20 * limit.get("max_lines", 0))
    r, w = os.pipe()
    _writer(w, endless=endless, cap=cap)
    tracemalloc.start()
    try:
        got = _in_thread(lambda: _error(lambda p: read_log(p, **limit), f"/dev/fd/{r}"))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        os.close(r)
    assert got != "hung"
    msg = str(got)
    assert f"/dev/fd/{r}: more than" in msg and flag in msg and "pipe" in msg
    assert peak < 8 * (1 << 20) + 4 * limit.get("max_bytes", 1 << 20)


def test_a_big_file_keeps_the_limit_and_counts_the_rest(tmp_path):
    """A file beyond ``max_bytes`` (here 40 MB of NUL bytes after real sentences): the lines
    within the limit are read, the rest counted as over the size limit — with memory near the
    limit, not the file's size."""
    good = b"$GPHDT,274.07,T*03\r\n" * 1000
    p = tmp_path / "big.nmea"
    with open(p, "wb") as f:
        f.write(good)
        for _ in range(40):
            f.write(bytes(1 << 20) + b"\n")
    tracemalloc.start()
    try:
        log = read_log(p, max_bytes=1 << 20)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    rep = log.report
    assert rep.balanced and rep.total_lines == 1000 + 40
    assert rep.parsed == {"HDT": 1000} and rep.rejected["over the size limit"] == 40
    assert any("--max-bytes" in n for n in rep.notes)
    assert peak < 16 * (1 << 20), peak


def test_max_lines_bounds_the_read_not_only_the_parse(tmp_path):
    """``--max-lines`` stops the read itself: a file of 2 million lines read with
    ``max_lines=1000`` never holds more than a few MB (the old code read it all first)."""
    line = b"$GPHDT,274.07,T*03\r\n"
    p = tmp_path / "long.nmea"
    p.write_bytes(line * 2_000_000)  # 40 MB
    tracemalloc.start()
    try:
        log = read_log(p, max_lines=1000)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    rep = log.report
    assert rep.parsed == {"HDT": 1000} and rep.rejected["over the size limit"] == 1_999_000
    assert rep.balanced
    assert peak < 8 * (1 << 20), peak


def test_the_command_names_the_limit(tmp_path):
    """``gripsense ingest --max-bytes`` and ``--max-lines`` on a pipe: one line, exit 2."""
    data = b"$GPHDT,274.07,T*03\r\n" * 5000
    for flag, value in (("--max-bytes", "10000"), ("--max-lines", "100")):
        proc = subprocess.run(
            [*GRIPSENSE, "ingest", "/dev/stdin", flag, value],
            input=data,
            capture_output=True,
            timeout=HANG_S,
            cwd=tmp_path,
        )
        err = proc.stderr.decode().strip()
        assert proc.returncode == 2 and err.count("\n") == 0, err
        assert f"more than {value}" in err and flag in err


# --- gzip bombs ---------------------------------------------------------------------------


def _bomb(path: Path, size: int, head: bytes = b"") -> None:
    """*head* then *size* NUL bytes, gzip-compressed (about 1000:1), written in pieces."""
    c = zlib.compressobj(9, zlib.DEFLATED, 16 + zlib.MAX_WBITS)
    with open(path, "wb") as f:
        f.write(c.compress(head))
        block = bytes(1 << 20)
        for _ in range(size >> 20):
            f.write(c.compress(block))
        f.write(c.flush())


def test_a_gzip_bomb_as_a_tyre_file_is_refused(tmp_path):
    """A ``.tir.gz`` that expands to 200 MB (a vehicle's ``[steering] tyre_file``): refused
    after :data:`MAX_TIR_BYTES` decompressed, in one line naming the file; the old code
    decompressed all of it (4 GB for the issue's bomb)."""
    bomb = tmp_path / "tyre.tir.gz"
    _bomb(bomb, 200 << 20, TIR.read_bytes())
    assert bomb.stat().st_size < 1 << 20
    tracemalloc.start()
    try:
        with pytest.raises(InputError) as e:
            read_tir(bomb)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    msg = str(e.value)
    assert msg.startswith(str(bomb)) and f"more than {MAX_TIR_BYTES} bytes (decompressed)" in msg
    assert peak < MAX_TIR_BYTES * 3 + (8 << 20), peak
    # the same file read as a real .tir.gz when it is one
    good = tmp_path / "good.tir.gz"
    good.write_bytes(gzip.compress(TIR.read_bytes()))
    assert read_tir(good).parameters() == read_tir(TIR).parameters()


def test_a_gzip_bomb_as_a_vehicle_tyre_file(tmp_path):
    """The issue's case through the vehicle file: one InputError, memory bounded."""
    from gripsense.config import Vehicle
    from gripsense.data import sample_path

    bomb = tmp_path / "tyre.tir.gz"
    _bomb(bomb, 100 << 20, TIR.read_bytes())
    text = sample_path("corolla_sim.toml").read_text()
    text, n = re.subn(r"(?m)^\[steering\].*$", '\\g<0>\ntyre_file = "tyre.tir.gz"', text)
    assert n == 1
    car = tmp_path / "car.toml"
    car.write_text(text)
    tracemalloc.start()
    try:
        with pytest.raises(InputError, match=r"tyre\.tir\.gz: more than"):
            Vehicle.from_toml(car)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < MAX_TIR_BYTES * 3 + (16 << 20), peak


def test_a_gzip_bomb_as_a_log_is_counted_not_held(tmp_path):
    """A 100 KB ``.nmea.gz`` of 100 MB: the real sentences at its start read, the rest counted
    beyond ``max_bytes`` while memory stays near the limit."""
    bomb = tmp_path / "drive.nmea.gz"
    _bomb(bomb, 100 << 20, b"$GPHDT,274.07,T*03\r\n" * 100 + b"\n")
    tracemalloc.start()
    try:
        log = read_log(bomb, max_bytes=1 << 20)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    rep = log.report
    assert rep.parsed == {"HDT": 100} and rep.balanced
    assert rep.rejected["over the size limit"] >= 1
    assert peak < 16 * (1 << 20), peak
