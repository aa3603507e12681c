"""What the design's time was cut with computes what it computed before, bit for bit.

* the per-pose Functions over N poses in chunks (model.fastcall.Columns, design.calls): the numbers of one
  call of the Function on all the poses, for every N and every mechanism, interpreted and compiled;
* the feasibility check's terms of the feasible poses (design.feasible): those pose_terms gives;
* the exchange's and the checked polish's bound (a lower bound of the objective, the trials it rules out
  not evaluated): the same choice as with every trial evaluated.

The reference designs (tests/test_design_reference.py) hold the whole of it to the designs before.
"""
import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.design import calls as dcalls
from zerocal_sym.design.constraints import _pointwise_ok
from zerocal_sym.design.feasible import _pointwise
from zerocal_sym.design.exchange import _trials
from zerocal_sym.design.terms import TERM_NAMES, pose_terms, pose_terms_fn
from zerocal_sym.model import compiled
from zerocal_sym.model.fastcall import LARGEST_CHUNK, SMALLEST_CHUNK, Columns
from zerocal_sym.model.robot import load_robot, paper_robot

from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _robots():
    return [paper_robot(), load_robot(EXAMPLES / "delta.toml"), load_robot(EXAMPLES / "linear_delta.toml")]


def _poses(robot, N, rng, region=None):
    """N poses in and around the region (default the workspace; some unreachable: their terms are NaN,
    compared as such)."""
    ws = region or design.make_constraints(robot).region
    lo, hi = np.asarray(ws.lo, float), np.asarray(ws.hi, float)
    return lo - 0.2 * (hi - lo) + rng.random((N, len(lo))) * 1.4 * (hi - lo)


@pytest.mark.parametrize("N", [1, 5, SMALLEST_CHUNK, 9, 100, 137, LARGEST_CHUNK - 1, LARGEST_CHUNK + 3, 2500])
def test_columns_equal_one_call_on_every_column(N):
    """Columns (chunks of powers of two, the last padded) returns a plain call's numbers for any N."""
    robot = paper_robot()
    f = pose_terms_fn(robot)
    P = _poses(robot, N, np.random.default_rng(N))
    got = Columns(f, (True, False))(P.T, robot.geometry)
    want = [o.full() for o in f.call([P.T, robot.geometry])]
    for g, w in zip(got, want):
        assert g.shape == w.shape
        assert np.array_equal(g, w, equal_nan=True)


@pytest.mark.parametrize("robot", _robots(), ids=lambda r: r.mechanism_name)
def test_pose_terms_and_kinematics_are_the_plain_calls(robot):
    """design.terms.pose_terms, design.calls.ik and fk: the Functions' own numbers, laid out as before (each
    (K, r) array column-major, which decides the order of a sum along its rows)."""
    rng = np.random.default_rng(3)
    P = _poses(robot, 300, rng)
    t = pose_terms(robot, P)
    out = pose_terms_fn(robot).call([P.T, robot.geometry])
    for name, o in zip(TERM_NAMES, out):
        want = o.full().T.reshape(len(P), -1)
        got = t[name] if name != "rho" else t[name][:, None]
        assert np.array_equal(got, want, equal_nan=True), name
        if name != "rho":
            assert got.flags.f_contiguous
    th, ratio = dcalls.ik(robot, P)
    w_th, w_ratio = robot.mechanism["ik"].call([P.T, robot.geometry])
    assert np.array_equal(th, w_th.full().T, equal_nan=True) and np.array_equal(ratio, w_ratio.full().T,
                                                                                  equal_nan=True)
    from zerocal_sym.model import kinematics as kin

    ok = np.all(np.isfinite(th), axis=1)
    assert np.array_equal(dcalls.fk(robot, th[ok]), kin.fk(robot, th[ok]), equal_nan=True)
    # the terms with the forward kinematics of their joints, in one Function: the same numbers as both apart
    fused = dcalls.calls(robot)("design_pose_terms_fk", P.T, robot.geometry)
    for a, o in zip(fused[:-1], out):
        assert np.array_equal(a, o.full(), equal_nan=True)
    assert np.array_equal(fused[-1].T[ok], kin.fk(robot, th[ok]), equal_nan=True)


