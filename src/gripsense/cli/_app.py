"""The ``gripsense`` application: every command registered, and the run of one command line
that turns any failure into one line on stderr (:func:`run`). :mod:`gripsense.cli` imports it
only once its signal handlers are in place.
"""

from __future__ import annotations

import os
import sys
from typing import Annotated, Any

import typer

from gripsense.cli._common import err_console
from gripsense.cli._numbers import FiniteGroup
from gripsense.cli.calibrate import calibrate
from gripsense.cli.fleet import fleet
from gripsense.cli.friction import friction, report_cmd, stiffness
from gripsense.cli.ingest import ingest
from gripsense.cli.live import live
from gripsense.cli.sensors import brake_mu, camber, camera_slip
from gripsense.cli.sim import demo, simulate
from gripsense.cli.steering import steering_app
from gripsense.cli.tyre import fit_contact, tyre_app
from gripsense.errors import GripsenseError

__all__ = ["app", "run", "usage_hint"]

app = typer.Typer(
    cls=FiniteGroup,  # no command takes nan or inf for a number
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help as written: a unit such as [deg] is not markup
    context_settings={"max_content_width": 100},
    help="gripsense: tyre-road friction, tyre and steering parameters from how a vehicle moves.",
)


def _print_version(value: bool) -> None:
    """``--version``: ``gripsense X.Y.Z`` (:mod:`gripsense._version`), then exit."""
    if value:
        from gripsense._version import __version__

        print(f"gripsense {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            help="Show the version and exit.",
            is_eager=True,
            callback=_print_version,
        ),
    ] = False,
) -> None:
    # the options of gripsense itself, before a command (the help is the app's)
    pass


app.command()(ingest)
app.command()(friction)
app.command("report")(report_cmd)
app.command()(stiffness)
app.command()(calibrate)
app.command("brake-mu")(brake_mu)
app.command()(camber)
app.command("camera-slip")(camera_slip)
app.command("fit-contact")(fit_contact)
app.command()(simulate)
app.command()(demo)
app.command()(live)
app.command()(fleet)
tyre_app.command("fit-contact")(fit_contact)
app.add_typer(tyre_app, name="tyre")
app.add_typer(steering_app, name="steering")


_FLAG_WORDS = {"true", "false", "yes", "no", "on", "off", "1", "0"}


def usage_hint(error: Any) -> str:
    """The message of a command-line usage error, with what to type instead where it is clear
    (a switch given a value: ``--strict true`` → ``--strict``; every other error: ``--help``).

    Parameters
    ----------
    error : Exception
        A click ``UsageError`` (typer's).

    Returns
    -------
    str
        One line.
    """
    msg = " ".join(error.format_message().split())
    words = [w.strip("'()") for w in msg.split()]
    if "unexpected extra argument" in msg and any(w.lower() in _FLAG_WORDS for w in words):
        return (
            f"{msg} — switches take no value: write --flag or --no-flag, not --flag true "
            f"(see {getattr(error.ctx, 'command_path', 'gripsense')} --help)"
        )
    return f"{msg} (see {getattr(error.ctx, 'command_path', 'gripsense')} --help)"


def run() -> None:
    """Run the command line in ``sys.argv``: every failure is one line on stderr and a non-zero
    exit, never a traceback (set ``GRIPSENSE_DEBUG=1`` to see one). A Ctrl-C reaches
    :func:`gripsense.cli.main` as ``KeyboardInterrupt``.
    """
    try:
        code = app(prog_name="gripsense", standalone_mode=False)
        sys.exit(code if isinstance(code, int) else 0)
    except Exception as e:  # typer's (vendored) click errors, known by their class names
        names = {c.__name__ for c in type(e).__mro__}
        if "NoArgsIsHelpError" in names:  # a bare group: its help
            print(e.format_message())  # type: ignore[attr-defined]
            sys.exit(0)
        if "UsageError" in names or "ClickException" in names:
            from rich.text import Text

            from gripsense.cli import finishing

            finishing()  # the outcome is this line: a signal now adds no second one

            where = getattr(getattr(e, "ctx", None), "command_path", None) or "gripsense"
            err_console.print(
                Text.assemble(("error: ", "bold red"), f"{where}: {usage_hint(e)}"),
                highlight=False,
            )
            sys.exit(2)
        if "Abort" in names:  # click's word for a Ctrl-C
            raise KeyboardInterrupt from None
        _fail(e)


def _fail(e: Exception) -> None:
    """The one place that turns any other failure into a one-line message and an exit code."""
    from gripsense.cli import Interrupted, interrupted_by

    signum = interrupted_by()
    if signum is not None:  # a library turned the signal into its own error: the signal's
        raise Interrupted(signum) from e
    if os.environ.get("GRIPSENSE_DEBUG"):
        raise e
    if isinstance(e, GripsenseError):
        msg, code = str(e), 2
    elif isinstance(e, OSError):
        where = f"{e.filename}: " if e.filename else ""
        msg, code = f"{where}{e.strerror or e}", 1
    elif isinstance(e, MemoryError):
        msg, code = "out of memory; read a smaller part of the input (--max-lines)", 1
    else:
        msg = (
            f"internal error: {type(e).__name__}: {e} — this is a bug in gripsense; rerun "
            "with GRIPSENSE_DEBUG=1 for the details and report them"
        )
        code = 1
    from rich.text import Text

    from gripsense.cli import finishing

    finishing()  # the outcome is this line: a signal now adds no second one
    err_console.print(Text.assemble(("error: ", "bold red"), msg), highlight=False)
    sys.exit(code)
