"""Measurement-pose design (zerocal_sym.design): criteria, constraints, methods, CLI."""
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from zerocal_sym import design
from zerocal_sym.design import criteria
from zerocal_sym.design import nlp as design_nlp
from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.paper import scheme
from zerocal_sym.identify import linear
from zerocal_sym.cli import main
from zerocal_sym.design import DesignError
from zerocal_sym.model.noise import NoiseModel
from roundoff import log_objective_tol

NOISE = NoiseModel.paper()


@pytest.fixture(scope="module")
def cons(robot):
    return design.make_constraints(robot)


@pytest.fixture(scope="module")
def crlb6(robot, cons):
    return design.optimize_design(robot, 6, "crlb", cons, NOISE, seed=0)


@pytest.fixture(scope="module")
def cond6(robot, cons):
    return design.optimize_design(robot, 6, "cond", cons, NOISE, seed=0)


# ----------------------------------------------------------------- criteria against independent code
def test_paper_baseline_values(robot):
    P = design.paper_baseline(robot, 6)
    np.testing.assert_array_equal(P, scheme.paper_poses(robot, 3))
    v = design.criterion_values(robot, P, NOISE)
    assert v["cond"] == pytest.approx(475.342, abs=1e-3)  # SPEC kappa_1
    assert v["crlb"] == pytest.approx(0.522, abs=5e-4)     # SPEC CRLB with the servo error


def test_odd_k_baseline(robot):
    P = design.paper_baseline(robot, 7)
    assert P.shape == (7, 2)
    assert np.all(P[:4, 1] == robot.workspace.H) and np.all(P[4:, 1] == robot.workspace.H + robot.workspace.h)
    np.testing.assert_allclose(P[:4, 0], np.linspace(-240, 240, 4))
    np.testing.assert_allclose(P[4:, 0], np.linspace(-240, 240, 3))


@settings(max_examples=15)
@given(seed=st.integers(0, 10_000), K=st.integers(5, 9))
def test_criteria_match_fisher_and_scheme(robot, cons, seed, K):
    """Batched criteria vs fisher.py (CRLB, F) and scheme.py (kappa of G) on random feasible designs."""
    P = design_nlp._random_start(robot, K, cons, np.random.default_rng(seed))
    th = kin.ik(robot, P)
    v = design.criterion_values(robot, P, NOISE)
    crlb = fisher.crlb_zero_offsets_deg(robot, th, "paper", NOISE)
    assert v["crlb"] == pytest.approx(np.sqrt(np.mean(crlb ** 2)), rel=1e-7)
    G, _ = linear.identification_matrix(robot, P, theta=th)
    assert v["cond"] == pytest.approx(linear.condition_number(G), rel=1e-7)
    T = np.diag(1 / fisher.parameter_scale(robot, "paper"))
    Fq = T @ fisher.fisher_information(robot, th, "paper", NOISE) @ T
    assert v["D"] == pytest.approx(np.linalg.slogdet(Fq)[1], rel=1e-7, abs=1e-7)
    assert v["A"] == pytest.approx(np.trace(np.linalg.inv(Fq)), rel=1e-6)
    assert v["E"] == pytest.approx(np.linalg.eigvalsh(Fq)[0], rel=1e-6)


@pytest.mark.parametrize("criterion", ["D", "A", "crlb"])
def test_symbolic_objective_matches_numeric(robot, cons, criterion):
    """The NLP's symbolic objective (LDL^T of the tridiagonal covariance) equals the numeric one."""
    rng = np.random.default_rng(3)
    P = design_nlp._random_start(robot, 7, cons, rng)
    fs, ms = design_nlp._scales(robot, P, NOISE)
    nlp = design_nlp._NLP(robot, 7, criterion, cons, NOISE, fs, ms)
    f, _ = nlp.fg(nlp.x0(P))
    o = criteria._objective(robot, criterion, P, NOISE)
    shift = {"D": 4 * np.log(fs), "A": np.log(fs), "crlb": np.log(fs)}[criterion]  # F_n = F / fs
    # two algorithms for one log-objective: at the round-off of F's conditioning (tests/roundoff.py)
    F = criteria._fisher(*criteria._terms_batch(robot, P, NOISE), criteria._noise_terms(NOISE)[0])[0]
    assert float(f) == pytest.approx(o + shift, rel=0, abs=log_objective_tol(F))


