"""Typed access to a parsed TOML document, with errors that name file, table and key."""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable
from typing import NoReturn

from gripsense.errors import InputError

__all__ = ["TomlReader"]


class TomlReader:
    """Typed access to a TOML document with errors that name file, table and key."""

    def __init__(self, doc: dict, source: str):
        self.doc = doc
        self.source = source

    def known(self, t: dict, table: str, keys: Iterable[str]) -> None:
        """Raise on the first key of *t* that is not one of *keys*, suggesting the closest.

        A misspelt key would otherwise be ignored and its default used without a word.

        Parameters
        ----------
        t : dict
            The table (``self.doc`` for the top level).
        table : str
            Its name, for the message (``""`` for the top level).
        keys : iterable of str
            The keys the table may hold.
        """
        keys = list(keys)
        for k in t:
            if k in keys:
                continue
            close = difflib.get_close_matches(k, keys, n=1, cutoff=0.6)
            hint = f"did you mean {close[0]!r}?" if close else f"known keys: {', '.join(keys)}"
            where = f"[{table}] " if table else ""
            raise InputError(f"{self.source}: {where}{k}: unknown key; {hint}")

    def fail(self, table: str, key: str, msg: str) -> NoReturn:
        """Raise an InputError naming the file, table and key."""
        raise InputError(f"{self.source}: [{table}] {key}: {msg}")

    def table(self, name: str, required: bool) -> dict:
        """The table *name* (empty when optional and absent)."""
        t = self.doc.get(name)
        if t is None:
            if required:
                raise InputError(f"{self.source}: missing table [{name}]")
            return {}
        if not isinstance(t, dict):
            raise InputError(f"{self.source}: [{name}] must be a table")
        return t

    def num(
        self,
        t: dict,
        table: str,
        key: str,
        *,
        unit: str,
        positive: bool = False,
        required: bool = True,
        plausible: tuple[float, float] | None = None,
    ) -> float | None:
        """A number of table *t* (None when optional and absent); errors name the unit.

        Parameters
        ----------
        t : dict
            The table.
        table : str
            Its name, for messages.
        key : str
            The key.
        unit : str
            Unit of the value, for messages.
        positive : bool
            Require a value > 0.
        required : bool
            Raise when the key is absent.
        plausible : tuple of float, optional
            (low, high): values outside are errors that name the range (a value typed in the
            wrong unit, e.g. centimetres for metres).

        Returns
        -------
        float or None
            The value.
        """
        if key not in t:
            if required:
                self.fail(table, key, f"missing [{unit}]")
            return None
        v = t[key]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            self.fail(table, key, f"= {v!r}: must be a number [{unit}]")
        if positive and v <= 0:
            self.fail(table, key, f"= {v}: must be > 0 [{unit}]")
        if plausible is not None and not plausible[0] <= v <= plausible[1]:
            self.fail(
                table,
                key,
                f"= {v} [{unit}] is outside the plausible range {plausible[0]:g}–{plausible[1]:g} "
                f"[{unit}]; check the unit",
            )
        return float(v)
