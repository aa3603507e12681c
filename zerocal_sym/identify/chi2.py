"""The chi² distribution without scipy: :func:`chi2_sf` (the upper tail: the fit check's p-value) and
:func:`chi2_cdf` (the lower tail).

Both are the regularised incomplete gamma function :func:`_gamma_pq`
(``P(dof/2, x/2)``, ``Q(dof/2, x/2)``): a series below ``a + 1``, Lentz's
continued fraction above, :func:`math.lgamma`; accurate to ~1e-14 relative
(``tests/test_fitcheck.py`` compares them with ``scipy.stats.chi2``).  Used by
the fit check (:mod:`zerocal_sym.identify.fitcheck`, :mod:`~zerocal_sym.identify.check.statistics`,
:mod:`~zerocal_sym.identify.diagnose.causes`) and the p-values of
:func:`~zerocal_sym.identify.batch.identify_batch`; :func:`_fmt_p` prints a p-value.
"""
from __future__ import annotations

import math

import numpy as np


def _fmt_p(p) -> str:
    """``p = 0.0123``, ``p < 1e-300`` (below the smallest double the tail reaches) or ``p n/a``."""
    if p is None or not np.isfinite(p):
        return "p n/a"
    return "p < 1e-300" if p == 0.0 else f"p = {p:.3g}"


def _gamma_pq(a: float, x: float) -> tuple:
    """Regularised incomplete gamma ``(P(a, x), Q(a, x))`` (series below ``a + 1``, continued fraction above)."""
    if x <= 0.0:
        return 0.0, 1.0
    if math.isinf(x):
        return 1.0, 0.0
    log_pre = -x + a * math.log(x) - math.lgamma(a)
    if x < a + 1.0:
        ap, term = a, 1.0 / a
        total = term
        for _ in range(100000):
            ap += 1.0
            term *= x / ap
            total += term
            if abs(term) < abs(total) * 1e-17:
                break
        p = math.exp(log_pre) * total if log_pre > -745.0 else 0.0
        p = min(max(p, 0.0), 1.0)
        return p, 1.0 - p
    tiny = 1e-300
    b = x + 1.0 - a
    c, d = 1.0 / tiny, 1.0 / b
    h = d
    for i in range(1, 100000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1.0 / d
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-16:
            break
    log_q = log_pre + math.log(h)
    q = math.exp(log_q) if log_q > -745.0 else 0.0
    q = min(max(q, 0.0), 1.0)
    return 1.0 - q, q


def chi2_sf(x, dof) -> float:
    """Survival function ``P(X >= x)`` of the chi² distribution with ``dof`` degrees of freedom.

    ``Q(dof/2, x/2)``, the regularised upper incomplete gamma function
    (series / Lentz continued fraction, :func:`math.lgamma`); accurate to
    ~1e-14 relative, down to ~1e-300 (then 0.0).  ``dof`` may be non-integer.

    Raises
    ------
    ValueError
        ``dof <= 0`` or not finite.
    """
    return _tail(x, dof, 1, "chi2_sf")


def chi2_cdf(x, dof) -> float:
    """Distribution function ``P(X <= x)`` (the lower tail, accurate when small)."""
    return _tail(x, dof, 0, "chi2_cdf")


def _tail(x, dof, upper: int, who: str) -> float:
    """``P(a, x/2)`` (``upper`` 0) or ``Q`` (1) with ``a = dof/2``, the arguments checked (NaN in, NaN out)."""
    dof = float(dof)
    if not (dof > 0 and math.isfinite(dof)):
        raise ValueError(f"{who}: dof must be positive, got {dof}")
    x = float(x)
    if math.isnan(x):
        return float("nan")
    return _gamma_pq(0.5 * dof, 0.5 * x)[upper]


def chi2_sf_array(x, dof) -> "np.ndarray":
    """:func:`chi2_sf` of every entry of ``x`` (any shape) at one ``dof``: the same numbers, bit for bit.

    The series and the continued fraction of :func:`_gamma_pq` run on all entries at once (numpy; each entry
    stops changing when it has converged, as the scalar loop breaks), in the same operations and order; the
    logarithms and exponentials of the end are :mod:`math`'s, entry by entry, as there.  NaN in, NaN out.
    """
    dof = float(dof)
    if not (dof > 0 and math.isfinite(dof)):
        raise ValueError(f"chi2_sf_array: dof must be positive, got {dof}")
    a = 0.5 * dof
    xx = 0.5 * np.asarray(x, float)
    q = np.full(xx.shape, np.nan)
    q[xx <= 0.0] = 1.0
    q[np.isinf(xx) & (xx > 0)] = 0.0
    live = np.isfinite(xx) & (xx > 0.0)
    lg = math.lgamma(a)
    ser = live & (xx < a + 1.0)
    with np.errstate(divide="ignore", over="ignore", under="ignore", invalid="ignore"):
        if ser.any():
            xs = xx[ser]
            ap, term = np.full(xs.shape, a), np.full(xs.shape, 1.0 / a)
            total = term.copy()
            go = np.ones(xs.shape, bool)
            for _ in range(100000):
                ap = np.where(go, ap + 1.0, ap)
                term = np.where(go, term * (xs / ap), term)
                total = np.where(go, total + term, total)
                go &= ~(np.abs(term) < np.abs(total) * 1e-17)
                if not go.any():
                    break
            out = []
            for xv, tv in zip(xs.tolist(), total.tolist()):
                log_pre = -xv + a * math.log(xv) - lg
                pv = math.exp(log_pre) * tv if log_pre > -745.0 else 0.0
                out.append(1.0 - min(max(pv, 0.0), 1.0))
            q[ser] = out
        cf = live & ~(xx < a + 1.0)
        if cf.any():
            xs = xx[cf]
            tiny = 1e-300
            b = xs + 1.0 - a
            c, d = np.full(xs.shape, 1.0 / tiny), 1.0 / b
            h = d.copy()
            go = np.ones(xs.shape, bool)
            for i in range(1, 100000):
                an = -i * (i - a)
                b = np.where(go, b + 2.0, b)
                dn = an * d + b
                dn = np.where(np.abs(dn) < tiny, tiny, dn)
                cn = b + an / c
                cn = np.where(np.abs(cn) < tiny, tiny, cn)
                dn = 1.0 / dn
                delta = dn * cn
                h = np.where(go, h * delta, h)
                d, c = np.where(go, dn, d), np.where(go, cn, c)
                go &= ~(np.abs(delta - 1.0) < 1e-16)
                if not go.any():
                    break
            out = []
            for xv, hv in zip(xs.tolist(), h.tolist()):
                log_q = -xv + a * math.log(xv) - lg + math.log(hv)
                qv = math.exp(log_q) if log_q > -745.0 else 0.0
                out.append(min(max(qv, 0.0), 1.0))
            q[cf] = out
    return q
