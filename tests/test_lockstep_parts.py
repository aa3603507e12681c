"""The lockstep Monte Carlo's batched parts give what their one-at-a-time twins give, bit for bit.

``VirtualPlant.measure_many`` (the rounds of several loops, their lengths in one mapped call) against
``VirtualPlant.measure`` one round at a time, each with its own generator, for every noise term (the shared
revisit error included); ``simulate_rounds`` against ``simulate_round``; ``max_tests`` against ``max_test``.
"""
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.identify.check.max_reading import max_test, max_tests
from zerocal_sym.identify.loop import simulate_round, simulate_rounds
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot, paper_robot

ROOT = Path(__file__).resolve().parents[1]


def _robot(which):
    return paper_robot() if which == "planar" else load_robot(ROOT / "examples" / f"{which}.toml")


def _plant_and_poses(robot, seed):
    """A plant with random small source errors and K = 8 poses around home, the first revisited at the end."""
    rng = np.random.default_rng(seed)
    err = robot.errors.zeros() + 1e-3 * rng.standard_normal(len(robot.errors))
    th = robot.home_joints() + 0.02 * rng.standard_normal((7, robot.m))
    th = np.vstack([th, th[:1]])
    return VirtualPlant(robot, err), th


@pytest.mark.parametrize("which", ["planar", "delta"])
@pytest.mark.parametrize("noise", [NoiseModel.paper(), NoiseModel(0.002, 0.0, 0.003), NoiseModel(0.0, 0.0, 0.0)],
                         ids=["paper", "scale+revisit", "none"])
def test_measure_many_is_measure_bit_for_bit(which, noise):
    robot = _robot(which)
    plant, th = _plant_and_poses(robot, 1)
    cmds = [th - 1e-3 * k for k in range(5)]
    alone = [plant.measure(c, noise, np.random.default_rng(k)) for k, c in enumerate(cmds)]
    gens = [np.random.default_rng(k) for k in range(len(cmds))]
    many = plant.measure_many(cmds, noise, gens)
    for a, b in zip(alone, many):
        assert a.tobytes() == b.tobytes()
    # every generator left where measure leaves it: the next draws agree
    after = [np.random.default_rng(k) for k in range(len(cmds))]
    for c, g in zip(cmds, after):
        plant.measure(c, noise, g)
    assert [g.random() for g in gens] == [g.random() for g in after]


def test_simulate_rounds_is_simulate_round():
    robot = paper_robot()
    plant, _ = _plant_and_poses(robot, 2)
    poses = robot.home_pose() + np.array([[0, 0], [60, 0], [-60, 0], [0, 40], [0, -40], [40, 40]], float)
    theta = kin.ik(robot, poses)
    noise = NoiseModel.paper()
    comps = [np.zeros(robot.m), np.array([1e-3, -2e-3]), np.array([-4e-4, 5e-4])]
    alone = [simulate_round(robot, plant, poses, c, noise, np.random.default_rng(7 + k), theta=theta)
             for k, c in enumerate(comps)]
    many = simulate_rounds(robot, plant, poses, [(c, theta, np.random.default_rng(7 + k))
                                                 for k, c in enumerate(comps)], noise)
    for a, b in zip(alone, many):
        assert a.theta_cmd.tobytes() == b.theta_cmd.tobytes()
        assert a.readings.tobytes() == b.readings.tobytes()


def test_max_tests_is_max_test_per_column():
    rng = np.random.default_rng(3)
    T = rng.standard_normal((9, 6)) * 2.5
    T[2, 1] = np.nan
    T[:, 4] = np.nan  # no testable reading: None
    T[5, 5] = 6.0     # one far off: rejected
    D = rng.standard_normal((9, 6))
    poses = np.arange(1, 10)
    got = max_tests(T, poses, D, 1e-3)
    want = [max_test(T[:, c], poses, D[:, c], 1e-3, True) for c in range(T.shape[1])]
    assert got == want
    assert got[4] is None and got[5]["rejected"]
