"""K ordered poses from a design measure: efficient rounding, replicates, visiting order.

Realisation of K poses (:func:`realize`): efficient rounding (Pukelsheim &
Rieder 1992) of the support's weights to counts; replicates of a support
point on a lattice around it (hexagonal in 2-D, face-centred cubic in 3-D,
spacing the minimum separation) inside the feasible set and the travel
window; the visiting order cycles through the support points (stride
scheduling, never the same point twice in a row, several cycle orders tried
and the best kept by the exact criterion).
"""
from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

import numpy as np

from zerocal_sym.design.constraints import Constraints, _pointwise_ok, make_constraints
from zerocal_sym.design.criteria import _criterion_terms, _criterion_weights, _noise_terms, _objective_batch
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.terms import _qscale, _user_scale, pose_distances, pose_terms

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


def _lattice(n, spacing, count):
    """Lattice offsets sorted by length, at least ``count`` of them, nearest neighbours ``spacing`` apart.

    Hexagonal in 2-D, face-centred cubic in 3-D, cubic otherwise.  Shape (M, n).
    """
    R = 2
    while (2 * R + 1) ** n < 3 * count + 10:
        R += 1
    r = np.arange(-R, R + 1)
    ijk = np.stack(np.meshgrid(*([r] * n), indexing="ij"), axis=-1).reshape(-1, n).astype(float)
    if n == 2:
        B = np.array([[1.0, 0.0], [0.5, math.sqrt(3) / 2]])
    elif n == 3:
        B = np.array([[0.0, 1.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 0.0]]) / math.sqrt(2)
    else:
        B = np.eye(n)
    off = ijk @ B * spacing
    order = np.argsort(np.linalg.norm(off, axis=1), kind="stable")
    return off[order]


def place_replicates(robot, cons: Constraints, reps, counts, window=None, score=None):
    """``counts[i]`` poses around each support point ``reps[i]``: the point itself and lattice neighbours.

    Lattice spacing: the minimum separation (at least 0.01 mm); each pose
    feasible (:func:`zerocal_sym.design.constraints._pointwise_ok`), with
    ``rho`` inside ``window`` and at least the spacing from every pose
    already placed.  Among the feasible lattice points near a support point
    those with the largest ``score`` are taken (``score(Y)`` -> shape (M,):
    the sensitivity ``d(x)`` of the optimal measure, i.e. the points that
    lose the least information); default the nearest.

    Returns
    -------
    P : ndarray, shape (K, n)
    label : ndarray of int, shape (K,)
        The support point of each pose.

    Raises
    ------
    DesignError
        If a support point has too few feasible neighbours.
    """
    n = robot.n
    sp = max(cons.min_separation_mm, 0.01) * (1 + 1e-6)
    us = _user_scale(robot)  # the lattice in file units: a degree of an orientation counts as a mm
    P, lab = [np.empty((0, n))], [np.empty(0, int)]
    placed = np.empty((0, n))
    for i, (x, c) in enumerate(zip(np.atleast_2d(reps), counts)):
        if c <= 0:
            continue
        m = 3 * c + 10
        while True:
            Y = x + _lattice(n, sp, m)[:m] / us
            ok = _pointwise_ok(robot, Y, cons)
            if window is not None and np.any(ok):
                rho = pose_terms(robot, Y[ok])["rho"]
                okk = (rho >= window[0] - 1e-9) & (rho <= window[1] + 1e-9)
                ok[np.flatnonzero(ok)] = okk
            if len(placed) and np.any(ok):
                dist = np.min(pose_distances(robot, Y[ok], placed), axis=1)
                ok[np.flatnonzero(ok)] = dist >= sp * (1 - 1e-9)
            good = Y[ok]
            if len(good) >= c:
                if score is not None and len(good) > c:
                    pool = good[:max(3 * c, c + 6)]
                    sc = score(pool)
                    sc[0] = np.inf if np.allclose(pool[0], x) else sc[0]  # the support point itself first
                    good = pool[np.argsort(-sc, kind="stable")[:c]]
                else:
                    good = good[:c]
                break
            if m > 64 * c + 2000:
                raise DesignError(f"cannot place {c} poses {sp:g} mm apart around the support point "
                                  f"{np.round(x, 3).tolist()} mm within the constraints")
            m *= 4
        P.append(good)
        lab.append(np.full(c, i))
        placed = np.vstack([placed, good])
    return np.vstack(P), np.concatenate(lab)


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
        ``counts`` per support point, ``objective`` (exact, internal),
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
    counts = efficient_rounding(ws, K)
    window = ad.window if cons.travel_mode == "range" else None
    P, lab = place_replicates(robot, cons, reps, counts, window, ad.sensitivity(robot, noise))
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
        o = float(_objective_batch(criterion, aq[idx][None], v[idx][None], sm2, wt)[0])
        if best is None or o < best[0]:
            best = (o, idx)
    if best is None:
        raise DesignError(f"no visiting order of the {K} poses keeps every change of rho within "
                          f"l0 = {cons.travel_mm:g} mm")
    o, idx = best
    return P[idx], {"counts": counts.tolist(), "support": reps.tolist(), "objective": o,
                    "orders_tried": len(prios)}
