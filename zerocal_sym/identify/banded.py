"""Tridiagonal covariances of the changes and their bidiagonal Cholesky factors: O(K) algebra, batched.

The covariance of the K - 1 measured changes, ``C = sigma_m^2 I + D diag(v) D^T``
(:class:`~zerocal_sym.identify.fisher.ChangeCovariance`), is tridiagonal: diagonal ``d`` (K-1,),
off-diagonal ``e`` (K-2,) (``C[k+1, k] = C[k, k+1] = e[k]``).  Its Cholesky factor ``L`` is lower
bidiagonal: diagonal ``l`` (K-1,), sub-diagonal ``b`` (K-2,) (``L[k+1, k] = b[k]``).  Everything here is
linear in K; nothing builds a (K-1) x (K-1) matrix.

Arrays may carry leading batch axes (N fits): ``d`` (N, K-1), ``e`` (N, K-2), right-hand sides (N, K-1)
or (N, K-1, c) (c columns, e.g. the p parameters).  The triangular solves are affine recurrences
``y_k = alpha_k y_{k-1} + beta_k`` evaluated as a parallel prefix (:func:`scan`: log2 K vectorised steps);
the factorisation itself is a loop over the changes (vectorised over the batch).
"""
from __future__ import annotations

import math

import numpy as np


def scan(alpha, beta) -> np.ndarray:
    """``y_k = alpha_k y_{k-1} + beta_k`` (``y_{-1} = 0``; ``alpha_0`` unused) along the axis of the changes.

    ``alpha`` (..., K-1); ``beta`` (..., K-1) or (..., K-1, c) (a new array is returned).  Hillis-Steele
    scan of the affine maps: ceil(log2 K) vectorised steps, O(K c log K) flops, O(K c) memory.
    """
    Y = np.array(beta, float)
    vec = Y.ndim == np.ndim(alpha)
    if vec:
        Y = Y[..., None]
    a = np.array(alpha, float)
    n = a.shape[-1]
    s = 1
    while s < n:
        Y[..., s:, :] += a[..., s:, None] * Y[..., :-s, :]
        a[..., s:] = a[..., s:] * a[..., :-s]
        s *= 2
    return Y[..., 0] if vec else Y


def _cols(l, V):
    """``V`` with the axis of the changes second to last (a column axis added to a vector), and whether it was one."""
    V = np.asarray(V, float)
    vec = V.ndim == np.ndim(l)
    return (V[..., None] if vec else V), vec


def forward(l, b, V) -> np.ndarray:
    """``L^-1 V`` (``L`` lower bidiagonal): ``y_k = (v_k - b_{k-1} y_{k-1}) / l_k``."""
    l, b = np.asarray(l, float), np.asarray(b, float)
    V, vec = _cols(l, V)
    alpha = np.zeros(l.shape)
    alpha[..., 1:] = -b / l[..., 1:]
    Y = scan(alpha, V / l[..., None])
    return Y[..., 0] if vec else Y


def backward(l, b, V) -> np.ndarray:
    """``L^-T V`` (``L^T`` upper bidiagonal): ``y_k = (v_k - b_k y_{k+1}) / l_k``, from the last row."""
    l, b = np.asarray(l, float), np.asarray(b, float)
    V, vec = _cols(l, V)
    alpha = np.zeros(l.shape)
    alpha[..., 1:] = (-b / l[..., :-1])[..., ::-1]
    Y = scan(alpha, (V / l[..., None])[..., ::-1, :])[..., ::-1, :]
    return Y[..., 0] if vec else Y


def solve(l, b, V) -> np.ndarray:
    """``C^-1 V = L^-T L^-1 V``."""
    return backward(l, b, forward(l, b, V))


def inverse_diagonal(l, b) -> np.ndarray:
    """The diagonal of ``C^-1`` (..., K-1): ``|L^-1 e_j|^2 = S_j / l_j^2``, ``S_j = 1 + (b_j / l_{j+1})^2 S_{j+1}``."""
    l, b = np.asarray(l, float), np.asarray(b, float)
    alpha = np.zeros(l.shape)
    alpha[..., 1:] = ((b / l[..., 1:]) ** 2)[..., ::-1]
    S = scan(alpha, np.ones(l.shape))[..., ::-1]
    return S / l**2


def times_factor(l, b, V) -> np.ndarray:
    """``L V`` (``(L V)_k = l_k v_k + b_{k-1} v_{k-1}``)."""
    l, b = np.asarray(l, float), np.asarray(b, float)
    V, vec = _cols(l, V)
    out = V * l[..., None]
    out[..., 1:, :] += V[..., :-1, :] * b[..., None]
    return out[..., 0] if vec else out


def cholesky(d, e):
    """``(l, b, ok)``: the bidiagonal Cholesky factor of the tridiagonal ``(d, e)``, batched over leading axes.

    ``l_k^2 = d_k - b_{k-1}^2``, ``b_k = e_k / l_k``.  ``ok`` (the batch shape): False where ``C`` is not
    positive definite (a pivot <= 0 or not finite); ``l`` and ``b`` are NaN from there on in that batch member.
    """
    d, e = np.asarray(d, float), np.asarray(e, float)
    n = d.shape[-1]
    if d.ndim == 1:  # one matrix: a loop on Python floats (fastest for long n)
        ls, bs = [], []
        prev, sqrt, inf = 0.0, math.sqrt, math.inf
        for dk, ek in zip(d.tolist(), e.tolist() + [0.0]):
            q = dk - prev * prev
            if not 0.0 < q < inf:
                break
            lk = sqrt(q)
            ls.append(lk)
            prev = ek / lk
            bs.append(prev)
        ok = len(ls) == n
        l, b = np.full(n, np.nan), np.full(max(n - 1, 0), np.nan)
        l[: len(ls)] = ls
        m = min(len(ls), n - 1) if ok else max(len(ls) - 1, 0)
        b[:m] = bs[:m]
        return l, b, ok
    l, b = np.empty(d.shape), np.empty(e.shape)
    prev = np.zeros(d.shape[:-1])
    with np.errstate(invalid="ignore", divide="ignore"):
        for k in range(n):
            q = d[..., k] - prev * prev
            l[..., k] = np.sqrt(np.where(q > 0, q, np.nan))
            if k < n - 1:
                prev = e[..., k] / l[..., k]
                b[..., k] = prev
    ok = np.all(np.isfinite(l), axis=-1)
    return l, b, ok


def submatrix(d, e, keep):
    """``(d, e)`` of ``C[keep][:, keep]`` (``keep`` sorted indices): tridiagonal again, 0 across a gap."""
    keep = np.asarray(keep, int)
    d, e = np.asarray(d, float), np.asarray(e, float)
    adjacent = np.diff(keep) == 1
    off = np.zeros(max(keep.size - 1, 0))
    off[adjacent] = e[keep[:-1][adjacent]]
    return d[keep].copy(), off
