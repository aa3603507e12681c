"""Truncated SVD: the solver, its truncation rules and the TSVD identification."""
import numpy as np
import pytest

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.errors import IdentificationError
from zerocal_sym.identify.fisher import crlb_zero_offsets_deg
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.identify.loop import simulate_round
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.identify.estimate.truncated_svd import tsvd_solve
from zerocal_sym.identify.tsvd import identify_tsvd
from roundoff import cond_tol


def _designed(sv, m=7, seed=0):
    rng = np.random.default_rng(seed)
    U, _ = np.linalg.qr(rng.normal(size=(m, len(sv))))
    V, _ = np.linalg.qr(rng.normal(size=(len(sv), len(sv))))
    return U @ np.diag(sv) @ V.T, U, V


@pytest.mark.parametrize("seed", range(5))
def test_full_rank_equals_least_squares(seed):
    rng = np.random.default_rng(seed)
    G = rng.normal(size=(9, 4))
    b = rng.normal(size=9)
    sol = tsvd_solve(G, b)
    assert sol.t == 4 and sol.rule == "threshold"
    # two SVD solves of one least-squares problem: each to cond(G)^2 EPS (a residual b - G x of the size of b), 16
    # for the two algorithms and their sums
    x = np.linalg.lstsq(G, b, rcond=None)[0]
    np.testing.assert_allclose(sol.x, x, rtol=0, atol=cond_tol(np.linalg.cond(G) ** 2, 16) * np.max(np.abs(x)))
    np.testing.assert_array_equal(sol.filter_factors, np.ones(4))
    np.testing.assert_allclose(sol.singular_values, np.linalg.svd(G, compute_uv=False))


def test_fixed_truncation_drops_the_weak_directions():
    G, U, V = _designed([1.0, 0.5, 0.1, 1e-3])
    x_true = V @ np.array([1.0, 2.0, 3.0, 4.0])
    sol = tsvd_solve(G, G @ x_true, t=2)
    np.testing.assert_allclose(sol.x, V[:, :2] @ np.array([1.0, 2.0]), atol=1e-12)
    np.testing.assert_array_equal(sol.filter_factors, [1, 1, 0, 0])
    assert sol.rule == "fixed"
    np.testing.assert_allclose(sol.residual_norms[2], np.hypot(0.1 * 3, 1e-3 * 4), rtol=1e-10)
    with pytest.raises(ValueError):
        tsvd_solve(G, G @ x_true, t=5)


def test_threshold_rule():
    G, _, _ = _designed([1.0, 0.5, 1e-4, 1e-9])
    assert tsvd_solve(G, np.ones(7)).t == 3  # default rtol 1e-6
    assert tsvd_solve(G, np.ones(7), rule="threshold", rtol=1e-3).t == 2


def test_gcv_drops_a_noise_only_component():
    G, U, V = _designed([1.0, 0.5, 0.1, 1e-4], m=12)
    rng = np.random.default_rng(1)
    x_true = V[:, :3] @ np.array([1.0, 1.0, 1.0])  # nothing along the weakest direction
    z = rng.normal(size=12)
    e = z - U @ (U.T @ z)  # noise outside range(G): the 4th coefficient is exactly 0
    b = G @ x_true + 1e-3 * e
    sol = tsvd_solve(G, b, rule="gcv")
    assert sol.t == 3 and sol.rule == "gcv"
    assert np.isfinite(sol.criterion[3]) and np.argmin(sol.criterion) == 3


def test_discrepancy_principle_needs_and_uses_the_noise_level():
    G, U, V = _designed([1.0, 0.5, 0.1, 1e-4], m=12)
    rng = np.random.default_rng(2)
    b = G @ (V @ np.array([1.0, 1.0, 1.0, 0.0])) + 1e-3 * rng.normal(size=12)
    with pytest.raises(ValueError, match="noise"):
        tsvd_solve(G, b, rule="discrepancy")
    sol = tsvd_solve(G, b, rule="discrepancy", noise_std=1e-3)
    assert sol.t == 3
    assert sol.residual_norms[sol.t] <= np.sqrt(12) * 1e-3
    # a much larger stated noise level truncates more
    assert tsvd_solve(G, b, rule="discrepancy", noise_std=0.05).t < 3


def test_unknown_rule():
    with pytest.raises(ValueError, match="unknown truncation rule"):
        tsvd_solve(np.eye(4), np.ones(4), rule="lcurve")


# ---------------------------------------------------------------- identify_tsvd
@pytest.fixture(scope="module")
def setup(robot):
    P = paper_poses(robot, 3)
    err = robot.errors.assemble((-2.0, 1.0), None, (1.0, -0.5))
    return P, VirtualPlant(robot, err), err


