"""The ``gripsense`` command line: a thin layer over the library, one module per command group.

==============  ==============================================================================
module          commands
==============  ==============================================================================
ingest          ``ingest``
friction        ``friction``, ``report``, ``stiffness``
calibrate       ``calibrate``
sensors         ``brake-mu``, ``camber``, ``camera-slip``
tyre            ``tyre eval``, ``tyre fit``, ``tyre fit-contact`` (also ``fit-contact``)
steering        ``steering identify``
sim             ``simulate``, ``demo``
live            ``live``
fleet           ``fleet``
==============  ==============================================================================

The console script's :func:`main` is all this module holds at import time: it installs the
signal handlers first and only then imports the commands, so a Ctrl-C or SIGTERM at any
moment — during those imports too — is one line and exit 130 (SIGINT) or 143 (SIGTERM), never
a traceback.

The command modules import only typer, rich and light gripsense modules at module level; each
command imports the library (numpy, pandas, numba, matplotlib …, seconds) when it runs, so
``gripsense --help``, ``gripsense COMMAND --help`` and ``--version`` start at once
(``tests/cli/test_startup.py`` checks what they import, ``benchmarks/startup.py`` times them).
"""

from __future__ import annotations

import os
import signal
import sys
import threading

TYPE_CHECKING = False  # not typing's: nothing that takes time before the handlers are in place
if TYPE_CHECKING:
    from types import FrameType
    from typing import Any, NoReturn

    from gripsense.cli._app import app, usage_hint  # noqa: F401

__all__ = ["app", "finishing", "main"]


class Interrupted(BaseException):
    """SIGINT or SIGTERM as an exception: a ``BaseException``, so no ``except Exception``
    swallows it and every ``finally`` on the way out runs (temporary outputs removed).

    Parameters
    ----------
    signum : int
        The signal's number [-].
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _importing(frame: FrameType | None) -> bool:
    """Whether the interrupted code runs inside an ``import`` (possibly a C extension's
    initialisation, which an exception raised there can leave half-done).
    """
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def _on_signal(signum: int, frame: FrameType | None) -> None:
    """SIGINT / SIGTERM: an exception, so every ``finally`` on the way out runs (an unfinished
    output removed). Inside an import (a C extension's initialisation that an exception would
    leave half-done, and ``import`` turns into an ``ImportError``) the signal is sent again
    50 ms later, until the import is over.
    """
    if _importing(frame):
        again = threading.Timer(0.05, os.kill, (os.getpid(), signum))
        again.daemon = True
        again.start()
        return
    _RAISED.append(signum)
    raise Interrupted(signum)  # not KeyboardInterrupt: typer turns that into a silent exit 130


_RAISED: list[int] = []  # the signals :func:`_on_signal` raised as Interrupted in this run


def interrupted_by() -> int | None:
    """The signal this run raised as :class:`Interrupted`, if any. A C library that checks for
    signals while it works catches the exception and raises its own (DuckDB: "Query
    interrupted"): the failure that reaches the top is then the signal's, not a bug.

    Returns
    -------
    int or None
        The signal's number [-]; None when no signal was raised.
    """
    return _RAISED[-1] if _RAISED else None


def _lost(unraisable: Any) -> None:
    """``sys.unraisablehook``: the :class:`Interrupted` of a signal that landed inside a
    callback from C (numba's compiler calls Python through ctypes) cannot leave the callback and
    would be lost — the run went on to the end, exit 0. The signal is sent again 50 ms later,
    until it lands in Python code; anything else goes to the default hook.
    """
    if isinstance(unraisable.exc_value, Interrupted):
        again = threading.Timer(0.05, os.kill, (os.getpid(), unraisable.exc_value.signum))
        again.daemon = True
        again.start()
        return
    sys.__unraisablehook__(unraisable)


def _leave(signum: int, _frame: object) -> None:
    """A second signal while the program ends: end now, quietly (the line is printed)."""
    os._exit(128 + signum)


def _say(signum: int) -> None:
    """The one line of a run stopped by a signal (written directly: nothing is imported)."""
    name = signal.Signals(signum).name
    try:
        os.write(2, f"error: interrupted ({name})\n".encode())
    except OSError:
        pass


def _stopped(signum: int) -> NoReturn:
    """End a run stopped by a signal: its one line and exit status 128 + the signal.

    Every ``finally`` on the way out has run (unfinished outputs removed, clusters closed); the
    process then ends without the interpreter's teardown: a signal that landed while numba or
    llvmlite initialised can leave their C state half-built, and tearing that down crashed the
    process (exit −11 after half the line) one time in many.
    """
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, _leave)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    _say(signum)
    os._exit(128 + signum)


def main() -> None:
    """Console-script entry point (``gripsense``): every failure is one line on stderr and a
    non-zero exit, never a traceback (set ``GRIPSENSE_DEBUG=1`` to see one); SIGINT (Ctrl-C)
    and SIGTERM at any moment end with one line and exit 130 or 143.
    """
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, _on_signal)
    sys.unraisablehook = _lost
    try:
        from gripsense.cli._app import run

        run()
    except KeyboardInterrupt:
        _stopped(signal.SIGINT)
    except Interrupted as e:
        _stopped(e.signum)
    finally:
        # the run is over, its outputs installed or removed: a signal while Python ends changes
        # nothing (it would kill the process by the default action, silently, at exit −2); one
        # that lands in finishing() itself, before its handlers are replaced, changes nothing
        # either (it escaped this block as a traceback, exit 1, once under load)
        while True:
            try:
                finishing()
                break
            except Interrupted:
                continue


def finishing() -> None:
    """The run's outcome is decided — it returned, or its one error line is being printed: a
    SIGINT or SIGTERM from now on changes nothing (no second line after the error's, which a
    signal deferred during an import could add as the command failed at once). Only where
    :func:`main` installed its handlers (not in a test's process).
    """
    for s in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(s) is _on_signal:
            signal.signal(s, signal.SIG_IGN)


def __getattr__(name: str) -> Any:
    """``app`` and ``usage_hint`` are imported when first asked for (they import every
    command).
    """
    if name in ("app", "usage_hint"):
        from gripsense.cli import _app

        return getattr(_app, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


if __name__ == "__main__":
    main()
