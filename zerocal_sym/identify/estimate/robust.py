"""Robust identification: iteratively reweighted Gauss-Newton on the exact model.

``identify_nlls(..., loss="huber" | "soft_l1", loss_scale=...)`` runs its robust stage
(:mod:`zerocal_sym.identify.nlls_robust`), which runs :func:`irls` after its l2 solution.
The changes are correlated (consecutive changes share a pose's servo error), so a robust loss on the *whitened*
residuals would not isolate a bad reading (whitening mixes it into the
following ones).  Instead each reading ``k`` is judged by its **conditional
residual** -- the measured change minus the model, minus what the other
readings' residuals predict for it through the covariance ``C``::

    c_k = e_k - C_{k,-k} C_{-k,-k}^-1 e_{-k} = (P e)_k / P_kk,   P = C_w^-1,

standardised by its nominal conditional std (``u_k = c_k / sd_k``; for a
diagonal ``C`` simply ``e_k / sigma_k``).  The loss gives the weight
``w_k = rho'(u_k) / u_k`` (huber: ``min(1, delta / |u|)``; soft_l1:
``1 / sqrt(1 + (u / delta)^2)``, ``delta`` = ``loss_scale`` in standard
deviations), applied by inflating reading k's own variance,
``C_w = C + diag((1 / w_k - 1) sd_k^2)`` (the conditional residual does not
depend on reading k's own variance, so the weights are a fixed-point
iteration of the M-estimator).  Each iteration: one evaluation of the exact
distance model and its Jacobians, weights, one Gauss-Newton step of the
generalised least squares with ``C_w``; until step and weights settle.

Readings whose final weight is below
:data:`zerocal_sym.identify.check.robust_fit.ROBUST_EXCLUDE_WEIGHT` are outliers:
identify_nlls names them, refits the exact model without them and leaves them
out of the fit check.

An earlier version put the loss on each reading's scale error with the servo
errors as latent variables in the Ipopt problem: with the paper's noise (servo
error ~15 x the scale error) a bad reading of 0.5 mm was then cheaper to
explain by servo errors and parameters along the weak direction than by the
steep loss on a 1 um scale error (RMS 14 x the CRLB at K = 12); this
iteration measures 1-2 x (docs/nonlinear.md).
"""
from __future__ import annotations

import numpy as np

#: default loss scale (standard deviations)
DEFAULT_SCALE = {"huber": 1.345, "soft_l1": 1.0}
def weights(loss: str, u, delta: float) -> np.ndarray:
    """``rho'(u) / u`` of the loss (1 for l2)."""
    u = np.abs(np.asarray(u, float))
    if loss == "l2":
        return np.ones_like(u)
    if loss == "huber":
        return np.where(u <= delta, 1.0, delta / np.where(u > 0, u, 1.0))
    if loss == "soft_l1":
        return 1.0 / np.sqrt(1.0 + (u / delta) ** 2)
    raise ValueError(f"unknown loss {loss!r} (known: l2, huber, soft_l1)")


def loss_value(loss: str, u, delta: float) -> np.ndarray:
    """``rho(u)`` (``0.5 u^2`` for small ``u``)."""
    u = np.abs(np.asarray(u, float))
    if loss == "l2":
        return 0.5 * u**2
    if loss == "huber":
        return np.where(u <= delta, 0.5 * u**2, delta * (u - 0.5 * delta))
    if loss == "soft_l1":
        return delta**2 * (np.sqrt(1.0 + (u / delta) ** 2) - 1.0)
    raise ValueError(f"unknown loss {loss!r} (known: l2, huber, soft_l1)")


class _Model:
    """The exact model of one round: residuals, Jacobian (scaled units) and covariance of the changes at z."""

    def __init__(self, robot, theta_cmd, readings, names, prior_q, noise, prior_whitener=None):
        from zerocal_sym.identify import fisher
        from zerocal_sym.identify.estimate.nlls_solve import noise_terms

        self.robot = robot
        self.theta = np.atleast_2d(np.asarray(theta_cmd, float))
        self.K = self.theta.shape[0]
        self.s = np.asarray(readings, float)[1:]
        self.idx = robot.errors.indices(names)
        self.scale = fisher.parameter_scale(robot, names)
        self.prior_q = np.asarray(prior_q, float)
        self.mu = robot.errors.take(self.prior_q, names)
        w = np.zeros((0, len(names))) if prior_whitener is None else np.asarray(prior_whitener, float)
        self.w = w[np.any(w != 0, axis=1)]
        self.Jp = self.w / self.scale
        self.sm2, self.sx2 = noise_terms(noise)

    def at(self, z):
        """``(e, A, C)``: measured minus predicted changes (K-1,), ``d pred / d z`` (K-1, p), ``Cov(s)``
        (:class:`~zerocal_sym.identify.fisher.ChangeCovariance`, tridiagonal, as bands)."""
        from zerocal_sym.identify.fisher import ChangeCovariance
        from zerocal_sym.model import kinematics as kin

        err = self.prior_q.copy()
        err[self.idx] = z / self.scale
        rho, de, dt = kin.distance_jacobians(self.robot, self.theta, err)
        e = self.s - np.diff(rho)
        A = np.diff(de[:, self.idx], axis=0) / self.scale
        v = self.sx2 * np.sum(dt**2, axis=1)
        return e, A, ChangeCovariance(self.sm2 + v[:-1] + v[1:], -v[1:-1])

    def prior_residual(self, z):
        return self.w @ (z / self.scale - self.mu)


