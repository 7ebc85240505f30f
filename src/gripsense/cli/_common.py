"""What every ``gripsense`` command module shares: consoles, safe printing, the error exit."""

from __future__ import annotations

from typing import Annotated, NoReturn

import typer
from rich.console import Console
from rich.text import Text

__all__ = ["Overwrite", "command_line", "console", "err_console", "fail", "say"]

Overwrite = Annotated[
    bool,
    typer.Option(
        "--overwrite",
        help="replace an earlier output of the same kind (only files gripsense wrote)",
    ),
]

console = Console()
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
    err_console.print(Text.assemble(("error: ", "bold red"), str(err)), highlight=False)
    raise typer.Exit(2)
