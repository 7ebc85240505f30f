"""Clean at every moment: SIGINT (Ctrl-C) and SIGTERM while a command starts (inside its
imports), while it works and while a fleet's Dask cluster runs are one line and exit 128 + the
signal; a fleet worker that dies is one line and the run goes on; no traceback from imports when
numba has nowhere to cache. Every signal is sent at a condition the test waits for (a library
mapped into the process, an output folder begun, a worker started), never after a fixed sleep.
"""

from __future__ import annotations

import glob
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
import pytest

import gripsense
from gripsense.sim.fleet_data import Site, write_fleet
from tests.cli.test_commands import EXE

pytestmark = pytest.mark.slow

DATA = Path(gripsense.__file__).parent / "data"
VEHICLE = DATA / "corolla_sim.toml"
DEMO = DATA / "demo" / "case021.nmea.gz"
SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM}


def _wait(cond, what: str, p: subprocess.Popen, timeout: float = 600.0) -> None:
    """Poll *cond* until true; fail when the process ended first or the time ran out."""
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        if cond():
            return
        if p.poll() is not None:
            pytest.fail(f"the command ended ({p.returncode}) before {what}: {p.stderr.read()}")
        time.sleep(0.002)
    p.kill()
    pytest.fail(f"no {what} within {timeout} s")


def _mapped(p: subprocess.Popen, lib: str) -> bool:
    try:
        return lib in Path(f"/proc/{p.pid}/maps").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False


def _children(pid: int) -> list[int]:
    out: list[int] = []
    for f in glob.glob(f"/proc/{pid}/task/*/children"):
        try:
            out += [int(c) for c in Path(f).read_text().split()]
        except FileNotFoundError:
            pass
    return out


def _workers(pid: int) -> list[int]:
    out = []
    for c in _children(pid):
        try:
            if b"spawn_main" in Path(f"/proc/{c}/cmdline").read_bytes():
                out.append(c)
        except FileNotFoundError:
            pass
    return out


def _one_line(p: subprocess.Popen, sig: int) -> str:
    _out, err = p.communicate(timeout=600)
    name = signal.Signals(sig).name
    assert p.returncode == 128 + sig, (p.returncode, err)
    assert err.strip() == f"error: interrupted ({name})", err
    return err


