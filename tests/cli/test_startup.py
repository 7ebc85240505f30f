"""A command line that starts at once (issue 45): ``gripsense --help``, ``gripsense COMMAND
--help`` and ``gripsense --version`` import none of the heavy libraries (numpy, pandas, numba,
scipy, matplotlib, dask, pydantic), every help page still lists every option of its command, no
help page cuts a word across lines, and ``--version`` names the installed version.

What is checked is *what is imported* (``python -X importtime`` of the console script), never
how long it took; the timing is ``benchmarks/startup.py``'s.
"""

from __future__ import annotations

import importlib.metadata
import os
import re
import subprocess
import sys

import pytest
import typer
from typer.testing import CliRunner

import gripsense
from gripsense.cli import app
from tests.cli.test_commands import EXE

HEAVY = {"numpy", "pandas", "numba", "scipy", "matplotlib", "dask", "distributed", "pydantic"}


def _commands(cmd, path=()):
    yield path, cmd
    for name, sub in getattr(cmd, "commands", {}).items():
        yield from _commands(sub, (*path, name))


COMMANDS = dict(_commands(typer.main.get_command(app)))
IDS = {p: " ".join(p) or "gripsense" for p in COMMANDS}


def _run_importtime(*args: str) -> tuple[subprocess.CompletedProcess, set[str]]:
    """Run the console script with ``-X importtime``: the result and the top-level packages
    it imported."""
    r = subprocess.run(
        [sys.executable, "-X", "importtime", EXE, *args],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "COLUMNS": "100"},
    )
    names = re.findall(r"^import time:\s*\d+ \|\s*\d+ \|\s*(\S+)$", r.stderr, flags=re.M)
    return r, {n.split(".")[0] for n in names}


def _options(cmd) -> list[str]:
    """What the help of *cmd* must name: every visible option's flags, every argument."""
    out = []
    for p in cmd.params:
        if getattr(p, "hidden", False):
            continue
        if p.param_type_name == "argument":
            out.append(p.name)
        else:
            out += [*p.opts, *p.secondary_opts]
    return out


@pytest.mark.parametrize("path", list(COMMANDS), ids=IDS.get)
def test_help_imports_no_heavy_library_and_lists_every_option(path):
    r, imported = _run_importtime(*path, "--help")
    assert r.returncode == 0, r.stderr[-2000:]
    assert imported, "no -X importtime report: the check would see nothing"
    assert "typer" in imported  # the report covers the command line's own imports
    assert not imported & HEAVY, sorted(imported & HEAVY)
    cmd = COMMANDS[path]
    words = set(re.findall(r"[^\s\[\]{}<>,]+", r.stdout))
    for name in _options(cmd):
        assert name in words, (IDS[path], name)
    for name, sub in getattr(cmd, "commands", {}).items():  # a group lists its commands
        if not sub.hidden:
            assert re.search(rf"^\s+{re.escape(name)}\s", r.stdout, flags=re.M), (IDS[path], name)


def test_version_is_the_installed_one_and_imports_nothing_heavy():
    r, imported = _run_importtime("--version")
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout == f"gripsense {importlib.metadata.version('gripsense')}\n"
    assert r.stdout == f"gripsense {gripsense.__version__}\n"
    assert not imported & HEAVY, sorted(imported & HEAVY)
    assert "--version" in _run_importtime("--help")[0].stdout


def test_a_bare_command_line_is_the_help_and_imports_nothing_heavy():
    r, imported = _run_importtime()
    assert r.returncode == 0 and r.stdout.startswith("Usage: gripsense"), r
    assert not imported & HEAVY, sorted(imported & HEAVY)


def _records(cmd, ctx) -> list[str]:
    """The unwrapped texts a help page wraps: its description and every parameter's line."""
    texts = [cmd.help or ""]
    for p in cmd.get_params(ctx):
        rec = p.get_help_record(ctx)
        if rec:
            texts += list(rec)
    return texts


@pytest.mark.parametrize("width", [60, 80, 100])
@pytest.mark.parametrize("path", list(COMMANDS), ids=IDS.get)
def test_help_never_cuts_a_word_across_lines(path, width):
    """Issue 45: ``friction --help`` printed 'steerin' / 'g_wheel', 'torqu' / 'e', and
    'friction-' / 'results]': every word of every help text (split at spaces, commas and '|',
    where a long mapping may break) is whole on one line of the page."""
    r = CliRunner().invoke(app, [*path, "--help"], terminal_width=width)
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    cmd = COMMANDS[path]
    with typer.main.get_command(app).make_context("gripsense", [], resilient_parsing=True) as c:
        ctx = cmd.make_context(IDS[path], [], parent=c, resilient_parsing=True) if path else c
        texts = _records(cmd, ctx)
    words = {w for t in texts for w in re.split(r"[\s,|]+", t) if w}
    assert words
    broken = [w for w in words if not any(w in line for line in lines)]
    assert not broken, (IDS[path], width, broken)


def test_the_help_defaults_are_the_readers_limits():
    """``ingest --max-lines/--max-bytes`` show the readers' limits without importing them."""
    from gripsense.cli import ingest
    from gripsense.io import text

    assert (ingest.MAX_LINES, ingest.MAX_BYTES) == (text.MAX_LINES, text.MAX_BYTES)
    params = {p.name: p.default for p in COMMANDS[("ingest",)].params}
    assert (params["max_lines"], params["max_bytes"]) == (text.MAX_LINES, text.MAX_BYTES)
