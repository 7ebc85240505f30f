"""``tests.cli.inprocess.cli`` gives what the console script gives: the same stdout, stderr and
exit code for a real command, warnings and unconfigured log lines on stderr as a fresh
interpreter prints them, and the process state it changed restored."""

from __future__ import annotations

import logging
import os
import signal
import warnings

import gripsense.cli._app as app_module
from tests.cli.inprocess import cli
from tests.cli.test_commands import run
from tests.conftest import GPSD


def test_same_output_as_the_console_script(tmp_path):
    """A table-printing command and a refused one: byte-equal stdout and stderr, same code."""
    for args in (
        ["ingest", str(GPSD / "hemi.log")],
        ["ingest", str(GPSD / "hemi.log"), "-o", str(tmp_path / "x.xlsx")],
    ):
        sub, inp = run(*args), cli(*args)
        assert (inp.returncode, inp.stdout, inp.stderr) == (sub.returncode, sub.stdout, sub.stderr)
    assert sub.returncode == 2 and "use .parquet or .csv" in sub.stderr


def test_warnings_and_log_lines_reach_stderr_and_state_is_restored(tmp_path, monkeypatch):
    """Under pytest a warning is recorded and a log record goes to pytest's handler: neither
    would reach the captured stderr, and a check of "one line on stderr" could not fail."""

    def command() -> None:
        logging.getLogger("somelib").warning("a library's log line")
        warnings.warn("a user-visible warning", FutureWarning, stacklevel=1)
        warnings.warn("hidden by default", DeprecationWarning, stacklevel=1)
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # as main()'s finishing() leaves it
        os.chdir(tmp_path)
        raise SystemExit(3)

    monkeypatch.setattr(app_module, "run", command)
    here, handler = os.getcwd(), signal.getsignal(signal.SIGINT)
    old = os.umask(0o022)
    try:
        r = cli("anything", umask=0o077)
        assert os.umask(0o022) == 0o022  # the umask of the call was undone
    finally:
        os.umask(old)
    assert r.returncode == 3
    assert "a library's log line" in r.stderr
    assert "FutureWarning: a user-visible warning" in r.stderr
    assert "hidden by default" not in r.stderr  # a fresh interpreter hides it too
    assert os.getcwd() == here and signal.getsignal(signal.SIGINT) is handler
