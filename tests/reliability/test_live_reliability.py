"""`gripsense live` under the rules of docs/reliability.md (issue 40): outputs replaced only by
proof, one run per output (a second run — or two started together — refused), bad TCP addresses
refused at the door, recovery that keeps every byte, and SIGINT/SIGTERM at any moment of a run.

Real parts throughout: the command as a subprocess where it is signalled, killed or races
another, real signals, real files and advisory locks; every wait is on a condition (a file with
N rows, a process that exited) with a timeout. The commands beside such a run (refused, a
recovery, a replay) and the refused arguments run in the test's process (``tests.cli.inprocess``:
the console script's entry point, its stdout, stderr and exit code) without a console script's
2–4 s of imports each.
"""

from __future__ import annotations

import gzip
import hashlib
import random
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gripsense
from gripsense.errors import InputError
from gripsense.live import open_replay, run_live
from gripsense.live.recording import (
    Recorder,
    check_live_outputs,
    output_paths,
    read_record,
    recover,
)
from gripsense.live.sources import TcpSource, parse_host_port
from tests.cli.inprocess import cli
from tests.cli.test_commands import EXE

DATA = Path(gripsense.__file__).parent / "data"
VEHICLE = DATA / "corolla_sim.toml"
DEMO = DATA / "demo" / "case001.nmea.gz"
NUMERIC = ["wall_time_s", "t_s", "mu", "mu_low", "mu_high", "grip_used", "grip_used_lower"]


def _demo_bytes() -> bytes:
    return gzip.decompress(DEMO.read_bytes())


@pytest.fixture(scope="module")
def short_log(tmp_path_factory) -> Path:
    """The first ~14 s of the demo drive (rows after a few seconds of log time)."""
    lines = _demo_bytes().splitlines(keepends=True)
    p = tmp_path_factory.mktemp("log") / "short.nmea"
    p.write_bytes(b"".join(lines[:1400]))
    return p


@pytest.fixture(scope="module")
def rows_file(short_log, tmp_path_factory) -> bytes:
    """The rows of a real live run (a CSV output), as the partial file of a Parquet run holds."""
    out = tmp_path_factory.mktemp("rows") / "r.csv"
    run_live(open_replay(short_log, 0.0), VEHICLE, output=out, handle_signals=False)
    data = out.read_bytes()
    assert data.count(b"\n") >= 10
    return data


def _hashes(root: Path) -> dict[str, str]:
    return {
        p.name: hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.iterdir())
        if p.is_file()
    }


def _cli(*args: str, timeout: float = 600.0) -> subprocess.CompletedProcess:
    """``gripsense live ARGS`` in the test's process (``tests.cli.inprocess``), for the runs
    that are refused, recover or replay beside a console-script run (its lock belongs to another
    process all the same); *timeout* is kept for the callers' sake (a replay ends by itself)."""
    return cli("live", *args)


def _live_args(log: Path, out: Path, speed: str = "0") -> list[str]:
    return ["--replay", str(log), "--speed", speed, "--vehicle", str(VEHICLE), "-o", str(out),
            "--quiet"]  # fmt: skip


def _one_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


def _wait_for(cond, timeout: float = 600.0) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "timed out waiting for a condition"
        time.sleep(0.05)


def _rows(path: Path) -> int:
    try:
        return max(path.read_bytes().count(b"\n") - 1, 0)
    except FileNotFoundError:
        return 0


def _consistent(out: Path, log_bytes: bytes) -> None:
    """A finished live output: results, raw and record present, every file what the record
    says, no partial and no temporary file left, numbers numeric, the raw a prefix of the log."""
    paths = output_paths(out)
    assert not paths["rows"].exists() or paths["rows"] == paths["results"]
    assert not list(out.parent.glob("*.gripsense-tmp"))
    rec = read_record(out)
    assert rec is not None and rec["state"] == "finished"
    for key in ("results", "raw"):
        p = paths[key]
        fp = {"bytes": p.stat().st_size, "sha256": hashlib.sha256(p.read_bytes()).hexdigest()}
        assert rec["files"][p.name] == [fp], key
    raw = paths["raw"].read_bytes()
    assert log_bytes.startswith(raw) and b"\x00" not in raw
    df = pd.read_parquet(out) if out.suffix == ".parquet" else pd.read_csv(out)
    for c in NUMERIC:
        assert pd.api.types.is_float_dtype(df[c]), c


# ---------------------------------------------------------------------------------------------
# ownership by proof


