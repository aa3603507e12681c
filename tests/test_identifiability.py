"""Identifiability of the paper's robot: rigid-motion invariance, rank, null space, gauge.

(The same properties for every mechanism: tests/test_contract.py.)"""
import numpy as np
import pytest
from hypothesis import given, strategies as st

from zerocal_sym.identify import fisher
from zerocal_sym.identify import identifiability as idf
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors

import planar_gauge as pg
from roundoff import cond_tol


@pytest.fixture(scope="module")
def th12(robot):
    return kin.ik(robot, paper_poses(robot, 6))


@given(angle=st.floats(-0.05, 0.05), sx=st.floats(-3, 3), sy=st.floats(-3, 3), group=st.integers(1, 6))
def test_rigid_motion_leaves_every_distance_unchanged(robot, th12, angle, sx, sy, group):
    err = table2_errors(group)
    moved = pg.rigid_motion(robot, err, angle, (sx, sy))
    np.testing.assert_allclose(kin.distance(robot, th12, moved), kin.distance(robot, th12, err), atol=1e-9)


def test_generators_span_the_null_space_of_all_twelve(robot, th12):
    for err in (None, table2_errors(1)):
        A = fisher.sensitivity(robot, th12, "all", err)
        G = idf.gauge_generators(robot, err)
        assert np.max(np.abs(A @ G.T)) < 1e-9 * np.max(np.abs(A))
        # the generated generators are the tangents of the exact finite rigid motions
        np.testing.assert_allclose(G, pg.rigid_motion_generators(robot, err)[[0, 1, 2]], atol=1e-12)
    rep = idf.identifiability_report(robot, th12, "all")
    assert rep["rank"] == 9 and rep["null_space_rigid"] is True
    assert not any(rep["identifiable"].values()) or rep["identifiable"]["L1"]
    assert rep["identifiable"]["L1"] and not rep["identifiable"]["theta1"]


def test_paper_set_full_rank_and_weak_common_mode(robot):
    th = kin.ik(robot, paper_poses(robot, 3))
    rep = idf.identifiability_report(robot, th, "paper")
    assert rep["rank"] == 4 and rep["null_space"] == []
    weakest = {t["param"]: t["weight"] for t in rep["directions"][-1]["combination"]}
    # the common-mode offset mixed with rMx: the rotation gauge, broken only by the nominal base line
    assert abs(weakest["theta1"]) == pytest.approx(1.0) and weakest["theta1"] == pytest.approx(weakest["theta2"],
                                                                                                 abs=1e-2)
    assert abs(weakest["rMx"]) > 0.2
    cr = fisher.crlb(robot, th, "paper", NoiseModel.paper())
    # two inverses of one information (the report's SVD, crlb's inv of the normalised F): each to cond(F) EPS, the
    # std half of it; 4 for forming F on two routes
    F = fisher.fisher_information(robot, th, "paper", NoiseModel.paper())
    sc = np.sqrt(np.diag(F))
    np.testing.assert_allclose([rep["crlb_std"][n] for n in rep["params"]], np.sqrt(np.diag(cr)),
                               rtol=cond_tol(np.linalg.cond(F / np.outer(sc, sc)), 4))
    assert "NOT IDENTIFIABLE" not in idf.format_report(rep)


def test_gauge_params_need_enough_poses(robot, th12):
    assert idf.identifiability_report(robot, th12, "gauge_fixed")["rank"] == 9
    th6 = kin.ik(robot, paper_poses(robot, 3))
    rep = idf.identifiability_report(robot, th6, "gauge_fixed")
    assert rep["rank"] == 5 and "NOT IDENTIFIABLE" in idf.format_report(rep)


def test_to_base_gauge(robot, th12):
    err = table2_errors(1)
    g = pg.to_base_gauge(robot, err)
    assert np.all(g[[2, 3, 5]] == 0.0)
    np.testing.assert_allclose(kin.distance(robot, th12, g), kin.distance(robot, th12, err), atol=1e-9)
    np.testing.assert_allclose(g[6:10], err[6:10])  # lengths are invariant
    np.testing.assert_allclose(pg.recovery_error(robot, pg.rigid_motion(robot, err, 0.01, (1, 2)), err), 0,
                               atol=1e-9)


def test_parameter_scale_and_sets(robot):
    assert robot.errors.resolve("paper+L1,L2") == ("theta1", "theta2", "L1", "L2", "rMx", "rMy")
    assert robot.errors.resolve("offsets+measuring") == robot.errors.resolve("paper")
    np.testing.assert_allclose(fisher.parameter_scale(robot, "paper"), [375, 375, 1, 1])
    with pytest.raises(ValueError):
        robot.errors.indices("")
