"""Exact-model refits of one round without some of its readings, in banded, leave-one-out form.

Shapes: K poses (K - 1 measured changes), p estimated parameters, N fits.

Leaving readings out of the correlated changes marginalises them out of
their covariance ``C`` (tridiagonal): the kept readings' covariance
``C[keep][:, keep]`` is tridiagonal again, so every fit is whitened by a
bidiagonal Cholesky factor in O(K) (:mod:`~zerocal_sym.identify.banded`).
Each fit is Gauss-Newton on the exact model with the weights re-evaluated at
every iterate, until the step is below ``tol`` (mm, scaled units).

:func:`refits` -- a few fits, each without a set of readings.

:func:`without_each` -- the K - 1 fits each without one reading, in
leave-one-out form.  Without reading ``j`` the whitened problem is the full one projected
orthogonally to the whitened indicator ``a_j = L^-1 e_j``::

    chi2_j = |r|^2 - (a_j^T r)^2 / |a_j|^2,    F_j = F - g_j g_j^T / |a_j|^2,   g_j = J^T a_j,

(``|a_j|^2`` is entry j of the diagonal of ``C^-1``, ``a_j^T r`` entry j of
``L^-T r``, ``g_j`` row j of ``L^-T J``), so the first Gauss-Newton step of all
K - 1 fits from one point is a rank-one downdate of that point's normal
equations: one evaluation of the model and O(K p^2) for all of them.  The
fits start from the full data's fit (Gauss-Newton from each start given), so
that one step leaves each within a few of its own minimum; every fit then
takes exact steps at its own iterate (the projected problem, whitened with
the full band) until its step is below ``tol``: what is reported is the
exact model's, evaluated at each fit's final point.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded, fisher
from zerocal_sym.identify.estimate.nlls_solve import noise_terms

#: the kinematics of a batch of fits is evaluated at about this many poses in one call (fits x K; at least
#: one fit): the calls have one size (the generated functions mapped over it are cached, their buffers
#: with them) and the fits' (K, p) arrays stay within a few tens of MB
BATCH_POSES = 1 << 15


class _Round:
    """The data of one round and its exact model, evaluated at N points at once."""

    def __init__(self, robot, theta_cmd, readings, names, prior_q, noise, prior_whitener=None):
        errors = robot.errors
        self.robot = robot
        self.theta = np.atleast_2d(np.asarray(theta_cmd, float))
        self.K = self.theta.shape[0]
        self.n = self.K - 1
        self.s = np.asarray(readings, float)[1:]
        self.names = tuple(names)
        self.idx = errors.indices(self.names)
        self.p = len(self.names)
        self.scale = fisher.parameter_scale(robot, self.names)
        self.prior_q = np.asarray(prior_q, float)
        self.mu = errors.take(self.prior_q, self.names)
        w = np.zeros((0, self.p)) if prior_whitener is None else np.asarray(prior_whitener, float)
        self.w = w[np.any(w != 0, axis=1)]
        self.Jp = self.w / self.scale
        self.sm2, self.sx2 = noise_terms(noise)

    def evaluate(self, Z):
        """At the N points ``Z`` (N, p): ``e`` (N, K-1) measured minus predicted changes, ``A`` (N, K-1, p)
        ``d pred / d z``, and the covariance of the changes as bands ``d`` (N, K-1), ``off`` (N, K-2).

        The points are padded to a power of two (at most :meth:`batch`): the kinematics is mapped over a
        few numbers of poses only (each mapped function is cached with its buffers)."""
        from zerocal_sym.model import kinematics as kin

        Z = np.atleast_2d(Z)
        N0, K = Z.shape[0], self.K
        N = min(max(self.batch(), N0), 1 << int(np.ceil(np.log2(N0))))
        if N > N0:
            Z = np.vstack([Z, np.repeat(Z[-1:], N - N0, axis=0)])
        E = np.tile(self.prior_q, (N * K, 1))
        E[:, self.idx] = np.repeat(Z / self.scale, K, axis=0)
        with np.errstate(invalid="ignore", over="ignore"):
            rho, de, dt = kin.distance_jacobians(self.robot, np.tile(self.theta, (N, 1)), E)
        e = self.s - np.diff(rho.reshape(N, K), axis=1)
        A = np.diff(de[:, self.idx].reshape(N, K, self.p), axis=1) / self.scale
        v = self.sx2 * np.sum(dt**2, axis=1).reshape(N, K)
        return e[:N0], A[:N0], (self.sm2 + v[:, :-1] + v[:, 1:])[:N0], -v[:N0, 1:-1]

    def prior_residual(self, Z):
        """Whitened prior residuals (N, rows) at ``Z`` (N, p)."""
        return (np.atleast_2d(Z) / self.scale - self.mu) @ self.w.T

    def batch(self) -> int:
        """How many fits are evaluated together (:data:`BATCH_POSES` poses)."""
        return max(1, BATCH_POSES // self.K)


def _lstsq(M, y, rows):
    """Minimum-norm least-squares solutions of the stacked ``M`` (N, R, p) ``x = y`` (N, R), as
    :func:`numpy.linalg.lstsq` with ``rcond = eps * max(rows, p)`` (``rows``: the rows the problem has)."""
    U, s, Vt = np.linalg.svd(M, full_matrices=False)
    cut = np.finfo(float).eps * max(rows, M.shape[-1]) * s[..., :1]
    inv = np.where(s > cut, 1.0 / np.where(s > cut, s, 1.0), 0.0)
    return np.einsum("nji,nj->ni", Vt, inv * np.einsum("nri,nr->ni", U, y))


def _chunks(idx, size):
    return [idx[i:i + size] for i in range(0, idx.size, size)]


def refits(robot, theta_cmd, readings, names, prior_q, noise, drops, z0, prior_whitener=None,
           max_iter: int = 20, tol: float = 1e-7) -> dict:
    """Exact-model least-squares fits of one round, each without some readings (a few fits).

    Fit ``j`` leaves out the changes ``drops[j]`` (0-based: change ``i`` is the
    reading at pose ``i + 1``) by marginalising them out of the covariance of
    the changes: Gauss-Newton with the weights re-evaluated at each iterate,
    from ``z0[j]`` (scaled units), until the step is below ``tol`` (mm) or
    ``max_iter``.  Each fit O(K p^2) per iteration, the fits' model
    evaluations batched.  For the fits each without one reading, all K - 1 of
    them: :func:`without_each`.

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
    rnd = _Round(robot, theta_cmd, readings, names, prior_q, noise, prior_whitener)
    n, p = rnd.n, rnd.p
    N = len(drops)
    Z = np.array(np.broadcast_to(np.asarray(z0, float), (N, p)))
    keeps = [np.setdiff1d(np.arange(n), np.asarray(d, int)) for d in drops]
    done, bad = np.zeros(N, bool), np.zeros(N, bool)
    chi2 = np.full(N, np.inf)
    dof = np.array([k.size + rnd.w.shape[0] - p for k in keeps])
    res = np.full((N, n), np.nan)
    cond = np.full((N, n), np.nan)

    def sweep(take_steps):
        for part in _chunks(np.flatnonzero(~bad & ~(done & take_steps)), rnd.batch()):
            e, A, d, off = rnd.evaluate(Z[part])
            rp = rnd.prior_residual(Z[part])
            for i, j in enumerate(part):
                kp = keeps[j]
                l, b, ok = banded.cholesky(*banded.submatrix(d[i], off[i], kp))
                rw = banded.forward(l, b, e[i, kp])
                Jw = banded.forward(l, b, -A[i, kp])
                if not (ok and np.all(np.isfinite(rw)) and np.all(np.isfinite(Jw))):
                    bad[j] = True
                    continue
                chi2[j] = float(rw @ rw + rp[i] @ rp[i])
                res[j] = e[i]
                drop = np.setdiff1d(np.arange(n), kp)
                if drop.size and not take_steps:  # each dropped reading's misfit given the others (conditional)
                    y = np.zeros(n)
                    y[kp] = banded.solve(l, b, e[i, kp])  # C_kk^-1 e_k, 0 at the dropped ones
                    pred = np.zeros(drop.size)
                    lo, hi = drop - 1, drop + 1   # C is tridiagonal: only the neighbours predict a reading
                    has = lo >= 0
                    pred[has] += off[i, lo[has]] * y[lo[has]]
                    has = hi < n
                    pred[has] += off[i, drop[has]] * y[hi[has]]
                    cond[j, drop] = e[i, drop] - pred
                if take_steps:
                    step = -np.linalg.lstsq(np.vstack([Jw, rnd.Jp]), np.concatenate([rw, rp[i]]), rcond=None)[0]
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