@pytest.mark.parametrize("region", ["workspace", "reachable"])
def test_pointwise_terms_are_those_of_the_feasible_poses(robot, region):
    """_pointwise: the feasibility of _pointwise_ok and, of the feasible poses, pose_terms's numbers and layout."""
    cons = design.make_constraints(robot) if region == "workspace" else design.make_constraints(
        robot, region="reachable", bounds=(-2000, 2000, 450, 2000))
    P = _poses(robot, 400, np.random.default_rng(5), cons.region)
    ok, t = _pointwise(robot, P, cons)
    assert 0 < ok.sum() < len(P)
    assert np.array_equal(ok, _pointwise_ok(robot, P, cons))
    want = pose_terms(robot, P[ok])
    for k, v in want.items():
        assert np.array_equal(t[k], v) and t[k].flags.f_contiguous == v.flags.f_contiguous, k


def _choice(o, cur):
    k = int(np.argmin(o))
    return (k, o[k]) if o[k] < cur - 1e-10 * max(abs(cur), 1.0) else None


def test_exchange_bound_makes_the_same_choice():
    """_trials with a lower bound (the trials it rules out left at inf): the exchange takes the same trial, or
    none, as with every trial evaluated -- with ties, bounds equal to the objective, infinite and NaN-free
    objectives, and an infinite current objective."""
    rng = np.random.default_rng(11)
    for case in range(3000):
        B = int(rng.integers(1, 60))
        full = np.round(rng.normal(size=B), int(rng.integers(0, 3)))  # rounding makes ties
        full[rng.random(B) < 0.1] = np.inf
        bound = full - np.where(rng.random(B) < 0.3, 0.0, rng.exponential(size=B))
        keep = rng.random(B) < 0.8
        cur = np.inf if case % 50 == 0 else float(rng.normal(0.5))
        trial = np.arange(B)[:, None]

        def fn(idx):
            return full[idx[:, 0]]

        fn_b = lambda idx: fn(idx)  # noqa: E731
        fn_b.lower = lambda idx: bound[idx[:, 0]]
        every = np.where(keep, full, np.inf)
        assert _choice(_trials(fn_b, trial, keep, cur), cur) == _choice(every, cur)
        assert np.array_equal(_trials(fn, trial, keep, cur), every)


def test_checked_lower_bound_is_its_crlb_objective(robot):
    """The checked objective's lower bound: evaluate_batch's crlb objective, the same numbers, never above the
    objective."""
    from zerocal_sym.design.checked import Objective
    from zerocal_sym.design.detection import Requirement, Terms
    from zerocal_sym.design.exchange import candidate_grid

    cons = design.make_constraints(robot)
    cand = candidate_grid(robot, cons)
    req = Requirement(robot, None)
    req.find_invisible(Terms(robot, cand, robot.noise))
    ob = Objective(robot, robot.noise, req)
    fn = ob(cand)
    rng = np.random.default_rng(2)
    idx = np.array([rng.choice(len(cand), 6, replace=False) for _ in range(200)])
    o, oc, _ = ob.of_terms(Terms(robot, cand, robot.noise).take(idx))
    lb = fn.lower(idx)
    assert np.array_equal(lb, oc)
    assert np.all(lb <= o)


@pytest.mark.slow
@pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler on this machine")
def test_compiled_design_calls_equal_the_interpreted(tmp_path, monkeypatch):
    """The design's Functions compiled (a cache of this test's own): the interpreted numbers, bit for bit, and
    the same design."""
    monkeypatch.setenv("ZEROCAL_CACHE", str(tmp_path / "cache"))
    robot = paper_robot()
    P = _poses(robot, 700, np.random.default_rng(9))
    monkeypatch.setenv("ZEROCAL_COMPILE", "never")
    interp = dcalls._Calls(robot.mechanism_name, tuple(robot.errors.resolve("paper")))
    d0 = design.optimize_design(robot, 6, "crlb", certificate=False).to_dict()
    monkeypatch.setenv("ZEROCAL_COMPILE", "always")
    comp = dcalls._Calls(robot.mechanism_name, tuple(robot.errors.resolve("paper")))
    assert comp.tier is not None and comp.tier.compiled, compiled.status()[-1:]
    for name in ("design_pose_terms", "ik"):
        for a, b in zip(interp(name, P.T, robot.geometry), comp(name, P.T, robot.geometry)):
            assert np.array_equal(a, b, equal_nan=True), name
    monkeypatch.setattr(dcalls, "_calls", lambda *a: comp)
    d1 = design.optimize_design(robot, 6, "crlb", certificate=False).to_dict()
    for d in (d0, d1):
        d.pop("timing_s")
        for k in ("exchange", "continuous"):
            d[k].pop("time_s", None)
            d[k].pop("build_s", None)
        for r in d["continuous"].get("runs", []):
            r.pop("time_s", None)
    assert d0 == d1