def test_psd_auxiliary_formulation_gives_eigenvalue_bounds(robot, cons):
    """E and cond: at Ipopt's solution the auxiliary bounds are the extreme eigenvalues."""
    P0 = design.paper_baseline(robot, 6)
    fs, ms = design_nlp._scales(robot, P0, NOISE)
    for criterion in ("E", "cond"):
        nlp = design_nlp._NLP(robot, 6, criterion, cons, NOISE, fs, ms)
        sol = nlp.solver(x0=nlp.x0(P0), lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        assert nlp.solver.stats()["success"]
        x = sol["x"].full().ravel()
        P = cons.region.center + cons.region.half * x[:12].reshape(6, 2)
        val = design.criterion_values(robot, P, NOISE)[criterion]
        f = float(sol["f"])
        got = np.exp(-f) * fs if criterion == "E" else np.exp(f)
        # E uses the principal minors: at a double smallest eigenvalue the minor tolerance (1e-9)
        # lets t exceed lambda_min by ~sqrt(tol); the design is always reported from the poses.
        assert got == pytest.approx(val, rel=1e-3 if criterion == "E" else 1e-6)


# ----------------------------------------------------------------- results that must be shown
def test_crlb_design_beats_paper_at_k6(crlb6):
    d = crlb6.to_dict()
    ratio = d["ratio"]["crlb_rms_design_over_paper"]
    print(f"K=6 CRLB design {d['crlb_rms_deg']:.4f} deg, paper {d['paper']['crlb_rms_deg']:.4f} deg, "
          f"ratio {ratio:.4f}")
    assert d["paper"]["crlb_rms_deg"] == pytest.approx(0.522, abs=5e-4)
    assert ratio < 0.88  # measured 0.846
    assert d["violations"] == []
    assert d["paper"]["violations"] == []


def test_cond_optimal_is_not_crlb_optimal(crlb6, cond6):
    """Measured on the paper's robot, K = 6, paper noise, seed 0: the two optima are far apart.

    kappa-optimal: kappa 45.72 (the paper's scheme: 475.34), CRLB 1.886 deg
    (the paper's: 0.522); CRLB-optimal: kappa 142.59, CRLB 0.4415 deg.
    Minimising kappa makes the zero offsets worse than the paper's scheme.
    """
    c, k = crlb6.to_dict(), cond6.to_dict()
    print(f"cond-optimal: kappa {k['kappa']:.2f}, CRLB {k['crlb_rms_deg']:.4f} deg; "
          f"crlb-optimal: kappa {c['kappa']:.2f}, CRLB {c['crlb_rms_deg']:.4f} deg")
    assert k["kappa"] < 0.6 * c["kappa"]
    assert c["crlb_rms_deg"] < 0.5 * k["crlb_rms_deg"]
    assert k["crlb_rms_deg"] > k["paper"]["crlb_rms_deg"]  # minimising kappa makes the CRLB worse than the paper's
    assert not np.allclose(np.sort(np.array(c["poses"]), axis=0), np.sort(np.array(k["poses"]), axis=0), atol=5)


def test_exchange_and_continuous_agree(robot, crlb6, cond6):
    """The two methods check each other: Ipopt multi-start (random + paper starts) vs the grid exchange."""
    for res in (crlb6, cond6):
        ex, co = res.exchange["objective"], res.continuous["objective"]
        assert co <= ex + 0.01  # log scale: continuous within 1 % of (or better than) the exchange
        assert criteria._objective(robot, res.criterion, res.poses, NOISE) <= min(ex, co) + 1e-12


def test_best_order_exhaustive(robot):
    """The order search improves the paper's kappa_1 (475.34) below the back-and-forth order's 330.28 (SPEC)."""
    P = design.paper_baseline(robot, 6)
    back_and_forth = P[[0, 1, 2, 5, 4, 3]]
    assert design.criterion_values(robot, back_and_forth, NOISE)["cond"] == pytest.approx(330.28, abs=0.01)
    order, obj = design.best_order(robot, P, "cond", NOISE)
    assert np.exp(obj) <= 330.28 + 1e-6
    assert design.criterion_values(robot, P[order], NOISE)["cond"] == pytest.approx(np.exp(obj), rel=1e-9)
    # reversal leaves every criterion unchanged
    v, r = design.criterion_values(robot, P, NOISE), design.criterion_values(robot, P[::-1], NOISE)
    for c in design.CRITERIA:
        assert v[c] == pytest.approx(r[c], rel=1e-9)


def test_best_order_local_search(robot, cons):
    P = design_nlp._random_start(robot, 10, cons, np.random.default_rng(1))
    o0 = criteria._objective(robot, "crlb", P, NOISE)
    order, obj = design.best_order(robot, P, "crlb", NOISE)
    assert sorted(order) == list(range(10))
    assert obj <= o0 and criteria._objective(robot, "crlb", P[order], NOISE) == pytest.approx(obj)


# ----------------------------------------------------------------- constraints: one test each
def _fast(robot, cons, criterion="crlb", K=6):
    return design.optimize_design(robot, K, criterion, cons, NOISE, seed=1, n_starts=3, exchange_starts=3)


def test_constraint_region(robot):
    cons = design.make_constraints(robot, region=(-100, 150, 650, 750))
    res = _fast(robot, cons)
    P = res.poses
    assert np.all(P[:, 0] >= -100 - 1e-9) and np.all(P[:, 0] <= 150 + 1e-9)
    assert np.all(P[:, 1] >= 650 - 1e-9) and np.all(P[:, 1] <= 750 + 1e-9)
    assert design.check_design(robot, P, cons) == []
    # the baseline is the paper's rule on the region's edges
    Pp = np.array(res.paper["poses"])
    assert set(np.round(Pp[:, 1], 9)) == {650.0, 750.0} and Pp[:, 0].min() == -100 and Pp[:, 0].max() == 150


def test_constraint_travel_range(robot):
    cons = design.make_constraints(robot, travel_mm=100.0)
    res = _fast(robot, cons)
    rho = kin.measuring_vector(robot, res.poses)[0]
    assert np.ptp(rho) <= 100.0 + 1e-6
    # the paper's scheme spans 192.8 mm: it is no baseline, the note and the rejection say why
    assert res.paper is None and "scale travel" in res.baseline_note
    assert any("scale travel" in v for v in res.baseline_rejected[0]["violations"])
    assert res.to_dict()["ratio"]["crlb_rms_design_over_paper"] is None
    assert design.check_design(robot, res.poses, cons) == []


def test_constraint_travel_consecutive(robot):
    cons = design.make_constraints(robot, travel_mm=60.0, travel_mode="consecutive")
    res = _fast(robot, cons)
    rho = kin.measuring_vector(robot, res.poses)[0]
    assert np.max(np.abs(np.diff(rho))) <= 60.0 + 1e-6
    assert design.check_design(robot, res.poses, cons) == []


def test_constraint_singularity_margin(robot):
    """A margin that excludes part of the workspace (min |sin| over it is 0.73)."""
    cons = design.make_constraints(robot, singularity_margin=0.8)
    grid = robot.workspace_grid()
    assert np.min(np.abs(kin.transmission(robot, grid)), axis=1).min() < 0.8
    res = _fast(robot, cons)
    s = np.abs(kin.transmission(robot, res.poses))
    assert s.min() >= 0.8 - 1e-6
    assert design.check_design(robot, res.poses, cons) == []


def test_constraint_joint_limits(robot):
    limits = ((-10.0, 30.0), (150.0, 200.0))
    cons = design.make_constraints(robot, joint_limits_deg=limits)
    res = _fast(robot, cons)
    deg = np.degrees(kin.ik(robot, res.poses))
    assert np.all(deg[:, 0] >= -10 - 1e-6) and np.all(deg[:, 0] <= 30 + 1e-6)
    assert np.all(deg[:, 1] >= 150 - 1e-6) and np.all(deg[:, 1] <= 200 + 1e-6)
    assert design.check_design(robot, res.poses, cons) == []
    assert res.paper is None and "outside [150, 200]" in res.baseline_note  # no baseline
    assert any("theta1" in v for v in res.baseline_rejected[0]["violations"])  # its corners need theta1 up to 38 deg


def test_constraint_min_separation(robot):
    cons = design.make_constraints(robot, min_separation_mm=40.0)
    res = _fast(robot, cons)
    d = np.linalg.norm(res.poses[:, None] - res.poses[None], axis=2)
    assert d[np.triu_indices(6, 1)].min() >= 40.0 - 1e-6


def test_check_design_reports_each_violation(robot):
    cons = design.make_constraints(robot, region=(-100, 100, 650, 750), travel_mm=50,
                                   joint_limits_deg=((0, 10), (170, 190)), min_separation_mm=5)
    P = np.array([[-240, 632], [0, 700], [0, 701], [100, 750], [50, 650]])
    text = " | ".join(design.check_design(robot, P, cons))
    for word in ("outside the region", "scale travel", "theta1", "apart"):
        assert word in text


# ----------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, match", [
    (dict(region=(-240, 240, 2000, 2100)), "not reachable"),
    (dict(region=(100, -100, 650, 750)), "XMIN < XMAX"),
    (dict(region=(-100, 100, 700, 700)), "thinner than 1 mm"),
    (dict(region=(-100, 100, float("nan"), 700)), "finite"),
    (dict(region=(1, 2, 3)), "4 numbers"),
    (dict(travel_mm=0), "positive"),
    (dict(travel_mode="sideways"), "travel mode"),
    (dict(singularity_margin=1.5), "margin"),
    (dict(joint_limits_deg=((10, 0), (150, 200))), "lo < hi"),
])
def test_bad_constraints(robot, kwargs, match):
    with pytest.raises(DesignError, match=match):
        design.make_constraints(robot, **kwargs)