def full_fit(rnd: _Round, z0, tol: float, max_iter: int):
    """Gauss-Newton on all the readings from ``z0`` (weights re-evaluated): ``(z, converged)``."""
    z = np.asarray(z0, float).copy()
    for _ in range(max_iter):
        e, A, d, off = rnd.evaluate(z[None])
        l, b, ok = banded.cholesky(d[0], off[0])
        if not ok:
            return z, False
        r, J = banded.forward(l, b, e[0]), banded.forward(l, b, -A[0])
        step = -np.linalg.lstsq(np.vstack([J, rnd.Jp]), np.concatenate([r, rnd.prior_residual(z)[0]]),
                                rcond=None)[0]
        if not np.all(np.isfinite(step)):
            return z, False
        z = z + step
        if np.max(np.abs(step)) < tol:
            return z, True
    return z, False


def without_each(rnd: _Round, starts, max_iter: int = 20, tol: float = 1e-7, select=None) -> dict:
    """The exact fits of one round each without one reading (leave-one-out form, module docstring).

    From each start (scaled units) the full data are fitted first; the K - 1
    fits without one reading start there (a start whose full fit lands where
    another's did adds nothing and is skipped).  Per reading the fit with the
    lower chi² over the starts is kept.

    ``select``: ``select(chi2_lin, chi2_start, dof) -> mask`` (K-1,) of the
    readings refitted exactly, from the chi² each fit has at the start
    (``chi2_start``) and after its first step in the model linearised there
    (``chi2_lin``; O(K p^2) for all); the others stop there (``refitted``
    False: their ``z`` and ``chi2`` are the linearised model's).  Default:
    every reading refitted (K - 1 exact fits: O(K^2) model evaluations).

    Returns
    -------
    dict
        ``z`` (K-1, p), ``chi2`` (K-1,), ``dof`` (K-1,), ``converged`` (K-1,)
        bool, ``refitted`` (K-1,) bool, ``dropped_error_mm`` (K-1,): the reading's
        misfit given the others at its fit (its residual minus what the
        others' correlated residuals predict for it) -- the estimated error of
        that reading.
    """
    n, p = rnd.n, rnd.p
    dof = (n - 1) + rnd.w.shape[0] - p
    out, seen = None, []
    for z0 in starts:
        z_full, ok = full_fit(rnd, z0, tol, max_iter)
        start = z_full if ok else np.asarray(z0, float)
        if any(np.max(np.abs(start - s)) < tol for s in seen):
            continue
        seen.append(start)
        one = _leave_one_out(rnd, start, tol, max_iter, (lambda c, c0: select(c, c0, dof)) if select else None)
        if out is None:
            out = one
            continue
        better = one["chi2"] < out["chi2"]
        for key in out:
            out[key][better] = one[key][better]
    out["dof"] = np.full(n, dof)
    return out


