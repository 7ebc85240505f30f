"""PAC89 tyre coefficient files in Project Chrono's JSON layout (``//`` comments allowed)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from gripsense.errors import InputError
from gripsense.io.text import read_text

__all__ = ["read_pac89_json"]


def _strip_json_comments(text: str) -> str:
    out = []
    for line in text.splitlines():
        # drop // comments that are not inside a string
        in_str = False
        for i, ch in enumerate(line):
            if ch == '"' and (i == 0 or line[i - 1] != "\\"):
                in_str = not in_str
            elif ch == "/" and not in_str and line[i : i + 2] == "//":
                line = line[:i]
                break
        out.append(line)
    return re.sub(r",(\s*[}\]])", r"\1", "\n".join(out))


def read_pac89_json(path: str | Path) -> dict[str, dict[str, float]]:
    """Read a Chrono-style PAC89 JSON file (``//`` comments allowed).

    Parameters
    ----------
    path : str or Path
        PAC89 JSON file.

    Returns
    -------
    dict
        ``{"lateral": {"a0": ...}, "longitudinal": {"b0": ...}, "aligning": {...}}``.
    """
    path = Path(path)
    try:
        doc = json.loads(_strip_json_comments(read_text(path, "PAC89 file")))
    except json.JSONDecodeError as e:
        raise InputError(f"{path} line {e.lineno}: not valid JSON ({e.msg})") from None
    out = {}
    for key, name in (
        ("Lateral Coefficients", "lateral"),
        ("Longitudinal Coefficients", "longitudinal"),
        ("Aligning Coefficients", "aligning"),
    ):
        if key in doc:
            out[name] = {k.lower(): float(v) for k, v in doc[key].items()}
    if "lateral" not in out:
        raise InputError(f"{path}: no 'Lateral Coefficients' object; is this a PAC89 file?")
    return out
