"""Ipopt's verdict on a converged Gauss-Newton point, taken from its own first-order test (nlls_solve.ipopt_accepts)
instead of its solve: the same statuses, word for word, and the same answers, on a reference set of
identifications over both methods, every mechanism and every option (tests/confirmation_cases.py; written
while Ipopt solved every confirmation)."""
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import compare_cases  # noqa: E402
import confirmation_cases as cc  # noqa: E402

from zerocal_sym.identify import nlls_solve  # noqa: E402

REFERENCE = json.loads(cc.REFERENCE.read_text())
#: the library versions that wrote the reference: there, every number is the same bit for bit
SAME_VERSIONS = REFERENCE["versions"] == compare_cases.versions()
#: Ipopt's two successful ends: which one a point within ``acceptable_tol`` but short of ``tol`` gets depends on the
#: Ipopt version (tests/test_linear_cost.py), not on our code: on other versions they are compared as one
_IPOPT_SUCCESS = re.compile(r"Solved_To_Acceptable_Level|Solve_Succeeded")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?")
#: the hexapod's identifications take seconds each (its model is not expanded: docs/nonlinear.md)
SLOW = {c[0] for c in cc.CASES if c[1] == "hexapod" or c[0].endswith("-all")}


def _ids(pred=lambda c: True):
    return [pytest.param(c[0], marks=pytest.mark.slow) if c[0] in SLOW else c[0] for c in cc.CASES if pred(c)]


def _case(cid):
    return next(c for c in cc.CASES if c[0] == cid)


def _run(cid, confirm, monkeypatch):
    monkeypatch.setattr(nlls_solve, "CONFIRM", confirm)
    return json.loads(json.dumps(cc.run_case(_case(cid))))


@pytest.mark.parametrize("cid", _ids(lambda c: c[6] == "nlls"))
def test_the_first_order_test_gives_what_ipopt_gives(cid, monkeypatch):
    """Each identification with the confirmation by Ipopt's first-order test and by Ipopt's solve, in this process:
    the same result, bit for bit (status, estimate, covariance, fit check, Ipopt's status and iterations)."""
    by_test = _run(cid, "test", monkeypatch)
    by_ipopt = _run(cid, "ipopt", monkeypatch)
    assert by_test == by_ipopt


def _masked(text):
    return _NUMBER.sub("#", _IPOPT_SUCCESS.sub("<ipopt success>", text))


def _close(a, b, rtol, path=""):
    """Every number of ``b`` within ``rtol`` of ``a`` (relative to the largest entry of its vector), texts with
    their numbers to ``rtol`` and their words the same, the rest equal."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), path
        for k in a:
            _close(a[k], b[k], rtol, f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        if a and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in a) and \
                all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in b):
            x, y = np.array(a, float), np.array(b, float)
            scale = float(np.max(np.abs(x))) if x.size else 0.0
            assert np.max(np.abs(x - y)) <= rtol * scale, (path, a, b)
        else:
            for i, (x, y) in enumerate(zip(a, b)):
                _close(x, y, rtol, f"{path}[{i}]")
    elif isinstance(a, str):
        assert _masked(a) == _masked(b), (path, a, b)
        for x, y in zip(_NUMBER.findall(a), _NUMBER.findall(b)):
            assert float(y) == pytest.approx(float(x), rel=max(rtol, 1e-2), abs=1e-300), (path, a, b)
    elif isinstance(a, float) and isinstance(b, float):
        assert b == pytest.approx(a, rel=rtol, abs=rtol * 1e-300), (path, a, b)
    else:
        assert a == b, (path, a, b)


@pytest.mark.parametrize("cid", _ids())
def test_the_reference_set_is_unchanged(cid, monkeypatch):
    """Every case against the reference written while Ipopt solved every confirmation: on the library versions
    that wrote it, the same bits; on others (the oldest declared versions), the same statuses word for word
    but for Ipopt's choice between its two successful ends, and the same numbers to the Gauss-Newton stopping
    tolerance relative to the condition of the problem (the numbers a status prints to their three digits)."""
    new = _run(cid, "test", monkeypatch)
    ref = REFERENCE["cases"][cid]
    if SAME_VERSIONS:
        assert new == ref
        return
    assert new["success"] == ref["success"]
    # the point is defined to the Gauss-Newton tolerance (1e-8 mm in scaled units) and what is computed there
    # moves with the condition of the whitened Jacobian; 1e-5 relative covers kappa up to 1e3 at points of 1 mm
    _close(ref, new, 1e-5, cid)


def test_the_test_is_ipopts_own():
    """At a converged point the test passes with a wide margin (the gradient far below Ipopt's tolerance) and
    Ipopt, asked, stops there after 0 iterations; a point one step short of convergence fails it, and Ipopt
    iterates."""
    from zerocal_sym.identify import nlls_problem
    from zerocal_sym.identify.nlls import identify_nlls

    case = _case("planar-default")
    robot = cc.robot_of(case[1])
    truth = cc.truth_of(robot, case[4])
    meas = cc.measurements(robot, case[2], case[3], truth, case[5])
    noise = cc.keywords(robot, truth, {})["noise"]
    res = identify_nlls(robot, meas, noise=noise)
    assert res.info["confirmation"] == "first-order test" and res.info["iterations"] == 0
    K = meas.theta_cmd.shape[0]
    prob = nlls_problem.get_problem(robot, K, "paper")
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.nlls import noise_terms

    names = robot.errors.resolve("paper")
    scale = fisher.parameter_scale(robot, names)
    par = prob.pack(meas.theta_cmd, robot.geometry, robot.errors.zeros(), meas.readings[1:], scale,
                    np.zeros(len(names)), np.zeros((len(names), len(names))), *noise_terms(noise))
    z = res.estimate * scale
    l, b = (np.array(o) for o in prob.fast["weights"](z, par))
    r, rp, J, _ = (np.array(o) for o in prob.fast["residuals"](z, par, l, b))
    assert nlls_solve.ipopt_accepts(J, r.ravel(), rp.ravel(), K)
    z_off = z + 1e-3  # a micrometre away: Ipopt iterates, and so does the test say
    r2, rp2, J2, _ = (np.array(o) for o in prob.fast["residuals"](z_off, par, l, b))
    assert not nlls_solve.ipopt_accepts(J2, r2.ravel(), rp2.ravel(), K)
    c = 1.0 / float(np.vdot(J[: K - 1], J[: K - 1]))
    solver = prob.solver_for(None)
    for zz, iterates in ((z, False), (z_off, True)):
        out = solver(zz, np.concatenate([par, l, b, [c]]), np.full(len(z), -np.inf), np.full(len(z), np.inf))[0]
        st = solver.stats()
        assert (st["iter_count"] > 0) == iterates and st["return_status"] == "Solve_Succeeded"
        assert np.array_equal(out, zz) != iterates
