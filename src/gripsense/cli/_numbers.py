"""Numbers on the command line are finite: ``nan`` or ``inf`` given to any option or argument
of any command is one line naming the option and exit 2, never a result computed from it.

Typer reads ``nan``, ``inf`` and ``-inf`` as floats. :class:`FiniteGroup`, the root command
group, gives every parameter of every command (sub-groups included, so a new option is covered
without being told) a check that refuses a converted value that is a non-finite float (before
the parameter's own callback, if it has one). Options that hold several numbers in one text
(``--fz 2000:6000:1000``, ``--settling 1,2,3``) are parsed with :func:`finite_numbers`, which
refuses them the same way.
"""

from __future__ import annotations

import math
import re
from typing import Any

import typer

from gripsense.cli._help import QuickGroup
from gripsense.errors import InputError

__all__ = ["FiniteGroup", "finite_numbers", "require_finite_params"]

_HOW = "give a finite number (nan and inf are not numbers a measurement can use)"


def _non_finite(value: Any) -> bool:
    if isinstance(value, float):
        return not math.isfinite(value)
    if isinstance(value, tuple | list):
        return any(_non_finite(v) for v in value)
    return False


def _finite_callback(old: Any) -> Any:
    """A parameter callback that refuses a non-finite number, then calls *old* (if any)."""
    if getattr(old, "_gripsense_finite", False):
        return old

    def check(ctx: Any, param: Any, value: Any) -> Any:
        if _non_finite(value):
            raise typer.BadParameter(f"{value!r}: {_HOW}", ctx=ctx, param=param)
        return old(ctx, param, value) if old is not None else value

    check._gripsense_finite = True  # type: ignore[attr-defined]
    return check


def require_finite_params(command: Any) -> None:
    """Make every parameter of *command* and of its sub-commands refuse non-finite numbers.

    Parameters
    ----------
    command : click.Command
        A command or group (typer's); changed in place.
    """
    for p in getattr(command, "params", []):
        p.callback = _finite_callback(p.callback)
    for sub in getattr(command, "commands", {}).values():
        require_finite_params(sub)


class FiniteGroup(QuickGroup):
    """The ``gripsense`` command group: no command takes ``nan`` or ``inf`` for a number
    (:func:`require_finite_params` on every command when the group is built); its help as
    :class:`~gripsense.cli._help.QuickGroup` writes it.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        require_finite_params(self)


def finite_numbers(text: str, option: str, sep: str = ",") -> list[float]:
    """The numbers of an option that holds several in one text, each finite.

    Parameters
    ----------
    text : str
        ``"1,2,3"`` (or split by *sep*).
    option : str
        The option, for the message (``--fz``).
    sep : str
        Separator characters (any of them separates).

    Returns
    -------
    list of float
        The numbers [the option's unit].

    Raises
    ------
    InputError
        Naming the option and the text that is not a finite number.
    """
    out = []
    for part in re.split(f"[{re.escape(sep)}]", text):
        if not part.strip():
            continue
        try:
            v = float(part)
        except ValueError:
            raise InputError(f"{option}: {part.strip()!r} in {text!r} is not a number") from None
        if not math.isfinite(v):
            raise InputError(f"{option}: {part.strip()!r} in {text!r}: {_HOW}")
        out.append(v)
    return out
