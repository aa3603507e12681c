"""The paper's measurement-pose scheme and identification matrix (Sections 4-5).

``n`` evenly spaced poses on the boundary ``y = H`` from ``x = -b/2`` to
``+b/2``, then ``n`` on ``y = H + h``, again from ``-b/2`` to ``+b/2``
(``K = 2n``).  This order reproduces the paper's ``kappa_1 = 475.34`` at
``n = 3`` (SPEC.md); the order matters because G differences consecutive rows.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import PoseError


def paper_poses(robot, n: int) -> np.ndarray:
    """The paper's 2n boundary poses.

    Returns
    -------
    ndarray, shape (2n, 2)
        mm, in visiting order.
    """
    if n < 2:
        raise PoseError(f"the paper's scheme needs n >= 2 poses per boundary, got n = {n}")
    xs = np.linspace(-robot.b / 2, robot.b / 2, n)
    return np.vstack([np.column_stack([xs, np.full(n, robot.H)]),
                      np.column_stack([xs, np.full(n, robot.H + robot.h)])])


def identification_matrix(robot, P, maemm_prior=(0.0, 0.0), theta=None):
    """Paper Eq. (28): ``G`` with rows ``g_{k+1} - g_k`` and the nominal lengths.

    The measuring-mechanism vector is corrected by the MAEMM prior as
    ``lambda_k - rM_prior`` (Eq. 30; the actual vector O1'O2' is
    ``P' - c - d - rM``).

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Nominal poses, mm.
    maemm_prior : (2,)
        MAEMM prior, mm.
    theta : ndarray, shape (K, 2), optional
        Joint angles at P (default: inverse kinematics).

    Returns
    -------
    G : ndarray, shape (K-1, 4)
        Columns ``(L1 dth1, L2 dth2, drMx, drMy)``.
    lam : ndarray, shape (K,)
        Corrected nominal lengths, mm.
    """
    P = np.atleast_2d(np.asarray(P, float))
    theta = kin.ik(robot, P) if theta is None else theta
    c_d = np.array([robot.param("cx") + robot.param("dx"), robot.param("cy") + robot.param("dy")])
    v = P - c_d - np.asarray(maemm_prior, float)
    lam = np.linalg.norm(v, axis=1)
    lam_hat = v / lam[:, None]
    J = kin.error_jacobian(robot, P, theta)
    rows = np.einsum("ki,kij->kj", lam_hat, np.concatenate([J, np.broadcast_to(-np.eye(2), J.shape)], axis=2))
    return np.diff(rows, axis=0), lam


def condition_number(G) -> float:
    """2-norm condition number ``sigma_max / sigma_min`` (inf if rank-deficient)."""
    s = np.linalg.svd(np.asarray(G, float), compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
