"""The sympy derivations: the paper's forms, staleness of the committed code, its header.

(Generated code against sympy, for every mechanism: tests/test_contract.py.)  The derivation is done once per
test process (the ``derived`` and ``generated`` fixtures of tests/conftest.py): it takes seconds.
"""
from pathlib import Path

import numpy as np
import pytest

sp = pytest.importorskip("sympy")

from derivations import codegen  # noqa: E402
from derivations.mechanisms import planar_2dof  # noqa: E402
from zerocal_sym.cli import main  # noqa: E402


@pytest.fixture(scope="module")
def mech(derived):
    return derived["planar_2dof"]


@pytest.fixture
def fresh_generate(monkeypatch, generated):
    """``codegen.generate`` answering with this process's fresh derivation (``generated``), for any directory."""
    def generate(out_dir=None, check_forms=True, derived=None):
        out = Path(out_dir) if out_dir else codegen.GENERATED_DIR
        return {out / path.name: text for path, text in generated.items()}

    monkeypatch.setattr(codegen, "generate", generate)


def test_reduces_to_paper_forms(mech):
    planar_2dof.check_paper_forms(mech)


def test_paper_form_check_can_fail(mech):
    """The symbolic check is not vacuous: a wrong J' is caught."""
    m = planar_2dof.build()
    name, J = m.outputs["error_jacobian"]["outputs"][0]
    J = J.copy()
    J[0, 1] = 2 * J[0, 1]
    m.outputs["error_jacobian"]["outputs"][0] = (name, J)
    with pytest.raises(AssertionError, match="error_jacobian"):
        planar_2dof.check_paper_forms(m)


def test_committed_code_is_fresh(fresh_generate):
    assert codegen.regen(check=True) == [], "generated code is stale: run `zerocal regen`"


def test_regen_check_cli_passes_then_fails_after_hand_edit(tmp_path, capsys, fresh_generate):
    """One ``regen --check`` over a copy where one file is hand-edited: that one stale, the other up to date.

    (A clean copy passing is test_committed_code_is_fresh; both compare with the same fresh derivation.)
    """
    out = tmp_path / "gen"
    out.mkdir()
    for name in codegen.MECHANISMS:
        committed = codegen.GENERATED_DIR / f"{name}.py"
        (out / f"{name}.py").write_text(committed.read_text())
    f = out / "planar_2dof.py"
    f.write_text(f.read_text().replace("ca.acos(", "ca.asin(", 1))
    rc = main(["regen", "--check", "--out-dir", str(out)])
    err = capsys.readouterr().err
    assert rc == 1
    stale = [ln for ln in err.splitlines() if ln.startswith("stale: ")]
    assert stale == [f"stale: {f}"], err
    assert "generated code is stale" in err
    assert len(codegen.MECHANISMS) >= 2  # so the other mechanism's unedited copy was checked and passed


@pytest.mark.parametrize("name", list(codegen.MECHANISMS))
def test_generated_header(name):
    text = (codegen.GENERATED_DIR / f"{name}.py").read_text()
    head = text[:600]
    assert "DO NOT EDIT" in head
    assert f"derivations/mechanisms/{name}.py" in head and "derivations/mechanism.py" in head
    assert f"sympy: {sp.__version__}" in head
    assert "inputs hash: " in head
    # where the contract suite finds the derivation (derivations.external.derivation_of)
    assert f"\nDERIVATION = 'derivations.mechanisms.{name}'\n" in text
