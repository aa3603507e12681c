"""Kinematics and error models: generated CasADi functions against independent checks."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import twin
from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import PoseError
from zerocal_sym.model.noise import VirtualPlant

xs = st.floats(-240, 240)
ys = st.floats(632, 782)


def test_home_position(robot):
    P0 = robot.home_pose()
    assert P0 == pytest.approx([0.0, 688.186], abs=5e-4)
    assert kin.ik(robot, P0[None])[0] == pytest.approx([0.0, np.pi], abs=1e-9)


@given(x=xs, y=ys)
def test_fk_inverts_ik_over_workspace(robot, x, y):
    P = np.array([[x, y]])
    th = kin.ik(robot, P)
    assert kin.fk(robot, th)[0] == pytest.approx(P[0], abs=1e-8)


@given(x=xs, y=ys)
def test_against_independent_numpy_twin(robot, x, y):
    P = np.array([x, y])
    th = kin.ik(robot, P[None])[0]
    assert th == pytest.approx(twin.ik(robot.geometry, P), abs=1e-9)
    assert kin.fk(robot, th[None])[0] == pytest.approx(twin.fk(robot.geometry, th), abs=1e-7)


def test_batched_matches_single(robot):
    P = robot.workspace_grid(7, 3)
    th = kin.ik(robot, P)
    for k in (0, 5, 20):
        assert th[k] == pytest.approx(kin.ik(robot, P[k:k + 1])[0], abs=1e-12)
    J = kin.error_jacobian(robot, P)
    assert J.shape == (21, 2, 2)
    assert J[5] == pytest.approx(kin.error_jacobian(robot, P[5:6])[0], abs=1e-12)


def _perturbed_pose(robot, theta, err):
    return VirtualPlant(robot, err).actual_pose(theta[None])[0]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_pose_error_jacobian_central_differences(robot, seed):
    """dP/d(source error) of the implicit differentiation vs central differences of exact FK."""
    rng = np.random.default_rng(seed)
    P = np.array([rng.uniform(-240, 240), rng.uniform(632, 782)])
    _assert_jacobian_matches_central_differences(robot, P)


def _assert_jacobian_matches_central_differences(robot, P):
    th = kin.ik(robot, P[None])[0]
    J = kin.pose_error_jacobian(robot, P[None])[0]
    assert np.all(np.isfinite(J))
    for j in range(10):
        h = 1e-6 if j < 2 else 1e-4
        e = np.zeros(12)
        e[j] = h
        fd = (_perturbed_pose(robot, th, e) - _perturbed_pose(robot, th, -e)) / (2 * h)
        assert J[:, j] == pytest.approx(fd, rel=1e-5, abs=1e-6), robot.errors.names[j]


def test_paper_jacobians_are_scaled_source_jacobian(robot):
    P = robot.workspace_grid(5, 3)
    Jsrc = kin.pose_error_jacobian(robot, P)
    Jfull = kin.error_jacobian_full(robot, P)
    J = kin.error_jacobian(robot, P)
    L1, L2 = robot.params(["L1", "L2"])
    # the simplified J equals the zero-offset columns of J'
    assert J[:, :, 0] == pytest.approx(Jfull[:, :, 0], abs=1e-14)
    assert J[:, :, 1] == pytest.approx(Jfull[:, :, 5], abs=1e-14)
    assert Jfull[:, :, 0] * L1 == pytest.approx(Jsrc[:, :, 0], abs=1e-12)
    assert Jfull[:, :, 5] * L2 == pytest.approx(Jsrc[:, :, 1], abs=1e-12)
    # paper order (e1x e1y L1 l1 | e2x e2y L2 l2) vs ours (e1x e1y e2x e2y L1 L2 l1 l2)
    for paper_col, ours in [(1, 2), (2, 3), (3, 6), (4, 8), (6, 4), (7, 5), (8, 7), (9, 9)]:
        assert Jfull[:, :, paper_col] == pytest.approx(Jsrc[:, :, ours], abs=1e-12)


def test_paper_closed_form_J(robot):
    """J = W^-1 diag(w_i^T Q u_i), written here from the paper's Eq. (13) in numpy."""
    Q = np.array([[0, -1], [1, 0]])
    for P in robot.workspace_grid(5, 3):
        th = kin.ik(robot, P[None])[0]
        e, L, l = twin.geometry_parts(robot.geometry)
        u = [np.array([np.cos(t), np.sin(t)]) for t in th]
        w = [(P - e[i] - L[i] * u[i]) / l[i] for i in range(2)]
        W = np.vstack(w)
        Jp = np.linalg.solve(W, np.diag([w[0] @ Q @ u[0], w[1] @ Q @ u[1]]))
        assert kin.error_jacobian(robot, P[None])[0] == pytest.approx(Jp, abs=1e-12)


