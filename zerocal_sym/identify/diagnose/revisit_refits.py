"""Exact refits without each single reading when the covariance carries the revisits' shared error.

The banded leave-one-out (:func:`zerocal_sym.identify.diagnose.leave_out.without_each`)
whitens by bidiagonal factors.  With a pose's systematic error shared by its
revisits the covariance ``C`` of the changes is the bands plus a low-rank
part (:mod:`zerocal_sym.identify.covariance`), and the same leave-one-out
identities hold with its whitening ``W`` (``W^T W = C^-1``): leaving reading
``j`` out is projecting the whitened problem orthogonally to ``a_j = W e_j``,
``chi2_j = |r|^2 - (a_j^T r)^2 / |a_j|^2``.  So every fit's first step from
the common point is a rank-one downdate of one evaluation, and the fits
``select`` keeps take exact Gauss-Newton steps on their own (one model
evaluation and O(K (p + G)) each): O(K^2) evaluations when every reading is
refitted, as the banded form.
"""
from __future__ import annotations

import numpy as np

#: Gauss-Newton steps of a refit at most, and its stopping step (scaled units, mm)
MAX_ITER, TOL = 20, 1e-7


def _problem(exact, z):
    """``(r, J, rp, Jp, C)`` at ``z``: whitened data residuals and Jacobian, prior rows, the covariance."""
    e, A = exact.raw(z)
    C = exact.covariance(z)
    rows = exact.prior_rows()
    rp = (np.asarray(z, float) / exact.scale - exact.mu) @ exact.w[rows].T
    return C.whiten(e), C.whiten(-A), rp, exact.w[rows] / exact.scale, C


def _project(r, J, a):
    aa = float(a @ a)
    psi = float(a @ r)
    return r - a * (psi / aa), J - np.outer(a, (a @ J) / aa), psi / aa


def _refit(exact, j, z):
    """Gauss-Newton without reading ``j`` from ``z``: ``(z, chi2, dropped error, converged)``."""
    n = exact.K - 1
    unit = np.zeros(n)
    unit[j] = 1.0
    for it in range(MAX_ITER + 1):
        r, J, rp, Jp, C = _problem(exact, z)
        a = C.whiten(unit)
        r, J, err = _project(r, J, a)
        chi2 = float(r @ r + rp @ rp)
        if not (np.isfinite(chi2) and np.all(np.isfinite(J))):
            return z, np.inf, np.nan, False
        if it == MAX_ITER:
            return z, chi2, err, False
        step = np.linalg.lstsq(np.vstack([J, Jp]), -np.concatenate([r, rp]), rcond=None)[0]
        if not np.all(np.isfinite(step)):
            return z, np.inf, np.nan, False
        if np.max(np.abs(step)) < TOL:
            return z, chi2, err, True
        z = z + step
    return z, chi2, err, False


def without_each_shared(exact, z_est=None, select=None) -> dict:
    """:func:`zerocal_sym.identify.diagnose.leave_out.without_each`'s result for a round whose covariance has the shared
    revisit error (``exact``: :class:`~zerocal_sym.identify.estimate.exact_model._Exact`), from its fit reached from
    ``z_est`` (else the prior)."""
    n, p = exact.K - 1, exact.p
    rows = exact.prior_rows()
    dof = (n - 1) + len(rows) - p
    start = exact.z_prior if z_est is None else np.asarray(z_est, float)
    try:
        z0 = exact.refine(start, max_iter=30)
    except (FloatingPointError, np.linalg.LinAlgError, ValueError):
        z0 = start
    r, J, rp, Jp, C = _problem(exact, z0)
    aa = C.inverse_diagonal()
    psi = C.whiten_transpose(r)          # a_j^T r
    G = C.whiten_transpose(J)            # rows g_j = J^T a_j
    chi2 = r @ r + rp @ rp - psi**2 / aa
    err = psi / aa
    F = J.T @ J + Jp.T @ Jp
    Fj = F - G[:, :, None] * G[:, None, :] / aa[:, None, None]
    gj = (J.T @ r + Jp.T @ rp) - G * (psi / aa)[:, None]
    step = -np.stack([np.linalg.lstsq(Fj[k], gj[k], rcond=None)[0] for k in range(n)])
    lin = chi2 + 2 * np.sum(step * gj, axis=1) + np.einsum("ni,nij,nj->n", step, Fj, step)
    refit = np.ones(n, bool) if select is None else np.asarray(select(lin, chi2.copy(), dof), bool)
    Z = z0 + step
    out = {"z": Z, "chi2": np.where(refit, chi2, lin), "converged": ~refit.copy(), "refitted": refit,
           "dropped_error_mm": err, "dof": np.full(n, dof)}
    out["converged"][:] = False
    for j in np.flatnonzero(refit):
        Z[j], out["chi2"][j], out["dropped_error_mm"][j], out["converged"][j] = _refit(exact, j, Z[j])
    return out
