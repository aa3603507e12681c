"""The calibration loop, the pose scheme and the paper's tables."""
import numpy as np
import pytest

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import ZerocalError
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.identify.loop import calibration_loop, home_error, position_errors, simulate_round
from zerocal_sym.paper.reproduction import kappas, reproduce, run_group, select_n
from zerocal_sym.paper.tables import (DEFAULT_MAEMM_PRIOR, PAPER_KAPPA_1, PAPER_KAPPA_M, PAPER_TABLE3, PAPER_TABLE4,
                                      PAPER_TABLE6, group_errors)
from zerocal_sym.identify.result import IdentificationResult
from zerocal_sym.paper.scheme import paper_poses

GROUPS = range(1, 7)


@pytest.fixture(scope="module")
def poses(robot):
    return paper_poses(robot, 3)


# ---------------------------------------------------------------- scheme
def test_kappas_and_eps_rule(robot):
    k1, km = kappas(robot, 3)
    assert k1 == pytest.approx(PAPER_KAPPA_1, abs=0.01)
    assert km == pytest.approx(PAPER_KAPPA_M, abs=0.3)
    sel = select_n(robot, eps0=0.01)
    assert sel.n == 3
    assert sel.table[0]["eps"] == pytest.approx((k1 - km) / k1)
    assert tuple(sel.maemm_prior) == DEFAULT_MAEMM_PRIOR


def test_kappa_grows_with_n(robot):
    k = np.array([kappas(robot, n) for n in (3, 5, 9, 15)])
    assert np.all(np.diff(k[:, 0]) > 0) and np.all(np.diff(k[:, 1]) > 0)
    assert np.all(k[:, 1] < k[:, 0])


def test_eps_rule_bad_eps0(robot):
    with pytest.raises(ZerocalError):
        select_n(robot, eps0=0.0)
    with pytest.raises(ZerocalError, match="no n"):
        select_n(robot, eps0=1e-9, n_max=4)


# ---------------------------------------------------------------- simulation
def test_simulate_round(robot, poses):
    err = group_errors(1)
    plant = VirtualPlant(robot, err)
    comp = np.radians([0.3, -0.2])
    m = simulate_round(robot, plant, poses, comp)
    np.testing.assert_allclose(m.theta_cmd, kin.ik(robot, poses) - comp)
    assert m.readings[0] == 0.0 and m.K == 6
    np.testing.assert_allclose(m.readings[1:], np.diff(kin.distance(robot, m.theta_cmd, err)))
    np.testing.assert_array_equal(m.target, poses)
    a = simulate_round(robot, plant, poses, noise=NoiseModel.paper(), rng=3).readings
    b = simulate_round(robot, plant, poses, noise=NoiseModel.paper(), rng=3).readings
    np.testing.assert_array_equal(a, b)


def test_group_errors_frames():
    lit = group_errors(1, "literal")
    pap = group_errors(1, "paper")
    np.testing.assert_allclose(np.degrees(lit[:2]), [2, -1])
    np.testing.assert_allclose(np.degrees(pap[:2]), [-2, 1])
    np.testing.assert_allclose(pap[[2, 4, 6, 7, 8, 9, 10]], lit[[2, 4, 6, 7, 8, 9, 10]])
    np.testing.assert_allclose(pap[[3, 5, 11]], -lit[[3, 5, 11]])
    with pytest.raises(ZerocalError, match="groups 1..6"):
        group_errors(7)
    with pytest.raises(ZerocalError):
        group_errors(1, "upside-down")


# ---------------------------------------------------------------- loop
@pytest.mark.parametrize("group", GROUPS)
def test_noise_free_loop_recovers_table2_exactly(robot, poses, group):
    """Zero geometric errors, no noise, full-rank TSVD (t = 4): the loop is a Gauss-Newton
    iteration on the exact model and converges quadratically to the set values."""
    err = group_errors(group)
    err[2:10] = 0.0
    loop = calibration_loop(robot, VirtualPlant(robot, err), poses, mu0_deg=1e-9, max_iter=20)
    assert loop.converged and loop.iterations <= 6
    assert np.max(np.abs(loop.compensation_deg - np.degrees(err[:2]))) < 1e-6
    assert np.max(np.abs(loop.maemm_mm - err[10:12])) < 1e-6
    assert all(h.result.info["truncation"] == 4 for h in loop.history)
    # the compensation value is the sum of the increments
    np.testing.assert_allclose(np.sum([h.increment_deg for h in loop.history], axis=0), loop.compensation_deg)
    assert loop.history[0].mu_deg is None and loop.history[0].kappa == pytest.approx(475.342, abs=1e-3)


