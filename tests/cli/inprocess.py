"""``gripsense ARGS`` run inside the test's own process, through the console script's entry
point (:func:`gripsense.cli.main`), for the checks that are about what a command computes and
writes rather than about the process itself.

A console-script subprocess pays the interpreter, numpy/pandas/numba/matplotlib imports and
numba's cache loading again (2–4 s of CPU per call); in-process, one test worker pays them once.
What a user sees is kept: the same argument parsing, the same one-line error handling and exit
code, stdout and stderr captured as text (rich's consoles write to ``sys.stdout`` /
``sys.stderr`` at the time of writing, at the pipe width a subprocess gets), warnings printed on
stderr as a fresh interpreter prints them (pytest's warning capture is lifted for the call), and
so are log records of loggers nobody configured (pytest's handlers are taken off the root logger
for the call: ``logging.lastResort`` writes them to stderr, as in a fresh interpreter).
The process-wide state a command may change — signal handlers, ``sys.unraisablehook``, the
working folder, the umask — is restored afterwards.

Checks about the process itself (signals, a SIGKILL, the import cost, exit at interpreter end)
keep using the console script (``tests.cli.test_commands.run``).
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import signal
import subprocess
import sys
import warnings
from pathlib import Path


def _fresh_interpreter_filters() -> None:
    """The warning filters of a fresh (non-debug) interpreter without ``-W`` options."""
    warnings.resetwarnings()
    for category in (ResourceWarning, ImportWarning, PendingDeprecationWarning, DeprecationWarning):
        warnings.simplefilter("ignore", category)
    warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")


def _show(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a warning on (the redirected) stderr as the interpreter's default hook does."""
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def cli(
    *args: object, cwd: Path | None = None, umask: int | None = None
) -> subprocess.CompletedProcess:
    """Run ``gripsense ARGS`` in this process.

    Parameters
    ----------
    *args : object
        The command line after ``gripsense`` (each turned into ``str``) [-].
    cwd : path, optional
        Working folder of the call (restored afterwards) [-].
    umask : int, optional
        The process umask during the call (restored afterwards) [-].

    Returns
    -------
    subprocess.CompletedProcess
        ``returncode``, ``stdout`` and ``stderr`` (text) as the console script's run gives.
    """
    from gripsense.cli import main

    argv, hook = sys.argv, sys.unraisablehook
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    here = os.getcwd()
    root = logging.getLogger()
    root_handlers, root_level = root.handlers[:], root.level
    old_mask = os.umask(umask) if umask is not None else None
    out, err = io.StringIO(), io.StringIO()
    sys.argv = ["gripsense", *map(str, args)]
    code = 0
    try:
        root.handlers, root.level = [], logging.WARNING
        if cwd is not None:
            os.chdir(cwd)
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(),
        ):
            _fresh_interpreter_filters()
            warnings.showwarning = _show
            try:
                main()
            except SystemExit as e:
                code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
                if isinstance(e.code, str):
                    err.write(e.code + "\n")
    finally:
        sys.argv, sys.unraisablehook = argv, hook
        root.handlers, root.level = root_handlers, root_level
        for s, h in handlers.items():
            signal.signal(s, h)
        os.chdir(here)
        if old_mask is not None:
            os.umask(old_mask)
    return subprocess.CompletedProcess(
        ["gripsense", *map(str, args)], code, out.getvalue(), err.getvalue()
    )
