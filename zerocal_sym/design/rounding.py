"""K ordered poses from a design measure: efficient rounding, replicates, visiting order.

Realisation of K poses (:func:`realize`): efficient rounding (Pukelsheim &
Rieder 1992) of the support's weights to counts (none above ``(K + 1) // 2``);
*true replicates*: each support point visited as many times as its count,
the same pose again (a measurement or pose file of the design says revisits
are intended, :mod:`zerocal_sym.io.measurement_checks`); the visiting order
cycles through the support points (stride scheduling, never the same point
twice in a row: a zero change carries no information; several cycle orders
tried and the best kept by the exact criterion).  The minimum separation
holds between distinct poses: a replicate is the support point itself.
"""
from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

import numpy as np

from zerocal_sym.design.constraints import Constraints, make_constraints
from zerocal_sym.design.criteria import _criterion_terms, _criterion_weights, _noise_terms, _objective_batch
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.replicates import cap_counts, no_successive
from zerocal_sym.design.terms import _qscale, pose_terms

if TYPE_CHECKING:
    from zerocal_sym.design.approx import ApproxDesign


def efficient_rounding(w, K):
    """Counts summing to K from weights (Pukelsheim & Rieder 1992), shape (s,).

    ``n_i = ceil((K - s/2) w_i)``, then the count with the smallest ``n_i / w_i``
    is raised (or the largest ``(n_i - 1) / w_i`` lowered) until the sum is K.
    """
    w = np.asarray(w, float)
    s = len(w)
    n = np.maximum(np.ceil((K - s / 2) * w), 0).astype(int)
    while n.sum() < K:
        n[int(np.argmin(n / w))] += 1
    while n.sum() > K:
        r = np.where(n > 0, (n - 1) / w, -np.inf)
        n[int(np.argmax(r))] -= 1
    return n


def place_replicates(reps, counts):
    """``counts[i]`` visits of each support point ``reps[i]``: true replicates (the same pose again).

    Returns
    -------
    P : ndarray, shape (K, n)
    label : ndarray of int, shape (K,)
        The support point of each pose.
    """
    reps = np.atleast_2d(np.asarray(reps, float))
    counts = np.asarray(counts, int)
    lab = np.repeat(np.arange(len(counts)), counts)
    return reps[lab].copy(), lab


def _interleave(counts, priority, rho=None, label_rho=None, l0=None):
    """Visiting sequence of support points: stride scheduling, never the same point twice in a row if avoidable.

    ``priority`` breaks ties (earlier first).  With ``l0`` (consecutive travel)
    a step is taken only to points whose ``rho`` is within ``l0`` of the
    previous one (``label_rho`` per support point).  Returns shape (K,) of
    support-point indices, or None if the travel rule blocks.
    """
    counts = np.asarray(counts, int)
    K = int(counts.sum())
    rank = np.empty(len(counts), int)
    rank[np.asarray(priority)] = np.arange(len(counts))
    cur = np.zeros(len(counts))
    left = counts.copy()
    seq = np.empty(K, int)
    prev = -1
    for k in range(K):
        cur[left > 0] += counts[left > 0]
        cand = np.flatnonzero(left > 0)
        if l0 is not None and prev >= 0:
            cand = cand[np.abs(label_rho[cand] - label_rho[prev]) <= l0]
            if len(cand) == 0:
                return None
        if len(cand) > 1 and prev in cand:
            cand = cand[cand != prev]
        score = cur[cand] - 1e-9 * rank[cand]
        j = int(cand[np.argmax(score)])
        cur[j] -= K
        left[j] -= 1
        seq[k] = j
        prev = j
    if K > 1 and np.any(seq[1:] == seq[:-1]) and l0 is None:  # stride order ran into one point: greedy order
        seq = no_successive(counts, priority)
    return seq


def realize(robot, ad: ApproxDesign, K: int, cons: Constraints | None = None, noise=None, tolerances=None,
            criterion=None, n_orders: int = 60, seed: int = 0):
    """K ordered poses from an approximate design: efficient rounding, replicates, visiting order.

    Parameters
    ----------
    ad : ApproxDesign
    K : int
    criterion : str, optional
        Criterion of the order search (default the measure's).
    n_orders : int
        Cycle orders of the support points tried (all of them for up to 5 points).

    Returns
    -------
    P : ndarray, shape (K, n)
        Poses in visiting order.
    info : dict
        ``counts`` per support point, ``objective`` (exact, internal; the independent noise alone),
        ``orders_tried``.
    """
    from zerocal_sym.model.noise import NoiseModel

    noise = NoiseModel.coerce(noise, robot=robot)
    cons = cons or make_constraints(robot)
    criterion = criterion or ad.criterion
    reps, ws = ad.support, ad.support_w
    if len(reps) > K:  # every support point gets a pose (small weights can carry the identifiability)
        keep = np.argsort(-ws)[:K]
        reps, ws = reps[keep], ws[keep] / ws[keep].sum()
    counts = cap_counts(efficient_rounding(ws, K), ws)
    P, lab = place_replicates(reps, counts)
    sm2, sx2 = _noise_terms(noise, robot)
    wt = _criterion_weights(robot, criterion, tolerances)
    t = pose_terms(robot, P)
    aq, v = _criterion_terms(robot, criterion, t, _qscale(robot), sx2, wt)
    rho = t["rho"]
    s = len(counts)
    label_rho = np.array([rho[lab == i].mean() if np.any(lab == i) else 0.0 for i in range(s)])
    l0 = cons.travel_mm if cons.travel_mode == "consecutive" else None
    rng = np.random.default_rng(seed)
    if s <= 5:
        prios = [np.array(pr) for pr in itertools.permutations(range(s))]
    else:
        prios = [np.argsort(-ws), np.arange(s)] + [rng.permutation(s) for _ in range(n_orders)]
    best = None
    members = [list(np.flatnonzero(lab == i)) for i in range(s)]
    for pr in prios:
        seq = _interleave(counts, pr, rho, label_rho, l0)
        if seq is None:
            continue
        nxt = [0] * s
        idx = np.empty(K, int)
        for k, j in enumerate(seq):
            idx[k] = members[j][nxt[j]]
            nxt[j] += 1
        if l0 is not None and np.any(np.abs(np.diff(rho[idx])) > l0):
            continue
        if K > 1 and np.any(seq[1:] == seq[:-1]):  # a zero change (the travel rule left no other way)
            continue
        o = float(_objective_batch(criterion, aq[idx][None], v[idx][None], sm2, wt)[0])
        if best is None or o < best[0]:
            best = (o, idx)
    if best is None:
        raise DesignError(f"no visiting order of the {K} poses keeps every change of rho within "
                          f"l0 = {cons.travel_mm:g} mm without visiting a pose twice in a row")
    o, idx = best
    return P[idx], {"counts": counts.tolist(), "support": reps.tolist(), "objective": o,
                    "orders_tried": len(prios)}
