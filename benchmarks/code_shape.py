"""The shape of the source tree, counted from its syntax (issue "The house, second pass").

Prints the counts a maintainer looks at before and after a restructuring:

* rooms (top-level parts of the package) and floors (their layers in
  ``tests/test_architecture.py``), imports that run back up, package-level circles;
* modules over 500 lines and functions over 100 lines;
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
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src" / "gripsense"
TESTS = HERE.parent / "tests"


def _modules(root: Path) -> dict[str, Path]:
    out = {}
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).with_suffix("")
        mod = ".".join(rel.parts)
        out[mod.removesuffix(".__init__")] = path
    return out


def _absolute(mod: str, path: Path, node: ast.ImportFrom) -> str:
    """The absolute module an ``ImportFrom`` names (relative imports resolved)."""
    if node.level == 0:
        return node.module or ""
    package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
    for _ in range(node.level - 1):
        package = package.rpartition(".")[0]
    return f"{package}.{node.module}" if node.module else package


def imports(root: Path = SRC) -> list[tuple[str, str, list[str], int]]:
    """(importing module, imported module, imported names, line) for every gripsense import."""
    out = []
    for mod, path in _modules(root).items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _absolute(mod, path, node)
                if target == "gripsense" or target.startswith("gripsense."):
                    out.append((mod, target, [a.name for a in node.names], node.lineno))
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name == "gripsense" or a.name.startswith("gripsense."):
                        out.append((mod, a.name, [], node.lineno))
    return out


def private_crossings(root: Path = SRC) -> list[str]:
    """Private names imported from another module, private modules from outside their package."""
    bad = []
    known = set(_modules(root))
    for mod, target, names, line in imports(root):
        parts = target.split(".")
        for i, part in enumerate(parts):
            if part.startswith("_") and not part.startswith("__"):
                owner = ".".join(parts[:i])
                if not (mod == owner or mod.startswith(owner + ".")):
                    bad.append(f"{mod}:{line} imports private module {target}")
                break
        for name in names:
            if not name.startswith("_") or name.startswith("__"):
                continue
            if f"{target}.{name}" in known:  # a private module of the target package
                if not (mod == target or mod.startswith(target + ".")):
                    bad.append(f"{mod}:{line} imports private module {target}.{name}")
            elif mod != target:
                bad.append(f"{mod}:{line} imports private name {name} from {target}")
    return bad


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


def _is_method_name(node: ast.AST) -> bool:
    return (isinstance(node, ast.Name) and node.id == "method") or (
        isinstance(node, ast.Attribute) and node.attr == "method"
    )


def _estimator_names() -> set[str]:
    from gripsense.estimate import ESTIMATORS

    return set(ESTIMATORS)


def method_branches(root: Path = SRC) -> list[str]:
    """Comparisons of ``method`` with an estimator's name (a string literal such as
    ``"axle-window"``)."""
    names = _estimator_names()
    out = []
    for mod, path in _modules(root).items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Compare):
                continue
            sides = [node.left, *node.comparators]
            literal = any(
                (isinstance(s, ast.Constant) and s.value in names)
                or (
                    isinstance(s, (ast.Tuple, ast.Set, ast.List))
                    and any(isinstance(e, ast.Constant) and e.value in names for e in s.elts)
                )
                for s in sides
            )
            if literal and any(_is_method_name(s) for s in sides):
                out.append(f"{mod}:{node.lineno}")
    return out


def rooms_and_floors() -> dict[str, object]:
    """Rooms, floors, back-up arrows and circles by the layers of the architecture test."""
    spec = importlib.util.spec_from_file_location("_arch", TESTS / "test_architecture.py")
    arch = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(arch)
    layers = arch.LAYERS
    edges: dict[str, set[str]] = {}
    back = []
    for mod, target, _, line in imports():
        a, b = arch._part(mod), arch._part(target)
        if a == b:
            continue
        edges.setdefault(a, set()).add(b)
        if layers[b] > layers[a] or (a, b) in arch.FORBIDDEN:
            back.append(f"{mod}:{line} → {target}")

    def reaches(src: str, dst: str, seen: set[str]) -> bool:
        return any(
            n == dst or (n not in seen and reaches(n, dst, seen | {n})) for n in edges.get(src, ())
        )

    circles = sorted({tuple(sorted((a, b))) for a in edges for b in edges[a] if reaches(b, a, {b})})
    rooms = [p for p in layers if not p.startswith("_") and p != "__init__"]
    return {
        "rooms": len(rooms),
        "floors": len(set(layers.values())),
        "back-up arrows": back,
        "circles": circles,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", action="store_true", help="name every offender")
    args = ap.parse_args(argv)
    shape = rooms_and_floors()
    modules, functions = long_units()
    branches = method_branches()
    private = private_crossings()
    rows = [
        ("rooms", shape["rooms"], []),
        ("floors", shape["floors"], []),
        ("imports back up", len(shape["back-up arrows"]), shape["back-up arrows"]),
        ("package circles", len(shape["circles"]), [" ⇄ ".join(c) for c in shape["circles"]]),
        ("modules > 500 lines", len(modules), [f"{n:5d} {m}" for n, m in modules]),
        ("functions > 100 lines", len(functions), [f"{n:5d} {f}" for n, f in functions]),
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