def _start(*args: str, cwd: Path | None = None) -> subprocess.Popen:
    return subprocess.Popen(
        [EXE, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd
    )


# libraries every command maps while it starts: the signal lands inside their import
LIBS = ["numpy/_core/_multiarray_umath", "pandas/_libs", "numba/_helperlib", "ft2font"]
COMMANDS = {
    "friction": lambda d: ["friction", str(DEMO), "--vehicle", str(VEHICLE), "-o", str(d / "o")],
    "fleet": lambda d: ["fleet", str(DEMO), "--vehicle", str(VEHICLE), "-o", str(d / "o")],
    "brake-mu": lambda d: ["brake-mu", str(d / "none.csv")],
}


# matplotlib (ft2font) only where the command draws from the start: since issue 45 a command
# imports what it uses when it runs (friction without --report, fleet draw with no matplotlib)
STARTS = [(c, lib) for c in COMMANDS for lib in LIBS if lib != "ft2font" or c == "brake-mu"]


@pytest.mark.parametrize("sig", SIGNALS)
@pytest.mark.parametrize(("command", "lib"), STARTS)
def test_a_signal_while_a_command_starts_is_one_line(command, lib, sig, tmp_path):
    p = _start(*COMMANDS[command](tmp_path))
    _wait(lambda: _mapped(p, lib), f"{lib} mapped", p)
    p.send_signal(SIGNALS[sig])
    if command == "brake-mu":  # its missing input may end it before the deferred signal
        _out, err = p.communicate(timeout=600)
        name = signal.Signals(SIGNALS[sig]).name
        assert (p.returncode, err.strip()) == (
            128 + SIGNALS[sig],
            f"error: interrupted ({name})",
        ) or (p.returncode == 2 and len(err.strip().splitlines()) == 1 and "no such file" in err), (
            p.returncode,
            err,
        )
    else:
        _one_line(p, SIGNALS[sig])
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("sig", SIGNALS)
def test_a_signal_while_friction_writes_is_one_line_and_no_half_result(sig, tmp_path):
    p = _start("friction", str(DEMO), "--vehicle", str(VEHICLE), "-o", str(tmp_path / "o"),
               "--report")  # fmt: skip
    _wait(lambda: any(d.iterdir() for d in tmp_path.glob(".gripsense-o-*")), "output begun", p)
    p.send_signal(SIGNALS[sig])
    out = tmp_path / "o"
    _out, err = p.communicate(timeout=600)
    if p.returncode == 0:  # the signal came once the run was over: its result complete
        assert err.strip() == "" and (out / "manifest.json").is_file(), err
    else:
        assert p.returncode == 128 + SIGNALS[sig], (p.returncode, err)
        assert err.strip() == f"error: interrupted ({sig})", err
        assert not out.exists() or (out / "manifest.json").is_file()  # never half a result
    assert not list(tmp_path.glob(".gripsense-o-*"))  # no temporary folder left


def test_a_signal_as_the_run_ends_changes_nothing(tmp_path):
    """Once the result is installed, a signal as the command ends leaves the complete result:
    one line and 130 while it still prints, exit 0 once it has returned — it used to kill the
    process by the default action while Python ended (exit −2, no line)."""
    p = _start("friction", str(DEMO), "--vehicle", str(VEHICLE), "-o", str(tmp_path / "o"))
    _wait(lambda: (tmp_path / "o" / "manifest.json").is_file(), "result installed", p)
    p.send_signal(signal.SIGINT)
    _out, err = p.communicate(timeout=600)
    # while the command still prints: one line and 130; once it has returned: nothing, 0
    assert p.returncode in (0, 128 + signal.SIGINT), (p.returncode, err)
    assert err.strip() == ("" if p.returncode == 0 else "error: interrupted (SIGINT)"), err
    assert (tmp_path / "o" / "manifest.json").is_file()


def test_a_signal_inside_the_end_of_the_run_changes_nothing():
    """The race the test above can only hit by chance, made certain: a SIGINT that lands while
    the command's ending (:func:`gripsense.cli.finishing`) is replacing the handlers leaves the
    outcome as it was — exit 0, no line (it escaped as a traceback, exit 1)."""
    code = (
        "import os, signal, sys\n"
        "import gripsense.cli as c\n"
        "done = c.finishing\n"
        "sent = []\n"
        "def ending():\n"
        "    if not sent:\n"
        "        sent.append(1)\n"
        "        os.kill(os.getpid(), signal.SIGINT)\n"
        "    done()\n"
        "c.finishing = ending\n"
        "sys.argv = ['gripsense', '--version']\n"
        "c.main()\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert (p.returncode, p.stderr) == (0, ""), p.stderr
    assert p.stdout.strip()  # the version was printed: the command ran to its end


@pytest.fixture(scope="module")
def fleet_logs(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("clean_exit_fleet")
    sites = [Site(n, 35.0 + 0.01 * i, 139.0, 30.0, mu)
             for i, (n, mu) in enumerate([("a", 0.9), ("b", 0.5), ("c", 0.3)])]  # fmt: skip
    write_fleet(d / "logs", VEHICLE, sites, n_vehicles=2)
    return d / "logs"


def _fleet(logs: Path, out: Path) -> subprocess.Popen:
    return _start("fleet", str(logs / "**" / "*.nmea*"), "--vehicle", str(VEHICLE),
                  "--workers", "2", "--logs-per-task", "1", "-o", str(out))  # fmt: skip


def _gone(pids: list[int], timeout: float = 600.0) -> list[int]:
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        alive = [c for c in pids if Path(f"/proc/{c}").exists() and _state(c) != "Z"]
        if not alive:
            return []
        time.sleep(0.05)
    return alive


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, IndexError):
        return "X"


@pytest.mark.parametrize("sig", SIGNALS)
@pytest.mark.parametrize("when", ["cluster starting", "tasks running"])
def test_a_signal_during_fleet_is_one_line_and_leaves_no_worker(when, sig, fleet_logs, tmp_path):
    """Dask's exit handler used to fail on a half-started cluster (AssertionError: Status.init,
    a traceback) and leave worker processes behind."""
    out = tmp_path / "o"
    p = _fleet(fleet_logs, out)
    tmp = str(tmp_path / ".gripsense-o-*")
    if when == "cluster starting":
        _wait(lambda: bool(glob.glob(tmp)) and len(_children(p.pid)) >= 1, "a worker started", p)
    else:
        _wait(lambda: bool(glob.glob(tmp + "/epochs/*/*.parquet")) and len(_workers(p.pid)) >= 2,
              "a task's output", p)  # fmt: skip
    kids = _children(p.pid)
    p.send_signal(SIGNALS[sig])
    _one_line(p, SIGNALS[sig])
    assert _gone(kids) == []
    assert not out.exists() and not glob.glob(tmp)


def test_a_fleet_worker_that_dies_is_one_line_and_its_tasks_rerun(fleet_logs, tmp_path):
    out = tmp_path / "o"
    p = _fleet(fleet_logs, out)
    tmp = str(tmp_path / ".gripsense-o-*")
    _wait(lambda: bool(glob.glob(tmp + "/epochs/*/*.parquet")) and len(_workers(p.pid)) >= 2,
          "a task's output", p)  # fmt: skip
    os.kill(_workers(p.pid)[0], signal.SIGKILL)
    _out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("note: a fleet worker process died"), err
    lg = pd.read_csv(out / "logs.csv", keep_default_na=False)
    assert len(lg) == 6 and (lg["problem"] == "").all()


# ------------------------------------------------------------------ numba's cache
NOT_WRITABLE = "-dac_override,-dac_read_search,-fowner"  # root without its override


@pytest.fixture
def read_only_install():
    """A copy of the package and a HOME that the (capability-less) test process cannot write:
    owned by another user, mode 555; numba finds neither place writable."""
    if shutil.which("setpriv") is None or os.geteuid() != 0:
        pytest.skip("needs root and setpriv to run a command that root's override cannot help")
    root = Path(tempfile.mkdtemp(prefix="gripsense-ro-"))
    try:
        pkg = root / "pkg"
        shutil.copytree(Path(gripsense.__file__).parent, pkg / "gripsense",
                        ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))  # fmt: skip
        home = root / "home"
        home.mkdir()
        (root / "tmp").mkdir()
        for d, _dirs, files in os.walk(root / "pkg"):
            os.chown(d, 65534, 65534)
            os.chmod(d, 0o555)
            for f in files:
                os.chown(Path(d) / f, 65534, 65534)
        os.chown(home, 65534, 65534)
        os.chmod(home, 0o555)
        yield root
    finally:
        for d, _dirs, _files in os.walk(root):
            os.chmod(d, 0o755)
        shutil.rmtree(root)


CALL = (
    "import os, gripsense; from gripsense.physics.brush import force_scalar; "
    "print(force_scalar(0.9, 0.05, 4000.0, 1e5, 0)); print(gripsense.__file__); "
    "print(os.environ.get('NUMBA_CACHE_DIR'))"
)


def _python(root: Path, **env: str) -> subprocess.CompletedProcess:
    e = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "XDG_"))}
    e.update(PYTHONPATH=str(root / "pkg"), HOME=str(root / "home"), TMPDIR=str(root / "tmp"))
    e.update(env)
    cmd = ["setpriv", "--bounding-set", NOT_WRITABLE, "--", sys.executable, "-c", CALL]
    return subprocess.run(cmd, capture_output=True, text=True, env=e, timeout=300)


