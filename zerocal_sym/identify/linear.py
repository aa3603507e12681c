"""The paper's linear identification model (Eq. 28), for every mechanism.

The unknowns are the zero offsets as lengths (``lever_i dtheta_i``, the
paper's ``L_i dtheta_i``, for revolute joints; the offsets themselves for
prismatic ones) and the measuring errors (the MAEMM ``drM``, and a platform
point's ``dd`` where it turns with the platform), all in mm; the
identification matrix ``G`` has the rows ``g_{k+1} - g_k`` with
``g_k = d rho_k / d(offsets as lengths, measuring errors)`` (generated
``g_row``; ``lambda_hat_k^T [J_k, -I_n]`` for ``lambda = P - c - d``), its
columns those of the identified set (the mechanism's default: ``(K-1) x p``).
Its condition number is the paper's ``kappa``.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model import kinematics as kin


def linear_columns(robot, params="default") -> tuple:
    """The names of ``params`` (zero offsets and measuring errors only: the linear model's unknowns).

    Raises
    ------
    ValueError
        A parameter outside the linear model.
    """
    errors = robot.errors
    names = errors.resolve(params)
    model = errors.resolve("offsets+measuring")
    outside = [n for n in names if n not in model]
    if outside:
        raise ValueError(f"the linear model (TSVD) identifies zero offsets and measuring errors only, not "
                         f"{', '.join(outside)}")
    return names


def identification_matrix(robot, P, maemm_prior=None, theta=None, params="default"):
    """Paper Eq. (28): ``G`` with rows ``g_{k+1} - g_k`` and the nominal lengths.

    The measuring-mechanism vector is corrected by the prior on the measuring
    errors (Eq. 30; for the paper's robot ``lambda_k - rM_prior``: the actual
    vector O1'O2' is ``P' - c - d - rM``): the prior is put on the errors'
    targets (``c``, ``d``) in the geometry.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Nominal poses (mm, rad).
    maemm_prior : ndarray, shape (u,) or (K, u), optional
        Prior of the measuring errors (every one, in their order; one per pose, or per pose), mm (default zero).
    theta : ndarray, shape (K, m), optional
        Joints at P (default: inverse kinematics).
    params : str or sequence of str
        The identified set (default: the mechanism's default set).

    Returns
    -------
    G : ndarray, shape (K-1, p)
        Columns: the zero offsets as lengths (joint order), then the measuring errors (mm), of ``params``.
    lam : ndarray, shape (K,)
        Corrected nominal lengths, mm.
    """
    from zerocal_sym.model.noise import geometry_error

    P = np.atleast_2d(np.asarray(P, float))
    errors = robot.errors
    theta = kin.ik(robot, P) if theta is None else theta
    g = robot.geometry
    if maemm_prior is not None and np.any(np.asarray(maemm_prior, float) != 0):
        prior = np.asarray(maemm_prior, float)
        pr = np.atleast_2d(prior)
        shift = geometry_error(robot, errors.put(np.zeros((pr.shape[0], len(errors))), errors.measuring, pr))
        g = g + (shift[0] if prior.ndim == 1 else shift)
    rows = kin.call(robot, "g_row", P, theta, g)[0][:, 0, :]
    lam = kin.call(robot, "measuring", P, g)[0][:, 0, 0]
    model = errors.resolve("offsets+measuring")
    cols = [model.index(n) for n in linear_columns(robot, params)]
    return np.diff(rows[:, cols], axis=0), lam


def condition_number(G) -> float:
    """2-norm condition number ``sigma_max / sigma_min`` (inf if rank-deficient)."""
    s = np.linalg.svd(np.asarray(G, float), compute_uv=False)
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
