"""Discrete exchange design (:func:`exchange_design`).

Coordinate exchange (Fedorov / DETMAX family) over a candidate grid of
feasible poses, every slot of the ordered design swapped against every
candidate until no swap improves; several seeded random starts.
"""
from __future__ import annotations

import time

import numpy as np

from zerocal_sym.design.limits import DesignError, _check_k
from zerocal_sym.design.constraints import Constraints, _feasible_random_subset, _pointwise_ok, make_constraints
from zerocal_sym.design.criteria import (_check_criterion, _criterion_terms, _criterion_weights, _noise_terms,
                                         _objective_batch, _user_value)
from zerocal_sym.design.terms import _qscale, pose_distances, pose_terms


# --------------------------------------------------------------------------- discrete exchange
def candidate_grid(robot, cons: Constraints, *grid):
    """Feasible candidate poses on a grid over the region, ndarray shape (N, n).

    ``grid``: the region's grid sizes -- ``nx, ny`` for a rectangle (default
    25 x 11), ``nr, na, nz`` (rings, points on the rim, levels) for a cylinder
    (default 4, 24, 5); none for the region's default.
    """
    pts = cons.region.grid(*(grid or cons.region.default_grid))
    return pts[_pointwise_ok(robot, pts, cons)]


def _trials(fn, trial, keep, cur):
    """The objective of the trials (B, K) that ``keep`` selects, inf for the others, shape (B,).

    With a lower bound (``fn.lower``, a cheaper function of the same trials, never above ``fn``) only the trials
    whose bound is below the improvement threshold of the current objective ``cur`` are evaluated: a trial
    left out cannot improve on ``cur``, and every trial that could be the least one, if the least improves,
    is evaluated -- the exchange's choice (the first least trial, if it improves) is the one it makes with
    every trial evaluated.
    """
    o = np.full(len(trial), np.inf)
    sel = np.flatnonzero(keep)
    lower = getattr(fn, "lower", None)
    if lower is not None and len(sel):
        sel = sel[lower(trial[sel]) < cur - 1e-10 * max(abs(cur), 1.0)]
    if len(sel):
        o[sel] = fn(trial[sel])
    return o


def exchange_design(robot, K, criterion="crlb", cons: Constraints | None = None, noise=None, seed=0,
                    n_starts: int = 8, grid=None, max_sweeps: int = 50, tolerances=None, step=None,
                    objective=None):
    """Discrete coordinate exchange over a candidate grid.

    Each start is a random ordered set of K distinct feasible candidates
    (seeded); each sweep tries, for every slot, every unused candidate and
    keeps the best improvement (Fedorov-type exchange, one slot at a time);
    sweeps repeat until none improves.

    Parameters
    ----------
    grid : tuple of int, optional
        Candidate grid (:func:`candidate_grid`); default the region's
        (25 x 11 on a rectangle, 4 rings / 24 on the rim / 5 levels on a
        cylinder).
    tolerances : dict, optional
        Tolerances of the omitted errors (``mse``).
    step : callable, optional
        ``step()`` after each start (progress).
    objective : callable, optional
        ``objective(candidates)`` returns a function of index sets (B, K) into the candidates (N, n) giving
        B internal objectives (smaller is better): used instead of the criterion's (the checked design,
        :mod:`zerocal_sym.design.checked`); ``value`` is then the criterion's value of the best design.

    Returns
    -------
    dict
        ``poses`` (K, n), ``objective``, ``value`` (user units), ``starts``
        (list of per-start objectives), ``n_candidates``, ``time_s``.
    """
    t0 = time.perf_counter()
    cons = cons or make_constraints(robot)
    _check_k(K, robot)
    _check_criterion(criterion)
    grid = tuple(grid or cons.region.default_grid)
    cand = candidate_grid(robot, cons, *grid)
    if len(cand) < K:
        raise DesignError(f"only {len(cand)} feasible candidate poses in the region on a "
                          f"{' x '.join(str(g) for g in grid)} grid (K = {K} needed): relax the singularity "
                          "margin or joint limits, or enlarge the region")
    sm2, sx2 = _noise_terms(noise, robot)
    qs = _qscale(robot)
    wc = _criterion_weights(robot, criterion, tolerances)
    t = pose_terms(robot, cand)
    aq_all, v_all = _criterion_terms(robot, criterion, t, qs, sx2, wc)
    rho = t["rho"]
    rng = np.random.default_rng(seed)
    N = len(cand)
    if objective is None:
        def fn(idx):
            return _objective_batch(criterion, aq_all[idx], v_all[idx], sm2, wc)
    else:
        fn = objective(cand)
    close = None
    if cons.min_separation_mm > 0:
        close = pose_distances(robot, cand) < cons.min_separation_mm
        np.fill_diagonal(close, False)
    best_idx, best_o, starts = None, np.inf, []
    seen = {}  # (design, slot) -> the best trial of that slot and its objective: the same design, the same trials
    for _ in range(n_starts):
        idx = _feasible_random_subset(rng, rho, K, cons, close=close)
        if idx is None:
            raise DesignError(f"no {K} candidate poses fit the scale travel l0 = {cons.travel_mm:g} mm "
                              f"({cons.travel_mode}) and the minimum separation {cons.min_separation_mm:g} mm")
        cur = fn(idx[None])[0]
        for _sweep in range(max_sweeps):
            improved = False
            for pos in rng.permutation(K):
                key = (idx.tobytes(), int(pos))
                if key in seen:  # this slot of this design was tried before (an earlier sweep or start): its best
                    k_idx, ok_ = seen[key]
                    if ok_ < cur - 1e-10 * max(abs(cur), 1.0):
                        idx, cur, improved = k_idx, ok_, True
                    continue
                free = np.setdiff1d(np.arange(N), idx)
                trial = np.repeat(idx[None], len(free), axis=0)
                trial[:, pos] = free
                # the objective of the trials that keep the travel and the separation (the others: inf)
                if cons.travel_mode == "range":
                    keep = ~(np.ptp(rho[trial], axis=1) > cons.travel_mm)
                else:
                    keep = ~(np.max(np.abs(np.diff(rho[trial], axis=1)), axis=1) > cons.travel_mm)
                if close is not None:
                    keep &= ~np.any(close[np.ix_(free, np.delete(idx, pos))], axis=1)
                o = _trials(fn, trial, keep, cur)
                k = int(np.argmin(o))
                seen[key] = (trial[k], o[k])
                if o[k] < cur - 1e-10 * max(abs(cur), 1.0):
                    idx, cur, improved = trial[k], o[k], True
            if not improved:
                break
        starts.append(float(cur))
        if step is not None:
            step()
        if cur < best_o:
            best_idx, best_o = idx.copy(), cur
    if not np.isfinite(best_o):
        raise DesignError("every exchange start is rank-deficient: the region cannot identify the parameters")
    if objective is not None:
        best_o = float(_objective_batch(criterion, aq_all[best_idx][None], v_all[best_idx][None], sm2, wc)[0])
    return {"poses": cand[best_idx], "objective": float(best_o),
            "value": _user_value(criterion, best_o, robot.errors.offset_unit),
            "starts": starts, "n_candidates": int(N), "grid": list(grid), "time_s": time.perf_counter() - t0}
