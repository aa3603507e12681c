"""Fisher information and Cramér–Rao bounds of the distance-change measurements.

The measured changes ``s = D rho(theta_cmd + xi; p) + m`` (``D`` the (K-1) x K
first-difference matrix) are linearised in the parameters ``p`` at ``p0``
with the exact derivatives of the generated distance model (CasADi AD).  Noise:

* scale error ``m ~ N(0, sigma_m^2 I)`` on each change,
* servo error ``xi_k ~ N(0, sigma_xi^2 I_2)`` on each pose's joints, propagated
  to first order: ``Cov(rho_k) = sigma_xi^2 |d rho_k / d theta|^2`` (independent
  poses), so ``Cov(s) = sigma_m^2 I + D diag(Cov(rho)) D^T`` (correlated:
  consecutive changes share a pose);
* optionally a pose's systematic error shared by its revisits (``sigma_r``):
  ``Cov(rho) += sigma_r^2 Z Z^T`` (:mod:`zerocal_sym.identify.covariance`).

``F = A^T Cov(s)^-1 A (+ prior precision)``; the CRLB of any unbiased estimator
is ``F^-1``.

``Cov(s)`` is tridiagonal: it is kept as its two bands
(:class:`ChangeCovariance`, :func:`change_covariance`) and whitened by its
lower-bidiagonal Cholesky factor, so memory and time are linear in K (the
dense :func:`measurement_covariance` is for small K and tests).  The shared
revisit error adds a low-rank part, one column per revisited pose, kept
exact by Woodbury (O(K G)).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.covariance import ChangeCovariance, band_forward  # noqa: F401 - importable from here
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.errors import PoseError
from zerocal_sym.model.noise import NoiseModel

def parameter_scale(robot, params="paper") -> np.ndarray:
    """Column scaling that makes rad and mm comparable, shape (p,).

    An angle is measured by the arc it moves its lever arm, ``L_i dtheta_i``
    (mm) -- the paper's own ``dq = (L1 dth1, L2 dth2)``; every other
    parameter is a length already (mm).  So the scaled parameter is
    ``q = c * p`` with ``c`` the lever arm (mm/rad) of an angle and 1
    otherwise, and the scaled sensitivity is ``A / c``.

    Returns
    -------
    ndarray, shape (p,)
        mm per unit of each parameter.
    """
    return robot.error_scale(robot.errors.resolve(params))


def difference_matrix(K: int) -> np.ndarray:
    """``D``, shape (K-1, K): ``(D rho)_k = rho_{k+1} - rho_k``."""
    return np.eye(K - 1, K, 1) - np.eye(K - 1, K)


def sensitivity(robot, theta_cmd, params="paper", err0=None):
    """``A = d s / d p``: derivative of the K-1 measured changes w.r.t. the parameters.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joints, rad.
    params : str or list of str
        Parameter set (names or set names, see :meth:`SourceErrors.resolve`).
    err0 : ndarray, shape (q,), optional
        Linearisation point (default zero).

    Returns
    -------
    ndarray, shape (K-1, len(params))
        Per rad for zero offsets, per mm for lengths.
    """
    _, de, _ = kin.distance_jacobians(robot, theta_cmd, err0)
    return np.diff(de[:, robot.errors.indices(params)], axis=0)


def pose_labels(robot, theta_cmd) -> np.ndarray:
    """The pose of each visit, shape (K,) (:func:`zerocal_sym.model.revisits.pose_groups` on the commanded
    joints in their file unit, to :data:`~zerocal_sym.model.revisits.REVISIT_TOL`)."""
    from zerocal_sym.model.revisits import REVISIT_TOL, pose_groups

    return pose_groups(units.joints_to_user(robot, np.atleast_2d(theta_cmd)), REVISIT_TOL)


def change_covariance(robot, theta_cmd, noise: NoiseModel, err0=None) -> ChangeCovariance:
    """Covariance of the K-1 measured changes in band form (:class:`ChangeCovariance`), O(K); with a shared
    revisit error (``noise.sigma_revisit_mm``) its revisited poses' low-rank part, O(K G)."""
    theta_cmd = np.atleast_2d(theta_cmd)
    _, _, dt = kin.distance_jacobians(robot, theta_cmd, err0)
    var_rho = noise.sigma_servo_rad**2 * np.sum(dt**2, axis=1)
    labels = pose_labels(robot, theta_cmd) if noise.has_shared else None
    return ChangeCovariance.from_variances(noise.sigma_scale_mm, var_rho, labels, noise.sigma_revisit_mm)


