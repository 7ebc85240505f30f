"""Typed access to a parsed TOML document, with errors that name file, table and key."""

from __future__ import annotations

import math

from gripsense.errors import InputError

__all__ = ["TomlReader"]


class TomlReader:
    """Typed access to a TOML document with errors that name file, table and key."""

    def __init__(self, doc: dict, source: str):
        self.doc = doc
        self.source = source

    def fail(self, table: str, key: str, msg: str):
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
    ) -> float | None:
        """A number of table *t* (None when optional and absent); errors name the unit."""
        if key not in t:
            if required:
                self.fail(table, key, f"missing [{unit}]")
            return None
        v = t[key]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            self.fail(table, key, f"= {v!r}: must be a number [{unit}]")
        if positive and v <= 0:
            self.fail(table, key, f"= {v}: must be > 0 [{unit}]")
        return float(v)
