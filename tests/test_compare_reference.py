"""`compare` reports the same numbers, bit for bit, for every row: before and after its Ipopt loops ran in lockstep
through the mapped Gauss-Newton (tests/compare_cases.py wrote the reference with the code before), and with the
lockstep against one loop after the other in this process."""
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import compare_cases as cc  # noqa: E402

from zerocal_sym.identify import montecarlo  # noqa: E402

REFERENCE = json.loads(cc.REFERENCE.read_text())
SAME_VERSIONS = REFERENCE["versions"] == cc.versions()


def _ids(slow=("hexapod",)):
    return [pytest.param(c[0], marks=pytest.mark.slow) if c[0] in slow else c[0] for c in cc.CASES]


def _case(cid):
    return next(c for c in cc.CASES if c[0] == cid)


@pytest.mark.parametrize("cid", _ids())
def test_compare_reports_the_reference_bit_for_bit(cid):
    """Every number of every row (the errors, their quantiles, dp0, failures, loops not converged,
    identifications per trial, the scipy reference's difference) equal to the reference's: on the library
    versions that wrote it (other builds may change the last bits, and a loop's stop with them: there the next
    test holds the lockstep to the one-by-one loops in the same process)."""
    if not SAME_VERSIONS:
        pytest.skip(f"the reference was written with {REFERENCE['versions']}, this is {cc.versions()}")
    assert cc.run_case(_case(cid)) == REFERENCE["cases"][cid]


@pytest.mark.parametrize("cid", [c for c in _ids(slow=("paper-g1-g4",)) if c != "hexapod"])
def test_lockstep_loops_equal_one_loop_after_the_other(cid, monkeypatch):
    """The Ipopt loops of a chunk in lockstep (each round through the mapped Gauss-Newton, confirmed by Ipopt's
    first-order test, the others by identify_nlls) and one after the other with identify_nlls: the same report."""
    case = _case(cid)
    monkeypatch.setattr(montecarlo, "NLLS_LOCKSTEP", True)
    lockstep = cc.run_case(case)
    monkeypatch.setattr(montecarlo, "NLLS_LOCKSTEP", False)
    assert cc.run_case(case) == lockstep


def test_lockstep_rounds_are_identify_nlls_results():
    """identify_rounds on rounds of different compensations and priors (a sequential MAP's covariance among
    them): each round's estimate, covariance, success and verdict are identify_nlls's, bit for bit."""
    import numpy as np

    from zerocal_sym.identify.nlls import identify_nlls
    from zerocal_sym.identify.nlls_rounds import identify_rounds
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.paper.tables import group_errors

    robot = cc.robot_of("paper")
    e = robot.errors
    noise = NoiseModel.paper()
    names = e.resolve("paper")
    plant = VirtualPlant(robot, group_errors(1))
    th0 = kin.ik(robot, paper_poses(robot, 3))
    rng = np.random.default_rng(3)
    rounds, priors, covs = [], [], []
    for k in range(12):
        comp = np.radians(rng.normal(0, 1.0, 2)) * (k % 3 != 0)
        th = th0 - comp
        rd = plant.measure(th, noise, rng)
        if k == 5:
            rd[3] += 0.5  # a bad reading: rejected (a misfit the loop uses)
        rounds.append(Measurements(th, rd))
        priors.append(e.put(e.put(e.zeros(), e.zero_offsets, comp), e.measuring, rng.normal(0, 0.5, 2) * (k % 2)))
        covs.append(np.diag([1e-4, 1e-4, 0.25, 0.25]) if k % 4 == 1 else None)
    out = identify_rounds(robot, rounds, priors, names, noise, covs)
    lean = 0
    for m, pr, cv, res in zip(rounds, priors, covs, out):
        ref = identify_nlls(robot, m, names, noise=noise, prior=pr, prior_cov=cv)
        lean += bool(res.info.get("lean"))
        assert np.array_equal(res.estimate, ref.estimate)
        assert np.array_equal(res.covariance, ref.covariance, equal_nan=True)
        assert res.success == ref.success and res.info["fit"]["rejected"] == ref.info["fit"]["rejected"]
        assert res.status.split(":")[0].split(" (")[0] == ref.status.split(":")[0].split(" (")[0]
    assert lean >= 10 and any(r.info["fit"]["rejected"] for r in out)
