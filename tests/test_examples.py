"""The examples gallery (examples/, docs/examples.md), run in its reduced form.

Each example is a script in percent format and the same as a notebook (``make examples``
regenerates the notebooks). Here: the notebook's code cells equal the script's (they cannot
drift), the notebook's cells are executed in order (reduced: ``GRIPSENSE_EXAMPLES_QUICK=1``),
every figure it writes is a non-blank image, every number that reproduces a source table is
within the printed digits of the source's value (``REPRODUCED``: ours, source, tolerance), and
every stated finding holds (``CHECKS``). docs/examples.md shows every figure the gallery makes.
"""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib.image as mpimg
import matplotlib.pyplot as plt
import numpy as np
import pytest

pytestmark = pytest.mark.slow  # end to end: `make test-fast` skips it

jupytext = pytest.importorskip("jupytext")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def code_cells(nb) -> list[str]:
    return [c.source.strip() for c in nb.cells if c.cell_type == "code"]


def test_the_gallery_exists():
    assert len(EXAMPLES) >= 7
    text = (ROOT / "docs" / "examples.md").read_text(encoding="utf-8")
    for py in EXAMPLES:
        assert py.name in text, f"docs/examples.md does not show {py.name}"
    for png in re.findall(r"\((examples/[\w.-]+\.png)\)", text):
        assert (ROOT / "docs" / png).stat().st_size > 5_000, png


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_as_a_notebook(script, tmp_path, monkeypatch):
    ipynb = script.with_suffix(".ipynb")
    assert ipynb.exists(), f"{ipynb.name} missing: run `make examples`"
    nb = jupytext.read(ipynb)
    assert code_cells(nb) == code_cells(jupytext.read(script)), "notebook and script differ"
    monkeypatch.setenv("GRIPSENSE_EXAMPLES_OUT", str(tmp_path))
    monkeypatch.setenv("GRIPSENSE_EXAMPLES_QUICK", "1")
    ns: dict = {"__name__": "__main__"}
    for src in code_cells(nb):
        exec(compile(src, f"{ipynb.name}", "exec"), ns)
    plt.close("all")
    pngs = sorted(tmp_path.glob("*.png"))
    assert pngs, "the example wrote no figure"
    for png in pngs:
        img = mpimg.imread(png)
        assert img.shape[0] > 200 and float(np.std(img[..., :3])) > 0.02, f"{png.name} is blank"
        assert (ROOT / "docs" / "examples" / png.name).exists(), f"{png.name} not in docs/"
    for what, (ours, source, tol) in ns["REPRODUCED"].items():
        assert abs(ours - source) <= tol, f"{what}: ours {ours:.6g}, source {source}"
    for what, ok in ns.get("CHECKS", {}).items():
        assert ok, what
