"""Finite planar rigid motions of the paper's robot (test helper, planar only).

The runtime knows the gauge to first order (the generated ``gauge``
generators, :func:`zerocal_sym.identify.identifiability.gauge_generators`);
these exact finite motions check that invariance beyond first order and map
an error vector to the base-joint gauge exactly (``e1x = e1y = e2y = 0``).
"""
import numpy as np

from zerocal_sym.model import kinematics as kin

BASE_GAUGE = ("e1x", "e1y", "e2y")
_Q = np.array([[0.0, -1.0], [1.0, 0.0]])
NAMES = ("theta1", "theta2", "e1x", "e1y", "e2x", "e2y", "L1", "L2", "l1", "l2", "rMx", "rMy")


def _ix(name):
    return NAMES.index(name)


def _points(robot, err):
    """Actual base joints A1, A2 and the effective measuring base point c + d + rM."""
    err = np.zeros(12) if err is None else np.asarray(err, float)
    A1 = np.array([robot.param("e1x") + err[_ix("e1x")], robot.param("e1y") + err[_ix("e1y")]])
    A2 = np.array([robot.param("e2x") + err[_ix("e2x")], robot.param("e2y") + err[_ix("e2y")]])
    M = np.array([robot.param("cx") + robot.param("dx") + err[_ix("rMx")],
                  robot.param("cy") + robot.param("dy") + err[_ix("rMy")]])
    return A1, A2, M


def rigid_motion_generators(robot, err=None) -> np.ndarray:
    """The three directions of the source errors invisible to distance changes.

    Parameters
    ----------
    robot : Robot
        A ``planar_2dof`` robot.
    err : ndarray, shape (12,), optional
        Point at which the (tangent) directions are taken (default zero).

    Returns
    -------
    ndarray, shape (3, 12)
        Rows: translation x, translation y (per mm), rotation about O (per rad).
    """
    if robot.mechanism_name != "planar_2dof":
        raise NotImplementedError(f"rigid motions of mechanism {robot.mechanism_name!r} are not described")
    A1, A2, M = _points(robot, err)
    G = np.zeros((3, 12))
    G[0, [_ix("e1x"), _ix("e2x"), _ix("rMx")]] = 1.0
    G[1, [_ix("e1y"), _ix("e2y"), _ix("rMy")]] = 1.0
    G[2, [_ix("theta1"), _ix("theta2")]] = 1.0
    G[2, [_ix("e1x"), _ix("e1y")]] = _Q @ A1
    G[2, [_ix("e2x"), _ix("e2y")]] = _Q @ A2
    G[2, [_ix("rMx"), _ix("rMy")]] = _Q @ M
    return G


def rigid_motion(robot, err, angle: float, shift=(0.0, 0.0)) -> np.ndarray:
    """Source errors of the same measurements after a finite planar rigid motion.

    ``X -> R(angle) X + shift`` applied to the robot and to the measuring
    base point; every ``rho`` is unchanged (exactly, not to first order).

    Parameters
    ----------
    err : ndarray, shape (12,)
    angle : float
        rad.
    shift : (2,)
        mm.

    Returns
    -------
    ndarray, shape (12,)
    """
    err = np.asarray(err, float).copy()
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    t = np.asarray(shift, float)
    A1, A2, M = _points(robot, err)
    out = err.copy()
    out[[_ix("theta1"), _ix("theta2")]] += angle
    out[[_ix("e1x"), _ix("e1y")]] = R @ A1 + t - np.array([robot.param("e1x"), robot.param("e1y")])
    out[[_ix("e2x"), _ix("e2y")]] = R @ A2 + t - np.array([robot.param("e2x"), robot.param("e2y")])
    cd = np.array([robot.param("cx") + robot.param("dx"), robot.param("cy") + robot.param("dy")])
    out[[_ix("rMx"), _ix("rMy")]] = R @ M + t - cd
    return out


def to_base_gauge(robot, err) -> np.ndarray:
    """The equivalent source errors with ``e1x = e1y = e2y = 0``.

    The rigid motion that puts the actual ``A1`` on its nominal position and
    the actual ``A2`` on the nominal base line (same ``y``); the result gives
    the same distances as ``err`` for every command.

    Parameters
    ----------
    err : ndarray, shape (12,)

    Returns
    -------
    ndarray, shape (12,)
    """
    A1, A2, _ = _points(robot, err)
    A1n = np.array([robot.param("e1x"), robot.param("e1y")])
    A2n = np.array([robot.param("e2x"), robot.param("e2y")])
    d, dn = A2 - A1, A2n - A1n
    angle = np.arctan2(dn[1], dn[0]) - np.arctan2(d[1], d[0])
    angle = (angle + np.pi) % (2 * np.pi) - np.pi
    c, s = np.cos(angle), np.sin(angle)
    shift = A1n - np.array([[c, -s], [s, c]]) @ A1
    out = rigid_motion(robot, err, angle, shift)
    gauge = [_ix(n) for n in BASE_GAUGE]
    out[gauge] = np.where(np.abs(out[gauge]) < 1e-12, 0.0, out[gauge])  # exact zeros, not round-off
    return out


def recovery_error(robot, estimate_err, true_err) -> np.ndarray:
    """Differences in the base gauge, shape (12,) (rad, mm).

    Both error vectors are mapped by :func:`to_base_gauge` before subtracting,
    so the three rigid-motion combinations do not count.
    """
    return to_base_gauge(robot, estimate_err) - to_base_gauge(robot, true_err)


def check_rigid_invariance(robot, theta_cmd, err, angle=1e-3, shift=(0.5, -0.3)) -> float:
    """Largest change of ``rho`` under a rigid motion of ``err`` (should be ~1e-12 mm)."""
    a = kin.distance(robot, theta_cmd, err)
    b = kin.distance(robot, theta_cmd, rigid_motion(robot, err, angle, shift))
    return float(np.max(np.abs(a - b)))