def test_loop_history_and_run_all(robot, poses):
    plant = VirtualPlant(robot, group_errors(2))
    loop = calibration_loop(robot, plant, poses, noise=NoiseModel.named("scale-only"), rng=1, run_all=True)
    assert len(loop.history) == 20 and loop.converged
    assert loop.iterations < 20
    h = loop.history[loop.iterations - 1]
    np.testing.assert_allclose(loop.compensation_deg, h.compensation_deg)
    assert h.mu_deg < 0.1 and all(x.mu_deg >= 0.1 for x in loop.history[1:loop.iterations - 1])
    mu = [x.mu_deg for x in loop.history[1:]]
    inc = [np.degrees(np.sqrt(np.mean(np.radians(x.increment_deg) ** 2))) for x in loop.history[1:]]
    np.testing.assert_allclose(mu, inc)
    assert loop.kappa_mean == pytest.approx(np.mean(loop.kappas))


def test_loop_takes_any_identifier(robot, poses):
    """A pluggable identifier (e.g. Ipopt) sees the prior; one returning the truth stops at j = 2."""
    err = group_errors(3)
    seen = []

    def oracle(robot_, meas, prior):
        seen.append(prior.copy())
        return IdentificationResult("oracle", ("theta1", "theta2", "rMx", "rMy"), err[[0, 1, 10, 11]].copy(),
                                    errors=robot.errors)

    loop = calibration_loop(robot, VirtualPlant(robot, err), poses, identify=oracle, maemm_prior=(0.5, 0.5))
    assert loop.converged and loop.iterations == 2 and loop.history[1].mu_deg == 0.0
    np.testing.assert_allclose(seen[0][10:], [0.5, 0.5])
    np.testing.assert_allclose(seen[1][[0, 1, 10, 11]], err[[0, 1, 10, 11]])
    assert np.isfinite(loop.history[0].kappa)


def test_loop_rejects_failed_identification(robot, poses):
    def failing(robot_, meas, prior):
        return IdentificationResult("x", ("theta1", "theta2"), np.zeros(2), success=False, status="diverged",
                                    errors=robot.errors)

    with pytest.raises(ZerocalError, match="diverged"):
        calibration_loop(robot, VirtualPlant(robot, group_errors(1)), poses, identify=failing)


# ---------------------------------------------------------------- the paper's tables
@pytest.mark.parametrize("group", GROUPS)
def test_dp0_before_matches_table3(robot, group):
    """Tolerance 0.002 mm: Table 3 prints 3 decimals (rounding 0.0005 mm); the largest residual,
    0.0015 mm (groups 4 and 5), is not explained.  Exact forward kinematics of the actual robot
    commanded to home, Table 2 read in the paper's frame (ours mirrored about x)."""
    dp0 = home_error(robot, VirtualPlant(robot, group_errors(group, "paper")))
    assert dp0 == pytest.approx(PAPER_TABLE3[group][2], abs=0.002)


@pytest.mark.parametrize("group", GROUPS)
def test_dpmax_before_matches_table4(robot, poses, group):
    """Tolerance 0.001 mm (3 printed decimals); the largest residual is 0.0004 mm."""
    d = np.max(position_errors(robot, VirtualPlant(robot, group_errors(group, "paper")), poses))
    assert d == pytest.approx(PAPER_TABLE4[group][0], abs=0.001)


def test_literal_reading_of_table2_does_not_match(robot, poses):
    """Read literally in our frame, Table 2 misses Table 3 by up to ~0.19 mm: why frame='paper'."""
    diffs = [abs(home_error(robot, VirtualPlant(robot, group_errors(g, "literal"))) - PAPER_TABLE3[g][2])
             for g in GROUPS]
    assert max(diffs) > 0.15


@pytest.mark.parametrize("group", [1, 4])
def test_noise_free_group_run_matches_table6_and_geometric_floor(robot, group):
    """Noise-free: the mean condition number over 20 identifications (the first included) is the
    paper's Table 6 within 0.05; the geometric errors alone leave < 0.01 deg."""
    r = run_group(robot, group, noise=None)
    assert r["kappa_mean"] == pytest.approx(PAPER_TABLE6[group], abs=0.05)
    assert max(r["delta_deg"]) < (0.01 if group <= 3 else 0.001)
    assert r["dp0_before_mm"] == pytest.approx(PAPER_TABLE3[group][2], abs=0.002)
    assert len(r["history"]["compensation_deg"]) == 20