USER_FILES = {
    "results.csv": ("r.csv", "r.csv", b"my own notes\n"),
    "results.csv with the live header": (
        "r.csv",
        "r.csv",
        b"wall_time_s,t_s,time_utc,unit,mu,mu_low,mu_high,surface,slippery,observable,"
        b"grip_used,grip_used_lower,n_valid,stale\n1,2,,rear,,,,,,,,,,\n",
    ),
    "raw.nmea": ("r.csv", "r.csv.raw.nmea", b"$GPGGA,my own recording\n"),
    "record": ("r.csv", "r.csv.gripsense.json", b'{"mine": true}\n'),
    "rejected": ("r.parquet", "r.parquet.rejected", b"my rejected rows\n"),
    "results.parquet": ("r.parquet", "r.parquet", b"PAR1 not really\n"),
}


@pytest.mark.parametrize("case", USER_FILES, ids=list(USER_FILES))
def test_overwrite_never_replaces_a_users_file(case, tmp_path, short_log):
    out_name, name, content = USER_FILES[case]
    (tmp_path / name).write_bytes(content)
    before = _hashes(tmp_path)
    with pytest.raises(InputError, match=re.escape(str(tmp_path / name))):
        Recorder(tmp_path / out_name, overwrite=True)
    assert _hashes(tmp_path) == before


@pytest.mark.slow  # subprocesses of the command
def test_overwrite_of_a_users_raw_recording_is_one_line_on_the_command(tmp_path, short_log):
    """The issue's example: `live --overwrite` truncated a user's OUT.raw.nmea."""
    raw = tmp_path / "r.csv.raw.nmea"
    raw.write_bytes(b"$GPGGA,my own recording\n")
    r = _cli(*_live_args(short_log, tmp_path / "r.csv"), "--overwrite")
    assert r.returncode == 2
    assert str(raw) in _one_line(r.stderr)
    assert raw.read_bytes() == b"$GPGGA,my own recording\n"
    assert not (tmp_path / "r.csv").exists()


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_own_files_are_replaced_edited_ones_are_not(suffix, tmp_path, short_log):
    out = tmp_path / f"r{suffix}"
    run_live(open_replay(short_log, 0.0), VEHICLE, output=out, handle_signals=False)
    _consistent(out, short_log.read_bytes())
    # unchanged: replaced, and the new files are recorded
    run_live(open_replay(short_log, 0.0), VEHICLE, output=out, handle_signals=False,
             overwrite=True)  # fmt: skip
    _consistent(out, short_log.read_bytes())
    paths = output_paths(out)
    for key in ("results", "raw", "record"):
        p = paths[key]
        keep = p.read_bytes()
        p.write_bytes(keep[:-2] + b"x" + keep[-1:])  # one byte edited by the user
        before = _hashes(tmp_path)
        with pytest.raises(InputError, match=r"not what gripsense wrote|is not a record"):
            check_live_outputs(out, overwrite=True)
        with pytest.raises(InputError):
            Recorder(out, overwrite=True)
        assert _hashes(tmp_path) == before
        p.write_bytes(keep)
    # an earlier run's files without their record prove nothing
    paths["record"].rename(tmp_path / "elsewhere.json")
    with pytest.raises(InputError, match="no record that gripsense wrote it"):
        check_live_outputs(out, overwrite=True)


