"""Truncated-SVD solution of ``G x = b`` (:func:`tsvd_solve`) and its truncation rules.

``x_t = sum_{i<=t} (u_i^T b / sigma_i) v_i``, the ``t`` largest singular
values kept; :func:`zerocal_sym.identify.tsvd.identify_tsvd` solves the
paper's identification model (Eq. 28-29) with it.

Truncation rules (:func:`tsvd_solve`)
-------------------------------------
``threshold`` (**the default**)
    keep ``sigma_i > rtol * sigma_1`` (default ``rtol = 1e-6``).  For the
    paper's 4-parameter model this keeps all four singular values (``sigma_4 /
    sigma_1 ~ 2.1e-3`` for the 6-pose scheme): the weakest direction (the
    common mode of the offsets mixed with ``rMx``) carries the offsets, and
    truncating it loses them (~0.4 deg even without noise, see
    ``docs/reproduction.md``).  In the paper the "truncation" is the reduction
    from the 12-parameter model (Eq. 24-27) to the 4-parameter one (Eq. 28);
    Eq. (29) is then solved at full rank.  It is the default because it is the
    only rule that reproduces the paper's accuracy and recovers the offsets
    exactly without noise.
``gcv``
    generalised cross-validation, ``t = argmin ||r_t||^2 / (m - t)^2``
    (``t < m``).  With ``m - p = 1`` degree of freedom (6 poses) it is fragile.
``discrepancy``
    Morozov's discrepancy principle: the smallest ``t`` with
    ``||r_t|| <= tau * delta``, ``delta^2 = sum(noise_std^2)`` the expected
    squared norm of the noise (``tau = 1``).  Needs the noise level, e.g. from
    a :class:`~zerocal_sym.model.noise.NoiseModel`
    (:func:`~zerocal_sym.identify.tsvd.identify_tsvd` derives it from the
    measurement covariance).

An explicit ``t`` overrides the rule.  The filter factors of TSVD are 1 for the
kept singular values and 0 for the others.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.errors import IdentificationError

RULES = ("threshold", "gcv", "discrepancy")
DEFAULT_RULE = "threshold"
DEFAULT_RTOL = 1e-6


@dataclass
class TSVDSolution:
    """A truncated-SVD solution of ``G x = b``.

    Attributes
    ----------
    x : ndarray, shape (p,)
    t : int
        Truncation level (number of singular values kept).
    singular_values : ndarray, shape (min(m, p),)
        All singular values of G, descending.
    filter_factors : ndarray, shape (min(m, p),)
        1 for kept, 0 for discarded singular values.
    rule : str
        ``"threshold"``, ``"gcv"``, ``"discrepancy"`` or ``"fixed"`` (t given).
    U : ndarray, shape (m, r)
    Vt : ndarray, shape (r, p)
    residual_norms : ndarray, shape (r + 1,)
        ``||G x_t - b||`` for ``t = 0 .. r``.
    criterion : ndarray, shape (r + 1,) or None
        GCV function (``gcv``) for each ``t``; None otherwise.
    """

    x: np.ndarray
    t: int
    singular_values: np.ndarray
    filter_factors: np.ndarray
    rule: str
    U: np.ndarray = field(repr=False, default=None)
    Vt: np.ndarray = field(repr=False, default=None)
    residual_norms: np.ndarray = field(repr=False, default=None)
    criterion: np.ndarray | None = field(repr=False, default=None)

    @property
    def condition_number(self) -> float:
        s = self.singular_values
        return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")

    def operator(self) -> np.ndarray:
        """The linear map ``b -> x`` of this truncation, shape (p, m)."""
        t = self.t
        return (self.Vt[:t].T / self.singular_values[:t]) @ self.U[:, :t].T


def tsvd_solve(G, b, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL, noise_std=None, tau=1.0) -> TSVDSolution:
    """Truncated-SVD solution of ``G x = b``.

    Parameters
    ----------
    G : ndarray, shape (m, p)
    b : ndarray, shape (m,)
    t : int, optional
        Truncation level, ``1 <= t <= min(m, p)``; overrides ``rule``.
    rule : {"threshold", "gcv", "discrepancy"}
        Automatic choice of ``t`` (module docstring); default ``threshold``.
    rtol : float
        Relative singular-value threshold of the ``threshold`` rule.
    noise_std : float or ndarray, shape (m,), optional
        Noise std of each element of ``b`` (``discrepancy`` rule; required there).
    tau : float
        Safety factor of the discrepancy principle.

    Returns
    -------
    TSVDSolution
    """
    G = np.asarray(G, float)
    b = np.asarray(b, float)
    if G.ndim != 2 or b.shape != (G.shape[0],):
        raise ValueError(f"G must be (m, p) and b (m,), got {G.shape} and {b.shape}")
    if not (np.isfinite(G).all() and np.isfinite(b).all()):
        raise IdentificationError("G or b contains NaN or inf")
    U, s, Vt = np.linalg.svd(G, full_matrices=False)
    return _solve_svd(U, s, Vt, b, G.shape[0], t, rule, rtol, noise_std, tau)


def _solve_svd(U, s, Vt, b, m, t, rule, rtol, noise_std, tau) -> TSVDSolution:
    """:func:`tsvd_solve` from the thin SVD ``U, s, Vt`` of the checked G (m rows)."""
    r = s.size
    beta = U.T @ b
    # ||r_t||^2 = ||b||^2 - sum_{i<=t} beta_i^2 (exact for the thin SVD plus the orthogonal part)
    tail = np.concatenate([np.cumsum((beta**2)[::-1])[::-1], [0.0]])
    perp = max(float(b @ b) - float(beta @ beta), 0.0)
    res2 = tail + perp
    criterion = None
    positive = int(np.count_nonzero(s > 0))
    if t is not None:
        t = int(t)
        if not 1 <= t <= r:
            raise ValueError(f"truncation t must be in 1..{r}, got {t}")
        used = "fixed"
    elif rule == "threshold":
        t = int(np.count_nonzero(s > rtol * s[0])) if s[0] > 0 else 0
        used = rule
    elif rule == "gcv":
        ts = np.arange(r + 1)
        criterion = np.full(r + 1, np.inf)
        ok = (ts < m) & (ts <= positive)
        criterion[ok] = res2[ok] / (m - ts[ok]) ** 2.0
        criterion[0] = np.inf
        t = int(np.argmin(criterion))
        used = rule
    elif rule == "discrepancy":
        if noise_std is None:
            raise ValueError("the discrepancy principle needs the noise level (noise_std)")
        delta = float(np.sqrt(np.sum(np.broadcast_to(np.asarray(noise_std, float), b.shape) ** 2)))
        ok = np.flatnonzero(np.sqrt(res2[1:positive + 1]) <= tau * delta)
        t = int(ok[0]) + 1 if ok.size else positive
        used = rule
    else:
        raise ValueError(f"unknown truncation rule {rule!r} (known: {', '.join(RULES)})")
    if t < 1:
        raise IdentificationError("G is zero: nothing can be identified")
    f = (np.arange(r) < t).astype(float)
    x = Vt[:t].T @ (beta[:t] / s[:t])
    return TSVDSolution(x=x, t=t, singular_values=s, filter_factors=f, rule=used, U=U, Vt=Vt,
                        residual_norms=np.sqrt(res2), criterion=criterion)
