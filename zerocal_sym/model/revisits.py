"""Revisited poses: rows of an array that repeat an earlier one, and the groups of visits of one pose.

A measurement round may visit a pose more than once (a *revisit*: the same
commanded joints, to :data:`REVISIT_TOL` in their file unit).  A revisit right
after the first visit (a *consecutive repeat*) measures a zero change and
carries no information; any other revisit is legitimate (a design's
replicates) when the file or the user says revisits are intended
(:mod:`zerocal_sym.io.measurement_checks`).

* :func:`first_duplicate` -- the first row that repeats an earlier one;
* :func:`consecutive_repeat` -- the first row that repeats the row before it;
* :func:`pose_groups` -- the visits of each pose: a label per row, the
  revisited poses' groups;
* :func:`shared_design` -- the shared (revisit) part of the distance
  covariance: which visits share a pose's systematic error
  (:mod:`zerocal_sym.identify.covariance`).

Shapes: K rows (poses), d columns.
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


#: up to this many rows :func:`first_duplicate` compares every pair at once (K^2 d numbers: the few poses of a
#: round in microseconds, where the cells' 3^d neighbour searches would cost more)
PAIRWISE_MAX_K = 64


def _first_duplicate_pairwise(X, tol):
    """:func:`first_duplicate` by every pair at once (finite ``X``, shape (K, d))."""
    D = np.max(np.abs(X[:, None, :] - X[None, :, :]), axis=2)
    rows = np.flatnonzero(np.tril(D <= tol, -1).any(axis=1))
    if not rows.size:
        return None
    k = int(rows[0])
    return k, int(np.argmin(D[k, :k]))


def first_duplicate(X, tol: float):
    """The first row that repeats an earlier one: ``(k, j)`` or None.

    ``k`` is the smallest index with an earlier row ``j`` within ``tol`` in
    every column (``max |X_j - X_k| <= tol``), ``j`` the nearest such row (the
    first of equals).  None at once when the sorted first column has no gap
    of ``tol`` or less (a repeat is within ``tol`` in that column too); else
    up to :data:`PAIRWISE_MAX_K` rows every pair at once; beyond, O(3^d K
    log K) in time and O(K d) in memory: rows are put in cells of side
    ``tol`` (hashed); a repeat lies in the same or a neighbouring cell.

    Parameters
    ----------
    X : ndarray, shape (K, d)
        Finite values.
    tol : float
        > 0.
    """
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    K, d = X.shape
    if K < 2:
        return None
    if not (np.all(np.isfinite(X)) and tol > 0) or float(np.max(np.abs(X))) / tol >= 2.0**50:
        return _first_duplicate_scan(X, tol)
    if np.all(np.diff(np.sort(X[:, 0])) > tol):  # no two rows within tol in the first column: none repeats
        return None
    if K <= PAIRWISE_MAX_K:
        return _first_duplicate_pairwise(X, tol)
    return _first_duplicate_hashed(X, tol)


def _first_duplicate_hashed(X, tol):
    """:func:`first_duplicate` through the hashed cells (finite ``X``, shape (K, d), K >= 2; ``tol > 0`` and
    ``max |X| / tol < 2^50``)."""
    from itertools import product

    K, d = X.shape
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


#: two poses whose coordinates (commanded joints in their file unit: deg or mm; or targets in mm) agree to this
#: are the same pose
REVISIT_TOL = 1e-9


def consecutive_repeat(X, tol: float = REVISIT_TOL):
    """The first row ``k`` within ``tol`` of row ``k - 1`` in every column (a zero change), or None."""
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    if X.shape[0] < 2:
        return None
    with np.errstate(invalid="ignore"):
        same = np.all(np.abs(np.diff(X, axis=0)) <= tol, axis=1)
    hit = np.flatnonzero(same)
    return int(hit[0]) + 1 if hit.size else None


def pose_groups(X, tol: float = REVISIT_TOL) -> np.ndarray:
    """The pose of each row: label ``g`` (0, 1, ... in order of first visit), shape (K,).

    Rows within ``tol`` of each other in every column are one pose (exact
    copies first, then any near copies merged: O(K log K) when there are
    none); ``tol = 0``: exact copies only.
    """
    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    K = X.shape[0]
    if K == 0:
        return np.zeros(0, int)
    _, first, inv = np.unique(X, axis=0, return_index=True, return_inverse=True)
    inv = np.ravel(inv)
    rep = np.sort(first)                      # one row per distinct pose, in order of first visit
    label_of_unique = np.empty(len(first), int)
    label_of_unique[np.argsort(first)] = np.arange(len(first))
    lab = label_of_unique[inv]
    # near copies (within tol, not equal): merge them into the earlier pose
    while tol > 0 and len(rep) > 1:
        dup = first_duplicate(X[rep], tol)
        if dup is None:
            break
        k, j = dup
        lab[lab == k] = j
        lab[lab > k] -= 1
        rep = np.delete(rep, k)
    return lab


def shared_design(labels) -> tuple:
    """``(singles, groups)`` of a pose labelling: the rows of poses visited once (bool (K,)) and the rows of
    each revisited pose (a list of index arrays, each of two or more rows, in order of first visit)."""
    lab = np.asarray(labels, int)
    counts = np.bincount(lab) if lab.size else np.zeros(0, int)
    singles = counts[lab] == 1
    order = np.argsort(lab, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)])
    groups = [order[starts[g]:starts[g + 1]] for g in np.flatnonzero(counts >= 2)]
    return singles, groups