def _leave_one_out(rnd: _Round, z0, tol, max_iter, select=None) -> dict:
    """The K - 1 fits each without one reading from the common point ``z0`` (module docstring);
    ``select(chi2_lin, chi2_start)``: the readings refitted exactly (:func:`without_each`)."""
    n, p = rnd.n, rnd.p
    Z = np.tile(np.asarray(z0, float), (n, 1))
    chi2, err = np.full(n, np.inf), np.full(n, np.nan)
    done, bad, refit = np.zeros(n, bool), np.zeros(n, bool), np.ones(n, bool)
    out = {"z": Z, "chi2": chi2, "converged": done, "refitted": refit, "dropped_error_mm": err}
    # the first step of every fit from the common point: a rank-one downdate of its normal equations
    e, A, d, off = rnd.evaluate(Z[:1])
    l, b, ok = banded.cholesky(d[0], off[0])
    r, J = banded.forward(l, b, e[0]), banded.forward(l, b, -A[0])
    rp = rnd.prior_residual(Z[:1])[0]
    if not (ok and np.all(np.isfinite(r)) and np.all(np.isfinite(J))):
        return out
    aa = banded.inverse_diagonal(l, b)
    psi = banded.backward(l, b, r)      # a_j^T r
    G = banded.backward(l, b, J)        # rows g_j = J^T a_j
    chi2[:] = r @ r + rp @ rp - psi**2 / aa
    err[:] = psi / aa
    F = J.T @ J + rnd.Jp.T @ rnd.Jp
    Fj = F - G[:, :, None] * G[:, None, :] / aa[:, None, None]
    gj = (J.T @ r + rnd.Jp.T @ rp) - G * (psi / aa)[:, None]
    w, V = np.linalg.eigh(Fj)           # F_j^+ with a cut at eps * max(n, p) of its largest eigenvalue
    keep = w > np.finfo(float).eps * max(n, p) * w[:, -1:]
    winv = np.where(keep, 1.0 / np.where(keep, w, 1.0), 0.0)
    step = -np.einsum("nij,nj->ni", V, winv * np.einsum("nji,nj->ni", V, gj))
    small = np.max(np.abs(step), axis=1) < tol
    bad |= ~np.all(np.isfinite(step), axis=1)
    done |= small & ~bad
    go = ~done & ~bad
    if select is not None:  # the others end after the step, in the linearised model
        lin = chi2 + 2 * np.sum(step * gj, axis=1) + np.einsum("ni,nij,nj->n", step, Fj, step)
        refit[:] = np.asarray(select(np.where(bad, np.inf, lin), chi2.copy()), bool)
        chi2[go & ~refit] = lin[go & ~refit]
        done &= refit
    Z[go] += step[go]
    # then each fit on its own: exact steps at its iterate (the projected problem, the full band)
    for _ in range(max_iter - 1):
        active = np.flatnonzero(~done & ~bad & refit)
        if not active.size:
            break
        for part in _chunks(active, rnd.batch()):
            _step(rnd, Z, part, chi2, err, done, bad, tol, take=True)
    rest = np.flatnonzero(~done & ~bad & refit)
    for part in _chunks(rest, rnd.batch()):  # not converged: the chi² where they stopped
        _step(rnd, Z, part, chi2, err, done, bad, tol, take=False)
    chi2[bad] = np.inf
    done &= ~bad
    return out