def test_g_rows_and_measuring(robot):
    P = robot.workspace_grid(5, 3)
    lam, lam_hat = kin.measuring_vector(robot, P)
    c = np.array([robot.param("cx"), robot.param("cy")])
    d = np.array([robot.param("dx"), robot.param("dy")])
    v = P - c - d
    assert lam == pytest.approx(np.linalg.norm(v, axis=1), abs=1e-10)
    assert lam_hat == pytest.approx(v / lam[:, None], abs=1e-12)
    g = kin.g_rows(robot, P)
    J = kin.error_jacobian(robot, P)
    for k in range(len(P)):
        assert g[k] == pytest.approx(lam_hat[k] @ np.hstack([J[k], -np.eye(2)]), abs=1e-12)


def test_distance_exact_and_first_order(robot):
    P = robot.workspace_grid(5, 3)
    th = kin.ik(robot, P)
    lam, _ = kin.measuring_vector(robot, P)
    assert kin.distance(robot, th) == pytest.approx(lam, abs=1e-9)
    # first order: d rho = g (L dth, drM) for a small error
    err = np.zeros(12)
    err[[0, 1, 10, 11]] = [1e-6, -2e-6, 1e-4, 5e-5]
    g = kin.g_rows(robot, P)
    dq = np.array([robot.param("L1") * err[0], robot.param("L2") * err[1], err[10], err[11]])
    assert kin.distance(robot, th, err) - lam == pytest.approx(g @ dq, abs=1e-9)


def test_distance_jacobians_central_differences(robot, rng):
    th = kin.ik(robot, robot.workspace_grid(3, 2))
    err0 = rng.normal(0, 1e-3, 12)
    rho, de, dt = kin.distance_jacobians(robot, th, err0)
    for j in range(12):
        e = np.zeros(12)
        e[j] = 1e-6
        fd = (kin.distance(robot, th, err0 + e) - kin.distance(robot, th, err0 - e)) / 2e-6
        assert de[:, j] == pytest.approx(fd, rel=1e-5, abs=1e-5)


def test_unreachable_pose_names_index(robot):
    P = np.array([[0.0, 700.0], [0.0, 5000.0]])
    with pytest.raises(PoseError, match="pose 1"):
        kin.ik(robot, P)


def test_check_poses_singularity_margin(robot):
    P = np.array([[0.0, 700.0]])
    kin.check_poses(robot, P)
    with pytest.raises(PoseError, match="singular"):
        kin.check_poses(robot, P, margin=0.99)
    with pytest.raises(PoseError, match="outside the workspace"):
        kin.check_poses(robot, np.array([[0.0, 600.0]]), in_workspace=True)


def test_error_jacobian_has_no_spurious_singularity(robot):
    """At P straight above B1 (w1 = (0, 1)) the Jacobian is regular; only det W may vanish.

    (An LU-pivoted implicit differentiation divides by w1x and gives inf here.)
    """
    P = np.array([robot.param("e1x") + robot.param("L1"), robot.param("e1y") + robot.param("l1")])
    assert kin.ik(robot, P[None])[0, 0] == pytest.approx(0.0, abs=1e-12)
    _assert_jacobian_matches_central_differences(robot, P)
