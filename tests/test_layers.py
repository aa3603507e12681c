"""The flow of the package, checked on its imports: model -> identify -> design -> paper -> cli,
io and report beside them; a mechanism's particulars only in its generated module."""
import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "zerocal_sym"
#: layer -> the layers it may import (itself included)
ALLOWED = {
    "model": {"model", "generated", "errors"},
    "identify": {"identify", "model", "errors"},
    "design": {"design", "identify", "model", "errors", "io"},
    "io": {"io", "model", "errors"},
    "report": {"report", "identify", "model", "io", "errors"},
    "paper": {"paper", "design", "identify", "model", "io", "report", "errors"},
    "cli": {"cli", "paper", "design", "identify", "model", "io", "report", "errors", "generated"},
}


def _imports(path: Path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("zerocal_sym"):
            parts = node.module.split(".")
            if len(parts) == 1:  # from zerocal_sym import x
                yield from ((a.name, node.lineno) for a in node.names)
            else:
                yield parts[1], node.lineno
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("zerocal_sym."):
                    yield a.name.split(".")[1], node.lineno


MODULES = sorted(p for layer in ALLOWED for p in (PKG / layer).rglob("*.py"))


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PKG)))
def test_imports_go_one_way(path):
    layer = path.relative_to(PKG).parts[0]
    bad = [(target, line) for target, line in _imports(path) if target not in ALLOWED[layer]
           and target not in ("__version__",)]
    assert not bad, f"{path.relative_to(PKG)} imports {bad} (a {layer} module may import {sorted(ALLOWED[layer])})"


def test_no_branch_on_a_mechanism_name():
    offenders = []
    for path in PKG.rglob("*.py"):
        if "generated" in path.parts:
            continue
        for i, line in enumerate(path.read_text().splitlines(), 1):
            if "mechanism_name ==" in line or "mechanism_name !=" in line or 'mechanism == "' in line:
                offenders.append(f"{path.relative_to(PKG)}:{i}")
    assert not offenders, offenders


# ---- inside identify: the stages, in order (estimate -> check -> diagnose -> budget -> the drivers) ----

IDENTIFY = PKG / "identify"
#: the stages of identify, in the order they may import one another: a module may import its own stage and
#: those before it.  ``core``: the shared basics at identify's top level; ``driver``: every other top-level
#: module (the entry points that compose the stages: identify_nlls, identify_tsvd, the batch, the loop, ...)
STAGES = ("core", "estimate", "check", "diagnose", "budget", "driver")
#: the shared basics every stage uses (they import no stage)
CORE = {"banded", "chi2", "covariance", "fisher", "identifiability", "linear", "result", "whitened"}


def _module_name(path: Path) -> str:
    rel = path.relative_to(IDENTIFY).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


IDENTIFY_MODULES = {_module_name(p): p for p in sorted(IDENTIFY.rglob("*.py"))}


def _stage(module: str) -> str:
    head = module.split(".")[0]
    if head in STAGES:
        return head
    return "core" if module in CORE or module == "" else "driver"


def _identify_imports(path: Path):
    """``(module, line)`` of every module of identify that ``path`` imports, at module level or in a function.

    ``from zerocal_sym.identify.a import b`` names ``a.b`` when that is a module, else ``a``."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module != "zerocal_sym.identify" and not node.module.startswith("zerocal_sym.identify."):
                continue
            base = node.module[len("zerocal_sym.identify"):].lstrip(".")
            for a in node.names:
                sub = f"{base}.{a.name}" if base else a.name
                yield (sub if sub in IDENTIFY_MODULES else base), node.lineno
        elif isinstance(node, ast.ImportFrom) and node.level:
            raise AssertionError(f"{path}: a relative import (line {node.lineno}); import by the full name")
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("zerocal_sym.identify."):
                    yield a.name[len("zerocal_sym.identify."):], node.lineno


def _identify_graph() -> dict:
    return {m: {t for t, _ in _identify_imports(p) if t != m} for m, p in IDENTIFY_MODULES.items()}


def test_identify_stages_are_known():
    """Every subpackage of identify is a stage (a new one must be placed in the order)."""
    subpackages = {m.split(".")[0] for m in IDENTIFY_MODULES if "." in m}
    assert subpackages <= set(STAGES), sorted(subpackages - set(STAGES))
    assert CORE <= set(IDENTIFY_MODULES), sorted(CORE - set(IDENTIFY_MODULES))


def _later_imports(module: str, path: Path) -> list:
    """``(module, line)`` of what ``path`` (identify's ``module``) imports from a later stage."""
    own = STAGES.index(_stage(module))
    return [(t, line) for t, line in _identify_imports(path) if t in IDENTIFY_MODULES and STAGES.index(_stage(t)) > own]


@pytest.mark.parametrize("module", sorted(IDENTIFY_MODULES), ids=lambda m: m or "__init__")
def test_identify_stages_import_only_earlier_stages(module):
    """A module of identify imports modules of its own stage and of the stages before it, never a later one."""
    later = _later_imports(module, IDENTIFY_MODULES[module])
    assert not later, (f"identify/{module or '__init__'} (stage {_stage(module)}) imports a later stage: "
                       + ", ".join(f"{t} ({_stage(t)}, line {line})" for t, line in later))


def test_identify_imports_name_modules_that_exist():
    """Each import of an identify module names one (the graph below sees every edge)."""
    unknown = sorted({(m, t) for m, p in IDENTIFY_MODULES.items() for t, _ in _identify_imports(p)
                      if t not in IDENTIFY_MODULES})
    assert not unknown, unknown


def _cycles(graph: dict) -> list:
    """The strongly connected components of more than one module, and the modules that import themselves."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycle_in_identify():
    """No module of identify imports, directly or through others, one that imports it (function-level imports
    count: a cycle hidden in a function is still a cycle)."""
    assert not _cycles(_identify_graph())


def test_the_checks_find_what_they_look_for(tmp_path):
    """The checks themselves: a later stage imported inside a function, a module imported from its package, a
    cycle."""
    src = tmp_path / "m.py"
    src.write_text("from zerocal_sym.identify import fisher\n"
                   "from zerocal_sym.identify.estimate import robust as rb\n\n\n"
                   "def f():\n    from zerocal_sym.identify.diagnose.causes import _diagnose\n")
    assert sorted(_identify_imports(src)) == [("diagnose.causes", 6), ("estimate.robust", 2), ("fisher", 1)]
    assert _later_imports("check.statistics", src) == [("diagnose.causes", 6)]
    assert _later_imports("fisher", src) == [("estimate.robust", 2), ("diagnose.causes", 6)]
    assert _later_imports("budget.bias", src) == [] and _later_imports("nlls", src) == []
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []
