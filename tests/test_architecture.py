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
    "_signals": 0,
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


def _absolute(mod: str, is_package: bool, node: ast.ImportFrom) -> str:
    """The module an ``ImportFrom`` names, relative imports resolved."""
    if node.level == 0:
        return node.module or ""
    package = mod if is_package else mod.rpartition(".")[0]
    for _ in range(node.level - 1):
        package = package.rpartition(".")[0]
    return f"{package}.{node.module}" if node.module else package


def _walk() -> list[tuple[str, str, list[str], int]]:
    """(importing module, imported gripsense module, names imported from it, line) for every
    import in the package — module level or inside a function, absolute or relative."""
    out = []
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        mod = ".".join(rel.parts).removesuffix(".__init__")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _absolute(mod, path.name == "__init__.py", node)
                found = [(target, [a.name for a in node.names])]
            elif isinstance(node, ast.Import):
                found = [(a.name, []) for a in node.names]
            else:
                continue
            for name, names in found:
                if name == "gripsense" or name.startswith("gripsense."):
                    out.append((mod, name, names, node.lineno))
    return out


WALK = _walk()
IMPORTS = [(m, t, line) for m, t, _, line in WALK]
MODULES = {
    ".".join(p.relative_to(ROOT.parent).with_suffix("").parts).removesuffix(".__init__")
    for p in ROOT.rglob("*.py")
}


def test_every_part_has_a_layer():
    parts = {_part(m) for m, _, _ in IMPORTS} | {_part(t) for _, t, _ in IMPORTS}
    assert parts <= set(LAYERS), sorted(parts - set(LAYERS))
    assert len(IMPORTS) > 200


def upward_imports() -> list[str]:
    """Imports that run up a layer or between parts that must not know each other."""
    bad = []
    for mod, target, line in IMPORTS:
        a, b = _part(mod), _part(target)
        if a == b:
            continue
        if LAYERS[b] > LAYERS[a] or (a, b) in FORBIDDEN:
            bad.append(f"{mod}:{line} imports {target} ({a}: layer {LAYERS[a]} → {b}: {LAYERS[b]})")
    return bad


def test_imports_go_downwards_only():
    bad = upward_imports()
    assert not bad, "\n".join(bad)


def _cycles(edges: dict[str, set[str]]) -> list[str]:
    def reaches(src: str, dst: str, seen: set[str]) -> bool:
        for n in edges.get(src, ()):
            if n == dst or (n not in seen and reaches(n, dst, seen | {n})):
                return True
        return False

    return sorted({" ⇄ ".join(sorted((a, b))) for a, bs in edges.items() for b in bs
                   if reaches(b, a, {b})})  # fmt: skip


def package_cycles() -> list[str]:
    """Circles between the top-level parts."""
    edges: dict[str, set[str]] = {}
    for mod, target, _ in IMPORTS:
        a, b = _part(mod), _part(target)
        if a != b:
            edges.setdefault(a, set()).add(b)
    return _cycles(edges)


def test_no_package_level_cycles():
    assert not package_cycles()


def estimator_branches() -> list[str]:
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
    assert not estimator_branches()


def private_crossings() -> list[str]:
    """Private names imported from another module; private modules from outside their package."""
    bad = []
    for mod, target, names, line in WALK:
        parts = target.split(".")
        for i, part in enumerate(parts):
            if part.startswith("_") and not part.startswith("__"):
                owner = ".".join(parts[:i])
                if not (mod == owner or mod.startswith(owner + ".")):
                    bad.append(f"{mod}:{line} imports the private module {target}")
                break
        for name in names:
            if not name.startswith("_") or name.startswith("__"):
                continue
            if f"{target}.{name}" in MODULES:  # a private module of the target package
                if not (mod == target or mod.startswith(target + ".")):
                    bad.append(f"{mod}:{line} imports the private module {target}.{name}")
            elif mod != target:
                bad.append(f"{mod}:{line} imports the private name {name} from {target}")
    return bad


def test_no_private_name_crosses_a_module():
    """``_name`` is the module's own; a private module (``_solve``, ``_axle_kernel``) is its
    package's own. Anything shared is public where it lives."""
    bad = private_crossings()
    assert not bad, "\n".join(bad)


def test_no_cycles_between_the_modules_of_a_subpackage():
    """Within a part (``estimate``, ``io.nmea`` …) the module-level imports form no circle: each
    module can be read after the ones it imports."""
    edges: dict[str, set[str]] = {}
    for path in ROOT.rglob("*.py"):
        mod = ".".join(path.relative_to(ROOT.parent).with_suffix("").parts).removesuffix(
            ".__init__"
        )
        if path.name == "__init__.py":
            continue  # a package's __init__ gathers its modules by design
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:  # module level only: imports inside functions run later
            if isinstance(node, ast.ImportFrom):
                t = _absolute(mod, False, node)
                targets = [f"{t}.{a.name}" if f"{t}.{a.name}" in MODULES else t for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            for t in targets:
                if t in MODULES and t != mod and _part(t) == _part(mod):
                    edges.setdefault(mod, set()).add(t)

    assert not _cycles(edges)


# the rooms of io (docs/architecture.md): a log never reads a tyre file or a sensor table's
# code and the other way round; all of them may use the shared leaves at io's top
IO_ROOMS = {"logs", "tyres", "sensors", "output_folder"}
IO_LEAVES = {"text", "table"}  # bounded reading; the one column convention
IO_MAY_USE = {
    "logs": IO_LEAVES | {"output_folder"},  # novatel's writer: the atomic write
    "tyres": IO_LEAVES,
    "sensors": IO_LEAVES,
    "output_folder": IO_LEAVES,
    "text": set(),
    "table": {"text"},
}


def _io_room(module: str) -> str | None:
    """The room of io a module belongs to (``gripsense.io.logs.nmea.reader`` -> ``logs``)."""
    parts = module.split(".")
    if len(parts) < 3 or parts[:2] != ["gripsense", "io"]:
        return None
    return parts[2]


def io_room_crossings() -> list[str]:
    """Imports (module level or in a function) from one room of io into a room it may not use."""
    bad = []
    for mod, target, line in IMPORTS:
        a, b = _io_room(mod), _io_room(target)
        if a is not None and target == "gripsense.io":  # the package gathers every room
            bad.append(f"{mod}:{line} imports gripsense.io (io room {a} → all of io)")
        if a is None or b is None or a == b:
            continue
        if b not in IO_MAY_USE.get(a, set()):
            bad.append(f"{mod}:{line} imports {target} (io room {a} → {b})")
    return bad


def test_every_io_module_is_in_a_room():
    rooms = {_io_room(m) for m in MODULES} - {None}
    assert rooms == set(IO_MAY_USE), sorted(rooms ^ set(IO_MAY_USE))


def test_the_rooms_of_io_import_only_the_shared_leaves():
    """Logs, tyres and sensors do not import each other; they share ``io.text`` and ``io.table``,
    which import no room (a log writer may also use the output folder's atomic write)."""
    bad = io_room_crossings()
    assert not bad, "\n".join(bad)


def test_no_cycles_between_the_rooms_of_io():
    edges: dict[str, set[str]] = {}
    for mod, target, _ in IMPORTS:
        a, b = _io_room(mod), _io_room(target)
        if a is not None and b is not None and a != b:
            edges.setdefault(a, set()).add(b)
    assert edges.get("logs"), "the walk sees io's rooms"
    assert not _cycles(edges)
