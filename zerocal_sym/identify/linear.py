"""The paper's linear identification model (Eq. 28), for every mechanism.

The unknowns are the zero offsets as lengths ``lever_i dtheta_i`` (the paper's
``L_i dtheta_i``) and the MAEMM ``drM`` (n components), all in mm; the
identification matrix ``G`` has the rows ``g_{k+1} - g_k`` with
``g_k = lambda_hat_k^T [J_k, -I_n]`` (generated ``g_row``), so ``G`` is
``(K-1) x (m + n)``.  Its condition number is the paper's ``kappa``.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model import kinematics as kin


def identification_matrix(robot, P, maemm_prior=None, theta=None):
    """Paper Eq. (28): ``G`` with rows ``g_{k+1} - g_k`` and the nominal lengths.

    The measuring-mechanism vector is corrected by the MAEMM prior as
    ``lambda_k - rM_prior`` (Eq. 30; the actual vector O1'O2' is
    ``P' - c - d - rM``).

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Nominal poses, mm.
    maemm_prior : sequence of n floats, optional
        MAEMM prior, mm (default zero).
    theta : ndarray, shape (K, m), optional
        Joint angles at P (default: inverse kinematics).

    Returns
    -------
    G : ndarray, shape (K-1, m + n)
        Columns: the zero offsets as lengths (joint order), then the MAEMM (mm).
    lam : ndarray, shape (K,)
        Corrected nominal lengths, mm.
    """
    P = np.atleast_2d(np.asarray(P, float))
    n = robot.n
    theta = kin.ik(robot, P) if theta is None else theta
    prior = np.zeros(n) if maemm_prior is None else np.asarray(maemm_prior, float)
    v = P - robot.measuring_point - prior
    lam = np.linalg.norm(v, axis=1)
    lam_hat = v / lam[:, None]
    J = kin.error_jacobian(robot, P, theta)
    rows = np.einsum("ki,kij->kj", lam_hat, np.concatenate([J, np.broadcast_to(-np.eye(n), J.shape[:1] + (n, n))],
                                                            axis=2))
    return np.diff(rows, axis=0), lam


def condition_number(G) -> float:
    """2-norm condition number ``sigma_max / sigma_min`` (inf if rank-deficient)."""
    s = np.linalg.svd(np.asarray(G, float), compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
