"""Visiting order of a design (:func:`best_order`).

Order: the visiting order matters (G differences consecutive rows; the scale
noise is on consecutive changes, the servo noise on poses, which makes the
Fisher information of servo-dominated noise almost order-free).  The NLP
keeps the labels of its start, so the multi-start explores orders; the best
design's order is then optimised over permutations (:func:`best_order`).
"""
from __future__ import annotations

import itertools

import numpy as np

from zerocal_sym.design.constraints import Constraints
from zerocal_sym.design.criteria import _criterion_terms, _criterion_weights, _noise_terms, _objective_batch
from zerocal_sym.design.terms import _qscale, pose_terms


# --------------------------------------------------------------------------- ordering
def best_order(robot, P, criterion, noise=None, cons: Constraints | None = None, exhaustive_max: int = 8,
               tolerances=None, objective=None):
    """Visiting order of the poses that minimises the criterion.

    Exhaustive over all K! orders for ``K <= exhaustive_max``; otherwise a
    local search over pair swaps and segment reversals (2-opt) from the
    given order, best improvement first.  With the ``consecutive`` travel
    mode, orders that break it are skipped.  ``objective(P)``, if given,
    returns a function of permutations (B, K) giving B internal objectives,
    used instead of the criterion's (the checked design).

    Returns
    -------
    order : ndarray of int, shape (K,)
    objective : float
        Internal objective of the best order.
    """
    P = np.atleast_2d(np.asarray(P, float))
    K = len(P)
    sm2, sx2 = _noise_terms(noise, robot)
    qs = _qscale(robot)
    wc = _criterion_weights(robot, criterion, tolerances)
    t = pose_terms(robot, P)
    rho = t["rho"]
    aq0, v0 = _criterion_terms(robot, criterion, t, qs, sx2, wc)

    fn = None if objective is None else objective(P)

    def objective(perms):
        o = _objective_batch(criterion, aq0[perms], v0[perms], sm2, wc) if fn is None else fn(perms)
        if cons is not None and cons.travel_mode == "consecutive":
            o[np.max(np.abs(np.diff(rho[perms], axis=1)), axis=1) > cons.travel_mm] = np.inf
        return o

    if K <= exhaustive_max:
        best, best_o = np.arange(K), objective(np.arange(K)[None])[0]
        it = itertools.permutations(range(K))
        while True:
            chunk = np.array(list(itertools.islice(it, 20000)), dtype=int)
            if chunk.size == 0:
                break
            o = objective(chunk)
            k = int(np.argmin(o))
            if o[k] < best_o - 1e-12 * abs(best_o):
                best, best_o = chunk[k], o[k]
        return np.asarray(best), float(best_o)
    order = np.arange(K)
    cur = objective(order[None])[0]
    for _ in range(200):
        moves = []
        for i in range(K):
            for j in range(i + 1, K):
                sw = order.copy()
                sw[[i, j]] = sw[[j, i]]
                moves.append(sw)
                rv = order.copy()
                rv[i:j + 1] = rv[i:j + 1][::-1]
                moves.append(rv)
        moves = np.array(moves)
        o = objective(moves)
        k = int(np.argmin(o))
        if not o[k] < cur - 1e-12 * abs(cur):
            break
        order, cur = moves[k], o[k]
    return order, float(cur)