def test_identify_reports_svd_and_total_estimates(robot, setup):
    P, plant, err = setup
    meas = simulate_round(robot, plant, P)
    res = identify_tsvd(robot, meas)
    assert res.method == "tsvd" and res.params == ("theta1", "theta2", "rMx", "rMy")
    assert res.info["truncation"] == 4
    np.testing.assert_array_equal(res.info["filter_factors"], np.ones(4))
    assert res.info["kappa"] == pytest.approx(475.342, abs=1e-3)
    assert len(res.info["singular_values"]) == 4 and res.info["singular_values"][-1] == pytest.approx(0.002415, 1e-3)
    # first-order solution from the nominal: close to the truth, not exact (linearisation)
    assert np.max(np.abs(res.zero_offsets_deg - [-2.0, 1.0])) < 0.2
    # estimate = prior + increment: identifying again at the estimate improves it
    prior = res.full_vector()
    meas2 = simulate_round(robot, plant, P, compensation_rad=prior[:2])
    res2 = identify_tsvd(robot, meas2, prior=prior)
    assert np.max(np.abs(res2.zero_offsets_deg - [-2.0, 1.0])) < 0.1 * np.max(np.abs(res.zero_offsets_deg - [-2, 1]))
    np.testing.assert_allclose(res2.info["increment"], res2.estimate - prior[[0, 1, 10, 11]], atol=1e-15)
    assert res2.residuals.shape == (5,)


def test_truncating_the_weakest_direction_loses_the_offsets(robot, setup):
    """t = 3 drops the common mode of the offsets (mixed with rMx): ~0.5 deg error without noise."""
    P, plant, err = setup
    prior = np.zeros(12)
    for _ in range(6):
        meas = simulate_round(robot, plant, P, compensation_rad=prior[:2])
        prior = identify_tsvd(robot, meas, prior=prior, t=3).full_vector()
    assert np.max(np.abs(np.degrees(prior[:2] - err[:2]))) > 0.3
    v4 = identify_tsvd(robot, meas, prior=prior, t=3).info["right_singular_vectors"][3]
    assert abs(v4[0]) > 0.6 and abs(v4[1]) > 0.6 and np.sign(v4[0]) == np.sign(v4[1]) and abs(v4[2]) > 0.2


def test_covariance_matches_crlb_and_monte_carlo(robot, setup):
    """Scale-only noise is white: the unweighted TSVD (t = 4) estimator attains the first-order CRLB."""
    P, plant, err = setup
    noise = NoiseModel.named("scale-only")
    th = kin.ik(robot, P)
    prior = err.copy()
    prior[2:10] = 0
    meas = simulate_round(robot, plant, P, compensation_rad=prior[:2])
    res = identify_tsvd(robot, meas, prior=prior, noise=noise)
    bound = crlb_zero_offsets_deg(robot, th, "paper", noise)
    np.testing.assert_allclose(res.std_zero_offsets_deg, bound, rtol=0.02)
    rng = np.random.default_rng(7)
    est = np.array([identify_tsvd(robot, simulate_round(robot, plant, P, prior[:2], noise, rng), prior=prior)
                    .zero_offsets_deg for _ in range(400)])
    emp = np.std(est, axis=0, ddof=1)
    np.testing.assert_allclose(emp, res.std_zero_offsets_deg, rtol=0.15)


def test_servo_noise_covariance_is_an_order_larger(robot, setup):
    P, plant, err = setup
    prior = err.copy()
    prior[2:10] = 0
    meas = simulate_round(robot, plant, P, compensation_rad=prior[:2])
    s_paper = identify_tsvd(robot, meas, prior=prior, noise=NoiseModel.paper()).std_zero_offsets_deg
    s_scale = identify_tsvd(robot, meas, prior=prior, noise=NoiseModel.named("scale-only")).std_zero_offsets_deg
    assert np.all(s_paper > 8 * s_scale) and np.all(s_paper > 0.5)


# ---------------------------------------------------------------- degenerate input
def _meas(robot, P, readings=None):
    th = kin.ik(robot, P)
    rd = np.concatenate([[0.0], np.diff(kin.distance(robot, th))]) if readings is None else readings
    return Measurements(theta_cmd=th, readings=rd, target=P)


def test_too_few_poses(robot):
    P = paper_poses(robot, 3)[:4]
    with pytest.raises(IdentificationError, match=r"too few poses: K = 4 < 5"):
        identify_tsvd(robot, _meas(robot, P))


def test_nan_reading_names_the_pose(robot):
    P = paper_poses(robot, 3)
    m = _meas(robot, P)
    m.readings[3] = np.nan
    with pytest.raises(IdentificationError, match="reading of pose 3 is not a finite number") as exc:
        identify_tsvd(robot, m)
    assert "pose 3" in str(exc.value)


