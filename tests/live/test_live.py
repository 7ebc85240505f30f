"""Live mode with real I/O on this machine: incremental = batch, a pseudo-terminal serial port,
a loopback TCP receiver that drops and comes back, SIGINT and SIGKILL on the command.

The runs that receive a signal are console scripts; the others (replays, recovery, refused
arguments) run in the test's process (``tests.cli.inprocess``: the console script's entry point,
its stdout, stderr and exit code) without a console script's 2–4 s of imports each."""

from __future__ import annotations

import gzip
import os
import signal
import socket
import subprocess
import threading
import time
import tty
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import gripsense
from gripsense.io import read_nmea
from gripsense.live import LiveIngest, SerialSource, TcpSource, run_live
from tests.cli.inprocess import cli
from tests.cli.test_commands import EXE

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

DATA = Path(gripsense.__file__).parent / "data"
GPSD = Path(__file__).parents[1] / "data" / "gpsd"
VEHICLE = DATA / "corolla_sim.toml"
DEMO = DATA / "demo" / "case001.nmea.gz"


def _demo_bytes() -> bytes:
    return gzip.decompress(DEMO.read_bytes())


def _feed(data: bytes, rng, max_lines=300, max_chunk=6000):
    live = LiveIngest(max_lines=max_lines)
    out, i = [], 0
    while i < len(data):
        n = int(rng.integers(1, max_chunk))
        out.append(live.feed(data[i : i + n]))
        i += n
    out.append(live.finish())
    return pd.concat([o for o in out if len(o)], ignore_index=True), live.report


def _same_report(a, b):
    return (
        a.total_lines,
        a.parsed,
        a.ignored,
        a.rejected,
        a.junk_prefix_lines,
        a.n_epochs,
        a.epochs_without_time,
    ) == (
        b.total_lines,
        b.parsed,
        b.ignored,
        b.rejected,
        b.junk_prefix_lines,
        b.n_epochs,
        b.epochs_without_time,
    )


@pytest.mark.parametrize("path", [*sorted(GPSD.glob("*.log")), DEMO], ids=lambda p: p.name)
def test_incremental_equals_batch(path):
    """Random chunk boundaries (mid-line, mid-CRLF), a tail trimmed many times: the epochs and
    the line accounting equal the batch reader's on the same bytes."""
    data = path.read_bytes()
    if path.suffix == ".gz":
        data = gzip.decompress(data)
    batch = read_nmea(data)
    ep, rep = _feed(data, np.random.default_rng(len(data)))
    pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)
    assert _same_report(rep, batch.report)


def test_memory_is_bounded_over_a_long_stream():
    data = _demo_bytes()
    live = LiveIngest(max_lines=400)
    for _ in range(5):
        for i in range(0, len(data), 4096):
            live.feed(data[i : i + 4096])
        assert len(live._tail) <= 4 * 400 + 200
    garbage = LiveIngest(max_lines=100)
    for _ in range(200):
        garbage.feed(b"\x00\xffnot nmea at all\n" * 20)
    assert len(garbage._tail) <= 4 * 100 + 20
    assert garbage.report.rejected["not NMEA"] == 4000


def test_serial_pseudo_terminal_equals_batch():
    """A pty pair: a writer thread feeds the demo log into the master side; gripsense reads the
    slave device with pyserial. Same epochs and accounting as the batch run."""
    data = _demo_bytes()
    master, slave = os.openpty()
    tty.setraw(slave)
    name = os.ttyname(slave)

    def writer():
        _wait_for(lambda: src.state == "open", 600.0)  # pyserial flushes what came before
        for i in range(0, len(data), 512):
            os.write(master, data[i : i + 512])
            time.sleep(0.002)

    src = SerialSource(name, 115200)
    th = threading.Thread(target=writer, daemon=True)
    th.start()
    got = []
    res = run_live(
        src,
        VEHICLE,
        duration_s=120.0,  # a guard: the run stops when every byte has arrived
        on_epochs=got.append,
        handle_signals=False,
        stop_when=lambda st: st.bytes >= len(data),
    )
    th.join()
    os.close(master)
    os.close(slave)
    batch = read_nmea(data)
    ep = pd.concat(got, ignore_index=True)
    pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)
    assert _same_report(res["report"], batch.report)
    assert len(res["summary"]) > 0