def conditional_residuals(e, C, infl):
    """``(c, sd)``: conditional residual of each reading given the others under ``C + diag(infl)`` and its
    nominal conditional std (reading k's own inflation removed).

    ``C``: :class:`~zerocal_sym.identify.fisher.ChangeCovariance`; ``c = (P e) / diag(P)`` with
    ``P = (C + diag(infl))^-1`` from its bidiagonal Cholesky factor, O(K).
    """
    Cw = C.plus_diagonal(infl)
    try:
        d = Cw.inverse_diagonal()
    except np.linalg.LinAlgError:  # not positive definite (the model undefined there): nothing to judge by
        nan = np.full(np.shape(e), np.nan)
        return nan, nan.copy()
    c = Cw.solve(e) / d
    var = 1.0 / d - infl
    return c, np.sqrt(np.maximum(var, 1e-300))


def irls(robot, theta_cmd, readings, names, prior_q, noise, z0, loss: str = "huber", delta: float | None = None,
         prior_whitener=None, max_iter: int = 100, tol: float = 1e-8, wtol: float = 1e-6) -> dict:
    """Iteratively reweighted Gauss-Newton of the robust loss (module docstring).

    Parameters
    ----------
    z0 : ndarray, shape (p,)
        Start, scaled units (``p = z / scale``).
    loss : {"huber", "soft_l1"}
    delta : float, optional
        Loss scale in standard deviations (default :data:`DEFAULT_SCALE`).

    Returns
    -------
    dict
        ``z`` (p,), ``weights`` (K-1,), ``u`` (K-1,) standardised conditional
        residuals, ``conditional_residual_mm`` (K-1,), ``C`` nominal and
        ``C_w`` weighted covariance of the changes at ``z`` (tridiagonal,
        :class:`~zerocal_sym.identify.fisher.ChangeCovariance`), ``A`` (K-1, p),
        ``e`` (K-1,), ``iterations``, ``converged``, ``objective`` (``sum rho(u_k)``
        at the end: the criterion between starts).
    """
    delta = DEFAULT_SCALE[loss] if delta is None else float(delta)
    weights(loss, [0.0], delta)  # validates the loss
    mdl = _Model(robot, theta_cmd, readings, names, prior_q, noise, prior_whitener)
    z = np.asarray(z0, float).copy()
    n = mdl.K - 1
    infl = np.zeros(n)
    om = np.ones(n)
    converged = False
    it = 0
    for it in range(1, max_iter + 1):
        e, A, C = mdl.at(z)
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(A))):
            break
        c, sd = conditional_residuals(e, C, infl)
        om_new = weights(loss, c / sd, delta)
        infl = (1.0 / om_new - 1.0) * sd**2
        Cw = C.plus_diagonal(infl)
        rw = Cw.whiten(e)
        Jw = Cw.whiten(-A)
        rp = mdl.prior_residual(z)
        step = -np.linalg.lstsq(np.vstack([Jw, mdl.Jp]), np.concatenate([rw, rp]), rcond=None)[0]
        z = z + step
        settled = np.max(np.abs(om_new - om)) < wtol
        om = om_new
        if np.max(np.abs(step)) < tol and settled:
            converged = True
            break
    e, A, C = mdl.at(z)
    c, sd = conditional_residuals(e, C, infl)
    u = c / sd
    om = weights(loss, u, delta)  # at the final point (max_iter = 0: the classification at z0)
    return {"z": z, "objective": float(np.sum(loss_value(loss, u, delta))), "weights": om, "u": u,
            "conditional_residual_mm": c, "C": C, "C_w": C.plus_diagonal(infl), "A": A, "e": e, "iterations": it,
            "converged": bool(converged and np.all(np.isfinite(z)))}
