"""Fisher information and Cramér–Rao bounds of the distance-change measurements.

The measured changes ``s = D rho(theta_cmd + xi; p) + m`` (``D`` the (K-1) x K
first-difference matrix) are linearised in the parameters ``p`` at ``p0``
with the exact derivatives of the generated distance model (CasADi AD).  Noise:

* scale error ``m ~ N(0, sigma_m^2 I)`` on each change,
* servo error ``xi_k ~ N(0, sigma_xi^2 I_2)`` on each pose's joints, propagated
  to first order: ``Cov(rho_k) = sigma_xi^2 |d rho_k / d theta|^2`` (independent
  poses), so ``Cov(s) = sigma_m^2 I + D diag(Cov(rho)) D^T`` (correlated:
  consecutive changes share a pose).

``F = A^T Cov(s)^-1 A (+ prior precision)``; the CRLB of any unbiased estimator
is ``F^-1``.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import PoseError
from zerocal_sym.model.noise import SOURCE_ERROR_NAMES, NoiseModel

#: Named parameter sets (indices into the source-error vector).
PARAM_SETS = {
    "paper": ("theta1", "theta2", "rMx", "rMy"),
    "offsets": ("theta1", "theta2"),
    "maemm": ("rMx", "rMy"),
    "geometric": ("e1x", "e1y", "e2x", "e2y", "L1", "L2", "l1", "l2"),
    "lengths": ("L1", "L2", "l1", "l2"),
    "base": ("e1x", "e1y", "e2x", "e2y"),
    "all": SOURCE_ERROR_NAMES,
}


def param_indices(params) -> list:
    """Indices of the named parameters, in the source-error order.

    Parameters
    ----------
    params : str or sequence of str
        A set name of :data:`PARAM_SETS`, parameter names, or a string
        combining both with ``,`` or ``+`` (``"paper+L1,L2"``).  Duplicates
        are dropped; the result is sorted in :data:`SOURCE_ERROR_NAMES` order.

    Returns
    -------
    list of int
    """
    if isinstance(params, str):
        params = [p.strip() for p in params.replace("+", ",").split(",") if p.strip()]
    names = []
    for p in params:
        names.extend(PARAM_SETS[p] if p in PARAM_SETS else [p])
    idx = set()
    for p in names:
        if p not in SOURCE_ERROR_NAMES:
            raise ValueError(f"unknown parameter {p!r} (known: {', '.join(SOURCE_ERROR_NAMES)}; "
                             f"sets: {', '.join(PARAM_SETS)})")
        idx.add(SOURCE_ERROR_NAMES.index(p))
    if not idx:
        raise ValueError("empty parameter set")
    return sorted(idx)


def param_names(params) -> tuple:
    """Names of the parameters selected by ``params`` (see :func:`param_indices`)."""
    return tuple(SOURCE_ERROR_NAMES[i] for i in param_indices(params))


def parameter_scale(robot, params="paper") -> np.ndarray:
    """Column scaling that makes rad and mm comparable, shape (p,).

    A zero offset is measured by the arc it moves the proximal link's end,
    ``L_i dtheta_i`` (mm) -- the paper's own ``dq = (L1 dth1, L2 dth2)``; every
    other parameter is a length already (mm).  So the scaled parameter is
    ``q = c * p`` with ``c = L_i`` (mm/rad) for ``theta_i`` and 1 otherwise, and
    the scaled sensitivity is ``A / c``.

    Returns
    -------
    ndarray, shape (p,)
        mm per unit of each parameter.
    """
    L = robot.link_lengths
    return np.array([L[i] if i < 2 else 1.0 for i in param_indices(params)])


def difference_matrix(K: int) -> np.ndarray:
    """``D``, shape (K-1, K): ``(D rho)_k = rho_{k+1} - rho_k``."""
    return np.eye(K - 1, K, 1) - np.eye(K - 1, K)


def sensitivity(robot, theta_cmd, params="paper", err0=None):
    """``A = d s / d p``: derivative of the K-1 measured changes w.r.t. the parameters.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, 2)
        Commanded joints, rad.
    params : str or list of str
    err0 : ndarray, shape (12,), optional
        Linearisation point (default zero).

    Returns
    -------
    ndarray, shape (K-1, len(params))
        Per rad for zero offsets, per mm for lengths.
    """
    _, de, _ = kin.distance_jacobians(robot, theta_cmd, err0)
    return np.diff(de[:, param_indices(params)], axis=0)


def measurement_covariance(robot, theta_cmd, noise: NoiseModel, err0=None):
    """Covariance of the K-1 measured changes, shape (K-1, K-1)."""
    theta_cmd = np.atleast_2d(theta_cmd)
    K = theta_cmd.shape[0]
    _, _, dt = kin.distance_jacobians(robot, theta_cmd, err0)
    D = difference_matrix(K)
    var_rho = noise.sigma_servo_rad**2 * np.sum(dt**2, axis=1)
    return noise.sigma_scale_mm**2 * np.eye(K - 1) + (D * var_rho) @ D.T


def whitener(cov) -> np.ndarray:
    """``W = L^-1`` with ``cov = L L^T`` (Cholesky): ``W r`` has identity covariance.

    Parameters
    ----------
    cov : ndarray, shape (n, n)

    Returns
    -------
    ndarray, shape (n, n)
        Lower triangular.
    """
    L = np.linalg.cholesky(np.asarray(cov, float))
    return np.linalg.solve(L, np.eye(L.shape[0]))


def fisher_information(robot, theta_cmd, params="paper", noise: NoiseModel | None = None,
                       err0=None, prior_std=None):
    """Fisher information of the parameters, shape (p, p).

    Parameters
    ----------
    prior_std : ndarray, shape (p,), optional
        Gaussian prior std per parameter (rad / mm); ``inf`` for none.
    """
    noise = noise or NoiseModel.paper()
    A = sensitivity(robot, theta_cmd, params, err0)
    C = measurement_covariance(robot, theta_cmd, noise, err0)
    if not np.any(C):
        raise ValueError("the noise model is zero: the Fisher information is unbounded")
    F = A.T @ np.linalg.solve(C, A)
    if prior_std is not None:
        F = F + np.diag(1.0 / np.asarray(prior_std, float) ** 2)
    return F


def crlb(robot, theta_cmd, params="paper", noise: NoiseModel | None = None, err0=None,
         prior_std=None, rcond=1e-12):
    """Cramér–Rao bound (covariance), shape (p, p).

    Raises
    ------
    PoseError
        If the parameters are not identifiable from these poses (singular
        Fisher information).
    """
    F = fisher_information(robot, theta_cmd, params, noise, err0, prior_std)
    scale = np.sqrt(np.diag(F))
    if np.any(scale == 0):
        raise PoseError("a parameter has no influence on the measurements: not identifiable")
    Fn = F / np.outer(scale, scale)
    s = np.linalg.svd(Fn, compute_uv=False)
    if s[-1] < rcond * s[0]:
        raise PoseError(f"Fisher information is singular (rank {int(np.sum(s >= rcond * s[0]))} "
                        f"of {F.shape[0]}): parameters not identifiable from these poses")
    return np.linalg.inv(Fn) / np.outer(scale, scale)


def crlb_zero_offsets_deg(robot, theta_cmd, params="paper", noise=None, err0=None, prior_std=None):
    """CRLB standard deviations of the two zero offsets, degrees, shape (2,)."""
    idx = param_indices(params)
    cov = crlb(robot, theta_cmd, params, noise, err0, prior_std)
    pos = [idx.index(0), idx.index(1)]
    return np.degrees(np.sqrt(np.diag(cov)[pos]))


def model_bias(robot, theta_cmd, err_true, params="paper", noise: NoiseModel | None = None, err0=None):
    """First-order bias of the weighted least-squares estimate from unmodelled errors.

    The parameters not in ``params`` are held at ``err0`` (default zero) by the
    model; if their true values differ, the estimate of ``params`` moves by
    ``b = (A^T C^-1 A)^-1 A^T C^-1 A_o (e_o - e0_o)``, ``A_o`` the sensitivity
    to the omitted errors.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, 2)
    err_true : ndarray, shape (12,)
        True source errors (rad, mm).
    noise : NoiseModel, optional
        Weighting (default: the paper's); a zero model means unweighted.
    err0 : ndarray, shape (12,), optional
        Linearisation point and the value the model assumes for the omitted errors.

    Returns
    -------
    ndarray, shape (p,)
        Bias of each parameter (rad, mm).
    """
    noise = NoiseModel.paper() if noise is None else noise
    idx = param_indices(params)
    omit = [i for i in range(len(SOURCE_ERROR_NAMES)) if i not in idx]
    err0 = np.zeros(len(SOURCE_ERROR_NAMES)) if err0 is None else np.asarray(err0, float)
    _, de, _ = kin.distance_jacobians(robot, theta_cmd, err0)
    A, Ao = np.diff(de[:, idx], axis=0), np.diff(de[:, omit], axis=0)
    if noise.is_zero:
        W = np.eye(A.shape[0])
    else:
        W = whitener(measurement_covariance(robot, theta_cmd, noise, err0))
    d = np.asarray(err_true, float)[omit] - err0[omit]
    sol, *_ = np.linalg.lstsq(W @ A, W @ (Ao @ d), rcond=None)
    return sol
