"""The certificate beyond the candidate grid: the sensitivity maximised over the region.

The equivalence theorem bounds the best design by the largest directional derivative ``d(x)`` of the
measure over the poses a design may use (:mod:`zerocal_sym.design.posemodel`); over a candidate grid it
bounds designs on the grid only, and a design polished off the grid (Ipopt) may beat it.  Here
(:func:`search_region`, decision):

1. **screen the cells** of the candidates: each candidate's Lipschitz-type bound on ``d`` over its cell,
   ``d_i + 2 g_i r``, with ``g_i`` the largest slope of ``d`` to a neighbour within 1.5 grid spacings and
   ``r`` the cell's half-diagonal (the factor 2 a margin for the slope's change in the cell); the cells
   whose bound reaches the measure's ``s`` (where ``d`` could pass it) and the largest ``d`` are the starts;
2. **maximise** ``d / s`` from each start over the region by a pattern search (:func:`maximise`: moves
   along the axes and, up to 3-D, the diagonals; only feasible poses, inside the travel window;
   the step halved when no move improves, down to :data:`FINAL_STEP` of the grid spacing), in one batch;
3. add the maxima that pass ``s (1 + tol)`` to the candidates and solve the measure again; repeat
   (:data:`ROUNDS` at most) until none does.

The certificate then covers the grid, its refinements and these maxima (``certificate.candidates``
counts them); the design's own poses are added to the set the bound covers
(:meth:`zerocal_sym.design.approx.ApproxDesign.cover`), so its efficiency is never reported against a
set it lies outside.  It is not a proof over the continuum: a maximum of ``d`` in a cell the screen passed
over (a slope that grows more than twofold within one cell) would escape it; the report says what the
bound covers.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design.constraints import _pointwise_ok
from zerocal_sym.design.feasible import _pointwise, take_terms
from zerocal_sym.design.posemodel import E_Q, PoseModel, _crit, _sens

#: rounds of (search, solve again) per window
ROUNDS = 3
#: starts of the pattern search per round, at most
MAX_STARTS = 32
#: a maximum is added when ``d > s (1 + tol)``, tol = this
REGION_TOL = 1e-3
#: the pattern search's first and last step, in grid spacings
FIRST_STEP, FINAL_STEP = 0.25, 4e-3
#: the pattern search's most moves per start
MAX_MOVES = 200
#: an infeasible move is halved back towards its start this many times, at most
BACKTRACK = 3
#: bisection steps of a boundary point (:func:`boundary_points`): to the grid spacing / 2^6
BOUNDARY_HALVINGS = 6


def directions(n: int) -> np.ndarray:
    """Unit moves of a pattern search: the axes, and for n <= 3 the diagonals of each pair, shape (D, n)."""
    E = np.eye(n)
    dirs = [E, -E]
    if n <= 3:
        for i in range(n):
            for j in range(i + 1, n):
                for si in (1, -1):
                    for sj in (1, -1):
                        dirs.append(((si * E[i] + sj * E[j]) / math.sqrt(2))[None])
    return np.vstack(dirs)


def boundary_points(robot, cons, X, h, halvings: int = BOUNDARY_HALVINGS) -> np.ndarray:
    """Points on the boundary of the feasible set next to the grid ``X`` (N, n) of spacing ``h``, shape (B, n).

    For each candidate and each unit move (:func:`directions`) whose neighbour one spacing away is not
    feasible, the last feasible point of the segment between them (bisection, ``halvings`` steps: to
    ``h / 2^halvings``); those more than ``h / 100`` from the candidate.  The grid's cells at the boundary
    are closed by them: near a singularity margin or the reach the sensitivity can climb steeply within
    the last cell, where the grid has no point.
    """
    n = X.shape[1]
    hs = np.broadcast_to(np.asarray(h, float), (n,))
    dirs = directions(n)
    base = np.repeat(X, len(dirs), axis=0)
    far = (X[:, None, :] + dirs[None] * hs).reshape(-1, n)
    out = ~_pointwise_ok(robot, far, cons)
    if not np.any(out):
        return np.zeros((0, n))
    lo, hi = base[out], far[out]  # lo feasible, hi not
    for _ in range(halvings):
        mid = 0.5 * (lo + hi)
        ok = _pointwise_ok(robot, mid, cons)
        lo[ok], hi[~ok] = mid[ok], mid[~ok]
    keep = np.linalg.norm((lo - base[out]) / hs, axis=1) > 1e-2
    return np.unique(np.round(lo[keep], 9), axis=0)


class Sensitivity:
    """``d(x) / s`` of a solved measure at any poses (the order-free pose model's terms of those poses)."""

    def __init__(self, robot, noise, criterion, weights, sol, W):
        self.robot, self.noise, self.criterion, self.weights = robot, noise, criterion, weights
        self.c = sol["c"]
        _, self.G, self.s = _crit(criterion, sol["M"], W, sol.get("q", E_Q))

    def __call__(self, Y, terms=None):
        """``(d / s, rho)`` at poses ``Y`` (M, n) (``terms``: their design terms, if at hand)."""
        m = PoseModel(self.robot, Y, self.noise, self.criterion, self.weights, terms)
        return _sens(self.G, m.aq, self.c, m.vt) / self.s, m.rho


def screen(X, r, h, k: int = MAX_STARTS) -> np.ndarray:
    """Indices of the candidates whose cell may hold a larger ``d / s`` than 1 (module docstring), the
    largest bounds first, at most ``k``; ``r`` (N,) is ``d / s`` at ``X`` (N, n), ``h`` the grid spacing."""
    N = len(X)
    hs = np.broadcast_to(np.asarray(h, float), (X.shape[1],))
    I, J, D = _neighbour_pairs(X / hs, 1.5)  # in grid spacings
    slope = np.zeros(N)
    np.maximum.at(slope, I, np.abs(r[I] - r[J]) / D)
    half_diag = 0.5 * math.sqrt(X.shape[1])
    bound = r + 2.0 * slope * half_diag
    cand = np.flatnonzero(bound >= 1.0)
    cand = cand[np.argsort(-bound[cand])][:k]
    top = np.argsort(-r)[: max(4, k // 4)]
    return np.unique(np.concatenate([cand, top]))


def _neighbour_pairs(U, radius):
    """All pairs ``(i, j)`` of the points ``U`` (N, n) with ``0 < |U_i - U_j| <= radius`` and their distances.

    The points hashed into cells of side ``radius``; each compared with those of its 3^n neighbouring cells
    (sorted cell codes and ``searchsorted``: O(3^n N) and the pairs, never N^2).
    """
    import itertools

    N, n = U.shape
    cell = np.floor(U / radius).astype(np.int64)
    cell -= cell.min(axis=0) - 1
    mult = np.cumprod(np.concatenate([[1], cell.max(axis=0)[:-1] + 2])).astype(np.int64)
    code = cell @ mult
    order = np.argsort(code, kind="stable")
    sc = code[order]
    idx = np.arange(N)
    Is, Js = [], []
    for o in itertools.product((-1, 0, 1), repeat=n):
        tgt = code + int(np.dot(o, mult))
        lo, hi = np.searchsorted(sc, tgt, "left"), np.searchsorted(sc, tgt, "right")
        cnt = hi - lo
        if not cnt.any():
            continue
        start = np.repeat(lo - (np.cumsum(cnt) - cnt), cnt)
        Is.append(np.repeat(idx, cnt))
        Js.append(order[start + np.arange(int(cnt.sum()))])
    if not Is:
        return np.zeros(0, int), np.zeros(0, int), np.zeros(0)
    I, J = np.concatenate(Is), np.concatenate(Js)
    D = np.sqrt(np.sum((U[I] - U[J]) ** 2, axis=1))
    keep = (D > 0) & (D <= radius)
    return I[keep], J[keep], D[keep]


class _Rows:
    """The design terms of rows of a batch of poses, filled as their feasibility is checked (the terms of the
    feasible ones, :func:`~zerocal_sym.design.feasible._pointwise`)."""

    def __init__(self, N, ok, t):
        self.N, self.t = N, None
        self.put(np.flatnonzero(ok), t)

    def put(self, rows, t):
        if t is None or not len(rows):
            return
        if self.t is None:
            self.t = {k: np.empty((self.N,) + v.shape[1:]) for k, v in t.items()}
        for k, v in t.items():
            self.t[k][rows] = v

    def of(self, ok):
        """The terms of the rows ``ok`` (bool), laid out as :func:`~zerocal_sym.design.terms.pose_terms`'s."""
        return take_terms(self.t, ok)


def maximise(robot, cons, sens: Sensitivity, X0, h, window):
    """Pattern search for the largest ``d / s`` from each start ``X0`` (S, n) over the feasible poses with
    ``rho`` in ``window``; returns ``(X (S, n), r (S,))``."""
    X = np.array(X0, float)
    S, n = X.shape
    hs = np.broadcast_to(np.asarray(h, float), (n,))
    dirs = directions(n)
    r, _ = sens(X)
    step = np.full(S, FIRST_STEP)
    moves = np.zeros(S, int)
    active = np.ones(S, bool)
    while np.any(active):
        a = np.flatnonzero(active)
        base = np.repeat(X[a], len(dirs), axis=0)
        Y = (X[a, None, :] + step[a, None, None] * dirs[None] * hs).reshape(-1, n)
        ok, t = _pointwise(robot, Y, cons)
        terms = _Rows(len(Y), ok, t)
        # a move that leaves the feasible set goes as far along it as feasible (halving back, BACKTRACK times):
        # at a curved boundary (the singularity margin, the reach) it slides along it
        for _ in range(BACKTRACK):
            bad = np.flatnonzero(~ok)
            if not len(bad):
                break
            Y[bad] = 0.5 * (Y[bad] + base[bad])
            ok[bad], t = _pointwise(robot, Y[bad], cons)
            terms.put(bad[ok[bad]], t)
        ry = np.full(len(Y), -np.inf)
        if np.any(ok):
            val, rho = sens(Y[ok], terms.of(ok))
            val[(rho < window[0]) | (rho > window[1])] = -np.inf
            ry[ok] = val
        ry = ry.reshape(len(a), len(dirs))
        k = np.argmax(ry, axis=1)
        best = ry[np.arange(len(a)), k]
        up = best > r[a] * (1 + 1e-12)
        ia = a[up]
        X[ia] = Y.reshape(len(a), len(dirs), n)[up, k[up]]
        r[ia] = best[up]
        moves[ia] += 1
        step[a[~up]] /= 2
        active = (step >= FINAL_STEP) & (moves < MAX_MOVES)
    return X, r


def search_region(robot, cons, noise, criterion, weights, model, idx, sol, window, h, solve, W, tol=REGION_TOL):
    """Add the local maxima of ``d`` over the region to the candidates until none passes ``s (1 + tol)``.

    ``model``: the :class:`PoseModel` of every candidate, ``idx`` those of this window, ``sol`` the measure
    solved on them; ``solve(model, idx, w0)`` solves it again.  Each round's maxima above ``s`` join the
    candidates; while one passes ``s (1 + tol)`` the measure is solved again, else the last maxima stay
    candidates of weight zero and the measure's efficiency bound takes them in (E: its certificate over
    the extended set).  Returns ``(model, idx, sol, info)``, ``info`` {``starts``, ``added``, ``rounds``,
    ``max_ratio`` (the largest ``d / s`` of the last search)}.
    """
    from zerocal_sym.design.measure import e_certificate

    starts = added = rounds = 0
    max_ratio = float(np.max(sol["d"]) / sol["s"])
    for rnd in range(ROUNDS):
        sens = Sensitivity(robot, noise, criterion, weights, sol, W)
        sub = model.subset(idx)
        r = sol["d"] / sol["s"]
        pick = screen(sub.X, r, h)
        starts += len(pick)
        Xm, rm = maximise(robot, cons, sens, sub.X[pick], h, window)
        max_ratio = max(float(np.max(r)), float(np.max(rm)) if len(rm) else 0.0)
        rounds += 1
        keep = rm > 1.0
        if not np.any(keep):
            break
        new, first = np.unique(np.round(Xm[keep], 9), axis=0, return_index=True)
        rnew = rm[keep][first]
        model = model.extend(PoseModel(robot, new, noise, criterion, weights))
        idx = np.concatenate([idx, np.arange(len(model.X) - len(new), len(model.X))])
        added += len(new)
        if np.any(rnew > 1.0 + tol) and rnd < ROUNDS - 1:
            w0 = np.concatenate([sol["w"], np.zeros(len(new))])
            sol = solve(model, idx, 0.9 * w0 / w0.sum() + 0.1 / len(w0))
            continue
        # the last maxima: candidates of weight zero, in the bound
        sol = dict(sol, w=np.concatenate([sol["w"], np.zeros(len(new))]),
                   d=np.concatenate([sol["d"], rnew * sol["s"]]))
        if criterion == "E":
            sol["eff_lb"], sol["E_bound"] = e_certificate(model.subset(idx), sol["M"], sol["c"])
        else:
            sol["eff_lb"] = float(sol["s"] / np.max(sol["d"]))
        break
    return model, idx, sol, {"starts": starts, "added": added, "rounds": rounds, "max_ratio": max_ratio}


def with_poses(robot, criterion, noise, weights, bound_windows, P) -> list:
    """Each window's measure (:attr:`~zerocal_sym.design.approx.ApproxDesign.bound_windows`) with its
    efficiency bound over its candidates *and* the poses of ``P`` (K, n) with ``rho`` in the window (one
    window: all of them): the largest ``d / s`` of both; E: its certificate over both
    (:func:`~zerocal_sym.design.measure.e_certificate`).  Returns the measures (dicts), in order."""
    from zerocal_sym.design.measure import e_certificate

    mP = PoseModel(robot, P, noise, criterion, weights)
    out = []
    for win, Xw, sol in bound_windows:
        inside = np.ones(len(P), bool) if len(bound_windows) == 1 else (mP.rho >= win[0]) & (mP.rho <= win[1])
        sol = dict(sol)
        if np.any(inside):
            if criterion == "E":
                ext = PoseModel(robot, np.vstack([Xw, P[inside]]), noise, "E", weights)
                sol["eff_lb"], sol["E_bound"] = e_certificate(ext, sol["M"], sol["c"])
            else:
                r = float(np.max(Sensitivity(robot, noise, criterion, weights, sol, mP.W)(P[inside])[0]))
                sol["eff_lb"] = 1.0 / max(1.0 / sol["eff_lb"], r)
        out.append(sol)
    return out
