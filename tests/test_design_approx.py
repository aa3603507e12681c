"""Approximate designs with certificates, reachable regions, bias-aware and position criteria.

No timing asserts (benchmarks/bench_design.py prints the times).
"""
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.cli import main
from zerocal_sym.design import DesignError, approx, criteria, fewest, measure, posemodel, rounding
from zerocal_sym.design import nlp as design_nlp
from zerocal_sym.identify.budget import bias
from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.design.terms import Weights
from zerocal_sym.model.noise import NoiseModel
from roundoff import cond_tol

NOISE = NoiseModel.paper()
DELTA_FILE = Path(__file__).resolve().parents[1] / "examples" / "delta.toml"


@pytest.fixture(scope="module")
def delta():
    from zerocal_sym.model.robot import load_robot

    return load_robot(DELTA_FILE)


@pytest.fixture(scope="module")
def ws_cons(robot):
    return design.make_constraints(robot)


@pytest.fixture(scope="module")
def crlb_measure(robot, ws_cons):
    return approx.approximate_design(robot, "crlb", ws_cons, NOISE)


@pytest.fixture(scope="module")
def reach450(robot):
    """The reachable set of the paper's robot with y >= 450 mm (default margin, l0 = 350 mm)."""
    return design.make_constraints(robot, region="reachable", bounds=(-np.inf, np.inf, 450, np.inf))


def _model(robot, criterion, X):
    return posemodel.PoseModel(robot, X, NOISE, criterion)


def _extended_objective_tol(robot, P, criterion, tolerances):
    """Absolute round-off bound of the ``position`` / ``mse`` log-objective at the design ``P``, first order.

    ``x = sum_ij W_ij [F^-1]_ji`` (position) or ``sum_j w_j ([F^-1]_jj + |b_j|^2)``, ``b = F^-1 H`` (mse; ``F``
    the (p, p) information, ``H`` the cross information with the omitted errors).  A backward-stable inverse errs
    by at most ``e = cond(F) EPS |F^-1|_2`` per entry (tests/roundoff.py); ``b_j`` inherits ``e |H|_F`` (for the
    worst-case model ``sqrt(r)`` times that), large against ``|b_j|`` since the bias is a near-cancellation
    (``|F^-1| |H| / |b|`` is ~1e5 at these designs); ``|b_j|^2`` moves by ``2 |b_j|`` times it, and
    ``d log x = dx / x``.  Two algorithms evaluate it (CasADi's symbolic inverse, numpy's LAPACK), each within
    the bound: a factor 2.
    """
    wt = Weights(robot, tolerances)
    aq, v, ao = criteria._terms_batch(robot, P, NOISE, omitted=True)
    F = criteria._fisher(wt.extend(aq, ao), v, criteria._noise_terms(NOISE)[0])[0]
    p = wt.p
    Fi, H = np.linalg.inv(F[:p, :p]), F[:p, p:]
    e = cond_tol(np.linalg.cond(F[:p, :p]), 1) * np.linalg.norm(Fi, 2)
    if criterion == "position":
        x = np.sum(wt.position * Fi.T)
        dx = e * np.sum(np.abs(wt.position))
    else:
        B = Fi @ H
        b = np.sum(np.abs(B), axis=1) if wt.bias_model == "worst" else np.linalg.norm(B, axis=1)
        db = e * np.linalg.norm(H) * (np.sqrt(wt.r) if wt.bias_model == "worst" else 1.0)
        x = (np.diag(Fi) + b ** 2) @ wt.crlb
        dx = (e + 2 * b * db + db ** 2) @ wt.crlb
    return 2 * dx / x


# ----------------------------------------------------------------- the pose model and its derivatives
@pytest.mark.parametrize("criterion", ["D", "crlb", "E"])
def test_fgh_matches_finite_differences(criterion):
    rng = np.random.default_rng(0)
    R = rng.normal(size=(9, 5))
    W = np.diag([1.0, 2.0, 0.0, 0.0])
    w = rng.uniform(size=9)
    w /= w.sum()
    f, g, H = measure._fgh(criterion, R, W, 8, w, 1.0)
    e = 1e-6
    E = np.eye(9)
    gn = np.array([(measure._fgh(criterion, R, W, 8, w + e * E[i], 1.0)[0]
                    - measure._fgh(criterion, R, W, 8, w - e * E[i], 1.0)[0]) / (2 * e) for i in range(9)])
    Hn = np.array([(measure._fgh(criterion, R, W, 8, w + e * E[i], 1.0)[1]
                    - measure._fgh(criterion, R, W, 8, w - e * E[i], 1.0)[1]) / (2 * e) for i in range(9)])
    np.testing.assert_allclose(g, gn, rtol=1e-6, atol=1e-8 * np.abs(g).max())
    np.testing.assert_allclose(H, Hn, rtol=1e-5, atol=1e-7 * np.abs(H).max())