def measurement_covariance(robot, theta_cmd, noise: NoiseModel, err0=None):
    """Covariance of the K-1 measured changes, dense, shape (K-1, K-1).

    For small K; everything in the package uses :func:`change_covariance` (bands, O(K)).
    """
    return change_covariance(robot, theta_cmd, noise, err0).dense()


def whitener(cov) -> np.ndarray:
    """``W = L^-1`` with ``cov = L L^T`` (Cholesky): ``W r`` has identity covariance.

    Parameters
    ----------
    cov : ndarray, shape (n, n), or ChangeCovariance

    Returns
    -------
    ndarray, shape (n, n)
        Lower triangular.
    """
    if isinstance(cov, ChangeCovariance):
        return cov.whitener()
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
    noise = NoiseModel.coerce(noise, robot=robot)
    A = sensitivity(robot, theta_cmd, params, err0)
    C = change_covariance(robot, theta_cmd, noise, err0)
    if C.is_zero:
        raise ValueError("the noise model is zero: the Fisher information is unbounded")
    WA = C.whiten(A)  # banded: O(K p), no (K-1) x (K-1) matrix
    F = WA.T @ WA
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
    """CRLB standard deviations of the zero offsets, degrees, shape (m,): revolute joints
    (:func:`crlb_zero_offsets_user` for any)."""
    if robot.errors.offset_unit != "rad":
        raise ValueError("crlb_zero_offsets_deg: this mechanism's zero offsets are lengths (mm); use "
                         "crlb_zero_offsets_user")
    return crlb_zero_offsets_user(robot, theta_cmd, params, noise, err0, prior_std)


def crlb_zero_offsets_user(robot, theta_cmd, params="paper", noise=None, err0=None, prior_std=None):
    """CRLB standard deviations of the zero offsets in file units (deg or mm), shape (m,).

    Raises
    ------
    ValueError
        If ``params`` does not contain every zero offset.
    """
    names = robot.errors.resolve(params)
    missing = [n for n in robot.errors.zero_offsets if n not in names]
    if missing:
        raise ValueError(f"the parameter set does not contain the zero offsets {', '.join(missing)}")
    cov = crlb(robot, theta_cmd, params, noise, err0, prior_std)
    pos = [names.index(n) for n in robot.errors.zero_offsets]
    return units.to_user(np.sqrt(np.diag(cov)[pos]), robot.errors.offset_unit)


def model_bias(robot, theta_cmd, err_true, params="paper", noise: NoiseModel | None = None, err0=None):
    """First-order bias of the weighted least-squares estimate from unmodelled errors.

    The parameters not in ``params`` are held at ``err0`` (default zero) by the
    model; if their true values differ, the estimate of ``params`` moves by
    ``b = (A^T C^-1 A)^-1 A^T C^-1 A_o (e_o - e0_o)``, ``A_o`` the sensitivity
    to the omitted errors.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
    err_true : ndarray, shape (q,)
        True source errors (rad, mm).
    noise : NoiseModel, optional
        Weighting (default: the paper's); a zero model means unweighted.
    err0 : ndarray, shape (q,), optional
        Linearisation point and the value the model assumes for the omitted errors.

    Returns
    -------
    ndarray, shape (p,)
        Bias of each parameter (rad, mm).
    """
    noise = NoiseModel.coerce(noise, robot=robot)
    idx = robot.errors.indices(params)
    omit = [i for i in range(len(robot.errors)) if i not in idx]
    err0 = robot.errors.zeros() if err0 is None else robot.errors.check_vector(err0)
    _, de, _ = kin.distance_jacobians(robot, theta_cmd, err0)
    A, Ao = np.diff(de[:, idx], axis=0), np.diff(de[:, omit], axis=0)
    d = np.asarray(err_true, float)[omit] - err0[omit]
    y = Ao @ d
    if not noise.is_zero:  # whitened by the banded Cholesky factor, O(K p)
        C = change_covariance(robot, theta_cmd, noise, err0)
        A, y = C.whiten(A), C.whiten(y)
    sol, *_ = np.linalg.lstsq(A, y, rcond=None)
    return sol
