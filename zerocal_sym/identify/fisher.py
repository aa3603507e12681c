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

``Cov(s)`` is tridiagonal: it is kept as its two bands
(:class:`ChangeCovariance`, :func:`change_covariance`) and whitened by its
lower-bidiagonal Cholesky factor, so memory and time are linear in K (the
dense :func:`measurement_covariance` is for small K and tests).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded
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


class ChangeCovariance:
    """``Cov(s) = sigma_m^2 I + D diag(v) D^T`` of the K-1 measured changes, kept as its two bands.

    Tridiagonal, (K-1) x (K-1): diagonal ``sigma_m^2 + v_k + v_{k+1}``,
    sub-diagonal ``-v_{k+1}`` (consecutive changes share a pose), ``v_k`` the
    variance of ``rho_k`` from the servo error.  Its Cholesky factor ``L`` is
    lower bidiagonal (diagonal ``l``, sub-diagonal ``b``); whitening ``L^-1 A``
    is a forward substitution.  Memory and time O(K) (O(K p) for a (K-1, p)
    matrix): nothing here is (K-1) x (K-1) unless :meth:`dense` is asked for.

    Attributes
    ----------
    diag : ndarray, shape (K-1,)
    off : ndarray, shape (K-2,)
        ``C[k+1, k] = C[k, k+1]``.
    """

    def __init__(self, diag, off):
        self.diag = np.asarray(diag, float).ravel()
        self.off = np.asarray(off, float).ravel()
        if self.off.size != max(self.diag.size - 1, 0):
            raise ValueError(f"off-diagonal of length {self.off.size} for a diagonal of {self.diag.size}")
        self._chol = None

    @classmethod
    def from_variances(cls, sigma_scale_mm: float, var_rho) -> "ChangeCovariance":
        """From ``sigma_m`` (mm) and ``v`` (K,), the variance of each pose's distance (mm^2)."""
        v = np.asarray(var_rho, float).ravel()
        return cls(sigma_scale_mm**2 + v[:-1] + v[1:], -v[1:-1])

    @property
    def n(self) -> int:
        return self.diag.size

    @property
    def is_zero(self) -> bool:
        return not (np.any(self.diag) or np.any(self.off))

    def dense(self) -> np.ndarray:
        """The full matrix, shape (K-1, K-1) (small problems and tests only)."""
        C = np.diag(self.diag)
        if self.n > 1:
            i = np.arange(self.n - 1)
            C[i + 1, i] = C[i, i + 1] = self.off
        return C

    def std(self) -> np.ndarray:
        """Standard deviation of each change, shape (K-1,)."""
        return np.sqrt(self.diag)

    def cholesky(self):
        """``(l, b)``: ``C = L L^T`` with ``L`` lower bidiagonal (``L[k, k] = l[k]``, ``L[k+1, k] = b[k]``).

        Raises
        ------
        numpy.linalg.LinAlgError
            ``C`` is not positive definite (a zero noise model).
        """
        if self._chol is None:
            l, b, ok = banded.cholesky(self.diag, self.off)
            if not ok:
                raise np.linalg.LinAlgError("the covariance of the changes is not positive definite")
            self._chol = (l, b)
        return self._chol

    def whiten(self, A) -> np.ndarray:
        """``L^-1 A`` (identity covariance), shape of ``A``: (K-1,) or (K-1, p); O(K p)."""
        l, b = self.cholesky()
        return band_forward(l, b, A)

    def factor_times(self, A) -> np.ndarray:
        """``A L``, ``A`` shape (p, K-1): then ``A C A^T = (A L)(A L)^T`` without the (K-1)^2 matrix."""
        l, b = self.cholesky()
        A = np.asarray(A, float)
        out = A * l
        if self.n > 1:
            out[:, :-1] += A[:, 1:] * b
        return out

    def sandwich(self, A) -> np.ndarray:
        """``A C A^T`` for ``A`` (p, K-1), O(K p^2) (works for a singular C too)."""
        A = np.asarray(A, float)
        out = (A * self.diag) @ A.T
        if self.n > 1:
            X = (A[:, 1:] * self.off) @ A[:, :-1].T
            out += X + X.T
        return out

    def whitener(self) -> np.ndarray:
        """``L^-1`` dense, shape (K-1, K-1) (small problems only)."""
        return self.whiten(np.eye(self.n))

    def solve(self, V) -> np.ndarray:
        """``C^-1 V``, ``V`` shape (K-1,) or (K-1, p); O(K p)."""
        l, b = self.cholesky()
        return banded.solve(l, b, V)

    def inverse_diagonal(self) -> np.ndarray:
        """The diagonal of ``C^-1``, shape (K-1,); O(K)."""
        return banded.inverse_diagonal(*self.cholesky())

    def take(self, keep) -> "ChangeCovariance":
        """The covariance of the changes ``keep`` (sorted indices), the others marginalised out: tridiagonal."""
        return ChangeCovariance(*banded.submatrix(self.diag, self.off, keep))

    def plus_diagonal(self, x) -> "ChangeCovariance":
        """``C + diag(x)``, ``x`` shape (K-1,)."""
        return ChangeCovariance(self.diag + np.asarray(x, float), self.off)


def band_forward(l, b, A) -> np.ndarray:
    """Solve ``L Y = A`` for lower-bidiagonal ``L`` (diagonal ``l`` (n,), sub-diagonal ``b`` (n-1,)).

    The recurrence ``y_k = (a_k - b_{k-1} y_{k-1}) / l_k`` evaluated as a
    parallel prefix (log2 n vectorised steps of ``y_k = alpha_k y_{k-1} +
    beta_k``), O(n p log n) flops, O(n p) memory.
    """
    A = np.asarray(A, float)
    return banded.forward(np.ravel(np.asarray(l, float)), np.ravel(np.asarray(b, float)), A.reshape(A.shape[0], -1)
                          ).reshape(A.shape)


def change_covariance(robot, theta_cmd, noise: NoiseModel, err0=None) -> ChangeCovariance:
    """Covariance of the K-1 measured changes in band form (:class:`ChangeCovariance`), O(K)."""
    theta_cmd = np.atleast_2d(theta_cmd)
    _, _, dt = kin.distance_jacobians(robot, theta_cmd, err0)
    var_rho = noise.sigma_servo_rad**2 * np.sum(dt**2, axis=1)
    return ChangeCovariance.from_variances(noise.sigma_scale_mm, var_rho)


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