def test_pose_model_bounds_every_order(robot):
    """F(ordered design) <= K M(xi) (Loewner) for random designs and orders, with the full noise model."""
    rng = np.random.default_rng(1)
    sm2, sx2 = criteria._noise_terms(NOISE)
    cons = design.make_constraints(robot)
    for K in (6, 9, 15):
        P = design_nlp._random_start(robot, K, cons, rng)
        for perm in (np.arange(K), rng.permutation(K)):
            Q = P[perm]
            aq, v = criteria._terms_batch(robot, Q, NOISE)
            F = criteria._fisher_batch(aq, v, sm2)[0]
            m = _model(robot, "D", Q)
            M, _ = posemodel._schur(*posemodel._stats(np.full(K, 1.0) / m.vt, m.aq))
            assert np.linalg.eigvalsh(M - F).min() >= -1e-9 * np.linalg.eigvalsh(M).max()


# ----------------------------------------------------------------- the equivalence-theorem certificate
@pytest.mark.parametrize("criterion", ["D", "A", "crlb", "position", "E"])
def test_no_candidate_improves_the_optimal_measure(robot, ws_cons, criterion):
    """At the optimal measure the directional derivative towards any candidate is within the tolerance.

    D: max_x d(x) <= p (1 + tol); linear criteria: max_x d(x) <= L (1 + tol); E: the E-certificate
    (lambda_min against the best trace-one E) within 1 %.
    """
    X, _ = approx.candidate_poses(robot, ws_cons, 600)
    m = _model(robot, criterion, X)
    tol = 1e-5
    sol = measure.solve_measure(m, criterion, tol=tol)
    if criterion == "E":
        assert sol["eff_lb"] >= 0.99
        return
    s, d = sol["s"], sol["d"]
    assert np.max(d) <= s * (1 + 1.5 * tol)
    assert sol["eff_lb"] >= 1 - 1.5 * tol
    # the one-point directions: moving a little weight to the best candidate does not improve the loss
    k = int(np.argmax(d))
    for a in (1e-3, 1e-2):
        w = (1 - a) * sol["w"]
        w[k] += a
        M, c = posemodel._schur(*posemodel._stats(w / m.vt, m.aq))
        loss = posemodel._crit(criterion, M, m.W)[0]
        assert loss >= sol["loss"] - a * tol * (p := M.shape[0]) - 1e-12


def _exact_optimum(criterion, m):
    """The optimal measure on a few candidates by an independent solver (SLSQP, tight), its loss."""
    from scipy.optimize import minimize

    N = len(m.vt)

    def loss(w):
        M, _ = posemodel._schur(*posemodel._stats(np.maximum(w, 0) / m.vt, m.aq))
        val = posemodel._crit(criterion, M, m.W)[0]
        return val if math.isfinite(val) else 1e6

    best = None
    rng = np.random.default_rng(0)
    for _ in range(6):
        w0 = rng.dirichlet(np.ones(N))
        r = minimize(loss, w0, method="SLSQP", bounds=[(0, 1)] * N,
                     constraints=[{"type": "eq", "fun": lambda w: w.sum() - 1}],
                     options={"ftol": 1e-15, "maxiter": 2000})
        if best is None or r.fun < best:
            best = r.fun
    return best


