"""The first row of an array that repeats an earlier one within a tolerance (:func:`first_duplicate`).

Used for repeated poses in a measurement file
(:mod:`zerocal_sym.io.measurement_checks`) and in a pose list.
"""
from __future__ import annotations

import numpy as np

#: odd multipliers of the cell hash (fixed: the result never depends on them, only the speed)
_HASH = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0xD6E8FEB86659FD93,
                  0xFF51AFD7ED558CCD, 0xC4CEB9FE1A85EC53], np.uint64)


def _first_duplicate_scan(X, tol):
    for k in range(1, X.shape[0]):
        d = np.max(np.abs(X[:k] - X[k]), axis=1)
        j = int(np.argmin(d))
        if d[j] <= tol:
            return k, j
    return None


def first_duplicate(X, tol: float):
    """The first row that repeats an earlier one: ``(k, j)`` or None.

    ``k`` is the smallest index with an earlier row ``j`` within ``tol`` in
    every column (``max |X_j - X_k| <= tol``), ``j`` the nearest such row (the
    first of equals).  O(3^d K log K) in time and O(K d) in memory: rows are
    put in cells of side ``tol`` (hashed); a repeat lies in the same or a
    neighbouring cell.

    Parameters
    ----------
    X : ndarray, shape (K, d)
        Finite values.
    tol : float
        > 0.
    """
    from itertools import product

    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    K, d = X.shape
    if K < 2:
        return None
    if not (np.all(np.isfinite(X)) and tol > 0) or float(np.max(np.abs(X))) / tol >= 2.0**50:
        return _first_duplicate_scan(X, tol)
    keys = np.floor(X / tol).astype(np.int64).view(np.uint64)
    if d > len(_HASH):
        return _first_duplicate_scan(X, tol)
    mult = _HASH[:d]
    with np.errstate(over="ignore"):
        code = (keys * mult).sum(axis=1, dtype=np.uint64)  # wraps: a hash, linear in the cell indices
    order = np.argsort(code, kind="stable")
    sc = code[order]
    eq = np.flatnonzero(sc[1:] == sc[:-1])
    if eq.size and np.any(keys[order[eq]] != keys[order[eq + 1]]):  # two cells with one hash: exact fallback
        return _first_duplicate_scan(X, tol)
    best = int(order[eq + 1].min()) if eq.size else K  # same cell (side tol): a repeat for certain
    # below ``best`` every cell holds one row: a neighbouring cell has at most one candidate
    n0 = best
    oR = np.argsort(code[:n0], kind="stable")
    scR = code[:n0][oR]
    for off in product((-1, 0, 1), repeat=d):
        nz = [o for o in off if o]
        if not nz or nz[0] < 0 or n0 < 2:  # each pair once: (i, j) by +off is (j, i) by -off
            continue
        with np.errstate(over="ignore"):
            shift = (np.asarray(off, np.int64).view(np.uint64) * mult).sum(dtype=np.uint64)
            q = code[:n0] + shift
        pos = np.minimum(np.searchsorted(scR, q), n0 - 1)
        hit = np.flatnonzero(scR[pos] == q)
        i, j = hit, oR[pos[hit]]
        close = np.max(np.abs(X[i] - X[j]), axis=1) <= tol
        if np.any(close):
            best = min(best, int(np.maximum(i[close], j[close]).min()))
    if best >= K:
        return None
    dist = np.max(np.abs(X[:best] - X[best]), axis=1)
    return best, int(np.argmin(dist))
