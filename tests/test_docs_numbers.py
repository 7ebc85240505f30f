"""Numbers in the docs that a program prints are produced by that program (issue "What a
newcomer trips on": docs/examples.md had drifted from what the examples print). A fenced block
in a doc that starts with ``$ python examples/NAME.py`` quotes that script's output: every quoted
line must be a line of a full run of the script."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"```text\n\$ python (examples/[\w.-]+\.py)\n(.*?)```", re.S)


def _quoted() -> list[tuple[Path, str, list[str]]]:
    out = []
    for doc in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
        for script, body in BLOCK.findall(doc.read_text(encoding="utf-8")):
            out.append((doc, script, [x for x in body.splitlines() if x.strip()]))
    return out


QUOTED = _quoted()


def test_the_docs_quote_at_least_one_run():
    assert QUOTED


@pytest.mark.parametrize("doc,script,lines", QUOTED, ids=lambda v: getattr(v, "name", ""))
def test_quoted_output_is_what_the_script_prints(doc, script, lines, tmp_path):
    env = {**os.environ, "GRIPSENSE_EXAMPLES_OUT": str(tmp_path)}
    env.pop("GRIPSENSE_EXAMPLES_QUICK", None)
    r = subprocess.run(
        [sys.executable, str(ROOT / script)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    printed = {x.strip() for x in r.stdout.splitlines()}
    for line in lines:
        assert line.strip() in printed, f"{doc.name} quotes {line!r}; {script} no longer prints it"