@pytest.mark.parametrize("criterion", ["D", "crlb", "A"])
def test_certificate_bounds_the_true_gap_small_case(robot, criterion):
    """Brute force on 7 candidate poses: the bound on the efficiency holds at suboptimal measures."""
    X = np.array([[-240, 632], [240, 632], [-240, 782], [240, 782], [0, 632], [0, 782], [120, 700.0]])
    m = _model(robot, criterion, X)
    best = _exact_optimum(criterion, m)
    p = m.aq.shape[1]
    rng = np.random.default_rng(3)
    for trial in range(8):
        w = rng.dirichlet(np.ones(len(X)) * (0.5 if trial % 2 else 3.0))
        M, c = posemodel._schur(*posemodel._stats(w / m.vt, m.aq))
        loss, G, s = posemodel._crit(criterion, M, m.W)
        d = posemodel._sens(G, m.aq, c, m.vt)
        if criterion == "D":
            true_eff = math.exp((best - loss) / p)  # (det M / det M*)^(1/p)
        else:
            true_eff = math.exp(best - loss)  # L* / L
        bound = s / d.max()
        assert true_eff >= bound * (1 - 1e-9), (trial, true_eff, bound)
        assert true_eff <= 1 + 1e-7
    # and our solver reaches the brute-force optimum
    sol = measure.solve_measure(m, criterion, tol=1e-9)
    assert sol["loss"] == pytest.approx(best, abs=1e-7)


def test_relaxation_bounds_every_ordered_design_brute_force(robot):
    """Every ordered 6-pose design on 5 candidates (5^6 sequences, repeats allowed): exact CRLB >= the bound."""
    X = np.array([[-240, 632], [240, 632], [-240, 782], [240, 782.0], [0, 632]])
    cons = design.make_constraints(robot)
    m = _model(robot, "crlb", X)
    sol = measure.solve_measure(m, "crlb", tol=1e-9)
    bound_loss = approx._loss_bound("crlb", sol)
    K = 6
    bound_deg = approx._mass_value("crlb", bound_loss, K, 4)
    seqs = np.array(list(itertools.product(range(5), repeat=K)))
    sm2, sx2 = criteria._noise_terms(NOISE)
    t = design.pose_terms(robot, X)
    aq = t["a"] * design.terms._qscale(robot)
    v = sx2 * np.sum(t["dth"] ** 2, axis=1)
    o = criteria._objective_batch("crlb", aq[seqs], v[seqs], sm2, design.terms._crlb_weights(robot))
    best = criteria._user_value("crlb", float(np.min(o)))
    print(f"best ordered 6-pose design on 5 candidates: CRLB {best:.5f} deg, bound {bound_deg:.5f} deg")
    assert best >= bound_deg * (1 - 1e-9)
    assert best <= bound_deg * 1.5  # the bound is not vacuous
    assert cons  # (the constraints are those of the workspace)


# ----------------------------------------------------------------- rounding, replicates, order
def test_efficient_rounding():
    w = np.array([0.2937, 0.2937, 0.2049, 0.2049, 0.0014, 0.0014])
    for K in (6, 7, 20, 100, 701):
        n = rounding.efficient_rounding(w, K)
        assert n.sum() == K and np.all(n >= 0)
        assert np.all(np.abs(n - K * w) <= len(w))
    np.testing.assert_array_equal(rounding.efficient_rounding(np.array([0.5, 0.5]), 4), [2, 2])


def test_realized_design_is_feasible_and_certified(robot, ws_cons, crlb_measure):
    K = 60
    P, info = rounding.realize(robot, crlb_measure, K, ws_cons, NOISE)
    assert P.shape == (K, 2) and sum(info["counts"]) == K
    assert design.check_design(robot, P, ws_cons) == []
    v = design.criterion_values(robot, P, NOISE)["crlb"]
    assert crlb_measure.bound(K) <= v  # the bound holds for the realised, ordered design
    eff = crlb_measure.efficiency(v, K)
    print(f"K = {K}: CRLB {v:.4f} deg, bound {crlb_measure.bound(K):.4f} deg, efficiency >= {eff:.3f}")
    assert 0.8 < eff <= 1


def test_optimize_design_auto_switches_to_approx(robot, ws_cons):
    res = design.optimize_design(robot, 30, "crlb", ws_cons, NOISE)
    d = res.to_dict()
    assert d["method"].startswith("approximate") and d["violations"] == []
    assert d["certificate"]["efficiency_lower_bound"] > 0.8
    assert d["crlb_rms_deg"] < d["paper"]["crlb_rms_deg"]
    with pytest.raises(DesignError, match="not concave"):
        design.optimize_design(robot, 30, "cond", ws_cons, NOISE, method="approx")
    with pytest.raises(DesignError, match="exact method"):
        design.optimize_design(robot, 150, "crlb", ws_cons, NOISE, method="exact")


