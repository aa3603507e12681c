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

from zerocal_sym import kinematics as kin
from zerocal_sym.errors import PoseError
from zerocal_sym.measurement import SOURCE_ERROR_NAMES, NoiseModel

#: Named parameter sets (indices into the source-error vector).
PARAM_SETS = {
    "paper": ("theta1", "theta2", "rMx", "rMy"),
    "offsets": ("theta1", "theta2"),
    "all": SOURCE_ERROR_NAMES,
}


def param_indices(params) -> list:
    """Indices of the named parameters (a set name or a list of names)."""
    if isinstance(params, str):
        if params in PARAM_SETS:
            params = PARAM_SETS[params]
        else:
            params = [p.strip() for p in params.split(",") if p.strip()]
    idx = []
    for p in params:
        if p not in SOURCE_ERROR_NAMES:
            raise ValueError(f"unknown parameter {p!r} (known: {', '.join(SOURCE_ERROR_NAMES)})")
        idx.append(SOURCE_ERROR_NAMES.index(p))
    return idx


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
