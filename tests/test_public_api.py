"""The public API is documented: every public function, class and method named in a
subpackage's ``__all__`` has a docstring whose numpydoc Parameters (or, for dataclasses,
Attributes) section names every parameter of its signature — the check python-control runs
(``control/tests/docstrings_test.py``), written here for numpydoc."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re

import pytest

PACKAGES = [
    "gripsense",
    "gripsense.config",
    "gripsense.io",
    "gripsense.physics",
    "gripsense.estimate",
    "gripsense.identify",
    "gripsense.sim",
    "gripsense.vision",
    "gripsense.report",
    "gripsense.live",
    "gripsense.fleet",
]

_HEADER = re.compile(r"^\s*(\w[\w ]*)\n\s*-{3,}\s*$", re.M)
_NAME = re.compile(r"^(\s*)(\*{0,2}\w+(?:\s*,\s*\*{0,2}\w+)*)\s*(?::|$)")


def _section(doc: str, title: str) -> set[str]:
    """Names documented in a numpydoc section (``a, b : type`` lines at the section's indent)."""
    doc = inspect.cleandoc(doc)
    heads = [(m.start(), m.end(), m.group(1).strip()) for m in _HEADER.finditer(doc)]
    names: set[str] = set()
    for i, (_, end, name) in enumerate(heads):
        if name != title:
            continue
        stop = heads[i + 1][0] if i + 1 < len(heads) else len(doc)
        body = doc[end:stop].strip("\n").splitlines()
        base = None
        for line in body:
            if not line.strip():
                continue
            indent = len(line) - len(line.lstrip())
            base = indent if base is None else base
            if indent == base:
                m = _NAME.match(line)
                if m:
                    names.update(n.strip().lstrip("*") for n in m.group(2).split(","))
    return names


_SEE = re.compile(r"Parameters as :(?:func|meth):`~?([\w.]+)`")


def _inherited(obj, doc: str) -> set[str]:
    """``Parameters as :func:`other``` documents the parameters by reference."""
    m = _SEE.search(doc)
    if not m:
        return set()
    mod = importlib.import_module(obj.__module__)
    target = mod
    for part in m.group(1).split("."):
        target = getattr(target, part, None)
        if target is None:
            return set()
    return _section(inspect.getdoc(target) or "", "Parameters")


def _params(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in sig.parameters.values()
        if p.name not in ("self", "cls") and not p.name.startswith("_")
    ]


def _public_callables():
    seen = set()
    for pkg in PACKAGES:
        mod = importlib.import_module(pkg)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith("gripsense"):
                continue
            key = f"{obj.__module__}.{obj.__qualname__}"
            if key in seen:
                continue
            seen.add(key)
            yield key, obj
            if inspect.isclass(obj):
                for mname, member in vars(obj).items():
                    if mname.startswith("_"):
                        continue
                    fn = (
                        member.__func__
                        if isinstance(member, classmethod | staticmethod)
                        else member
                    )
                    if inspect.isfunction(fn):
                        yield f"{key}.{mname}", fn


CALLABLES = sorted(_public_callables())


def test_the_walk_finds_the_api():
    names = {k for k, _ in CALLABLES}
    assert len(names) > 150
    assert "gripsense.pipeline.FrictionRun.run_log" in names
    assert "gripsense.physics.brush.invert" in names


@pytest.mark.parametrize("name,obj", CALLABLES, ids=[k for k, _ in CALLABLES])
def test_public_parameters_are_documented(name, obj):
    doc = inspect.getdoc(obj)
    assert doc, f"{name}: no docstring"
    if inspect.isclass(obj):
        target = obj.__init__ if "__init__" in vars(obj) else obj
        params = _params(target)
        documented = set()
        for base in obj.__mro__:  # attributes documented on a gripsense base class count
            if base.__module__.startswith("gripsense") and base.__doc__:
                documented |= _section(base.__doc__, "Parameters")
                documented |= _section(base.__doc__, "Attributes")
        if dataclasses.is_dataclass(obj):
            # dataclass fields: documented under Attributes (or Parameters)
            params = [f.name for f in dataclasses.fields(obj) if f.init and not f.name[0] == "_"]
    else:
        params = _params(obj)
        documented = _section(doc, "Parameters") | _inherited(obj, doc)
        if not params:
            return
    missing = [p for p in params if p not in documented]
    assert not missing, f"{name}: parameters not documented: {missing}"
