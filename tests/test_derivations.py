"""The sympy derivations: paper forms, generated code against sympy, staleness."""
import subprocess
import sys

import numpy as np
import pytest

sp = pytest.importorskip("sympy")

from derivations import codegen, planar_2dof  # noqa: E402
from zerocal_sym.generated import planar_2dof as gen  # noqa: E402


@pytest.fixture(scope="module")
def mech():
    return planar_2dof.build()


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


def test_generated_functions_match_sympy(mech):
    funcs = gen.build_functions()
    rng = np.random.default_rng(7)
    g0 = np.array([80, 0, -80, 0, 375, 375, 825, 825, 0, 79, 0, 51.0])
    for fname, spec in mech.outputs.items():
        syms = [s for _, ss in spec["inputs"] for s in ss]
        exprs = [m for _, m in spec["outputs"]]
        lam = sp.lambdify(syms, exprs, "numpy")
        for _ in range(5):
            g = g0 + rng.normal(0, 0.5, 12)
            P = np.array([rng.uniform(-240, 240), rng.uniform(632, 782)])
            th = np.array([rng.uniform(-0.4, 0.6), rng.uniform(2.4, 3.7)])
            vals = {"P": P, "theta": th, "theta_cmd": th, "g": g, "err": rng.normal(0, 1e-3, 12)}
            args = [vals[n] for n, _ in spec["inputs"]]
            want = lam(*np.concatenate(args))
            got = funcs[fname](*args)
            got = got if isinstance(got, tuple) else (got,)
            for w, o in zip(want, got):
                np.testing.assert_allclose(o.full(), np.asarray(w, float).reshape(o.shape), rtol=1e-10, atol=1e-10,
                                           err_msg=fname)


def test_committed_code_is_fresh():
    assert codegen.regen(check=True) == [], "generated code is stale: run `zerocal regen`"


def test_regen_check_cli_passes_then_fails_after_hand_edit(tmp_path):
    out = tmp_path / "gen"
    out.mkdir()
    committed = codegen.GENERATED_DIR / "planar_2dof.py"
    (out / "planar_2dof.py").write_text(committed.read_text())
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "regen", "--check", "--out-dir", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "up to date" in r.stdout
    f = out / "planar_2dof.py"
    f.write_text(f.read_text().replace("ca.acos(", "ca.asin(", 1))
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "regen", "--check", "--out-dir", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 1
    assert "stale" in r.stderr


def test_generated_header():
    text = (codegen.GENERATED_DIR / "planar_2dof.py").read_text()
    head = text[:600]
    assert "DO NOT EDIT" in head
    assert "derivations/planar_2dof.py" in head
    assert f"sympy: {sp.__version__}" in head
    assert "inputs hash: " in head
