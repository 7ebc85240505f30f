"""The shape of the source tree, counted from its syntax (issue "The house, second pass").

Prints the counts a maintainer looks at before and after a restructuring:

* rooms (top-level parts of the package) and floors (their layers in
  ``tests/test_architecture.py``), imports that run back up, package-level circles;
* the rooms of ``io`` (logs, tyres, sensors, output folder; the shared leaves beside them) and
  imports from one into another it may not use;
* modules over 500 lines and functions over 100 lines (in all, and of code: docstrings,
  comments and blank lines not counted);
* branches on an estimator's name (a comparison of ``method`` with one of
  :data:`gripsense.estimate.ESTIMATORS`' names);
* private names imported across modules (``from a.b import _c`` from another module, or a
  private module imported from outside its package).

Run ``python benchmarks/code_shape.py`` from the repository root; ``--list`` names every
offender.  Nothing here is timed; the figures are recorded in ``benchmarks/README.md``.
"""

from __future__ import annotations

import argparse
import ast
import importlib.util
import io
import sys
import tokenize
from pathlib import Path

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src" / "gripsense"
TESTS = HERE.parent / "tests"


def _modules(root: Path) -> dict[str, Path]:
    out = {}
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).with_suffix("")
        out[".".join(rel.parts).removesuffix(".__init__")] = path
    return out


def _architecture():
    """``tests/test_architecture.py``: the layers and the import walk the test checks."""
    spec = importlib.util.spec_from_file_location("_arch", TESTS / "test_architecture.py")
    arch = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(arch)
    return arch


def long_units(root: Path = SRC, module_lines: int = 500, function_lines: int = 100):
    """Modules over ``module_lines`` lines and functions over ``function_lines`` lines."""
    modules, functions = [], []
    for mod, path in _modules(root).items():
        text = path.read_text(encoding="utf-8")
        n = text.count("\n")
        if n > module_lines:
            modules.append((n, mod))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > function_lines:
                    functions.append((length, f"{mod}.{node.name}"))
    return sorted(modules, reverse=True), sorted(functions, reverse=True)


def _code_lines(text: str, tree: ast.AST) -> set[int]:
    """Line numbers that hold code: a token that is not a comment, and not a docstring."""
    docs: set[int] = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            v = body[0].value
            if isinstance(v, ast.Constant) and isinstance(v.value, str):
                docs.update(range(body[0].lineno, body[0].end_lineno + 1))
    lines: set[int] = set()
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT}
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type not in skip and tok.type != tokenize.ENDMARKER:
            lines.update(range(tok.start[0], tok.end[0] + 1))
    return lines - docs


def long_code(root: Path = SRC, function_lines: int = 100):
    """Functions over ``function_lines`` lines of code (docstrings, comments and blank lines
    not counted)."""
    out = []
    for mod, path in _modules(root).items():
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        code = _code_lines(text, tree)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = len(code & set(range(node.lineno, node.end_lineno + 1)))
                if n > function_lines:
                    out.append((n, f"{mod}.{node.name}"))
    return sorted(out, reverse=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", action="store_true", help="name every offender")
    args = ap.parse_args(argv)
    arch = _architecture()
    modules, functions = long_units()
    code = long_code()
    branches = arch.estimator_branches()
    private = arch.private_crossings()
    back, circles = arch.upward_imports(), arch.package_cycles()
    rooms = [p for p in arch.LAYERS if not p.startswith("_") and p != "__init__"]
    io_rooms = sorted(set(arch.IO_MAY_USE) - arch.IO_LEAVES)
    crossings = arch.io_room_crossings()
    rows = [
        ("rooms", len(rooms), []),
        (
            "rooms of io (+ shared leaves)",
            f"{len(io_rooms)} (+ {len(arch.IO_LEAVES)})",
            [*io_rooms, *(f"{leaf} (shared leaf)" for leaf in sorted(arch.IO_LEAVES))],
        ),
        ("io room crossings", len(crossings), crossings),
        ("floors", len(set(arch.LAYERS.values())), []),
        ("imports back up", len(back), back),
        ("package circles", len(circles), circles),
        ("modules > 500 lines", len(modules), [f"{n:5d} {m}" for n, m in modules]),
        ("functions > 100 lines", len(functions), [f"{n:5d} {f}" for n, f in functions]),
        ("functions > 100 lines of code", len(code), [f"{n:5d} {f}" for n, f in code]),
        ("branches on a method name", len(branches), branches),
        ("private names across modules", len(private), private),
    ]
    for name, count, items in rows:
        print(f"{name:32s} {count}")
        if args.list:
            for item in items:
                print(f"    {item}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