def test_exact_path_reports_certificate(robot, ws_cons):
    """The K = 6 crlb design (0.4415 deg) against the bound of any 6-pose design on the candidates."""
    res = design.optimize_design(robot, 6, "crlb", ws_cons, NOISE, seed=0, n_starts=3, exchange_starts=3)
    c = res.certificate
    assert c["bound"] <= res.report["crlb_rms_deg"] and 0.85 < c["efficiency_lower_bound"] <= 1
    assert design.optimize_design(robot, 6, "cond", ws_cons, NOISE, n_starts=1, exchange_starts=1).certificate is None


# ----------------------------------------------------------------- fewest poses for a target CRLB
def test_fewest_poses_for_target(robot, ws_cons, crlb_measure):
    out = fewest.fewest_poses(robot, 0.2, ws_cons, NOISE, ad=crlb_measure)
    K, lb = out["K"], out["K_lower_bound"]
    assert lb <= K and out["crlb_rms_deg"] <= 0.2
    # certified: the bound at K_lb - 1 poses is above the target
    assert crlb_measure.bound(lb - 1) > 0.2 >= crlb_measure.bound(lb)
    ev = out["evaluated"]
    assert all(v > 0.2 for k, v in ev.items() if k < K)
    assert design.check_design(robot, out["poses"], ws_cons) == []
    with pytest.raises(DesignError, match="positive"):
        fewest.fewest_poses(robot, -1, ws_cons, NOISE, ad=crlb_measure)


