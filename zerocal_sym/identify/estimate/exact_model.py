"""The exact whitened model of one identification problem: evaluated, linearised, refined, refitted.

:class:`_Exact` evaluates the residuals and Jacobian of the exact model (the
CasADi functions of :mod:`zerocal_sym.identify.estimate.nlls_problem`, the
numpy twin of :mod:`~zerocal_sym.identify.estimate.nlls_banded` for long
rounds), linearises it for the fit check
(:class:`~zerocal_sym.identify.whitened._Linear`), refines an estimate by
Gauss-Newton (TSVD's fit check point, its truncated directions) and fits
altered data from the prior (the causes of a rejection:
:mod:`zerocal_sym.identify.diagnose.causes`).  :func:`_exact_for` is the
exact model of a result, at its fit check's point.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.identify.estimate.nlls_banded import round_problem
from zerocal_sym.identify.estimate.nlls_shared import pred_jacobian
from zerocal_sym.identify.estimate.nlls_solve import GN_STEP_TOL, noise_terms
from zerocal_sym.identify.whitened import RANK_RTOL, _Linear
from zerocal_sym.model.noise import NoiseModel

#: exact-model refinement (TSVD) stops when its step (scaled units, mm) is below this
REFINE_TOL = 1e-9


class _Exact:
    """The exact whitened model of one identification problem (robot, poses, readings, parameters)."""

    def __init__(self, robot, theta_cmd, readings, names, prior_q, noise, prior_whitener=None):
        self.robot = robot
        self.theta = np.atleast_2d(np.asarray(theta_cmd, float))
        self.readings = np.asarray(readings, float)
        self.K = self.theta.shape[0]
        self.names = tuple(names)
        self.p = len(self.names)
        self.prior_q = np.asarray(prior_q, float)
        errors = robot.errors
        self.scale = fisher.parameter_scale(robot, self.names)
        self.mu = errors.take(self.prior_q, self.names)
        self.w = np.zeros((self.p, self.p)) if prior_whitener is None else np.asarray(prior_whitener, float)
        self.noise = noise
        self.prob = round_problem(robot, self.K, self.names)
        self.par = self.prob.pack(self.theta, robot.geometry, self.prior_q, self.readings[1:], self.scale, self.mu,
                                  self.w, *noise_terms(noise))

    @property
    def z_prior(self):
        return self.mu * self.scale

    @property
    def shared(self) -> bool:
        """Whether the noise has the revisits' shared error (the covariance is more than the bands)."""
        return self.noise.has_shared and not self.noise.is_zero

    def evaluate(self, z):
        """``(r, rp, J, pred, l, b)`` at ``z`` (weights at ``z``); copies.  With the revisits' shared error
        ``r`` and the data rows of ``J`` are whitened by the full covariance (:meth:`covariance`)."""
        last = getattr(self, "_last", None)
        if last is not None and np.array_equal(last[0], z):
            return last[1]
        fast = self.prob.fast
        l, b = (np.array(o, float) for o in fast["weights"](z, self.par))
        r, rp, J, pred = (np.array(o, float) for o in fast["residuals"](z, self.par, l, b))
        r, J, pred, l, b = r.ravel(), np.reshape(J, (-1, np.size(z))), pred.ravel(), l.ravel(), b.ravel()
        if self.shared:
            C = self.covariance(z)
            J = np.vstack([C.whiten(-pred_jacobian(l, b, J, self.K)), J[self.K - 1:]])
            r = C.whiten(self.readings[1:] - pred)
        return r, rp.ravel(), J, pred, l, b

    def covariance(self, z):
        """The covariance of the changes at ``z`` (:func:`~zerocal_sym.identify.fisher.change_covariance`)."""
        err = self.robot.errors.put(self.prior_q, self.names, np.asarray(z, float) / self.scale)
        return fisher.change_covariance(self.robot, self.theta, self.noise, err)

    def raw(self, z):
        """``(e, A)`` at ``z``: the residuals of the changes (mm) and ``d pred / d z`` (K-1, p)."""
        fast = self.prob.fast
        l, b = (np.array(o, float) for o in fast["weights"](z, self.par))
        _, _, J, pred = (np.array(o, float) for o in fast["residuals"](z, self.par, l, b))
        return self.readings[1:] - pred.ravel(), pred_jacobian(l, b, J, self.K)

    def prior_rows(self) -> np.ndarray:
        return np.flatnonzero(np.any(self.w != 0, axis=1))

    def linear(self, z, basis=None, point=None) -> _Linear:
        """The whitened problem at ``z``; ``basis`` (p, c) restricts the fitted directions (TSVD)."""
        r, rp, J, pred, l, b = self.evaluate(z)
        K1 = self.K - 1
        rows = self.prior_rows()
        basis = np.eye(self.p) if basis is None else np.asarray(basis, float)
        rr = np.concatenate([r, rp[rows]])
        JJ = np.vstack([J[:K1], J[K1:][rows]]) @ basis
        return _Linear(rr, JJ, self.covariance(z) if self.shared else (l, b), np.arange(1, self.K),
                       self.readings[1:] - pred, basis, self.scale, self.names, len(rows), point)

    def refine(self, z0, basis=None, max_iter: int = 10):
        """Gauss-Newton on the exact model from ``z0`` within ``span(basis)`` (weights re-evaluated)."""
        z = np.asarray(z0, float).copy()
        if not self.shared and (basis is None or (np.shape(basis)[1] == self.p and not np.any(self.w))):
            # the whole space: the nlls problem's Gauss-Newton blocks (one CasADi call per 3 iterations)
            z_gn, step, r, rp, J, pred, l, b = self.prob.run_gauss_newton(z, self.par, True, GN_STEP_TOL)
            if np.all(np.isfinite(z_gn)) and float(step[0]) < GN_STEP_TOL:
                z_gn = np.ravel(z_gn)
                self._last = (z_gn.copy(), (r.ravel(), rp.ravel(), J, pred.ravel(), l.ravel(), b.ravel()))
                return z_gn
        basis = np.eye(self.p) if basis is None else np.asarray(basis, float)
        K1 = self.K - 1
        rows = self.prior_rows()
        for _ in range(max_iter):
            r, rp, J, *_ = self.evaluate(z)
            rr = np.concatenate([r, rp[rows]])
            JJ = np.vstack([J[:K1], J[K1:][rows]]) @ basis
            if not (np.all(np.isfinite(rr)) and np.all(np.isfinite(JJ))):  # (LAPACK would print to stdout on it)
                raise FloatingPointError("the exact model is not finite at the refinement's point")
            step = basis @ np.linalg.lstsq(JJ, -rr, rcond=None)[0]
            if not np.all(np.isfinite(step)):
                raise FloatingPointError("exact-model refinement diverged")
            z = z + step
            if np.max(np.abs(step)) < REFINE_TOL:
                break
        return z

    def chi2_fit(self, theta=None, readings=None):
        """chi² and dof of the exact-model least-squares fit (from the prior) to altered data."""
        if self.shared:  # the full covariance: Gauss-Newton in numpy on a copy with the altered data
            alt = _Exact(self.robot, self.theta if theta is None else theta,
                         self.readings if readings is None else readings, self.names, self.prior_q, self.noise,
                         self.w if np.any(self.w) else None)
            try:
                lin = alt.linear(alt.refine(alt.z_prior, max_iter=30))
            except (FloatingPointError, np.linalg.LinAlgError, ValueError):
                return float("inf"), (self.K - 1) + len(self.prior_rows()) - self.p
            return (float(lin.r @ lin.r) if lin.valid else float("inf")), lin.dof
        par = self.par.copy()
        K = self.K
        if theta is not None:
            par[: self.theta.size] = np.asarray(theta, float).ravel()
        if readings is not None:
            par[self.prob.s_slice(len(self.robot.geometry), len(self.robot.errors))] = np.asarray(readings)[1:]
        out = self.prob.run_gauss_newton(self.z_prior, par, True, GN_STEP_TOL)
        r, rp = np.array(out[2]).ravel(), np.array(out[3]).ravel()
        rows = self.prior_rows()
        chi2 = float(r @ r + rp[rows] @ rp[rows])
        J = np.array(out[4])
        JJ = np.vstack([J[: K - 1], J[K - 1:][rows]])
        if not (np.isfinite(chi2) and np.all(np.isfinite(JJ))):  # no fit: the model is not finite there
            return float("inf"), (K - 1) + len(rows) - self.p   # (and LAPACK would print to stdout on it)
        sv = np.linalg.svd(JJ, compute_uv=False)
        rank = int(np.sum(sv > RANK_RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
        dof = (K - 1) + len(rows) - rank
        return (chi2 if np.isfinite(chi2) else float("inf")), dof


def _exact_for(robot, meas, result, noise=None) -> tuple:
    """(_Exact, z at the fit check's evaluation point, basis) of a result."""
    info = result.info
    if noise is None:
        nd = info.get("noise")
        noise = NoiseModel.from_dict(nd) if nd else NoiseModel.paper()
    prior_q = np.asarray(info.get("prior", robot.errors.zeros()), float)
    w = info.get("prior_whitener")
    exact = _Exact(robot, meas.theta_cmd, meas.readings, result.params, prior_q, noise,
                   None if w is None else np.asarray(w, float))
    z = np.asarray(info.get("fit_point", result.estimate), float) * exact.scale
    basis = info.get("fit_basis")
    return exact, z, (None if basis is None else np.asarray(basis, float))
