"""What every ``gripsense`` command module shares: the consoles and the error exit."""

from __future__ import annotations

import typer
from rich.console import Console

__all__ = ["console", "err_console", "fail"]

console = Console()
err_console = Console(stderr=True, soft_wrap=True)


def fail(err: Exception) -> None:
    """Print *err* as one line on stderr and exit with status 2 (bad input)."""
    err_console.print(f"[bold red]error:[/] {err}", markup=True, highlight=False)
    raise typer.Exit(2)