def test_reproduce_keys_and_trials(robot):
    rep = reproduce(robot, trials=2, noise="scale-only", groups=(1, 5), max_iter=5)
    keys = {"group", "compensation_deg", "delta_deg", "dp0_before_mm", "dp0_after_mm", "dpmax_before_mm",
            "dpmax_after_mm", "delta_maemm_mm", "kappa_mean"}
    for g in rep["groups"]:
        assert keys <= set(g) and "delta_deg_std" in g and g["trials"] == 2
    assert [p["group"] for p in rep["paper"]] == [1, 5]
    assert rep["crlb_zero_offsets_deg"]["paper"][0] == pytest.approx(0.522, abs=0.002)
    assert rep["crlb_zero_offsets_deg"]["scale-only"][0] == pytest.approx(0.048, abs=0.001)
    with pytest.raises(ZerocalError):
        reproduce(robot, groups=(0,))
    with pytest.raises(ZerocalError):
        reproduce(robot, noise="loud")


@pytest.mark.slow
def test_accuracy_scale_only_vs_paper_noise(robot, poses):
    """delta over trials: at the CRLB level with the scale error alone (~0.05 deg, as the paper),
    an order of magnitude larger (~0.5 deg) with the servo error of Eq. 35."""
    def rms_delta(noise, trials):
        d = []
        for g in (1, 4):
            plant = VirtualPlant(robot, group_errors(g))
            for s in range(trials):
                loop = calibration_loop(robot, plant, poses, noise=noise, rng=[s, g])
                d.append(loop.compensation_deg - np.degrees(group_errors(g)[:2]))
        return np.sqrt(np.mean(np.square(d)))

    scale = rms_delta(NoiseModel.named("scale-only"), 40)
    paper = rms_delta(NoiseModel.paper(), 40)
    assert 0.025 < scale < 0.08
    assert 0.25 < paper < 0.8


# ---------------------------------------------------------------- loops in lockstep, a shared first round
def test_calibration_loops_in_lockstep_are_the_single_loops(robot, poses):
    """calibration_loops with the batched TSVD = calibration_loop per seed (bit for bit), the first round shared."""
    from functools import partial

    from zerocal_sym.errors import IdentificationError
    from zerocal_sym.identify.loop import calibration_loops
    from zerocal_sym.identify.tsvd import identify_tsvd, identify_tsvd_many

    plant = VirtualPlant(robot, group_errors(1))
    noise = NoiseModel.paper()
    th = kin.ik(robot, poses)
    lean = partial(identify_tsvd, diagnostics=False)
    seeds = [np.random.SeedSequence([4, k]) for k in range(7)]
    single = [calibration_loop(robot, plant, poses, identify=lean, noise=noise, rng=np.random.default_rng(ss),
                               max_iter=6, kappa=False) for ss in seeds]
    firsts, rngs = [], []
    for ss in seeds:  # the first round simulated outside, the loop continuing the same generator
        g = np.random.default_rng(ss)
        firsts.append(simulate_round(robot, plant, poses, None, noise, g, theta=th))
        rngs.append(g)
    one = calibration_loop(robot, plant, poses, identify=lean, noise=noise, rng=rngs[0], max_iter=6, kappa=False,
                           theta=th, first=firsts[0])
    np.testing.assert_array_equal(one.compensation_deg, single[0].compensation_deg)
    rngs[0], firsts[0] = np.random.default_rng(seeds[0]), None  # loop 0 simulates its own first round
    calls = []

    def many(robot_, rounds, priors):
        calls.append(len(rounds))
        return identify_tsvd_many(robot_, rounds, priors)

    runs = calibration_loops(robot, plant, poses, many, rngs, noise=noise, max_iter=6, kappa=False, theta=th,
                             firsts=firsts)
    assert calls[0] == len(seeds) and calls == sorted(calls, reverse=True)
    for (loop, n_id, secs), ref in zip(runs, single):
        assert n_id == len(ref.history) == len(loop.history)
        assert secs > 0 and loop.converged == ref.converged and loop.iterations == ref.iterations
        np.testing.assert_array_equal(loop.compensation_deg, ref.compensation_deg)
        np.testing.assert_array_equal(loop.maemm_mm, ref.maemm_mm)
        assert [h.mu_deg for h in loop.history] == [h.mu_deg for h in ref.history]

    def fails_in_round_2(robot_, rounds, priors):  # the second loop's second identification fails
        out = identify_tsvd_many(robot_, rounds, priors)
        if np.any(priors[0][:2]) and not failed:
            failed.append(1)
            out[1] = IdentificationError("no")
        return out

    failed = []

    runs = calibration_loops(robot, plant, poses, fails_in_round_2, [np.random.default_rng(s) for s in seeds[:3]],
                             noise=noise, max_iter=6, catch=(IdentificationError,))
    assert isinstance(runs[1][0], IdentificationError) and runs[1][1] == 2
    assert not isinstance(runs[0][0], Exception) and not isinstance(runs[2][0], Exception)
    failed.clear()
    with pytest.raises(IdentificationError):  # not caught: propagates
        calibration_loops(robot, plant, poses, fails_in_round_2, [np.random.default_rng(s) for s in seeds[:3]],
                          noise=noise, catch=())
