"""Per-pose terms of the design model.

For each pose: the inverse-kinematics joints, the transmission sines, the
distance ``rho`` and its exact derivatives (CasADi AD of the generated
mechanism functions, at zero source errors), and the q-unit scaling of the
sensitivities (see :mod:`zerocal_sym.design.criteria`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

#: paper parameter indices in the source-error vector
_PAPER = (0, 1, 10, 11)


def _call_ik(robot, P):
    f = robot.mechanism["ik"]
    theta, ratio = f(np.asarray(P, float).T, robot.geometry)
    return theta.full().T, ratio.full().T


# --------------------------------------------------------------------------- per-pose terms
@lru_cache(maxsize=None)
def _pose_terms_fn(mech_name: str):
    """CasADi Function (P[2], g[12]) -> theta[2], ratio[2], s[3], rho, a[4], dth[2].

    ``a = d rho / d (dth1, dth2, drMx, drMy)`` (per rad, per mm) and
    ``dth = d rho / d theta`` (per rad), exact derivatives at zero source
    errors, joints from the inverse kinematics.
    """
    import casadi as ca

    from zerocal_sym.model.mechanism import get_mechanism

    mech = get_mechanism(mech_name)
    P = ca.SX.sym("P", 2)
    g = ca.SX.sym("g", mech["ik"].size1_in(1))
    theta, ratio = mech["ik"](P, g)
    s = mech["transmission"](P, theta, g)
    th = ca.SX.sym("th", 2)
    ne = mech["distance"].size1_in(2)
    err = ca.SX.sym("err", ne)
    rho = mech["distance"](th, g, err)
    de = ca.jacobian(rho, err)
    dt = ca.jacobian(rho, th)
    sub = ca.Function("drho", [th, g, err], [rho, de, dt])
    r, de_v, dt_v = sub(theta, g, ca.DM.zeros(ne))
    a = ca.vertcat(*[de_v[0, i] for i in _PAPER])
    return ca.Function("design_pose_terms", [P, g], [theta, ratio, s, r, a, dt_v.T],
                       ["P", "g"], ["theta", "ratio", "s", "rho", "a", "dth"])


def pose_terms(robot, P) -> dict:
    """Per-pose quantities of the design model.

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses, mm.

    Returns
    -------
    dict
        ``theta`` (K, 2) rad, ``ratio`` (K, 2), ``s`` (K, 3) transmission
        sines, ``rho`` (K,) mm, ``a`` (K, 4) d rho / d p (per rad, per mm),
        ``dth`` (K, 2) d rho / d theta (mm/rad).
    """
    P = np.atleast_2d(np.asarray(P, float))
    f = _pose_terms_fn(robot.mechanism_name)
    out = f(P.T, robot.geometry)
    names = ("theta", "ratio", "s", "rho", "a", "dth")
    res = {n: o.full().T for n, o in zip(names, out)}
    res["rho"] = res["rho"][:, 0]
    return res


def _qscale(robot):
    """``1 / fisher.parameter_scale``: q-unit sensitivities are ``a * qs``, shape (4,)."""
    L1, L2 = robot.link_lengths
    return np.array([1.0 / L1, 1.0 / L2, 1.0, 1.0])
