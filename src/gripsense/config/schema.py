"""Declarative schemas of the configuration tables: one entry per key (unit, plausible range,
default, meaning) that drives reading, validation, did-you-mean, the key tables of the docs and
the TOML templates.

A :class:`Table` reads one TOML table with :class:`~gripsense.config.toml_reader.TomlReader`:
unknown keys are errors with the closest known key suggested, numbers are checked against their
plausible range (a value typed in the wrong unit is caught there) and absent optional keys take
their default. Rules that tie several keys together stay with the description they build
(:meth:`gripsense.config.Vehicle.from_dict`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from gripsense.config.toml_reader import TomlReader

__all__ = ["REQUIRED", "Key", "Table"]


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED = _Required()
"""The default of a key that must be given."""


@dataclass(frozen=True)
class Key:
    """One key of a configuration table.

    Attributes
    ----------
    name : str
        The key.
    unit : str
        Its unit (``-`` for a ratio; ``""`` for text and tables).
    doc : str
        What it means, one line.
    default : object
        Value when absent (:data:`REQUIRED`: must be given; None: absent stays None).
    plausible : tuple of float, optional
        (low, high) of a number; outside is an error naming the range.
    positive : bool
        A number must be > 0.
    kind : str
        ``number``, ``text``, ``range`` ([low, high]) or ``other`` (read by the description's
        own code: tables, lists, choices).
    """

    name: str
    unit: str
    doc: str
    default: Any = None
    plausible: tuple[float, float] | None = None
    positive: bool = False
    kind: str = "number"

    @property
    def required(self) -> bool:
        """Whether the key must be given."""
        return self.default is REQUIRED


@dataclass(frozen=True)
class Table:
    """The schema of one configuration table.

    Attributes
    ----------
    name : str
        The table's name as written in the file (``vehicle``, ``tyre.front`` …).
    keys : tuple of Key
        Its keys, in the order the docs list them.
    doc : str
        What the table describes.
    """

    name: str
    keys: tuple[Key, ...]
    doc: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        """The keys' names."""
        return tuple(k.name for k in self.keys)

    def __getitem__(self, name: str) -> Key:
        for k in self.keys:
            if k.name == name:
                return k
        raise KeyError(name)

    def read(self, r: TomlReader, t: dict, where: str | None = None) -> dict:
        """The table's values: unknown keys refused, numbers checked, defaults filled in.

        Parameters
        ----------
        r : TomlReader
            Reader of the document (names the file in messages).
        t : dict
            The table as parsed.
        where : str, optional
            The table's name in messages (default: :attr:`name`).

        Returns
        -------
        dict
            Key → value for every key of the schema (``other`` keys as written, or their
            default).
        """
        where = where or self.name
        r.known(t, where, self.names)
        out: dict = {}
        for k in self.keys:
            if k.kind == "number":
                v = r.num(
                    t,
                    where,
                    k.name,
                    unit=k.unit,
                    positive=k.positive,
                    required=k.required,
                    plausible=k.plausible,
                )
                out[k.name] = k.default if v is None and not k.required else v
            elif k.kind == "text":
                v = t.get(k.name)
                if v is not None and not isinstance(v, str):
                    r.fail(where, k.name, f"= {v!r}: must be text")
                if v is None and k.required:
                    r.fail(where, k.name, "missing")
                out[k.name] = v if v is not None else k.default
            elif k.kind == "range":
                out[k.name] = _range(r, t, where, k)
            else:
                if k.name not in t and k.required:
                    r.fail(where, k.name, "missing")
                out[k.name] = t.get(k.name, None if k.required else k.default)
        return out

    def markdown(self) -> str:
        """The table's keys as a Markdown table (key, unit, default, plausible range, meaning).

        Returns
        -------
        str
            The Markdown lines.
        """
        lines = [
            f"`[{self.name}]`" + (f" — {self.doc}" if self.doc else ""),
            "",
            "| key | unit | default | plausible | meaning |",
            "|---|---|---|---|---|",
        ]
        for k in self.keys:
            lines.append(
                f"| `{k.name}` | {k.unit or ''} | {_show(k.default)} | "
                f"{'' if k.plausible is None else f'{k.plausible[0]:g} … {k.plausible[1]:g}'} | "
                f"{k.doc.replace('|', '/')} |"
            )
        return "\n".join(lines)

    def template(self, values: dict | None = None) -> str:
        """A TOML template of the table: required keys with a placeholder (or *values*),
        optional keys commented out at their default, each with its unit and meaning.

        Parameters
        ----------
        values : dict, optional
            Values to write instead of placeholders.

        Returns
        -------
        str
            The TOML text.
        """
        values = values or {}
        out = [f"[{self.name}]"]
        for k in self.keys:
            note = f"# [{k.unit}] {k.doc}" if k.unit else f"# {k.doc}"
            if k.name in values:
                out.append(f"{k.name} = {_toml(values[k.name])}  {note}")
            elif k.required:
                out.append(f"{k.name} =   {note} (required)")
            elif k.default is not None:
                out.append(f"# {k.name} = {_toml(k.default)}  {note}")
            else:
                out.append(f"# {k.name} =   {note}")
        return "\n".join(out) + "\n"


def _show(v: object) -> str:
    if v is REQUIRED:
        return "required"
    if v is None:
        return "—"
    return f"`{_toml(v)}`"


def _toml(v: object) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, Iterable):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return f"{v:g}" if isinstance(v, float) else str(v)


def _range(r: TomlReader, t: dict, where: str, k: Key):
    """An optional ``key = [low, high]`` within the key's plausible range (None: absent)."""
    if k.name not in t:
        if k.required:
            r.fail(where, k.name, f"missing [{k.unit}]")
        return k.default
    v = t[k.name]
    lo, hi = k.plausible if k.plausible is not None else (float("-inf"), float("inf"))
    if (
        not isinstance(v, list)
        or len(v) != 2
        or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in v)
        or not lo <= v[0] <= v[1] <= hi
    ):
        r.fail(where, k.name, f"= {v!r}: give [low, high] within {lo:g}–{hi:g}")
    return (float(v[0]), float(v[1]))