def test_bad_k_and_criterion(robot, cons):
    with pytest.raises(DesignError, match="too small"):
        design.optimize_design(robot, 4, "crlb", cons)
    with pytest.raises(DesignError, match="unknown criterion"):
        design.optimize_design(robot, 6, "G", cons)
    with pytest.raises(DesignError, match="integer"):
        design.optimize_design(robot, 6.5, "crlb", cons)
    with pytest.raises(DesignError, match="noise model is zero"):
        design.optimize_design(robot, 6, "crlb", cons, NoiseModel())


def test_no_feasible_candidates(robot):
    cons = design.make_constraints(robot, joint_limits_deg=((100, 110), (150, 200)))
    with pytest.raises(DesignError, match="feasible candidate"):
        design.optimize_design(robot, 6, "crlb", cons)


@pytest.mark.parametrize("argv, match", [
    (["--K", "4"], "too small"),
    (["--region", "-240", "240", "2000", "2100"], "not reachable"),
    (["--region", "240", "-240", "632", "782"], "XMIN < XMAX"),
    (["--verify", "-3"], "--verify"),
    (["--l0", "-1"], "positive"),
])
def test_cli_bad_input_exit_2(argv, match, capsys, tmp_path):
    png = tmp_path / "p.png"
    rc = main(["design", "--optimize", "--plot", str(png)] + argv)
    err = capsys.readouterr().err
    assert rc == 2 and match in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not png.exists()


