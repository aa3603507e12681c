"""The exact whitened model of one identification problem, and exact-model refits without readings.

:class:`_Exact` evaluates the residuals and Jacobian of the exact model (the
CasADi functions of :mod:`zerocal_sym.identify.nlls_problem`, imported when
used, not with this module: nlls_problem imports the fit check), linearises
it for the fit check (:class:`~zerocal_sym.identify.fitstats._Linear`),
refines an estimate by Gauss-Newton and refits altered data (the causes of a
rejection, :mod:`zerocal_sym.identify.diagnosis`).  :func:`refits` fits one
round many times at once, each without some readings (the deletion
diagnostics, the bad reading of a rejection, the robust loss's outliers);
:func:`_without_each` without each single reading.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.fitstats import RANK_RTOL, _Linear, band_whitener

#: exact-model refinement (TSVD) stops when its step (scaled units, mm) is below this
REFINE_TOL = 1e-9


class _Exact:
    """The exact whitened model of one identification problem (robot, poses, readings, parameters)."""

    def __init__(self, robot, theta_cmd, readings, names, prior_q, noise, prior_whitener=None):
        from zerocal_sym.identify import fisher
        from zerocal_sym.identify.nlls import noise_terms
        from zerocal_sym.identify.nlls_problem import get_problem

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
        self.prob = get_problem(robot, self.K, self.names)
        self.par = self.prob.pack(self.theta, robot.geometry, self.prior_q, self.readings[1:], self.scale, self.mu,
                                  self.w, *noise_terms(noise))

    @property
    def z_prior(self):
        return self.mu * self.scale

    def evaluate(self, z):
        """``(r, rp, J, pred, l, b)`` at ``z`` (weights at ``z``); copies."""
        last = getattr(self, "_last", None)
        if last is not None and np.array_equal(last[0], z):
            return last[1]
        fast = self.prob.fast
        l, b = (np.array(o, float) for o in fast["weights"](z, self.par))
        r, rp, J, pred = (np.array(o, float) for o in fast["residuals"](z, self.par, l, b))
        return r.ravel(), rp.ravel(), J, pred.ravel(), l.ravel(), b.ravel()

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
        return _Linear(rr, JJ, band_whitener(l, b), np.arange(1, self.K), self.readings[1:] - pred, basis,
                       self.scale, self.names, len(rows), point)

    def refine(self, z0, basis=None, max_iter: int = 10):
        """Gauss-Newton on the exact model from ``z0`` within ``span(basis)`` (weights re-evaluated)."""
        from zerocal_sym.identify.nlls_solve import GN_STEP_TOL

        z = np.asarray(z0, float).copy()
        if basis is None or (np.shape(basis)[1] == self.p and not np.any(self.w)):
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
        par = self.par.copy()
        K = self.K
        if theta is not None:
            par[: self.theta.size] = np.asarray(theta, float).ravel()
        if readings is not None:
            par[self.prob.s_slice(len(self.robot.geometry), len(self.robot.errors))] = np.asarray(readings)[1:]
        from zerocal_sym.identify.nlls_solve import GN_STEP_TOL

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


def refits(robot, theta_cmd, readings, names, prior_q, noise, drops, z0, prior_whitener=None,
           max_iter: int = 20, tol: float = 1e-7) -> dict:
    """Exact-model least-squares fits of one round, each without some readings (vectorised over the fits).

    Fit ``j`` leaves out the changes ``drops[j]`` (0-based: change ``i`` is the
    reading at pose ``i + 1``) by marginalising them out of the covariance of
    the changes (the rows and columns of ``C`` dropped): Gauss-Newton with the
    weights re-evaluated at each iterate, from ``z0[j]`` (scaled units), until
    the step is below ``tol`` (mm) or ``max_iter``.  One call of the generated
    distance Jacobians per iteration for all fits.

    Returns
    -------
    dict
        ``z`` (N, p) scaled estimates, ``chi2`` (N,), ``dof`` (N,),
        ``converged`` (N,) bool, ``residual_mm`` (N, K-1) measured minus
        predicted changes at each fit (the dropped ones too), ``dropped_error_mm``
        (N, K-1): each dropped reading's misfit given the other readings (its
        residual minus what their correlated residuals predict for it; NaN
        where not dropped) -- the estimated error of that reading.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.nlls import noise_terms
    from zerocal_sym.model import kinematics as kin

    errors = robot.errors
    theta = np.atleast_2d(np.asarray(theta_cmd, float))
    K = theta.shape[0]
    s = np.asarray(readings, float)[1:]
    names = tuple(names)
    idx = errors.indices(names)
    p = len(names)
    scale = fisher.parameter_scale(robot, names)
    mu = errors.take(np.asarray(prior_q, float), names)
    w = np.zeros((0, p)) if prior_whitener is None else np.asarray(prior_whitener, float)
    w = w[np.any(w != 0, axis=1)]
    Jp = w / scale
    sm2, sx2 = noise_terms(noise)
    D = fisher.difference_matrix(K)
    N = len(drops)
    Z = np.array(np.broadcast_to(np.asarray(z0, float), (N, p)))
    keeps = [np.setdiff1d(np.arange(K - 1), np.asarray(d, int)) for d in drops]
    done = np.zeros(N, bool)
    bad = np.zeros(N, bool)
    chi2 = np.full(N, np.inf)
    dof = np.array([k.size + w.shape[0] - p for k in keeps])
    res = np.full((N, K - 1), np.nan)
    cond = np.full((N, K - 1), np.nan)
    thN = np.tile(theta, (N, 1))

    def sweep(take_steps):
        E = np.tile(np.asarray(prior_q, float), (N * K, 1))
        E[:, idx] = np.repeat(Z / scale, K, axis=0)
        rho, de, dt = kin.distance_jacobians(robot, thN, E)
        for j in range(N):
            if bad[j] or (take_steps and done[j]):
                continue
            sl = slice(j * K, (j + 1) * K)
            e = s - np.diff(rho[sl])
            A = np.diff(de[sl][:, idx], axis=0) / scale
            v = sx2 * np.sum(dt[sl] ** 2, axis=1)
            C = sm2 * np.eye(K - 1) + (D * v) @ D.T
            kp = keeps[j]
            try:
                L = np.linalg.cholesky(C[np.ix_(kp, kp)])
                rw = np.linalg.solve(L, e[kp])
                Jw = np.linalg.solve(L, -A[kp])
            except np.linalg.LinAlgError:
                bad[j] = True
                continue
            rp = w @ (Z[j] / scale - mu)
            if not (np.all(np.isfinite(rw)) and np.all(np.isfinite(Jw))):
                bad[j] = True
                continue
            chi2[j] = float(rw @ rw + rp @ rp)
            res[j] = e
            drop = np.setdiff1d(np.arange(K - 1), kp)
            if drop.size and not take_steps:  # each dropped reading's misfit given the others (conditional)
                Ck = C[np.ix_(drop, kp)]
                cond[j, drop] = e[drop] - Ck @ np.linalg.solve(C[np.ix_(kp, kp)], e[kp])
            if take_steps:
                step = -np.linalg.lstsq(np.vstack([Jw, Jp]), np.concatenate([rw, rp]), rcond=None)[0]
                Z[j] = Z[j] + step
                done[j] = bool(np.max(np.abs(step)) < tol)

    for _ in range(max_iter):
        sweep(True)
        if np.all(done | bad):
            break
    sweep(False)
    chi2[bad] = np.inf
    return {"z": Z, "chi2": chi2, "dof": dof, "converged": done & ~bad, "residual_mm": res,
            "dropped_error_mm": cond}


def _without_each(exact: "_Exact", z_est=None) -> dict:
    """Exact refits without each single reading, from the prior and from ``z_est``; the lower chi² per reading."""
    K1 = exact.K - 1
    starts = [exact.z_prior] if z_est is None or np.allclose(z_est, exact.z_prior) else [exact.z_prior, z_est]
    drops = [[j] for _ in starts for j in range(K1)]
    z0 = np.vstack([np.tile(z, (K1, 1)) for z in starts])
    out = refits(exact.robot, exact.theta, exact.readings, exact.names, exact.prior_q, exact.noise, drops, z0,
                 prior_whitener=exact.w if np.any(exact.w) else None)
    c = out["chi2"].reshape(len(starts), K1)
    pick = np.argmin(np.where(np.isfinite(c), c, np.inf), axis=0)
    rows = pick * K1 + np.arange(K1)
    return {key: out[key][rows] for key in ("z", "chi2", "dof", "converged", "residual_mm", "dropped_error_mm")}