def test_tcp_receiver_drops_and_comes_back():
    """A loopback server streams part of the log, closes mid-stream, is gone for 0.5 s, then
    streams again from a later line. The client reconnects; its epochs equal the batch run on
    the bytes it could receive, and the missing interval is reported as a gap."""
    lines = _demo_bytes().split(b"\n")
    k, lost = 1200, 300
    part1 = b"\n".join(lines[:k]) + b"\n"
    part2 = b"\n".join(lines[k + lost :])
    srv = socket.socket()
    srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)
    port = srv.getsockname()[1]

    def server():
        for chunk in (part1, part2):
            conn, _ = srv.accept()
            for i in range(0, len(chunk), 1024):
                conn.sendall(chunk[i : i + 1024])
                time.sleep(0.001)
            conn.close()
            time.sleep(0.5)
        srv.close()

    th = threading.Thread(target=server, daemon=True)
    th.start()
    got = []
    src = TcpSource("127.0.0.1", port)
    n = len(part1) + len(part2)
    res = run_live(src, VEHICLE, duration_s=120.0, on_epochs=got.append, handle_signals=False,
                   stop_when=lambda st: st.bytes >= n)  # fmt: skip
    th.join()
    batch = read_nmea(part1 + part2)
    ep = pd.concat(got, ignore_index=True)
    pd.testing.assert_frame_equal(ep, batch.epochs, check_exact=False, rtol=0, atol=1e-9)
    assert src.reconnects >= 1  # (a connect to the closing listener may count too)
    gaps = res["stats"].gaps
    assert len(gaps) == 1 and gaps[0][1] > 1.0  # the lost lines were several epochs long


def _start(tmp_path, out: str):
    return subprocess.Popen(
        [
            EXE,
            "live",
            "--replay",
            str(DEMO),
            "--speed",
            "3",
            "--vehicle",
            str(VEHICLE),
            "-o",
            str(tmp_path / out),
            "--quiet",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for(cond, timeout: float) -> None:
    """Poll *cond* until it holds (fails the test after *timeout* seconds)."""
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "timed out waiting for a condition"
        time.sleep(0.05)


def _rows(path: Path) -> int:
    """Complete data rows in a live rows file so far (0 when it does not exist yet)."""
    try:
        return max(path.read_bytes().count(b"\n") - 1, 0)
    except FileNotFoundError:
        return 0


def test_sigint_stops_cleanly(tmp_path):
    p = _start(tmp_path, "res.csv")
    _wait_for(lambda: _rows(tmp_path / "res.csv") >= 2 or p.poll() is not None, 600.0)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=600)
    assert p.returncode == 0, err
    assert "stopped: SIGINT" in out
    df = pd.read_csv(tmp_path / "res.csv")
    assert len(df) > 0 and df["unit"].notna().all()
    raw = (tmp_path / "res.csv.raw.nmea").read_bytes()
    assert raw and _demo_bytes().startswith(raw)  # every received byte, in order


def test_sigkill_leaves_a_readable_file_and_recovery(tmp_path):
    p = _start(tmp_path, "res.parquet")
    part = tmp_path / "res.parquet.partial.csv"
    _wait_for(lambda: _rows(part) >= 2 or p.poll() is not None, 600.0)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=120)
    df = pd.read_csv(part)  # complete rows up to the last flush
    assert len(df) > 0
    r = cli("live", "--recover", tmp_path / "res.parquet")
    assert r.returncode == 0, r.stderr
    back = pd.read_parquet(tmp_path / "res.parquet")
    assert len(back) == len(df)


def test_bad_arguments():
    r = cli("live", "--vehicle", VEHICLE)
    assert r.returncode == 2 and "exactly one source" in r.stderr
    r = cli("live", "--tcp", "nohostport", "--vehicle", VEHICLE)
    assert r.returncode == 2 and "HOST:PORT" in r.stderr


def test_clock_going_backwards_restarts_the_window_and_batch_says_so(tmp_path):
    """Two sessions back to back (time jumps back): live restarts its window; the batch
    friction command names the jump instead of failing inside pandas."""
    from gripsense.live.runner import LiveFriction
    from gripsense.pipeline import FrictionRun

    two = _demo_bytes() * 2
    est = LiveFriction(VEHICLE, window_s=30.0)
    live = LiveIngest()
    for i in range(0, len(two), 8192):
        est.add(live.feed(two[i : i + 8192]))
    est.add(live.finish())
    assert est.resets == 1
    assert len(est.estimate()) > 0
    with pytest.raises(gripsense.errors.InputError, match="time goes backwards"):
        FrictionRun(VEHICLE).run(read_nmea(two).epochs)


def test_replay_gives_the_same_rows_at_any_speed(tmp_path):
    """Updates follow the log's own clock: a replay at speed 0 (as fast as possible), 2 and 10
    (paced by the wall clock: the path real time takes) writes the same rows (all but the
    wall-clock columns), and the display's last line ends."""
    lines = _demo_bytes().decode("ascii").splitlines(keepends=True)
    log = tmp_path / "short.nmea"
    log.write_text("".join(lines[:1400]), encoding="ascii")  # the first ~14 s (circle entry)
    tables = {}
    for speed in ("0", "2", "10"):
        out = tmp_path / f"res{speed}.csv"
        r = cli("live", "--replay", log, "--speed", speed, "--vehicle", VEHICLE, "-o", out)
        assert r.returncode == 0, r.stderr
        assert "\nstopped: end of input" in r.stdout, r.stdout[-300:]
        tables[speed] = pd.read_csv(out).drop(columns=["wall_time_s", "stale"])
    ref = tables["0"]
    assert len(ref) >= 10 and ref["t_s"].is_monotonic_increasing  # one row per log second
    for speed in ("2", "10"):
        pd.testing.assert_frame_equal(tables[speed], ref)
