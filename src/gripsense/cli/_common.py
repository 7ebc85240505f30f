"""What every ``gripsense`` command module shares: consoles, safe printing, the error exit."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Annotated, NoReturn

import typer
from rich.console import Console
from rich.text import Text

__all__ = [
    "LOG_COLUMNS_HELP",
    "Columns",
    "Dbc",
    "Overwrite",
    "TimeOffset",
    "command_line",
    "console",
    "err_console",
    "fail",
    "log_options",
    "old_column_flags",
    "say",
]

Overwrite = Annotated[
    bool,
    typer.Option(
        "--overwrite",
        help="replace an earlier output of the same kind (only files gripsense wrote)",
    ),
]

Columns = Annotated[
    str | None,
    typer.Option(
        "--columns",
        help="name=HEADER[:unit],… (units s, ms, m/s, km/h, mps2, g, deg, rad, dps, N, kN, "
        "mm, kg; '-' before HEADER flips a sign); default: headers with a known name and "
        "unit suffix (time_s, ax_mps2, slip_deg …)",
    ),
]
"""The one ``--columns`` option of every command that reads a table."""


def _width(stream) -> int | None:
    """The console width: the terminal's; in a pipe, a log file or a CI job ``COLUMNS`` or 160
    (rich's 80 cut tables to "measur…", "undete…").
    """
    try:
        if stream.isatty():
            return None
    except (AttributeError, ValueError):
        pass
    try:
        return max(int(os.environ.get("COLUMNS", "0")), 0) or PIPE_WIDTH
    except ValueError:
        return PIPE_WIDTH


PIPE_WIDTH = 160
"""Width of the output when it is not a terminal [characters]."""

console = Console(width=_width(sys.stdout))
err_console = Console(stderr=True, soft_wrap=True)


def command_line() -> str:
    """The command line as the user typed it (for result manifests)."""
    import shlex
    import sys

    return " ".join(shlex.quote(a) for a in ["gripsense", *sys.argv[1:]])


def say(*parts: object) -> None:
    """Print text that may hold user data (file names, vehicle names, log lines) literally:
    no Rich markup is interpreted, so ``[/b]`` in a name prints as it is.

    Parameters
    ----------
    *parts : object
        Joined with spaces.
    """
    console.print(Text(" ".join(str(p) for p in parts)), soft_wrap=True)


def fail(err: Exception | str) -> NoReturn:
    """Print *err* as one line on stderr and exit with status 2 (bad input).

    Parameters
    ----------
    err : Exception or str
        The error; its text is printed literally (``[vehicle] mass_kg`` stays as it is).
    """
    from gripsense.cli import finishing

    finishing()  # the outcome is this line: a signal now adds no second one
    err_console.print(Text.assemble(("error: ", "bold red"), str(err)), highlight=False)
    raise typer.Exit(2)


def old_column_flags(used: list[str], columns: str | None, example: str) -> bool:
    """The deprecated per-command column flags: an error when mixed with ``--columns``, a
    deprecation note otherwise.

    Parameters
    ----------
    used : list of str
        The old flags given on this command line (e.g. ``["--ax-col", "--units"]``).
    columns : str or None
        The ``--columns`` value.
    example : str
        The same mapping written with ``--columns``, for the messages.

    Returns
    -------
    bool
        Whether the old flags are in use.
    """
    from gripsense.errors import InputError

    if used and columns:
        raise InputError(
            f"give either --columns or the old flags ({', '.join(used)}), not both; "
            f"e.g. --columns {example}"
        )
    if used:
        say(
            f"note: {', '.join(used)} {'is' if len(used) == 1 else 'are'} deprecated and go "
            f"in the next release; use --columns {example} (or name the headers with a unit "
            "suffix)"
        )
    return bool(used)


LOG_COLUMNS_HELP = (
    "channels of a VBOX, MDF4 or CAN log or topics of a ROS bag (/topic.field): heading=…,"
    "course=…,speed=…, optionally lat=…,lon=…,"
    "yaw_rate=…,steer=…:deg,steering_wheel=…:deg,torque=…:Nm (units after ':', else the "
    "file's; docs/ingest.md)"
)
Dbc = Annotated[
    Path | None,
    typer.Option(
        "--dbc", help="DBC database that decodes a CAN log (BLF, ASC, raw CAN frames in MDF4)"
    ),
]
TimeOffset = Annotated[
    float | None,
    typer.Option(
        "--time-offset",
        help="seconds since 1970 UTC of an MDF4/CAN log's time zero (when it has no start time)",
    ),
]


def log_options(columns: str | None, dbc: Path | None, time_offset: float | None, **kw):
    """The :class:`~gripsense.io.logs.LogOptions` of a command's log flags.

    Parameters
    ----------
    columns : str or None
        ``--columns``.
    dbc : Path or None
        ``--dbc``.
    time_offset : float or None
        ``--time-offset`` [s].
    **kw
        Further fields (``strict``, ``max_lines``).
    """
    from gripsense.io.logs import LogOptions

    return LogOptions(columns=columns, dbc=dbc, time_offset=time_offset, **kw)
