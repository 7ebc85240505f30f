"""The result of tokenizing an NMEA byte buffer: per-line outcome plus raw field tables.

Both tokenizers return a :class:`Tokens`; everything after tokenizing is shared.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["IGNORED", "PARSED", "REJECTED", "Tokens", "lines_at", "split_lines"]

PARSED = 0
IGNORED = 1
REJECTED = 2


@dataclass
class Tokens:
    """Per-line outcome of tokenizing and the raw values of the sentences that were read.

    Attributes
    ----------
    outcome : numpy.ndarray of int8
        Per line: ``PARSED``, ``IGNORED`` or ``REJECTED``.
    code : numpy.ndarray of int32
        Per line: index into :attr:`names` of the line's label — the sentence type key (parsed,
        ignored) or the reject reason.
    names : list of str
        Label names.
    junk_prefix : numpy.ndarray of bool
        Per line: the sentence started after other bytes on the same line (e.g. binary
        receiver output without a line break before the ``$``).
    raw : dict
        Type key -> column name -> array; every table has ``line`` (0-based line index) and one
        float64 (numeric kinds) or uint8 (``char`` kind) column per field of the type's spec.
    details : dict
        0-based line index -> human-readable detail of the reject (at least for the first rejects).
    """

    outcome: np.ndarray
    code: np.ndarray
    names: list[str]
    junk_prefix: np.ndarray
    raw: dict[str, dict[str, np.ndarray]]
    details: dict[int, str] = field(default_factory=dict)

    @property
    def n_lines(self) -> int:
        """Number of lines tokenized."""
        return int(self.outcome.size)

    @property
    def labels(self) -> np.ndarray:
        """Per-line label names (object array; for tests and small inputs)."""
        return np.array([*self.names, ""], dtype=object)[self.code]

    def name_code(self, name: str) -> int:
        """Code of a label name (added if new)."""
        if name not in self.names:
            self.names.append(name)
        return self.names.index(name)

    def counts(self, outcome: int) -> dict[str, int]:
        """Label name -> number of lines with this outcome."""
        c = np.bincount(self.code[self.outcome == outcome], minlength=len(self.names))
        return {self.names[i]: int(v) for i, v in enumerate(c) if v}

    def reject(self, lines: np.ndarray, reason: str, details: list[str]) -> None:
        """Move *lines* (0-based indices of parsed lines) to the rejected bucket."""
        self.outcome[lines] = REJECTED
        self.code[lines] = self.name_code(reason)
        for i, d in zip(lines.tolist(), details, strict=True):
            self.details[int(i)] = d


def split_lines(data: bytes) -> list[bytes]:
    r"""Split a buffer into lines the way every gripsense reader does.

    Lines end at ``\\n``; a final line without a terminator counts; a terminator at the very end
    does not start another line. ``\\r`` is not a terminator (it is stripped as whitespace).
    """
    if not data:
        return []
    parts = data.split(b"\n")
    if parts[-1] == b"":
        parts.pop()
    return parts


def lines_at(data: bytes, indices) -> dict[int, bytes]:
    """Lines number *indices* (0-based, as :func:`split_lines` counts them) of a buffer,
    found by searching the line ends up to the last of them — for the few lines whose reject
    is worded, without splitting a large buffer.
    """
    want = sorted({int(i) for i in indices})
    out: dict[int, bytes] = {}
    pos = 0
    line = 0
    for i in want:
        while line < i:
            pos = data.index(b"\n", pos) + 1
            line += 1
        end = data.find(b"\n", pos)
        out[i] = data[pos : len(data) if end < 0 else end]
    return out


STRIP = b" \t\r"


def empty_raw(spec_fields) -> dict[str, np.ndarray]:
    """An empty raw table for a sentence spec's fields."""
    out: dict[str, np.ndarray] = {"line": np.empty(0, dtype=np.int64)}
    for f in spec_fields:
        out[f.name] = np.empty(0, dtype=np.uint8 if f.kind == "char" else np.float64)
    return out
