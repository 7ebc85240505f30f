"""Help pages as click writes them, with two changes: a long token is never cut inside a name,
and asking for help (``gripsense COMMAND --help``) imports nothing it does not need.

click (typer's) wraps a help text with :class:`textwrap.TextWrapper`, cutting a word longer
than the column anywhere (``t=...,road_wheel=...|steerin`` / ``g_wheel=...``) and any word at a
hyphen (``[default: friction-`` / ``results]``, ``--steer-`` / ``columns``). Here a word is never
broken at a hyphen, and one longer than a line only after one of its separators (``,`` or
``|``), so every name stays whole; a word without one that fits nowhere is kept whole on its
own line. Every other line is as click writes it.

typer (≥ 0.2x) converts a parameter's value with a pydantic ``TypeAdapter`` (pydantic takes
~0.2 s to import) — also the value of a group's ``--help`` flag when it is absent (``None``),
which is every ``gripsense COMMAND …``. A group's help flag here defaults to ``False``, a value
typer passes through unconverted; nothing else changes.
"""

from __future__ import annotations

import textwrap
from typing import Any

from typer.core import TyperGroup

__all__ = ["HelpContext", "HelpFormatter", "QuickGroup", "wrap_text"]

_Context: Any = TyperGroup.context_class  # typer's click (vendored since typer 0.2x, else click's)
_SEPARATORS = ",|"


class _Wrapper(textwrap.TextWrapper):
    """:class:`textwrap.TextWrapper` that breaks a word longer than a line only after a
    separator (``,`` ``|``) — never inside a name, nor at a hyphen.
    """

    def _handle_long_word(
        self, reversed_chunks: list[str], cur_line: list[str], cur_len: int, width: int
    ) -> None:
        word = reversed_chunks[-1]
        room = max(width - cur_len, 1)
        cut = max(word.rfind(s, 0, room) for s in _SEPARATORS) + 1  # just after a separator
        if cut <= 0:  # none within this line's room
            if cur_line:  # the word starts the next line (a whole line's room)
                return
            after = [i for i in (word.find(s) for s in _SEPARATORS) if i >= 0]
            cut = min(after) + 1 if after else len(word)  # the line runs over, the name whole
        cur_line.append(word[:cut])
        reversed_chunks[-1] = word[cut:]


def wrap_text(
    text: str,
    width: int = 78,
    initial_indent: str = "",
    subsequent_indent: str = "",
    preserve_paragraphs: bool = False,
) -> str:
    r"""Wrap *text* as click's ``wrap_text`` does, but never cut a name (see the module).

    Parameters
    ----------
    text : str
        The text; with *preserve_paragraphs*, paragraphs are separated by an empty line and one
        that starts with a line holding only ``\\b`` is not rewrapped.
    width : int
        Line width [characters].
    initial_indent, subsequent_indent : str
        Indents of the first and of the other lines.
    preserve_paragraphs : bool
        Wrap each paragraph on its own, keeping its indent.

    Returns
    -------
    str
        The wrapped text.
    """
    text = text.expandtabs()
    wrapper = _Wrapper(
        width,
        initial_indent=initial_indent,
        subsequent_indent=subsequent_indent,
        replace_whitespace=False,
        break_on_hyphens=False,
    )
    if not preserve_paragraphs:
        return wrapper.fill(text)
    paragraphs: list[tuple[int, bool, str]] = []
    buf: list[str] = []
    indent: int | None = None

    def flush() -> None:
        if buf:
            if buf[0].strip() == "\b":
                paragraphs.append((indent or 0, True, "\n".join(buf[1:])))
            else:
                paragraphs.append((indent or 0, False, " ".join(buf)))
            buf.clear()

    for line in text.splitlines():
        if not line:
            flush()
            indent = None
        else:
            if indent is None:
                stripped = line.lstrip()
                indent = len(line) - len(stripped)
                line = stripped
            buf.append(line)
    flush()
    out = []
    for extra, raw, par in paragraphs:
        first, rest = initial_indent + " " * extra, subsequent_indent + " " * extra
        if raw:
            out.append(
                "\n".join((first if i == 0 else rest) + ln for i, ln in enumerate(par.splitlines()))
            )
        else:
            wrapper.initial_indent, wrapper.subsequent_indent = first, rest
            out.append(wrapper.fill(par))
    return "\n\n".join(out)


class HelpFormatter(_Context.formatter_class):
    """click's help formatter whose text and definition lists never cut a name."""

    def write_text(self, text: str) -> None:
        """Write re-indented text, its paragraphs kept (as click's)."""
        indent = " " * self.current_indent
        self.write(wrap_text(text, self.width, indent, indent, preserve_paragraphs=True))
        self.write("\n")

    def write_dl(self, rows: Any, col_max: int = 30, col_spacing: int = 2) -> None:
        """Write a definition list (options, commands) as click's: first column, then the
        wrapped text beside it.
        """
        rows = list(rows)
        first_width = max((len(r[0]) for r in rows), default=0)
        first_col = min(first_width, col_max) + col_spacing
        for first, second, *_ in ((*r, "") for r in rows):
            self.write(f"{'':>{self.current_indent}}{first}")
            if not second:
                self.write("\n")
                continue
            if len(first) <= first_col - col_spacing:
                self.write(" " * (first_col - len(first)))
            else:
                self.write("\n")
                self.write(" " * (first_col + self.current_indent))
            text_width = max(self.width - first_col - 2, 10)
            lines = wrap_text(second, text_width, preserve_paragraphs=True).splitlines()
            if not lines:
                self.write("\n")
                continue
            self.write(f"{lines[0]}\n")
            for line in lines[1:]:
                self.write(f"{'':>{first_col + self.current_indent}}{line}\n")


class HelpContext(_Context):
    """A command's context whose help pages are written by :class:`HelpFormatter`."""

    formatter_class = HelpFormatter


def _use_help_context(command: Any) -> None:
    """Give *command* and every sub-command :class:`HelpContext` (changed in place)."""
    command.context_class = HelpContext
    for sub in getattr(command, "commands", {}).values():
        _use_help_context(sub)


class QuickGroup(TyperGroup):
    """A typer command group whose commands' help never cuts a name (:class:`HelpFormatter`)
    and whose ``--help`` flag, when absent, is ``False`` — not ``None``, which typer converts
    with pydantic (0.2 s to import) on every ``gripsense COMMAND …``.
    """

    context_class = HelpContext

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        _use_help_context(self)

    def get_help_option(self, ctx: Any) -> Any:
        """The group's ``--help`` option, ``False`` when not given."""
        option = super().get_help_option(ctx)
        if option is not None and option.default is None:
            option.default = False
        return option