def test_numba_caches_in_a_private_temporary_folder_when_nothing_else_is_writable(
    read_only_install,
):
    root = read_only_install
    r = _python(root)
    assert r.returncode == 0, r.stderr
    assert "cannot cache" not in r.stderr and "Traceback" not in r.stderr, r.stderr
    _value, where, cache = r.stdout.split()
    assert where == str(root / "pkg" / "gripsense" / "__init__.py")  # the read-only copy
    assert Path(cache).parent == root / "tmp"
    assert list(Path(cache).rglob("*.nbi")), "nothing was cached"
    assert (Path(cache).stat().st_mode & 0o077) == 0  # private
    # the same folder next time (the cache is kept)
    assert _python(root).stdout.split()[2] == cache


def test_numba_cache_dir_the_user_set_is_kept(read_only_install):
    """The control: with an unwritable NUMBA_CACHE_DIR of the user's own, gripsense changes
    nothing and numba fails as it does (this is what the sandbox does to numba)."""
    root = read_only_install
    r = _python(root, NUMBA_CACHE_DIR=str(root / "home" / "cache"))
    assert "cannot cache function" in r.stderr and r.returncode != 0


def test_numba_cache_left_alone_where_the_install_is_writable():
    code = "import os, gripsense; print(os.environ.get('NUMBA_CACHE_DIR'))"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                       env=env)  # fmt: skip
    assert r.stdout.strip() == "None", r.stdout + r.stderr


_CALLBACK_RUN = """
import ctypes, os, signal, sys, time
import gripsense.cli as cli
import gripsense.cli._app as app

def run():
    def inside():  # a Python callback called from C, as numba's compiler calls one
        os.kill(os.getpid(), signal.SIGINT)
        t = time.monotonic()
        while time.monotonic() - t < 0.2:  # the handler runs here and its exception is lost
            pass
        return 0
    ctypes.CFUNCTYPE(ctypes.c_int)(inside)()
    t = time.monotonic()
    while time.monotonic() - t < 20:  # the run goes on: the signal must still end it
        pass
    print("ran to the end")

app.run = run
cli.main()
"""


def test_a_signal_inside_a_callback_from_c_is_not_lost():
    """A signal whose exception landed inside a ctypes callback (numba's compiler) was
    "ignored" with a traceback, and the run went on to exit 0 — seen in a fresh-clone run."""
    p = subprocess.run([sys.executable, "-c", _CALLBACK_RUN], capture_output=True, text=True,
                       timeout=600)  # fmt: skip
    assert (p.returncode, p.stderr.strip(), p.stdout) == (130, "error: interrupted (SIGINT)", "")


def test_a_signal_a_library_turned_into_its_own_error_ends_as_the_signal(monkeypatch):
    """DuckDB checks for signals while a query runs: the Interrupted that SIGINT raises there
    comes back as its own "Query interrupted" error (a fleet interrupted during `--bucket`'s
    check read "internal error" one time in three). A run that raised a signal ends as
    interrupted; without one, the same error is the internal error it is."""
    import gripsense.cli as cli
    from gripsense.cli._app import _fail

    err = RuntimeError("Query interrupted")
    monkeypatch.setattr(cli, "_RAISED", [])
    with pytest.raises(SystemExit) as bug:
        _fail(err)
    assert bug.value.code == 1
    monkeypatch.setattr(cli, "_RAISED", [int(signal.SIGINT)])
    with pytest.raises(cli.Interrupted) as stop:
        _fail(err)
    assert stop.value.signum == signal.SIGINT and stop.value.__cause__ is err
