"""Live UBX: a u-blox stream (UBX frames mixed with NMEA) read as it arrives — over a pty and a
loopback socket — gives the batch reader's epochs and accounting; other formats replay too."""

from __future__ import annotations

import gzip
import os
import socket
import threading
import time
import tty

import numpy as np
import pandas as pd
import pytest

from gripsense.data import path as data_path
from gripsense.io import read_nmea
from gripsense.io.logs.ubx import parse_ubx, write_ubx
from gripsense.io.logs.vbo import write_vbo
from gripsense.live import AutoIngest, EpochReplay, SerialSource, TcpSource, open_replay, run_live

pytest.importorskip("pyubx2")

DEMO = data_path("demo")
VEHICLE = data_path("corolla_sim.toml")


@pytest.fixture(scope="module")
def stream(tmp_path_factory) -> bytes:
    """The demo drive as a moving-base rover sends it (UBX + NMEA), with a damaged frame and
    junk bytes."""
    d = tmp_path_factory.mktemp("ubx")
    nmea = DEMO / "case001.nmea.gz"
    lines = gzip.decompress(nmea.read_bytes()).decode().splitlines()
    write_ubx(read_nmea(nmea).epochs, d / "s.ubx", nmea_lines=lines)
    b = bytearray((d / "s.ubx").read_bytes())
    b[5000] ^= 0xFF
    b[20000:20010] = b"garbage\n\xb5b"
    return bytes(b)


def _same(live: pd.DataFrame, batch) -> None:
    ep = batch.epochs
    assert len(live) == len(ep)
    assert (live["time_utc"] == ep["time_utc"]).all()
    for c in ("t_s", "heading_deg", "yaw_rate_rps", "lat_deg", "speed_mps", "course_deg"):
        np.testing.assert_allclose(live[c], ep[c], rtol=0, atol=1e-9, err_msg=c)


@pytest.mark.parametrize("seed", [0, 1])
def test_any_chunking_gives_the_batch_answer(stream, seed):
    rng = np.random.default_rng(seed)
    ing = AutoIngest(source="s")
    outs, pos = [], 0
    while pos < len(stream):
        k = int(rng.integers(1, 2500))
        outs.append(ing.feed(stream[pos : pos + k]))
        pos += k
    outs.append(ing.finish())
    batch = parse_ubx(stream, "s")
    _same(pd.concat([o for o in outs if len(o)], ignore_index=True), batch)
    live, ref = ing.report, batch.report
    assert ing.kind == "ubx"
    assert (live.total_lines, live.parsed, live.ignored) == (
        ref.total_lines,
        ref.parsed,
        ref.ignored,
    )
    assert {k: v for k, v in live.rejected.items() if v} == {
        k: v for k, v in ref.rejected.items() if v
    }


@pytest.mark.slow
def test_ubx_over_a_pty_and_a_socket_equals_batch(stream):
    batch = parse_ubx(stream, "s")
    # a serial port: a pty pair, the stream written into the master side
    master, slave = os.openpty()
    tty.setraw(slave)

    src = SerialSource(os.ttyname(slave), 115200)

    def to_pty():
        _wait_for(lambda: src.state == "open", 600.0)  # pyserial flushes what came before
        for i in range(0, len(stream), 512):
            os.write(master, stream[i : i + 512])
            time.sleep(0.002)

    th = threading.Thread(target=to_pty, daemon=True)
    th.start()
    got: list = []
    # 120 s is a guard: the run stops when every byte has arrived
    run_live(src, VEHICLE, duration_s=120.0, on_epochs=got.append, handle_signals=False,
             stop_when=lambda st: st.bytes >= len(stream))  # fmt: skip
    th.join()
    os.close(master)
    os.close(slave)
    _same(pd.concat(got, ignore_index=True), batch)
    # a network receiver: a loopback server
    srv = socket.socket()
    srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)

    def serve():
        conn, _ = srv.accept()
        for i in range(0, len(stream), 700):
            conn.sendall(stream[i : i + 700])
            time.sleep(0.001)
        conn.close()
        srv.close()

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    got = []
    res = run_live(TcpSource("127.0.0.1", srv.getsockname()[1]), VEHICLE, duration_s=120.0,
                   on_epochs=got.append, handle_signals=False,
                   stop_when=lambda st: st.bytes >= len(stream))  # fmt: skip
    th.join()
    _same(pd.concat(got, ignore_index=True), batch)
    assert res["report"].format == "u-blox UBX + NMEA 0183"


def _wait_for(cond, timeout: float) -> None:
    """Poll *cond* until it holds (fails the test after *timeout* seconds)."""
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "timed out waiting for a condition"
        time.sleep(0.01)


def test_a_vbox_log_replays_as_epochs(tmp_path):
    ep = read_nmea(DEMO / "case001.nmea.gz").epochs
    write_vbo(ep, tmp_path / "d.vbo")
    src = open_replay(tmp_path / "d.vbo", speed=0)
    assert isinstance(src, EpochReplay)
    got: list = []
    res = run_live(src, VEHICLE, on_epochs=got.append, handle_signals=False)
    live = pd.concat(got, ignore_index=True)
    assert len(live) == len(ep) and res["stopped_by"] == "end of input"
    assert res["report"].format == "VBOX VBO" and len(res["summary"])