def _step(rnd, Z, part, chi2, err, done, bad, tol, take):
    """Evaluate the fits ``part`` (fit j leaves out reading j) at their iterates: chi², the dropped reading's
    error, and (``take``) a Gauss-Newton step; a fit whose step is below ``tol`` is done where it is."""
    n = rnd.n
    B = part.size
    e, A, d, off = rnd.evaluate(Z[part])
    l, b, ok = banded.cholesky(d, off)
    with np.errstate(invalid="ignore", divide="ignore"):
        r, J = banded.forward(l, b, e), banded.forward(l, b, -A)
        unit = np.zeros((B, n))
        unit[np.arange(B), part] = 1.0
        a = banded.forward(l, b, unit)                       # whitened indicator of the reading left out
        aa = np.sum(a * a, axis=1)
        psi = np.sum(a * r, axis=1)
        g = np.einsum("bn,bnp->bp", a, J)
        r = r - a * (psi / aa)[:, None]                      # projected: the kept readings' problem
        J = J - a[:, :, None] * (g / aa[:, None])[:, None, :]
    rp = rnd.prior_residual(Z[part])
    fin = ok & np.all(np.isfinite(r), axis=1) & np.all(np.isfinite(J), axis=(1, 2))
    bad[part[~fin]] = True
    part, r, J, rp, psi, aa = part[fin], r[fin], J[fin], rp[fin], psi[fin], aa[fin]
    chi2[part] = np.sum(r * r, axis=1) + np.sum(rp * rp, axis=1)
    err[part] = psi / aa
    if not take or not part.size:
        return
    M = np.concatenate([J, np.broadcast_to(rnd.Jp, (part.size,) + rnd.Jp.shape)], axis=1)
    step = -_lstsq(M, np.concatenate([r, rp], axis=1), n - 1 + rnd.Jp.shape[0])
    fin = np.all(np.isfinite(step), axis=1)
    bad[part[~fin]] = True
    small = fin & (np.max(np.abs(np.where(np.isfinite(step), step, 0.0)), axis=1) < tol)
    done[part[small]] = True
    move = fin & ~small
    Z[part[move]] += step[move]