def test_nan_angle_names_the_pose(robot):
    P = paper_poses(robot, 3)
    m = _meas(robot, P)
    m.theta_cmd[2, 1] = np.inf
    with pytest.raises(IdentificationError, match="pose 2"):
        identify_tsvd(robot, m)


def test_collinear_measuring_vectors_rank_deficient(robot):
    """Poses on the line x = 0 through O1: all lambda_k parallel, G rank-deficient."""
    P = np.column_stack([np.zeros(6), np.linspace(632, 782, 6)])
    with pytest.raises(IdentificationError, match=r"rank [0-3] < 4"):
        identify_tsvd(robot, _meas(robot, P))


@pytest.mark.parametrize("line", ["horizontal", "diagonal"])
def test_poses_on_one_line(robot, line):
    x = np.linspace(-200, 200, 7)
    y = np.full(7, 700.0) if line == "horizontal" else 700 + 0.3 * x
    with pytest.raises(IdentificationError, match="one straight line"):
        identify_tsvd(robot, _meas(robot, np.column_stack([x, y])))


# ---------------------------------------------------------------- without diagnostics, many rounds at once
def _rounds(robot, n, seed=0):
    """Noisy rounds of the paper's poses (and of 8 poses) at random compensations and priors."""
    from zerocal_sym.paper.tables import group_errors

    rng = np.random.default_rng(seed)
    plant = VirtualPlant(robot, group_errors(2))
    rounds, priors = [], []
    for i in range(n):
        P = paper_poses(robot, 3 if i % 3 else 4)
        prior = np.zeros(len(robot.errors))
        prior[[0, 1, 10, 11]] = rng.normal(0, [0.03, 0.03, 1.0, 1.0])
        rounds.append(simulate_round(robot, plant, P, prior[:2], NoiseModel.paper(), rng))
        priors.append(prior)
    return rounds, priors


def _same(a, b):
    """Two outcomes of identify_tsvd(diagnostics=False) are the same: the numbers bit for bit, or the same error."""
    if isinstance(a, Exception) or isinstance(b, Exception):
        return type(a) is type(b) and str(a) == str(b)
    return (np.array_equal(a.estimate, b.estimate) and a.status == b.status and a.success == b.success
            and a.info["kappa"] == b.info["kappa"] and np.array_equal(a.info["increment"], b.info["increment"])
            and np.array_equal(a.info["singular_values"], b.info["singular_values"])
            and np.array_equal(a.info["nominal_poses"], b.info["nominal_poses"]))


def _alone(robot, meas, prior, **kw):
    try:
        return identify_tsvd(robot, meas, prior, diagnostics=False, **kw)
    except Exception as exc:  # noqa: BLE001
        return exc


def test_without_diagnostics_the_same_estimate(robot):
    rounds, priors = _rounds(robot, 6, seed=3)
    for meas, prior in zip(rounds, priors):
        full = identify_tsvd(robot, meas, prior)
        lean = identify_tsvd(robot, meas, prior, diagnostics=False)
        np.testing.assert_array_equal(lean.estimate, full.estimate)
        assert lean.success and full.success and lean.info["kappa"] == full.info["kappa"]
        assert lean.covariance is None and lean.std_kind == "lower bound" and "fit" not in lean.info
        assert "fit not checked" in lean.status and lean.info["diagnostics"] is False


def test_identify_tsvd_many_is_one_by_one(robot):
    """The batch gives each round's numbers bit for bit, and each bad round the error it raises alone."""
    from zerocal_sym.identify.tsvd import identify_tsvd_many

    rounds, priors = _rounds(robot, 13)
    P = paper_poses(robot, 3)
    bad_reading = _meas(robot, P)
    bad_reading.readings[3] = np.nan
    line = np.column_stack([np.linspace(-200, 200, 6), np.full(6, 700.0)])
    collinear = np.column_stack([np.zeros(6), np.linspace(632, 782, 6)])
    rounds[2:2] = [bad_reading, _meas(robot, line), _meas(robot, collinear), _meas(robot, P[:4]), _meas(robot, P)]
    priors[2:2] = [None, None, None, None, np.zeros(3)]  # the last: a prior of the wrong length
    out = identify_tsvd_many(robot, rounds, priors)
    alone = [_alone(robot, m, p) for m, p in zip(rounds, priors)]
    assert [type(a).__name__ for a in alone[2:7]] == ["IdentificationError"] * 4 + ["ValueError"]
    assert sum(isinstance(a, Exception) for a in alone) == 5
    for a, b in zip(out, alone):
        assert _same(a, b), (a, b)
    for kw in ({"t": 3}, {"rule": "gcv"}):
        for a, b in zip(identify_tsvd_many(robot, rounds, priors, **kw), [_alone(robot, m, p, **kw)
                                                                            for m, p in zip(rounds, priors)]):
            assert _same(a, b), (kw, a, b)
    assert identify_tsvd_many(robot, []) == []
    with pytest.raises(ValueError, match="priors"):
        identify_tsvd_many(robot, rounds[:2], priors[:1])


