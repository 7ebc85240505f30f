"""The README's Python example runs as written, from any folder (issue "What a newcomer trips
on": it named a path that exists only in a source checkout)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_python_example_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        ns: dict = {}
        exec(compile(code, str(README), "exec"), ns)
    assert (tmp_path / "out" / "manifest.json").is_file()
    assert "mu_low" in ns["result"].summary
