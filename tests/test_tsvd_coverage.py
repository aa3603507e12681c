"""TSVD's std per parameter, against the exact virtual plant: how often |error| <= 2 std over 2000 rounds.

Each round is simulated by :class:`~zerocal_sym.model.noise.VirtualPlant` (the exact kinematics with the true
source errors, the servo error on the joints, the scale error on each change: nothing of the estimator's
linearisation), identified by the batched path (``identify_tsvd_many(..., noise=...)``, the std as
``identify_tsvd`` computes it) and its error divided by the reported std.

Acceptance: the coverage of ``|z| <= 2`` must be in [0.93, 0.97] for a parameter whose std is honest
(``"total"``) in at least 90 % of the rounds, and at least 0.93 for every parameter (a std labelled ``"bound"``
may cover more, never less).  The band is widened by the sampling error of the rounds: a coverage fails only
when it lies more than 2.58 binomial standard errors (at the band's edge, ``sqrt(c (1 - c) / rounds)``) outside
the band -- a 1 % chance per check for a true coverage on the edge.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.identify.tsvd import identify_tsvd_many
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot, paper_robot
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import group_errors

ROOT = Path(__file__).resolve().parents[1]
ROUNDS = 2000
BAND = (0.93, 0.97)
Z = 2.58
#: a parameter is held to the band when its std is honest in at least this fraction of the rounds
HONEST_MAJORITY = 0.9


def _edge(c):
    return Z * math.sqrt(c * (1.0 - c) / ROUNDS)


LOW, HIGH = BAND[0] - _edge(BAND[0]), BAND[1] + _edge(BAND[1])


def _scenario(which):
    """(robot, truth (q,), poses) of each mechanism: its default noise, moderate offsets, the default scheme."""
    if which == "planar":
        robot = paper_robot()  # Table 2 group 1 in the paper's frame, the 4-parameter model exact
        return robot, robot.errors.put(group_errors(1, "paper"), robot.errors.geometry, 0.0), paper_poses(robot, 3)
    robot = load_robot(ROOT / "examples" / f"{which}.toml")
    e = robot.errors
    offsets, maemm, n = {"delta": ((1.2, -0.7, 0.3), (0.5, -0.2, 0.1), 6),
                         "linear_delta": ((0.6, -0.35, 0.15), (0.5, -0.2, 0.0), 6),  # rMz: not identified
                         "hexapod": ((0.3, -0.2, 0.1, 0.25, -0.15, 0.05), (0.5, -0.2, 0.1, 0.3, 0.2, -0.4), 16)}[which]
    return robot, e.assemble(None, None, maemm, zero_offsets_user=offsets), robot.workspace.boundary_scheme(n)


def _rounds(robot, truth, P, noise, seed):
    """ROUNDS rounds at the poses P, all at once: exact distances with the servo error, then the scale error."""
    th = kin.ik(robot, P)
    K = th.shape[0]
    rng = np.random.default_rng(seed)
    rho = VirtualPlant(robot, truth).lengths(np.tile(th, (ROUNDS, 1)), noise, rng).reshape(ROUNDS, K)
    s = np.diff(rho, axis=1) + rng.normal(0.0, noise.sigma_scale_mm, (ROUNDS, K - 1))
    return [Measurements(th, np.concatenate([[0.0], si])) for si in s]


def _coverage(robot, truth, rounds, noise, iterations=1):
    """Per parameter: the fraction of rounds with |error| <= 2 std, and the fraction whose std is honest."""
    priors = None
    for _ in range(iterations - 1):
        priors = [r.full_vector() for r in identify_tsvd_many(robot, rounds, priors)]
    res = identify_tsvd_many(robot, rounds, priors, noise=noise)
    names = res[0].params
    assert all(r.params == names and r.covariance is not None for r in res)
    err = np.array([r.estimate for r in res]) - robot.errors.take(truth, names)
    std = np.array([np.sqrt(np.diag(r.covariance)) for r in res])
    honest = np.array([[r.info["std_kinds"][n] == "total" for n in names] for r in res])
    noise_sd = np.array([np.sqrt(np.diag(r.info["covariance_noise"])) for r in res])
    # the diagnosis: the noise alone (its spread against the one propagated, how often it covers the error)
    print("noise alone: sd(error) / noise std", np.round(np.std(err, axis=0) / np.mean(noise_sd, axis=0), 3),
          "; |error| <= 2 noise std", np.round(np.mean(np.abs(err) <= 2 * noise_sd, axis=0), 4))
    return names, np.mean(np.abs(err) <= 2 * std, axis=0), honest.mean(axis=0)


def _check(names, cover, honest):
    print({n: (round(float(c), 4), round(float(h), 3)) for n, c, h in zip(names, cover, honest)})
    for n, c, h in zip(names, cover, honest):
        assert c >= LOW, f"{n}: |z| <= 2 in {c:.4f} of the rounds, below {BAND[0]} beyond the sampling error"
        if h >= HONEST_MAJORITY:
            assert c <= HIGH, f"{n}: honest std, |z| <= 2 in {c:.4f} of the rounds, above {BAND[1]}"


#: per mechanism: the parameters whose one-step std must be honest in most rounds, and those that must be bounds
EXPECTED = {
    "planar": (set(), {"theta1", "theta2", "rMx"}),  # 2 deg offsets: a bias of 0.17-0.34 sd, not known well enough
    "delta": (set(), {"rMx", "rMy"}),  # ring n = 6: the bias of rMx and rMy is not known within the noise
    "linear_delta": ({"s1", "s2", "s3", "rMx", "rMy"}, set()),
    "hexapod": ({"L1", "L2", "L3", "L4", "L5", "L6", "rMx", "rMy", "rMz", "ddx", "ddy", "ddz"}, set()),
}


@pytest.mark.slow
@pytest.mark.parametrize("which", ["planar", "delta", "linear_delta", "hexapod"])
def test_one_step_tsvd_std_covers_its_error(which):
    """The paper's one-step TSVD: honest where its linearisation bias is small and well determined, else a bound
    that covers at least as often as it says."""
    robot, truth, P = _scenario(which)
    noise = NoiseModel.of_robot(robot)
    names, cover, honest = _coverage(robot, truth, _rounds(robot, truth, P, noise, seed=11), noise)
    _check(names, cover, honest)
    want_honest, want_bound = EXPECTED[which]
    for n, h in zip(names, honest):
        if n in want_honest:
            assert h >= HONEST_MAJORITY, (n, h)
        if n in want_bound:
            assert h <= 1 - HONEST_MAJORITY, (n, h)


@pytest.mark.slow
@pytest.mark.parametrize("which", ["planar", "delta", "linear_delta"])
def test_iterated_tsvd_std_is_honest(which):
    """An iterated TSVD (relinearised at its estimate until it stops moving) has no linearisation bias: every
    parameter's std is honest and in the band."""
    robot, truth, P = _scenario(which)
    noise = NoiseModel.of_robot(robot)
    names, cover, honest = _coverage(robot, truth, _rounds(robot, truth, P, noise, seed=12), noise, iterations=6)
    assert np.all(honest >= 0.99), dict(zip(names, honest))
    _check(names, cover, honest)
