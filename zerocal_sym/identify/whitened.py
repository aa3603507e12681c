"""The linearised, whitened problem at a point: what the estimators hand to the fit check and the diagnosis.

:class:`_Linear` is the whitened problem at the fit check's evaluation point
(whitened residuals and Jacobian, the banded Cholesky factor of the data rows'
covariance, the rank of the Jacobian); :meth:`_Linear.per_reading` gives each
reading's mean-shift statistic, leverage, estimated error and the move of the
parameters without it, in O(n c) time and memory (no n x n matrix).  The chi²
test and the per-reading statistics made of it: :mod:`zerocal_sym.identify.check.statistics`;
their definitions: :mod:`zerocal_sym.identify.fitcheck`.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded

#: a reading whose mean-shift information is below this fraction of its own is not testable (leverage ~1)
LEVERAGE_TOL = 1e-9
#: relative singular-value threshold for the rank of the whitened Jacobian
RANK_RTOL = 1e-9


class _Linear:
    """The whitened problem at the evaluation point of a fit check.

    ``r`` (N,) whitened residuals, data rows first (n of them) then the prior
    rows; ``J`` (N, c) whitened Jacobian w.r.t. the fitted coordinates;
    ``band = (l, b)`` the lower-bidiagonal Cholesky factor of the data rows'
    covariance (diagonal ``l`` (n,), sub-diagonal ``b`` (n-1,)) they are
    whitened with, or the covariance itself when it is more than the bands
    (a :class:`~zerocal_sym.identify.covariance.ChangeCovariance` with the
    shared revisit error: its ``whiten`` is the whitening); ``poses`` (n,) the pose index k of each data row; ``raw``
    (n,) residuals in mm; ``basis`` (p, c) maps the fitted coordinates to the
    scaled parameters ``z`` (``p = z / scale``).  ``svd``: the caller's thin
    SVD of ``J`` (its U may carry extra zero rows below); ``terms``: the
    per-reading statistics ``(t, leverage, delta, move)`` already computed
    (``nlls_problem._fit_terms``; full column rank, no prior rows).
    """

    def __init__(self, r, J, band, poses, raw, basis, scale, names, n_prior_rows=0, point=None, svd=None,
                 terms=None):
        self.r = np.asarray(r, float)
        self.J = np.atleast_2d(np.asarray(J, float))
        self.poses = np.asarray(poses, int)
        self.raw = np.asarray(raw, float)
        self.basis = np.asarray(basis, float)
        self.scale = np.asarray(scale, float)
        self.names = tuple(names)
        self.n = self.poses.size
        self.n_prior_rows = int(n_prior_rows)
        self.point = point
        self._cov = None
        if hasattr(band, "whiten_transpose"):  # the covariance (bands + shared part): its whitening
            self._cov = band
            band = band.cholesky()
        l, b = (np.ravel(np.asarray(x, float)) for x in band)
        self._band, self._terms = (l, b), terms
        #: False when the exact model cannot be evaluated there (a pose is not an assembly with these errors)
        self.valid = bool(np.isfinite(self.r).all() and np.isfinite(self.J).all() and np.isfinite(l).all()
                          and np.isfinite(b).all() and np.all(l != 0))
        if not self.valid:
            self.r = np.where(np.isfinite(self.r), self.r, 0.0)
            self.J = np.where(np.isfinite(self.J), self.J, 0.0)
            svd, self._terms = None, None
        if svd is None:
            U, s, Vt = np.linalg.svd(self.J, full_matrices=False)
        else:
            U, s, Vt = svd
            U = U[: self.J.shape[0]]
        tol = RANK_RTOL * (s[0] if s.size else 0.0)
        self.rank = int(np.count_nonzero(s > tol)) if s.size else 0
        self.U, self.s, self.Vt = U[:, : self.rank], s[: self.rank], Vt[: self.rank]
        self.dof = self.n + self.n_prior_rows - self.rank
        if self._terms is not None and (self.rank != self.J.shape[1] or self.n_prior_rows
                                        or self.r.size != self.n or self._cov is not None):
            self._terms = None  # the terms assume full column rank and no prior rows

    def per_reading(self, moves: bool = True):
        """``(t, leverage, delta, dz)`` for every data row: the mean-shift statistic, leverage,
        estimated error of the reading (mm) and the change of ``z`` (n, p) when the reading is removed
        (None with ``moves=False``).

        With ``a_j = [W e_j; 0]`` the whitened indicator of reading j (``W = L^-1``
        for the bands) and ``H = U U^T`` the hat matrix: ``aa_j = |a_j|^2`` (the
        diagonal of ``C^-1``), ``U^T a_j`` (row j of ``W^T U_data``), ``a_j^T r``
        (entry j of ``W^T r_data``): every term from bidiagonal solves, O(n c)
        (O(n (c + G)) with the shared revisit error).
        """
        n = self.n
        if self._terms is not None:  # computed by the caller (the same quantities)
            t, lev, delta, move = self._terms
            t, lev, delta = np.ravel(t), np.ravel(lev), np.ravel(delta)
            dz = (self.basis @ np.reshape(move, (self.J.shape[1], n), order="F")).T if moves else None
            return t, lev, delta, dz
        if not self.valid:  # nothing to test there (statistics() reports why)
            nan = np.full(n, np.nan)
            return nan, np.ones(n), nan.copy(), (np.full((n, self.basis.shape[0]), np.nan) if moves else None)
        l, b = self._band
        if self._cov is None:
            aa = banded.inverse_diagonal(l, b)
            WT = lambda V: banded.backward(l, b, V)  # noqa: E731 - W^T = L^-T
        else:
            aa = self._cov.inverse_diagonal()
            WT = self._cov.whiten_transpose
        UA = WT(self.U[:n]).T                             # (rank, n): column j is U^T a_j
        den = aa - np.sum(UA * UA, axis=0)                # a^T (I - H) a
        num = WT(self.r[:n]) - UA.T @ (self.U.T @ self.r)   # a^T (I - H) r
        with np.errstate(divide="ignore", invalid="ignore"):
            lev = np.where(aa > 0, 1.0 - den / aa, 1.0)
            ok = den > LEVERAGE_TOL * aa
            t = np.where(ok, num / np.sqrt(np.where(ok, den, 1.0)), np.nan)
            delta = np.where(ok, num / np.where(ok, den, 1.0), np.nan)
        if not moves:
            return t, lev, delta, None
        # the fit with a free error on reading j moves the coordinates by F^+ J^T a_j delta_j
        if self.rank:
            Q = self.Vt.T @ (UA / self.s[:, None])       # F^+ J^T a_j per unit error of reading j
            dz = (self.basis @ (Q * delta[None, :])).T
        else:
            dz = np.full((n, self.basis.shape[0]), np.nan)
        dz[~ok] = np.nan
        return t, lev, delta, dz


def standardised_many(r, J, l, b) -> tuple:
    """:meth:`_Linear.per_reading`'s ``(t, delta)`` of N data sets at once, whitened by the bands (no prior rows).

    ``r`` (N, n) whitened residuals, ``J`` (N, n, c) whitened Jacobians, ``l`` (N, n) and ``b`` (N, n-1) the
    bidiagonal Cholesky factors: the same formulas (the hat matrix from each ``J``'s thin SVD, its rank by
    :data:`RANK_RTOL`), batched over the data sets, O(N n c) time and memory.  NaN where a reading is not
    testable (:data:`LEVERAGE_TOL`)."""
    r, J = np.asarray(r, float), np.asarray(J, float)
    U, s, _ = np.linalg.svd(J, full_matrices=False)                    # (N, n, c), (N, c)
    U = U * (s > RANK_RTOL * s[:, :1])[:, None, :]                      # the columns beyond each rank dropped
    aa = banded.inverse_diagonal(l, b)                                  # (N, n)
    UA = banded.backward(l, b, U)                                       # row j: U^T a_j
    den = aa - np.sum(UA * UA, axis=2)
    num = banded.backward(l, b, r) - np.einsum("njc,nc->nj", UA, np.einsum("njc,nj->nc", U, r))
    with np.errstate(divide="ignore", invalid="ignore"):
        ok = den > LEVERAGE_TOL * aa
        t = np.where(ok, num / np.sqrt(np.where(ok, den, 1.0)), np.nan)
        delta = np.where(ok, num / np.where(ok, den, 1.0), np.nan)
    return t, delta
