"""Data flows one way (docs/architecture.md): every ``import gripsense.…`` in the package —
module level or inside a function — goes to the same or a lower layer, io and physics never
import each other, estimators never import outputs, and no package imports one that imports it."""

from __future__ import annotations

import ast
from pathlib import Path

import gripsense

ROOT = Path(gripsense.__file__).parent

# layer of each top-level part of the package (lower = closer to the data)
LAYERS = {
    "_version": 0,
    "_arrays": 0,
    "constants": 0,
    "errors": 0,
    "data": 0,
    "io": 1,
    "physics": 1,
    "config": 2,
    "estimate": 3,
    "identify": 3,
    "sim": 3,
    "vision": 3,
    "tyre_models": 4,
    "pipeline": 4,
    "report": 5,
    "live": 5,
    "fleet": 5,
    "demo": 6,
    "cli": 7,
    "__init__": 8,
}
# pairs in one layer that must not know each other
FORBIDDEN = {("io", "physics"), ("physics", "io"), ("estimate", "report"), ("estimate", "sim")}


def _part(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _imports() -> list[tuple[str, str, int]]:
    """(importing module, imported gripsense module, line) for every import in the package."""
    out = []
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        mod = ".".join(rel.parts)
        if mod.endswith(".__init__"):
            mod = mod[: -len(".__init__")]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            for name in names:
                if name == "gripsense" or name.startswith("gripsense."):
                    out.append((mod, name, node.lineno))
    return out


IMPORTS = _imports()


def test_every_part_has_a_layer():
    parts = {_part(m) for m, _, _ in IMPORTS} | {_part(t) for _, t, _ in IMPORTS}
    assert parts <= set(LAYERS), sorted(parts - set(LAYERS))
    assert len(IMPORTS) > 200


def test_imports_go_downwards_only():
    bad = []
    for mod, target, line in IMPORTS:
        a, b = _part(mod), _part(target)
        if a == b:
            continue
        if LAYERS[b] > LAYERS[a] or (a, b) in FORBIDDEN:
            bad.append(f"{mod}:{line} imports {target} ({a}: layer {LAYERS[a]} → {b}: {LAYERS[b]})")
    assert not bad, "\n".join(bad)


def test_no_package_level_cycles():
    edges: dict[str, set[str]] = {}
    for mod, target, _ in IMPORTS:
        a, b = _part(mod), _part(target)
        if a != b:
            edges.setdefault(a, set()).add(b)

    def reaches(src: str, dst: str, seen: set[str]) -> bool:
        for n in edges.get(src, ()):
            if n == dst or (n not in seen and reaches(n, dst, seen | {n})):
                return True
        return False

    cycles = sorted(f"{a} ⇄ {b}" for a, bs in edges.items() for b in bs if reaches(b, a, {b}))
    assert not cycles, cycles


def _estimator_branches() -> list[str]:
    """Comparisons of ``method`` (a name or attribute) with an estimator's name."""
    from gripsense.estimate import ESTIMATORS

    names = set(ESTIMATORS)
    out = []
    for path in ROOT.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Compare):
                continue
            sides = [node.left, *node.comparators]
            lits = [
                e
                for s in sides
                for e in (s.elts if isinstance(s, ast.Tuple | ast.List | ast.Set) else [s])
            ]
            named = any(
                (isinstance(s, ast.Name) and s.id == "method")
                or (isinstance(s, ast.Attribute) and s.attr == "method")
                for s in sides
            )
            if named and any(isinstance(e, ast.Constant) and e.value in names for e in lits):
                out.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return out


def test_no_consumer_branches_on_an_estimator_name():
    """What a consumer needs comes from the estimator object (``gripsense.estimate.
    ESTIMATORS``: per_window, online(), needs_receiver, description), never from its name."""
    assert not _estimator_branches()