@pytest.mark.slow  # subprocesses of the command
def test_a_killed_runs_files_are_its_own_and_stay_so_until_edited(tmp_path, receiver):
    """SIGKILL between flushes: each file is in a state the record names, so --overwrite may
    replace it; a byte appended by someone else afterwards makes it the user's."""
    out = tmp_path / "k.csv"
    address = receiver(_long_log(tmp_path).read_bytes())
    p = subprocess.Popen([EXE, "live", *_tcp_args(address, out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip
    _wait_for(lambda: _rows(out) >= 2 or p.poll() is not None)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=120)
    rec = read_record(out)
    assert rec is not None and rec["state"] == "running"
    check_live_outputs(out, overwrite=True)  # proven: no error
    with open(out, "ab") as fh:
        fh.write(b"my line\n")
    with pytest.raises(InputError, match="not what gripsense wrote"):
        check_live_outputs(out, overwrite=True)


def _long_log(tmp_path: Path) -> Path:
    """The demo drive three times (~2 min of log time, three sessions)."""
    p = tmp_path / "drive.nmea"
    if not p.exists():
        p.write_bytes(_demo_bytes() * 3)
    return p


@pytest.fixture
def receiver():
    """A receiver on loopback that streams a log to every client and then stays connected
    until the test ends: a live run on it never ends by itself, however loaded the machine
    (a replay at real time ended before a slow test could meet it). Returns a function of the
    log's bytes that gives ``HOST:PORT``."""
    done = threading.Event()
    servers: list = []

    def start(data: bytes) -> str:
        import socket

        srv = socket.socket()
        srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        srv.bind(("127.0.0.1", 0))
        srv.listen(8)
        srv.settimeout(0.2)
        servers.append(srv)

        def serve(conn) -> None:
            with conn:
                try:
                    conn.sendall(data)
                except OSError:
                    return
                done.wait()

        def accept() -> None:
            while not done.is_set():
                try:
                    conn, _ = srv.accept()
                except OSError:
                    continue
                threading.Thread(target=serve, args=(conn,), daemon=True).start()

        threading.Thread(target=accept, daemon=True).start()
        return f"127.0.0.1:{srv.getsockname()[1]}"

    yield start
    done.set()
    for srv in servers:
        srv.close()


def _tcp_args(address: str, out: Path) -> list[str]:
    return ["--tcp", address, "--vehicle", str(VEHICLE), "-o", str(out), "--quiet"]


# ---------------------------------------------------------------------------------------------
# one run per output


@pytest.mark.slow  # subprocesses of the command
def test_a_second_run_on_the_same_output_is_refused(tmp_path, receiver):
    """The issue's example: two runs on one -o left 22 000 NUL bytes and the other run's frames
    in the recording. The second is refused (with or without --overwrite) while the first
    runs; the first's files are untouched and complete."""
    log = _long_log(tmp_path)
    out = tmp_path / "two.csv"
    a = subprocess.Popen([EXE, "live", *_tcp_args(receiver(log.read_bytes()), out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        _wait_for(lambda: _rows(out) >= 1 or a.poll() is not None)
        assert a.poll() is None, a.communicate()
        for extra in ((), ("--overwrite",)):
            r = _cli(*_live_args(log, out, speed="0"), *extra)
            assert r.returncode == 2
            line = _one_line(r.stderr)
            assert "another gripsense live run is writing it" in line and str(a.pid) in line
            assert a.poll() is None
        r = _cli("--recover", str(out))
        assert r.returncode == 2
    finally:
        a.send_signal(signal.SIGINT)
        o, e = a.communicate(timeout=600)
    assert a.returncode == 0, e
    assert "stopped: SIGINT" in o, o[-300:]
    _consistent(out, log.read_bytes())


@pytest.mark.slow  # subprocesses of the command
def test_two_runs_started_together_one_wins(tmp_path, receiver):
    """Stress: two processes started at the same moment on one new -o (both --overwrite),
    three rounds: every time exactly one runs, the other is refused in one line, and the
    result is one run's, whole."""
    log = _long_log(tmp_path)
    address = receiver(log.read_bytes())
    for rnd in range(3):
        out = tmp_path / f"race{rnd}.parquet"
        procs = [
            subprocess.Popen([EXE, "live", *_tcp_args(address, out), "--overwrite"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for _ in range(2)
        ]  # fmt: skip
        try:
            _wait_for(lambda: any(p.poll() is not None for p in procs))  # noqa: B023
            loser = next(p for p in procs if p.poll() is not None)
            winner = next(p for p in procs if p is not loser)
            _, err = loser.communicate()
            assert loser.returncode == 2, err
            assert "another gripsense live run" in _one_line(err) or "appeared" in err
        finally:
            for p in procs:
                if p.poll() is None:
                    p.send_signal(signal.SIGINT)
        _, e = winner.communicate(timeout=600)
        assert winner.returncode == 0, e
        _consistent(out, log.read_bytes())


def test_many_recorders_at_once_one_wins(tmp_path):
    """Eight recorders racing for one output (threads: each its own open file, as processes
    have), on a new output and on an earlier run's: exactly one gets it while it is open."""
    for rnd in range(10):
        out = tmp_path / f"m{rnd % 2}.csv"
        gate = threading.Barrier(8)
        won: list[Recorder] = []
        lost: list[str] = []
        lock = threading.Lock()

        def attempt(out=out, gate=gate, won=won, lost=lost, lock=lock):
            gate.wait()
            try:
                r = Recorder(out, overwrite=True)
            except InputError as e:
                with lock:
                    lost.append(str(e))
                return
            with lock:
                won.append(r)

        threads = [threading.Thread(target=attempt) for _ in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=600)
        assert len(won) == 1 and len(lost) == 7, lost
        won[0].raw(b"$GPGGA,x\n")
        won[0].close()
        assert read_record(out)["state"] == "finished"


def test_runs_on_different_outputs_in_one_folder_do_not_block_each_other(tmp_path):
    """The folder's lock is held only while files are checked and created."""
    a = Recorder(tmp_path / "a.csv")
    b = Recorder(tmp_path / "b.parquet")
    a.raw(b"$GPGGA,a\n")
    b.raw(b"$GPGGA,b\n")
    a.close()
    b.close()
    assert (tmp_path / "a.csv.raw.nmea").read_bytes() == b"$GPGGA,a\n"
    assert (tmp_path / "b.parquet.raw.nmea").read_bytes() == b"$GPGGA,b\n"
    assert read_record(tmp_path / "b.parquet")["state"] == "finished"


# ---------------------------------------------------------------------------------------------
# addresses at the door


BAD_TCP = ["localhost:99999", "localhost:0", "localhost:-1", ":10110", "localhost:", "localhost",
           "a b:10110", "::1:10110", "[::zz]:10110", "localhost:80x",
           "localhost:\uff11\uff10"]  # fmt: skip


@pytest.mark.parametrize("addr", BAD_TCP)
def test_bad_tcp_addresses_are_refused(addr):
    with pytest.raises(InputError, match="--tcp"):
        parse_host_port(addr)


def test_tcp_source_checks_its_port():
    with pytest.raises(InputError, match="1 to 65535"):
        TcpSource("localhost", 99999)
    assert parse_host_port("[::1]:10110") == ("::1", 10110)
    assert parse_host_port("gnss-base.local:2101") == ("gnss-base.local", 2101)


@pytest.mark.slow  # subprocesses of the command
@pytest.mark.parametrize("addr", ["localhost:99999", "a b:10110", "localhost:0"])
def test_bad_tcp_address_on_the_command_is_one_line_and_exit_2(addr):
    """The issue's example: `live --tcp host:99999` exited 0 after "reconnecting"."""
    r = _cli("--tcp", addr, "--vehicle", str(VEHICLE), "--duration-s", "3", "--quiet",
             timeout=600)  # fmt: skip
    assert r.returncode == 2, r.stdout[-300:]
    assert "--tcp" in _one_line(r.stderr)


@pytest.mark.slow  # subprocesses of the command
@pytest.mark.parametrize(
    "opt", [("--speed", "-1"), ("--window-s", "0"), ("--duration-s", "-2"), ("--baud", "0")]
)
def test_bad_numbers_are_one_line_and_exit_2(opt, short_log, tmp_path):
    args = ["--serial", "/dev/null"] if opt[0] == "--baud" else ["--replay", str(short_log)]
    r = _cli(*args, "--vehicle", str(VEHICLE), *opt, "--quiet", timeout=600)
    assert r.returncode == 2
    assert opt[0] in _one_line(r.stderr)


# ---------------------------------------------------------------------------------------------
# recovery keeps every byte


def _partial(tmp_path: Path, data: bytes) -> Path:
    out = tmp_path / "rec.parquet"
    output_paths(out)["rows"].write_bytes(data)
    return out


def _lines(b: bytes) -> list[bytes]:
    """Lines as the rows file holds them: each with its \\n, the last maybe without."""
    out = [ln + b"\n" for ln in b.split(b"\n")]
    out[-1] = out[-1][:-1]
    return out if out[-1] else out[:-1]


def _check_recovered(out: Path, data: bytes, n_bad: int) -> None:
    paths = output_paths(out)
    assert not paths["rows"].exists()
    df = pd.read_parquet(out)
    for c in NUMERIC:
        assert pd.api.types.is_float_dtype(df[c]), c
    header, *lines = _lines(data)
    rejected = paths["rejected"].read_bytes() if paths["rejected"].exists() else header
    assert rejected.startswith(header)
    bad = _lines(rejected[len(header) :])
    assert len(bad) == n_bad and len(df) + len(bad) == len(lines)
    it = iter(lines)  # the rejected lines are the partial's own, byte for byte, in order
    assert all(any(ln == x for x in it) for ln in bad)
    rec = read_record(out)
    assert rec is not None and rec["state"] == "finished"


def test_recovery_keeps_the_rows_it_cannot_read(tmp_path, rows_file):
    """The issue's examples: a row with an extra field was dropped, and a NUL tail after a
    power loss turned wall_time_s into text; then the partial file was deleted."""
    head, *rows = rows_file.splitlines(keepends=True)
    extra = rows[3].rstrip(b"\n") + b",surplus\n"
    texty = b"twelve" + rows[4][rows[4].index(b",") :]
    data = head + b"".join(rows[:3]) + extra + texty + b"".join(rows[5:]) + b"\x00" * 22000
    out = _partial(tmp_path, data)
    res = recover(out)
    assert res["rows"] == len(rows) - 2
    assert [b[2].split(" ")[0] for b in res["rejected"]] == ["15", "wall_time_s", "NUL"]
    _check_recovered(out, data, 3)
    assert output_paths(out)["rejected"].read_bytes() == head + extra + texty + b"\x00" * 22000


def test_recovery_of_a_cut_last_row(tmp_path, rows_file):
    data = rows_file[:-7]  # the last row without its end (and some digits)
    out = _partial(tmp_path, data)
    res = recover(out)
    assert res["rejected"][0][2] == "no line end (cut off)"
    _check_recovered(out, data, 1)


def test_recovery_of_a_csv_output_after_a_power_loss(tmp_path, short_log):
    """A .csv output is written as it goes; a NUL tail and a cut row after a power loss made
    wall_time_s text. --recover moves exactly those lines to .rejected, keeps the rest."""
    out = tmp_path / "pl.csv"
    run_live(open_replay(short_log, 0.0), VEHICLE, output=out, handle_signals=False)
    clean = out.read_bytes()
    assert recover(out)["rejected"] == []  # nothing to move: unchanged
    assert out.read_bytes() == clean and not output_paths(out)["rejected"].exists()
    tail = b"1795749927.7,41.2,2018-02-08 04:00:41.2\n" + b"\x00" * 3000  # cut row, NULs
    with open(out, "ab") as fh:
        fh.write(tail)
    assert not pd.api.types.is_float_dtype(pd.read_csv(out)["wall_time_s"])  # the symptom
    res = recover(out)
    assert out.read_bytes() == clean
    assert output_paths(out)["rejected"].read_bytes() == clean.split(b"\n", 1)[0] + b"\n" + tail
    assert res["rows"] == clean.count(b"\n") - 1 and len(res["rejected"]) == 2
    assert pd.api.types.is_float_dtype(pd.read_csv(out)["wall_time_s"])
    check_live_outputs(out, overwrite=True)  # recovered files are proven gripsense's


def test_recovery_refused_keeps_the_partial(tmp_path, rows_file):
    """A user's file where the result goes: the partial is kept, byte for byte."""
    out = _partial(tmp_path, rows_file + b"1,2,3\n")
    out.write_bytes(b"my parquet\n")
    before = _hashes(tmp_path)
    with pytest.raises(InputError, match="not what gripsense wrote"):
        recover(out)
    assert _hashes(tmp_path) == before


DAMAGE = st.lists(
    st.tuples(
        st.sampled_from(["extra", "missing", "text", "nul", "bytes", "cut", "crlf", "quote"]),
        st.integers(0, 10_000),
        st.binary(min_size=1, max_size=12),
    ),
    max_size=6,
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(damage=DAMAGE)
def test_recovery_accounts_for_every_line_of_a_damaged_partial(tmp_path_factory, rows_file,
                                                                damage):  # fmt: skip
    """Random damage to a real partial file: the parquet holds the readable rows with numeric
    columns, .rejected holds the others verbatim, nothing else is lost."""
    head, *rows = rows_file.splitlines(keepends=True)
    for kind, at, junk in damage:
        i = at % len(rows)
        r = rows[i]
        if kind == "extra":
            rows[i] = r.rstrip(b"\n") + b"," + junk.replace(b"\n", b"") + b"\n"
        elif kind == "missing" and b"," in r:
            rows[i] = r[: r.rindex(b",")] + b"\n"
        elif kind == "text":
            rows[i] = b"x" + r
        elif kind == "nul":
            rows[i] = r[: at % len(r)] + b"\x00" * (1 + at % 50) + r[at % len(r) :]
        elif kind == "bytes":
            rows[i] = r[: at % len(r)] + junk + r[at % len(r) :]
        elif kind == "cut":
            rows = [*rows[:i], r[: at % len(r)]] if at % len(r) else rows[:i]
        elif kind == "crlf":
            rows[i] = r.rstrip(b"\n") + b"\r\n"
        elif kind == "quote":
            rows[i] = b'"' + r
        if not rows:
            break
    data = head + b"".join(rows)
    tmp = tmp_path_factory.mktemp("dmg")
    out = _partial(tmp, data)
    res = recover(out)
    body = data[len(head) :]
    n_lines = len(body.split(b"\n")) - (1 if body.endswith(b"\n") or not body else 0)
    assert res["rows"] + len(res["rejected"]) == n_lines
    _check_recovered(out, data, len(res["rejected"]))


@pytest.mark.slow  # subprocesses of the command
def test_power_loss_after_a_kill_then_recover_on_the_command(tmp_path, receiver):
    """A real run killed, its partial file given a NUL tail (as a power loss leaves it): the
    command recovers the rows, names the rejected ones in one note, keeps them verbatim."""
    log = _long_log(tmp_path)
    out = tmp_path / "pl.parquet"
    p = subprocess.Popen([EXE, "live", *_tcp_args(receiver(log.read_bytes()), out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip
    part = output_paths(out)["rows"]
    _wait_for(lambda: _rows(part) >= 2 or p.poll() is not None)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=120)
    good = part.read_bytes()
    with open(part, "ab") as fh:
        fh.write(b"\x00" * 4096)
    r = _cli("--recover", str(out))
    assert r.returncode == 0, r.stderr
    assert "could not be read" in r.stdout and "NUL" in r.stdout
    assert len(pd.read_parquet(out)) == good.count(b"\n") - 1
    assert output_paths(out)["rejected"].read_bytes().endswith(b"\x00" * 4096)
    assert not part.exists()
    # the recovered result is the run's own: the next run may replace it
    r = _cli(*_live_args(_short(tmp_path), out), "--overwrite")
    assert r.returncode == 0, r.stderr
    assert not output_paths(out)["rejected"].exists()  # it went with the result it belonged to


def _short(tmp_path: Path) -> Path:
    p = tmp_path / "short.nmea"
    p.write_bytes(b"".join(_demo_bytes().splitlines(keepends=True)[:800]))
    return p


# ---------------------------------------------------------------------------------------------
# signals at any moment


def _moments() -> list[tuple[str, str, float]]:
    rng = random.Random(40)
    out = []
    for sig in ("SIGINT", "SIGTERM"):
        out += [(sig, "files", 0.0), (sig, "rows", 0.0)]
        out += [(sig, "after", round(rng.uniform(0.0, 6.0), 2)) for _ in range(2)]
    return out


@pytest.mark.slow
@pytest.mark.parametrize("sig,moment,delay", _moments())
def test_a_signal_at_any_moment_gives_one_line_and_consistent_files(sig, moment, delay,
                                                                      tmp_path):  # fmt: skip
    """SIGINT or SIGTERM when the files were just created, when rows are being written, or
    after a random delay (the start included): the documented exit (0 once the run is set up:
    it stops cleanly; 128+signal before, with one line; killed by the signal only before the
    interpreter runs), no traceback, and either no output at all or a complete one the record
    proves."""
    log = _long_log(tmp_path)
    out = tmp_path / "sig.parquet"
    paths = output_paths(out)
    p = subprocess.Popen([EXE, "live", *_live_args(log, out, speed="3")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    if moment == "files":
        _wait_for(lambda: paths["record"].exists() or p.poll() is not None)
    elif moment == "rows":
        _wait_for(lambda: _rows(paths["rows"]) >= 1 or p.poll() is not None)
    else:
        time.sleep(delay)  # the moment itself is random (this is the stimulus, not a wait)
    p.send_signal(getattr(signal, sig))
    o, e = p.communicate(timeout=600)
    code = p.returncode
    assert "Traceback" not in e, e
    if code == 0:
        assert f"stopped: {sig}" in o or "stopped: end of input" in o
        _consistent(out, log.read_bytes())
    elif code == -getattr(signal, sig):  # before the interpreter took the signal over
        assert not e and not any(p.exists() for p in paths.values())
    else:
        assert code == 128 + getattr(signal, sig), (code, e)
        assert len(e.strip().splitlines()) == 1, e
        assert not any(p.exists() for p in paths.values())


def test_signal_handlers_are_restored_after_a_run(short_log, tmp_path):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    run_live(open_replay(short_log, 0.0), VEHICLE, output=tmp_path / "x.csv")
    assert {s: signal.getsignal(s) for s in before} == before


if sys.platform == "win32":  # pragma: no cover
    pytestmark = pytest.mark.skip("advisory locks and signals are POSIX")