def test_cli_bad_criterion_is_argparse_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["design", "--optimize", "--criterion", "Z"])
    assert exc.value.code == 2


# ----------------------------------------------------------------- CLI
def test_cli_json_and_plot(tmp_path, capsys):
    png = tmp_path / "design.png"
    rc = main(["design", "--optimize", "--K", "6", "--criterion", "crlb", "--starts", "3", "--json",
               "--plot", str(png)])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    for key in ("poses", "criterion", "crlb_zero_offsets_deg", "kappa"):
        assert key in d and key in d["paper"]
    assert len(d["poses"]) == 6 and len(d["paper"]["poses"]) == 6
    assert d["criterion"]["name"] == "crlb" and set(d["criterion"]["values"]) == set(design.CRITERIA)
    assert d["paper"]["kappa"] == pytest.approx(475.342, abs=1e-3)
    assert d["ratio"]["crlb_rms_design_over_paper"] < 0.9
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_text(capsys):
    rc = main(["design", "--optimize", "--K", "5", "--criterion", "D", "--starts", "2"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "CRLB ratio design / paper" in out and "paper" in out and "kappa" in out


# ----------------------------------------------------------------- Monte Carlo (slow)
@pytest.mark.slow
def test_monte_carlo_confirms_crlb_gain(robot, crlb6):
    """K = 6: the Ipopt estimator's RMS error follows the CRLB, and the design beats the paper's scheme."""
    n = 300
    vd = design.verify_design(robot, crlb6.poses, n, NOISE, seed=11)
    vp = design.verify_design(robot, design.paper_baseline(robot, 6), n, NOISE, seed=11)
    print(f"MC RMS design {vd['rms_error_rms_deg']:.4f} (CRLB {vd['crlb_at_truth_rms_deg']:.4f}), "
          f"paper {vp['rms_error_rms_deg']:.4f} (CRLB {vp['crlb_at_truth_rms_deg']:.4f})")
    assert vd["n_failed"] == 0 and vp["n_failed"] == 0
    for v in (vd, vp):
        assert v["rms_error_rms_deg"] == pytest.approx(v["crlb_at_truth_rms_deg"], rel=0.15)
    assert vd["rms_error_rms_deg"] / vp["rms_error_rms_deg"] < 0.95


@pytest.mark.slow
def test_k20_design(robot, cons):
    res = design.optimize_design(robot, 20, "crlb", cons, NOISE, seed=0, n_starts=3, exchange_starts=3)
    d = res.to_dict()
    assert d["violations"] == [] and len(d["poses"]) == 20
    assert d["ratio"]["crlb_rms_design_over_paper"] < 0.9
