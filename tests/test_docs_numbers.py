"""Numbers in the docs that a program prints are produced by that program (issues "What a
newcomer trips on" and 45: docs/examples.md had drifted from what the examples print, and
``make examples`` changed the tracked figures).

Every example script is run once, in full, into a temporary folder (the runs are shared by the
tests below; about a minute on two cores) and then:

* a fenced block in a doc that starts with ``$ python examples/NAME.py`` quotes that script's
  output: every quoted line must be a line of the run;
* every section of docs/examples.md that shows a script quotes its run in such a block;
* every decimal number in a section's text is one the run prints or one the script states
  (a source's printed value, a parameter), to the digits the text gives;
* every figure the run writes is the figure docs/examples/ tracks (``make examples`` would not
  change it);
* the run leaves nothing in the temporary-files folder.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"```text\n\$ python (examples/[\w.-]+\.py)\n(.*?)```", re.S)
EXAMPLES_MD = ROOT / "docs" / "examples.md"
SCRIPTS = sorted((ROOT / "examples").glob("*.py"))
NUMBER = re.compile(r"(?<![\w.])[-−]?(?:\d+\.\d+(?:e[-+]?\d+)?|\d{3,})(?![\w.]*\d)")
"""A decimal number (1.5, 4.05e+07) or a whole one of three digits or more (2613 kg)."""
REFERENCE = re.compile(
    r"(?:§|\bFigs?\.?|\bTables?|\beqs?\.)\s*\d+(?:\.\d+)?(?:\s*(?:[–,/→]|and)\s*\d+(?:\.\d+)?)*"
)
"""A reference to a section, figure, table or equation of a source (§15.9, Figs 4.2/4.5)."""


def _quoted() -> list[tuple[Path, str, list[str]]]:
    out = []
    for doc in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
        for script, body in BLOCK.findall(doc.read_text(encoding="utf-8")):
            out.append((doc, script, [x for x in body.splitlines() if x.strip()]))
    return out


def _sections() -> list[tuple[str, str]]:
    """(script name, the section's text) of every docs/examples.md section that shows one."""
    text = EXAMPLES_MD.read_text(encoding="utf-8")
    out = []
    for part in re.split(r"\n(?=### )", text)[1:]:
        head = part.splitlines()[0]
        m = re.search(r"`([\w.-]+\.py)`", head)
        if m:
            out.append((m.group(1), part))
    return out


QUOTED = _quoted()
SECTIONS = _sections()


@pytest.fixture(scope="module")
def run_example(tmp_path_factory):
    """``run_example(script)``: the full run of *script*, once per test module (the file's
    tests stay on one worker: ``make test`` distributes by file)."""
    cache: dict[str, tuple[str, Path, list[str]]] = {}

    def get(script: str) -> tuple[str, Path, list[str]]:
        if script not in cache:
            cache[script] = _run(script, tmp_path_factory.mktemp(Path(script).stem))
        return cache[script]

    return get


def _run(script: str, base: Path) -> tuple[str, Path, list[str]]:
    """A full run of *script* in *base*: its output, its figure folder and what it left in its
    temporary-files folder."""
    out, tmp = base / "out", base / "tmp"
    out.mkdir()
    tmp.mkdir()
    env = {**os.environ, "GRIPSENSE_EXAMPLES_OUT": str(out), "TMPDIR": str(tmp)}
    env.pop("GRIPSENSE_EXAMPLES_QUICK", None)
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples" / script)],
        capture_output=True,
        text=True,
        cwd=base,
        env=env,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout, out, sorted(p.name for p in tmp.iterdir())


def _value(token: str) -> float:
    return float(token.replace("−", "-"))


def _matches(token: str, printed: list[float]) -> bool:
    """Whether a number written with the digits of *token* is one of *printed* rounded."""
    mant = token.split("e")[0]
    digits = len(mant.split(".")[1]) if "." in mant else 0
    scale = 10.0 ** int(token.split("e")[1]) if "e" in token else 1.0
    half = 0.5 * 10.0**-digits * scale * (1 + 1e-9)
    v = _value(token)
    return any(abs(abs(p) - abs(v)) <= half for p in printed)


def test_the_docs_quote_at_least_one_run():
    assert QUOTED


def test_every_example_has_its_section():
    assert {s for s, _ in SECTIONS} == {p.name for p in SCRIPTS}


@pytest.mark.parametrize("doc,script,lines", QUOTED, ids=lambda v: getattr(v, "name", ""))
def test_quoted_output_is_what_the_script_prints(doc, script, lines, run_example):
    stdout, _, _ = run_example(Path(script).name)
    printed = {x.strip() for x in stdout.splitlines()}
    for line in lines:
        assert line.strip() in printed, f"{doc.name} quotes {line!r}; {script} no longer prints it"


@pytest.mark.parametrize("script,text", SECTIONS, ids=[s for s, _ in SECTIONS])
def test_every_section_quotes_its_run(script, text):
    assert f"$ python examples/{script}" in text, (
        f"docs/examples.md: the section of {script} quotes no run of it (```text block)"
    )


@pytest.mark.parametrize("script,text", SECTIONS, ids=[s for s, _ in SECTIONS])
def test_numbers_in_the_text_are_printed_or_stated_by_the_script(script, text, run_example):
    stdout, _, _ = run_example(script)
    source = (ROOT / "examples" / script).read_text(encoding="utf-8")
    printed = [_value(t) for t in NUMBER.findall(stdout + "\n" + source)]
    prose = re.sub(r"```.*?```", "", text, flags=re.S)  # blocks: checked line by line above
    prose = re.sub(r"!\[[^]]*\]\([^)]*\)", "", prose)  # figure file names
    prose = REFERENCE.sub("", prose)
    prose = re.sub(r"(?m)^#.*$", "", prose)  # headings (seed numbers)
    wrong = [t for t in NUMBER.findall(prose) if not _matches(t, printed)]
    assert not wrong, f"docs/examples.md, {script}: {wrong} are neither printed nor stated"


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.stem)
def test_figures_are_the_tracked_ones_and_nothing_is_left_behind(script, run_example):
    _, out, left = run_example(script.name)
    assert not left, f"{script.name} left {left} in the temporary-files folder"
    for png in sorted(out.glob("*.png")):
        tracked = ROOT / "docs" / "examples" / png.name
        assert tracked.exists(), f"{png.name}: not in docs/examples/ (run `make examples`)"
        a, b = mpimg.imread(png)[..., :3], mpimg.imread(tracked)[..., :3]
        assert a.shape == b.shape, f"{png.name}: another size than the tracked figure"
        d = np.abs(a - b)
        rms, changed = float(np.sqrt(np.mean(d**2))), float(np.mean(d.max(axis=-1) > 0.1))
        assert rms < 0.005 and changed < 1e-4, (
            f"docs/examples/{png.name} is not what {script.name} draws (rms {rms:.4f}, "
            f"{changed:.2%} of pixels): run `make examples` and commit the figures"
        )


def test_every_quoted_run_in_the_docs_is_checked():
    """A fenced block that quotes a run (``$ …``) is one of the blocks checked above: a quoted
    command whose output nothing checks would drift again."""
    for doc in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
        text = doc.read_text(encoding="utf-8")
        runs = re.findall(r"```\w*\n\$ ", text)
        checked = BLOCK.findall(text)
        assert len(runs) == len(checked), f"{doc.name} quotes a run no test checks"
