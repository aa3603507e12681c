"""Numeric kinematics on top of the generated CasADi functions.

Everything here is batched over K poses and works for every mechanism: poses
are ``ndarray, shape (K, n)`` in mm, joint angles ``ndarray, shape (K, m)`` in
radians, source errors ``ndarray, shape (q,)`` in the mechanism's order (rad,
mm; built by name with :class:`~zerocal_sym.model.source_errors.SourceErrors`).
Degrees appear only at the user-facing edges (CLI, data files, reports).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import PoseError
from zerocal_sym.model.fastcall import mapped


def fmt_pose(p, spec: str = "g") -> str:
    """``(x, y[, z])`` with ``%g`` numbers (or the format ``spec``, e.g. ``".3f"``), for messages."""
    return "(" + ", ".join(format(float(v), spec) for v in p) + ")"


def fmt_user_pose(robot, p, spec: str = "g") -> str:
    """A pose for messages in file units with its unit: ``(x, y, z) mm`` or ``(x, y, z mm, roll, pitch, yaw deg)``."""
    from zerocal_sym.model import units

    mech = robot.mechanism
    u = [units.pose_unit(mech, name) for name in mech.pose_names]
    v = units.pose_to_user(mech, np.asarray(p, float))
    if len(set(u)) == 1:
        return f"{fmt_pose(v, spec)} {u[0]}"
    parts = [format(float(x), spec) + (f" {ui}" if k + 1 == len(u) or u[k + 1] != ui else "")
             for k, (x, ui) in enumerate(zip(v, u))]
    return "(" + ", ".join(parts) + ")"


def _cols(a, n):
    a = np.asarray(a, dtype=float)
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.shape[-1] != n:
        raise ValueError(f"expected shape (K, {n}), got {a.shape}")
    return a


def call(robot, fname, *args):
    """Evaluate a generated function column-wise over K poses.

    Array arguments of shape (K, n) are passed as (n, K) to the function
    mapped over K columns (the 1-D arguments shared), through a zero-copy
    buffer (:mod:`zerocal_sym.model.fastcall`).  Returns the outputs as
    numpy arrays with shape (K, rows, cols).
    """
    arrs = [np.asarray(a, float) for a in args]
    per_pose = tuple(a.ndim == 2 for a in arrs)
    K = max(a.shape[0] for a, pp in zip(arrs, per_pose) if pp)
    f = robot.mechanism[fname]
    outs = mapped(f, K, per_pose)(*[a.T if pp else a for a, pp in zip(arrs, per_pose)])
    res = []
    for k, o in enumerate(outs):
        r, c = f.size_out(k)
        res.append(np.reshape(o, (r, c * K), order="F").reshape(r, K, c).transpose(1, 0, 2).copy())
    return res


_call = call


def ik_ratio(robot, P):
    """Inverse kinematics and the reach ratios (``|ratio| <= 1`` where a limb closes within its travel).

    Returns
    -------
    theta, ratio : ndarray, shape (K, m) each
    """
    theta, ratio = _call(robot, "ik", _cols(P, robot.n), robot.geometry)
    return theta[:, :, 0], ratio[:, :, 0]


def ik(robot, P, check: bool = True):
    """Inverse kinematics on the branch continuous with home.

    Parameters
    ----------
    robot : Robot
    P : ndarray, shape (K, n)
        Platform positions, mm.
    check : bool
        Raise :class:`PoseError` naming the first unreachable pose.

    Returns
    -------
    ndarray, shape (K, m)
        Joint angles, rad.
    """
    P = _cols(P, robot.n)
    theta, ratio = _call(robot, "ik", P, robot.geometry)
    theta = theta[:, :, 0]
    if check:
        bad = np.flatnonzero(~np.all(np.abs(ratio[:, :, 0]) <= 1.0, axis=1) | ~np.all(np.isfinite(theta), axis=1))
        if bad.size:
            k = int(bad[0])
            raise PoseError(f"pose {fmt_user_pose(robot, P[k])} is unreachable (a limb cannot close, or a joint "
                            "is beyond its travel)", where=f"pose {k}")
    return theta


def fk(robot, theta):
    """Forward kinematics (the assembly mode farther from the base).

    Parameters
    ----------
    theta : ndarray, shape (K, m)
        Joint angles, rad.

    Returns
    -------
    ndarray, shape (K, n)
        Positions, mm; NaN where the limbs do not close.
    """
    return _call(robot, "fk", _cols(theta, robot.m), robot.geometry)[0][:, :, 0]


def _at_pose(robot, fname, P, theta=None):
    P = _cols(P, robot.n)
    theta = ik(robot, P) if theta is None else _cols(theta, robot.m)
    return _call(robot, fname, P, theta, robot.geometry)[0]


def error_jacobian(robot, P, theta=None):
    """Paper Eq. (13): ``dP = J dq`` with ``dq = (lever_i dth_i)`` (``L_i dth_i``).

    Returns
    -------
    ndarray, shape (K, n, m)
    """
    return _at_pose(robot, "error_jacobian", P, theta)


def error_jacobian_full(robot, P, theta=None):
    """Paper Eq. (12) (planar robot only): ``dP = J' dq'``, ``dq' = (L1 dth1, de1x, de1y, dL1, dl1, L2 dth2, ...)``.

    Returns
    -------
    ndarray, shape (K, 2, 10)
    """
    return _at_pose(robot, "error_jacobian_full", P, theta)


def pose_error_jacobian(robot, P, theta=None):
    """dP / d(robot source errors): every source error but the measuring ones, in order.

    Returns
    -------
    ndarray, shape (K, n, r)
        Per rad for angles, per mm for lengths.
    """
    return _at_pose(robot, "pose_error_jacobian", P, theta)


def transmission(robot, P, theta=None):
    """The mechanism's singularity indicators (sines of transmission angles, ...).

    A zero is a singular configuration (planar: ``(u_i, w_i)`` serial,
    ``(w_1, w_2)`` parallel; Delta: per limb and ``det[w_1; w_2; w_3]``).

    Returns
    -------
    ndarray, shape (K, s)
    """
    return _at_pose(robot, "transmission", P, theta)[:, :, 0]


def measuring_vector(robot, P):
    """Nominal measuring-mechanism length and unit vector.

    Returns
    -------
    lam : ndarray, shape (K,)
    lam_hat : ndarray, shape (K, n)
    """
    lam, lam_hat = _call(robot, "measuring", _cols(P, robot.n), robot.geometry)
    return lam[:, 0, 0], lam_hat[:, :, 0]


def g_rows(robot, P, theta=None):
    """Rows ``g_k = lam_hat_k^T [J_k, -I]`` of paper Eq. (28).

    Returns
    -------
    ndarray, shape (K, m + n)
    """
    return _at_pose(robot, "g_row", P, theta)[:, 0, :]


def distance(robot, theta_cmd, err=None):
    """Exact measuring-mechanism length for commanded joints and source errors.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joint angles, rad.
    err : ndarray, shape (q,) or (K, q), optional
        Source errors (rad, mm) in the mechanism's order.

    Returns
    -------
    ndarray, shape (K,)
    """
    theta_cmd = _cols(theta_cmd, robot.m)
    err = robot.errors.zeros() if err is None else robot.errors.check_vector(err)
    return _call(robot, "distance", theta_cmd, robot.geometry, err)[0][:, 0, 0]


def gauge(robot) -> np.ndarray:
    """The mechanism's gauge motions at the robot's geometry, shape (q, z) (columns ``gauge_names``)."""
    return np.array(robot.mechanism["gauge"](robot.geometry).full()).reshape(len(robot.errors), -1)


def check_poses(robot, P, margin=None, in_workspace=False, tol=1e-6):
    """Raise :class:`PoseError` for the first unusable pose.

    Checks reachability, the singularity margin (every ``|sin|`` of
    :func:`transmission` at least ``margin``) and, if asked, the workspace.

    Returns
    -------
    theta : ndarray, shape (K, m)
    """
    P = _cols(P, robot.n)
    if not np.all(np.isfinite(P)):
        k = int(np.flatnonzero(~np.all(np.isfinite(P), axis=1))[0])
        raise PoseError("pose is not finite", where=f"pose {k}")
    if in_workspace:
        out = np.flatnonzero(~robot.workspace.contains(P, tol))
        if out.size:
            k = int(out[0])
            raise PoseError(f"pose {fmt_user_pose(robot, P[k])} is outside the workspace {robot.workspace.describe()}",
                            where=f"pose {k}")
    theta = ik(robot, P)
    margin = robot.singularity_margin if margin is None else margin
    s = np.abs(transmission(robot, P, theta))
    bad = np.flatnonzero(np.min(s, axis=1) < margin)
    if bad.size:
        k = int(bad[0])
        raise PoseError(
            f"pose {fmt_user_pose(robot, P[k])} is too close to a singular configuration "
            f"(min |sin transmission angle| = {np.min(s[k]):.3g} < margin {margin:g})", where=f"pose {k}")
    return theta


def distance_jacobians(robot, theta_cmd, err=None):
    """Exact distance and its derivatives (CasADi AD of the exact model).

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joint angles, rad.
    err : ndarray, shape (q,) or (K, q), optional
        Source errors at which to linearise (default zero).

    Returns
    -------
    rho : ndarray, shape (K,)
    drho_derr : ndarray, shape (K, q)
        Per rad for angles, per mm for lengths.
    drho_dtheta : ndarray, shape (K, m)
        Per rad.
    """
    theta_cmd = _cols(theta_cmd, robot.m)
    err = robot.errors.zeros() if err is None else robot.errors.check_vector(err)
    rho, de, dt = _call(robot, "distance_jacobians", theta_cmd, robot.geometry, err)
    return rho[:, 0, 0], de[:, 0, :], dt[:, 0, :]


def sketch(robot, P, theta=None):
    """The robot drawn as line segments at K poses: its mechanism's optional ``sketch`` output, or None.

    Parameters
    ----------
    P : ndarray, shape (K, n)
    theta : ndarray, shape (K, m), optional
        The joints (default: the inverse kinematics of ``P``).

    Returns
    -------
    ndarray, shape (K, s, 2, l) or None
        Segment k of pose i runs from ``[i, k, 0]`` to ``[i, k, 1]`` (l = 2 or 3 coordinates, mm); None when
        the mechanism draws no sketch.
    """
    if "sketch" not in robot.mechanism.functions:
        return None
    P = _cols(P, robot.n)
    theta = ik(robot, P, check=False) if theta is None else _cols(theta, robot.m)
    seg = _call(robot, "sketch", P, theta, robot.geometry)[0]  # (K, l, 2 s)
    K, dim, cols = seg.shape
    return seg.reshape(K, dim, cols // 2, 2).transpose(0, 2, 3, 1)


def measuring_line(robot, P):
    """The measuring mechanism's ends at K poses: ``O1 = c`` on the base and ``O2 = c + lambda(P)``.

    Returns
    -------
    ndarray, shape (K, 2, l)
        mm.
    """
    lam, lam_hat = measuring_vector(robot, P)
    c = robot.params(robot.mechanism.measuring_base)
    o2 = c[None, :] + lam[:, None] * lam_hat
    return np.stack([np.broadcast_to(c, o2.shape), o2], axis=1)
