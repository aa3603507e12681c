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
