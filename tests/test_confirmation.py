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

from zerocal_sym.identify.estimate import nlls_solve  # noqa: E402

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


def _texts_agree(a, b, rtol=1e-2):
    """The same words (Ipopt's two successful ends as one), the numbers to ``rtol`` (a status prints 3-4 digits)."""
    if a is None or b is None:
        return a == b
    if _masked(a) != _masked(b):
        return False
    return all(float(y) == pytest.approx(float(x), rel=rtol, abs=1e-300)
               for x, y in zip(_NUMBER.findall(a), _NUMBER.findall(b)))


def _vectors_agree(a, b, rtol):
    x, y = np.array(a, float), np.array(b, float)
    fin = np.isfinite(x)
    if x.shape != y.shape or not np.array_equal(fin, np.isfinite(y)):
        return False
    scale = float(np.max(np.abs(x[fin]))) if fin.any() else 0.0
    return bool(np.all(np.abs(x[fin] - y[fin]) <= rtol * scale))


@pytest.mark.parametrize("cid", _ids())
def test_the_reference_set_is_unchanged(cid, monkeypatch):
    """Every case against the reference written while Ipopt solved every confirmation: on the library versions
    that wrote it, the same bits; on others (the oldest declared versions), the same success, the same status
    word for word but for Ipopt's choice between its two successful ends (its numbers to the digits it prints),
    the same rank and fit verdict, the estimate and covariance to the Gauss-Newton stopping tolerance relative
    to the condition of the problem."""
    new = _run(cid, "test", monkeypatch)
    ref = REFERENCE["cases"][cid]
    if SAME_VERSIONS:
        assert new == ref
        return
    # other builds (the oldest declared versions): the answers and the verdicts; the point is defined to the
    # Gauss-Newton tolerance (1e-8 mm in scaled units) and moves with the condition of the whitened Jacobian:
    # 1e-5 relative covers kappa up to 1e3 at points of 1 mm
    assert new["success"] == ref["success"]
    assert _texts_agree(ref["status"], new["status"]), (ref["status"], new["status"])
    assert _vectors_agree(ref["estimate"], new["estimate"], 1e-5)
    assert new["info"].get("rank") == ref["info"].get("rank")
    assert new["fit"]["rejected"] == ref["fit"]["rejected"] and new["fit"]["checked"] == ref["fit"]["checked"]
    if ref["std_kind"] == "total":  # (a zero noise model's covariance is scaled by the round-off residuals)
        assert _vectors_agree(ref["covariance"], new["covariance"], 1e-5)


def test_the_test_is_ipopts_own():
    """At a converged point the test passes with a wide margin (the gradient far below Ipopt's tolerance) and
    Ipopt, asked, stops there after 0 iterations; a point one step short of convergence fails it, and Ipopt
    iterates."""
    from zerocal_sym.identify.estimate import nlls_problem
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
    from zerocal_sym.identify.estimate.nlls_solve import noise_terms

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
