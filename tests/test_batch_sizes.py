"""The batched path's pieces: p-values computed at once, mapped Functions per power of two."""
import math

import numpy as np

from zerocal_sym.identify.chi2 import chi2_sf, chi2_sf_array


def test_vectorised_p_values_are_the_scalar_ones_bit_for_bit():
    rng = np.random.default_rng(0)
    for dof in (1, 2, 5, 17, 300, 2.5):
        x = np.concatenate([rng.chisquare(dof, 400), [0.0, 1e-300, 1e-5, dof + 2, 1e3, 1e4, np.inf, np.nan]])
        a = chi2_sf_array(x, dof)
        b = np.array([chi2_sf(v, dof) for v in x])
        assert np.array_equal(a, b, equal_nan=True), dof
    assert chi2_sf_array(np.array([[1.0, 2.0]]), 3).shape == (1, 2)
    assert math.isnan(chi2_sf_array([np.nan], 2)[0])


def test_batch_functions_per_power_of_two_give_each_column_alone():
    """N data sets through the Function mapped over the next power of two (padded): each column the same bits as
    that data set alone, and one Function serves every N up to its size."""
    from zerocal_sym.identify.estimate import nlls_problem
    from zerocal_sym.identify.batch import identify_batch
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.paper.tables import group_errors

    assert [nlls_problem.batch_size(n) for n in (1, 2, 3, 4, 5, 1000)] == [1, 2, 4, 4, 8, 1024]
    robot = paper_robot()
    noise = NoiseModel.paper()
    th = kin.ik(robot, paper_poses(robot, 3))
    R = np.array([VirtualPlant(robot, group_errors(1)).measure(th, noise, np.random.default_rng(k)) for k in range(7)])
    prob = nlls_problem.get_problem(robot, 6, "paper")
    prob._batch.clear()
    whole = identify_batch(robot, th, R, "paper", noise=noise)
    for k in range(7):
        one = identify_batch(robot, th, R[k], "paper", noise=noise)
        assert np.array_equal(one.estimate[0], whole.estimate[k]) and one.chi2[0] == whole.chi2[k]
    assert set(prob._batch) <= {1, 2, 4, 8}