def test_identify_tsvd_many_falls_back_to_one_by_one(robot, monkeypatch):
    """When the batch itself fails (e.g. an unreachable pose among them), each round is identified alone."""
    from zerocal_sym.errors import PoseError
    from zerocal_sym.identify import linear
    from zerocal_sym.identify.tsvd import identify_tsvd_many

    rounds, priors = _rounds(robot, 5, seed=1)
    alone = [_alone(robot, m, p) for m, p in zip(rounds, priors)]
    real = linear.identification_matrix

    def only_one_round(robot_, P, *a, **kw):
        if len(P) > 8:
            raise PoseError("pose (1, 2) mm is unreachable")
        return real(robot_, P, *a, **kw)

    monkeypatch.setattr(linear, "identification_matrix", only_one_round)
    for a, b in zip(identify_tsvd_many(robot, rounds, priors), alone):
        assert _same(a, b)
    # Ctrl-C that C code turned into an error is not a round's outcome: it propagates
    monkeypatch.setattr(linear, "identification_matrix", lambda *a, **kw: (_ for _ in ()).throw(
        RuntimeError("KeyboardInterrupt")))
    with pytest.raises(RuntimeError, match="KeyboardInterrupt"):
        identify_tsvd_many(robot, rounds, priors)


def test_identify_tsvd_many_with_noise_gives_the_std_of_one_by_one(robot):
    """With a noise model the batch gives each round the std identify_tsvd computes for it (the noise at the
    estimate, the linearisation bias of TSVD's own operator, each parameter's kind), to the round-off of the
    batched linear algebra; a truncated round is identified alone, its truncation bound included."""
    from zerocal_sym.identify.tsvd import identify_tsvd_many

    noise = NoiseModel.paper()
    rounds, priors = _rounds(robot, 6, seed=4)
    for kw in ({}, {"t": 3}):
        for a, meas, prior in zip(identify_tsvd_many(robot, rounds, priors, noise=noise, **kw), rounds, priors):
            b = identify_tsvd(robot, meas, prior, noise=noise, **kw)
            np.testing.assert_array_equal(a.estimate, b.estimate)
            scale = np.sqrt(np.outer(np.diag(b.covariance), np.diag(b.covariance)))
            assert np.max(np.abs(a.covariance - b.covariance) / scale) < 1e-9
            np.testing.assert_allclose(a.info["linearisation_bias"], b.info["linearisation_bias"], rtol=1e-6,
                                       atol=1e-9 * np.max(np.sqrt(np.diag(b.covariance))))
            assert a.std_kind == b.std_kind and a.info["std_kinds"] == b.info["std_kinds"]
            assert set(b.info["std_kinds"].values()) <= {"total", "bound"}
            assert b.std_kind == ("bound" if "bound" in b.info["std_kinds"].values() else "total")
        if kw:  # truncated: the truncated directions' bias bound makes every offset's std a bound
            assert all(r.info["std_kinds"]["theta1"] == "bound" for r in identify_tsvd_many(robot, rounds, priors,
                                                                                          noise=noise, **kw))


def test_linearisation_bias_is_the_bias_of_tsvds_operator(robot):
    """Noise-free data: the one-step estimate's error is its linearisation bias, and the bias reported is that
    error (t* is the truth); an iterated TSVD has none."""
    from zerocal_sym.paper.tables import group_errors

    truth = robot.errors.put(group_errors(1, "paper"), robot.errors.geometry, 0.0)
    th = kin.ik(robot, paper_poses(robot, 3))
    meas = Measurements(th, VirtualPlant(robot, truth).measure(th))
    one = identify_tsvd(robot, meas, noise=NoiseModel.paper())
    err = one.estimate - robot.errors.take(truth, one.params)
    assert np.max(np.abs(np.degrees(err[:2]))) > 0.05  # the paper's one step at 2 deg offsets
    np.testing.assert_allclose(one.info["linearisation_bias"], err, rtol=1e-6, atol=1e-12)
    it = identify_tsvd(robot, meas, noise=NoiseModel.paper(), iterations=20)
    assert it.info["tsvd_converged"] and it.std_kind == "total"
    assert np.max(np.abs(it.info["linearisation_bias"])) < 1e-9