def test_cli_target_crlb_json(capsys):
    rc = main(["design", "--target-crlb", "0.15", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["K"] >= d["K_lower_bound"] and d["crlb_rms_deg"] <= 0.15
    assert len(d["poses"]) == d["K"] and d["violations"] == []
    assert main(["design", "--target-crlb", "0.15", "--K", "8"]) == 2
    assert "--K" in capsys.readouterr().err


# ----------------------------------------------------------------- regions
def test_reachable_region(robot, reach450):
    reg = reach450.region
    assert reg.kind == "reachable" and reg.lo[1] == 450
    X = reg.grid(400)
    ok = design.constraints._pointwise_ok(robot, X, reach450)
    th = kin.ik(robot, X[ok])
    np.testing.assert_allclose(kin.fk(robot, th), X[ok], atol=1e-6)  # one assembly mode
    assert np.min(kin.transmission(robot, X[ok]) * np.asarray(reach450.mode_signs)) >= 0.2 - 1e-9
    assert X[ok][:, 0].min() < -900 and X[ok][:, 0].max() > 900  # far beyond the workspace rectangle


def test_reachable_k6_design_and_baseline(robot, reach450):
    """Benchmark case (bench_design.py prints it): K = 6, reachable set with y >= 450 mm, l0 = 350 mm."""
    res = design.optimize_design(robot, 6, "crlb", reach450, NOISE, seed=0, n_starts=3, exchange_starts=3)
    d = res.to_dict()
    print(f"reachable y >= 450: CRLB {d['crlb_rms_deg']:.5f} deg, bound {d['certificate']['bound']:.5f}")
    assert d["violations"] == [] and np.ptp(kin.measuring_vector(robot, res.poses)[0]) <= 350 + 1e-6
    assert d["crlb_rms_deg"] < 0.05 * d["paper"]["crlb_rms_deg"]
    assert d["baseline_scheme"] == "paper scheme on the workspace" and d["paper"]["violations"] == []
    assert design.check_design(robot, np.array(d["paper"]["poses"]), reach450) == []


def test_certificate_is_not_above_a_denser_candidate_set(robot, reach450):
    """The certificate holds beyond its grid: for the K = 6 design of the reachable set (y >= 450 mm), the
    efficiency it certifies (with the local maxima of the sensitivity over the region) is not above what a
    grid of four times the candidates alone gives the same design -- up to the search's tolerance.  The grid
    alone (the certificate before the search) is above it."""
    from zerocal_sym.design import certify

    res = design.optimize_design(robot, 6, "crlb", reach450, NOISE, seed=0, n_starts=2, exchange_starts=2)
    v, cert = res.report["crlb_rms_deg"], res.certificate
    dense = approx.approximate_design(robot, "crlb", reach450, NOISE, n_candidates=6000, search=False)
    grid = approx.approximate_design(robot, "crlb", reach450, NOISE, search=False)
    print(f"efficiency >= {cert['efficiency_lower_bound']:.4f} certified; {dense.efficiency(v, 6):.4f} on "
          f"{dense.n_candidates} grid poses; {grid.efficiency(v, 6):.4f} (bound {grid.bound(6):.5f} deg) on the "
          f"{grid.n_candidates} of the grid alone")
    assert cert["efficiency_lower_bound"] <= dense.efficiency(v, 6) * (1 + certify.REGION_TOL)
    assert grid.efficiency(v, 6) > dense.efficiency(v, 6)  # what the search corrects
    assert cert["certificate"] == f"over {cert['n_candidates']} candidates" and cert["region_search"]["added"] > 0
    assert "the design's 6 poses" in cert["candidates"]


def test_baseline_never_singular_or_infeasible(robot):
    """A region whose edges are singular: the rule on them is rejected, the workspace scheme taken."""
    cons = design.make_constraints(robot, region="reachable", bounds=(-700, 700, 450, 800))
    P, label, note, rejected = design.optimize.choose_baseline(robot, 6, cons)
    assert label == "paper scheme on the workspace" and note is None
    cons = design.make_constraints(robot, region=(-240, 240, 632, 782), travel_mm=100)
    P, label, note, rejected = design.optimize.choose_baseline(robot, 6, cons)
    assert P is None and "scale travel" in note and rejected


@pytest.mark.parametrize("poly", [
    [(-300, 600), (300, 600), (300, 850), (-300, 850)],                       # convex
    [(-300, 600), (300, 600), (300, 850), (0, 700), (-300, 850)],             # non-convex (a notch)
])
def test_polygon_region(robot, poly):
    cons = design.make_constraints(robot, region=["polygon"] + [c for xy in poly for c in xy])
    pg = cons.region.clip
    res = design.optimize_design(robot, 6, "crlb", cons, NOISE, seed=0, n_starts=2, exchange_starts=2)
    assert np.all(pg.contains(res.poses, 1e-6)) and design.check_design(robot, res.poses, cons) == []
    if not pg.convex:
        assert not np.any(pg.contains(np.array([[0, 800.0]]), 0.0))  # the notch is outside


@pytest.mark.parametrize("kwargs, match", [
    (dict(region="reachable", bounds=(1, 2, 3)), "needs 4 numbers"),
    (dict(region="reachable", bounds=(0, -10, 450, 900)), "MIN < MAX"),
    (dict(region=["polygon", 0, 0, 1, 1]), "at least 3 vertices"),
    (dict(region=["polygon", 0, 0, 100, 100, 100, 0, 0, 100]), "cross"),
    (dict(region="sideways"), "unknown region"),
    (dict(region=(-240, 240, 632, 782), bounds=(0, 1, 2, 3)), "--bounds"),
    (dict(region="reachable", bounds=(-10, 10, 5000, 5100)), "no reachable pose"),
])
def test_bad_regions(robot, kwargs, match):
    with pytest.raises(DesignError, match=match):
        design.make_constraints(robot, **kwargs)


def test_cli_reachable_and_polygon(capsys):
    rc = main(["design", "--optimize", "--K", "6", "--starts", "1", "--region", "reachable",
               "--bounds", "open", "open", "450", "open", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["constraints"]["region_kind"] == "reachable" and d["violations"] == []
    rc = main(["design", "--optimize", "--K", "6", "--starts", "1", "--criterion", "crlb", "--region", "polygon",
               "-200", "640", "200", "640", "0", "780"])
    out = capsys.readouterr().out
    assert rc == 0 and "polygon" in out and "certificate" in out
    assert main(["design", "--optimize", "--region", "reachable", "--bounds", "a", "b", "1", "2"]) == 2
    assert "--bounds" in capsys.readouterr().err


# ----------------------------------------------------------------- bias and the mse criterion
def test_tolerance_bias_against_model_bias(robot):
    """Worst case = the largest |b| over the corners of the tolerance box; S e = fisher.model_bias."""
    P = design.paper_baseline(robot, 6)
    th = kin.ik(robot, P)
    tol = bias.default_tolerances(robot)
    S, names = bias.bias_sensitivity(robot, th, "paper", NOISE)
    t = bias.tolerance_vector(robot, tol, names)
    corners = np.array(list(itertools.product((-1, 1), repeat=len(t)))) * t
    b = corners @ S.T  # (2^r, p)
    rep = bias.tolerance_bias(robot, th, tol, "paper", NOISE)
    np.testing.assert_allclose(np.degrees(np.max(np.abs(b[:, :2]), axis=0)), rep["zero_offsets"]["worst_case_deg"],
                               rtol=1e-10)
    err = robot.errors.vector(dict(zip(names, corners[5])))
    np.testing.assert_allclose(S @ corners[5], fisher.model_bias(robot, th, err, "paper", NOISE), rtol=1e-8,
                               atol=1e-14)
    rng = np.random.default_rng(0)
    draws = rng.uniform(-1, 1, size=(40000, len(t))) * t
    rms_mc = np.degrees(np.sqrt(np.mean((draws @ S.T) ** 2, axis=0)))[:2]
    np.testing.assert_allclose(rms_mc, rep["zero_offsets"]["rms_deg"], rtol=0.02)
    # the paper's robot carries the magnitudes of Table 2's set A as its tolerances
    from zerocal_sym.paper.tables import SET_A

    assert {k: abs(v) for k, v in SET_A.items()} == {k: v for k, v in robot.tolerances().items() if k in SET_A}
    assert set(tol) == set(SET_A)


def test_tolerances_from_items_and_file(robot, tmp_path):
    f = tmp_path / "tol.toml"
    f.write_text("L1 = 0.05\nl2 = 0.1\n")
    tol = bias.make_tolerances(robot, ["e1x=0.2"], f, scale=10)
    assert tol["e1x"] == pytest.approx(2.0) and tol["L1"] == pytest.approx(0.5) and tol["l2"] == pytest.approx(1.0)
    assert tol["e2y"] == pytest.approx(0.1)  # default 0.01 x 10
    for items, match in ((["theta1=1"], "identified"), (["foo=1"], "not a source error"), (["L1=-1"], ">= 0"),
                         (["L1"], "NAME=VALUE")):
        with pytest.raises(Exception, match=match):
            bias.make_tolerances(robot, items)


def test_mse_criterion_matches_bias_report(robot):
    P = design.paper_baseline(robot, 6)
    tol = bias.make_tolerances(robot, scale=10)
    rep = design.evaluate(robot, P, "mse", NOISE, tolerances=tol)
    # two routes to sqrt(x): half the log-objective's round-off, relative
    assert rep["criterion"]["values"]["mse"] == pytest.approx(rep["bias"]["rms_error_rms_deg"],
                                                              rel=_extended_objective_tol(robot, P, "mse", tol) / 2)


@pytest.mark.parametrize("criterion", ["mse", "position"])
def test_symbolic_objective_new_criteria(robot, ws_cons, criterion):
    rng = np.random.default_rng(5)
    P = design_nlp._random_start(robot, 7, ws_cons, rng)
    fs, ms = design_nlp._scales(robot, P, NOISE)
    tol = bias.make_tolerances(robot, scale=10)
    nlp = design_nlp._NLP(robot, 7, criterion, ws_cons, NOISE, fs, ms, tolerances=tol)
    f, _ = nlp.fg(nlp.x0(P))
    # two algorithms for one log-objective: at its round-off (relative 1.2e-8 of f for mse at this design)
    assert float(f) == pytest.approx(criteria._objective(robot, criterion, P, NOISE, tol) + np.log(fs), rel=0,
                                     abs=_extended_objective_tol(robot, P, criterion, tol))


def test_bias_aware_design_trades_crlb_for_bias(robot, reach450):
    """Ten times set A: the mse design has a larger CRLB and a smaller RMS error than the crlb design."""
    tol = bias.make_tolerances(robot, scale=10)
    kw = dict(seed=0, n_starts=2, exchange_starts=2, tolerances=tol, certificate=False)
    c = design.optimize_design(robot, 6, "crlb", reach450, NOISE, **kw).to_dict()
    m = design.optimize_design(robot, 6, "mse", reach450, NOISE, **kw).to_dict()
    print(f"crlb design: CRLB {c['crlb_rms_deg']:.5f}, RMS error {c['criterion']['values']['mse']:.5f}; "
          f"mse design: CRLB {m['crlb_rms_deg']:.5f}, RMS error {m['criterion']['values']['mse']:.5f} deg")
    assert m["criterion"]["values"]["mse"] < 0.8 * c["criterion"]["values"]["mse"]
    assert m["crlb_rms_deg"] >= c["crlb_rms_deg"]


def test_worst_case_bias_model(robot, reach450):
    """mse with the worst-case bias: the criterion is sqrt(mean(CRLB^2 + worst^2)); its design lowers the worst case."""
    tw = bias.make_tolerances(robot, scale=10, bias_model="worst")
    P = design.paper_baseline(robot, 6)
    rep = design.evaluate(robot, P, "mse", NOISE, tolerances=tw)
    want = np.sqrt(np.mean(np.square(rep["crlb_zero_offsets_deg"]) + np.square(rep["bias"]["worst_case_deg"])))
    assert rep["criterion"]["values"]["mse"] == pytest.approx(want, rel=_extended_objective_tol(robot, P, "mse", tw) / 2)
    rng = np.random.default_rng(2)
    Q = design_nlp._random_start(robot, 7, reach450, rng)
    fs, ms = design_nlp._scales(robot, Q, NOISE)
    nlp = design_nlp._NLP(robot, 7, "mse", reach450, NOISE, fs, ms, tolerances=tw)
    f, _ = nlp.fg(nlp.x0(Q))  # the epigraph starts at |B| (1 + 1e-6)
    assert float(f) - np.log(fs) == pytest.approx(criteria._objective(robot, "mse", Q, NOISE, tw), abs=1e-5)
    kw = dict(seed=0, n_starts=2, exchange_starts=2)
    w = design.optimize_design(robot, 6, "mse", reach450, NOISE, tolerances=tw, certificate=False, **kw)
    c = design.optimize_design(robot, 6, "crlb", reach450, NOISE, certificate=False, **kw)
    assert w.report["criterion"]["value"] < 0.6 * design.criterion_values(robot, c.poses, NOISE, tw)["mse"]
    with pytest.raises(Exception, match="bias model"):
        bias.make_tolerances(robot, bias_model="median")


# ----------------------------------------------------------------- the position criterion
def test_position_criterion(robot):
    P = design.paper_baseline(robot, 6)
    pos = design.criteria.position_report(robot, P, NOISE)
    v = design.criterion_values(robot, P, NOISE)["position"]
    assert v == pytest.approx(pos["rms_mm"], rel=1e-9) and pos["max_mm"] >= pos["rms_mm"]
    # independent: covariance of the offsets (deg -> arcs) through the error Jacobian at each grid point
    th = kin.ik(robot, P)
    cov = fisher.crlb(robot, th, "paper", NOISE)[:2, :2]
    L = robot.error_scale(robot.errors.zero_offsets)
    grid = robot.workspace_grid()
    J = kin.error_jacobian(robot, grid)
    e2 = np.einsum("gni,ij,gnj->g", J, cov * np.outer(L, L), J)
    assert pos["rms_mm"] == pytest.approx(np.sqrt(e2.mean()), rel=1e-6)
    assert pos["max_mm"] == pytest.approx(np.sqrt(e2.max()), rel=1e-6)


# ----------------------------------------------------------------- the Delta
def test_delta_approx_design_ring_baseline(delta):
    cons = design.make_constraints(delta)
    res = design.optimize_design(delta, 60, "crlb", cons, NOISE)
    d = res.to_dict()
    assert d["method"].startswith("approximate") and d["violations"] == []
    assert d["baseline_scheme"] == "ring scheme" and len(d["paper"]["poses"]) == 60
    assert d["crlb_rms_deg"] < 0.05 * d["paper"]["crlb_rms_deg"]
    assert 0.8 < d["certificate"]["efficiency_lower_bound"] <= 1


def test_delta_reachable_cylinder_bounds(delta):
    cons = design.make_constraints(delta, region="reachable", bounds=(300, -950, -650))
    reg = cons.region
    assert reg.clip.kind == "cylinder"
    X = reg.grid(300)
    assert np.all(np.hypot(X[:, 0], X[:, 1]) <= 300 + 1e-6)
    res = design.optimize_design(delta, 8, "crlb", cons, NOISE, seed=0, n_starts=2, exchange_starts=2,
                                 certificate=False)
    assert design.check_design(delta, res.poses, cons) == []
    assert res.to_dict()["baseline_scheme"] == "ring scheme on the workspace"


# ----------------------------------------------------------------- singular information, overflow
@pytest.mark.parametrize("criterion", ["D", "A", "crlb", "E", "position"])
def test_candidates_that_cannot_identify_are_a_design_error(robot, criterion):
    """Twenty copies of one pose see no parameter combination: solve_measure says so (a DesignError)."""
    X = np.repeat(design.paper_baseline(robot, 6)[:1], 20, axis=0)
    model = posemodel.PoseModel(robot, X, NOISE, criterion)
    with pytest.raises(DesignError, match=r"cannot identify the parameters \(singular information\)"):
        measure.solve_measure(model, criterion)


def _singular_after_first(monkeypatch):
    """``measure._evaluate`` that goes singular (no value, no derivative) from its second call on: the active-set
    loop's guard is reached whatever the round-off (on real candidates that barely identify the parameters,
    whether the information turns singular first or the loop converges first is round-off's choice; numpy 1.24
    and 2.x differ on the same region)."""
    real, calls = measure._evaluate, []

    def fake(*args, **kwargs):
        calls.append(1)
        out = real(*args, **kwargs)
        return out if len(calls) == 1 else (out[0], None) + tuple(out[2:])

    monkeypatch.setattr(measure, "_evaluate", fake)
    return calls


def test_a_measure_that_becomes_singular_is_a_design_error(robot, monkeypatch):
    """A measure whose information turns singular after its start (it raised AttributeError there): a DesignError
    that says so; and on candidates that barely identify the parameters (a 4 x 20 mm region) either that error or
    a measure, never another exception."""
    cons = design.make_constraints(robot, region=(-2, 2, 640, 660))
    X, _ = approx.candidate_poses(robot, cons)
    model = posemodel.PoseModel(robot, X, NOISE, "crlb")
    try:
        out = measure.solve_measure(model, "crlb", tol=1e-2, certify=False)
        assert np.isfinite(out["loss"]) and out["w"].sum() == pytest.approx(1.0)
    except DesignError as e:
        assert "became singular" in str(e) and "widen the region" in str(e)
    calls = _singular_after_first(monkeypatch)
    with pytest.raises(DesignError, match=r"crlb measure on these candidate poses became singular: .* widen the "
                                          r"region"):
        measure.solve_measure(model, "crlb", tol=1e-2, certify=False)
    assert len(calls) == 2


def test_a_measure_that_becomes_singular_is_one_line_from_the_cli(capsys, tmp_path, monkeypatch):
    out = tmp_path / "d.json"
    _singular_after_first(monkeypatch)
    assert main(["design", "--optimize", "--K", "6", "--region", "-2", "2", "640", "660", "--method", "approx",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "zerocal design: error: no travel window" in err and "became singular" in err
    assert not out.exists()


def test_e_value_far_above_its_scale_is_inf_without_overflow():
    """E's convex form sum(pi^q) at a trial point far from the start (pi >> 1): +inf, rejected by the
    backtracking, computed without an overflow RuntimeWarning (an error under the tests' warning filter)."""
    rng = np.random.default_rng(0)
    R = rng.normal(size=(12, 5))
    w = np.full(12, 1 / 12)
    Ninv = np.linalg.inv((R.T * w) @ R)[1:, 1:]
    top = float(np.linalg.eigvalsh(Ninv)[-1])
    f, st = measure._value("E", R, None, 256, w, escale=top)  # pi <= 1: the value, finite
    assert st is not None and 0.99 < f <= 4 and f == pytest.approx(np.sum(st[3][0] ** 256))  # max pi = 1
    f, st = measure._value("E", R, None, 256, w, escale=top / 100)  # pi up to 100: 100^256 > 1.8e308
    assert f == math.inf and st is None
