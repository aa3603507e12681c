"""The checked design: the least RMS CRLB among designs whose fit check sees what they assume.

:func:`checked_search` finds the K poses that minimise the penalised objective of
:func:`zerocal_sym.design.detection.evaluate_batch` (the crlb criterion's plus
:data:`~zerocal_sym.design.detection.PENALTY` times the shortfall of the
:class:`~zerocal_sym.design.detection.Requirement`): the discrete exchange on the penalised objective,
then, from its best design, from the crlb-optimal design (and shaken copies of it) and from the baseline
scheme, the best visiting order (:func:`zerocal_sym.design.order.best_order`) and a pattern search over the
poses (:func:`polish`: one pose along an axis or a diagonal, or all of them along random directions, only
feasible moves, the best taken, the step halved when none improves); the winner is the best end whose
report (:func:`~zerocal_sym.design.detection.detection`, the orders refitted exactly) meets the
requirement.  Ipopt's polish is not used: its objective is the crlb alone, and at the crlb optimum the fit
check often sees nothing (a mirror-symmetric design: the reversed order's readings are its own).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design.certify import directions
from zerocal_sym.design.constraints import Constraints, _pointwise_ok, check_design
from zerocal_sym.design.criteria import _noise_terms
from zerocal_sym.design.detection import (ORDER_MARGIN, PENALTY, Requirement, Terms, crlb_objective_batch,
                                          detection, evaluate_batch)
from zerocal_sym.design.terms import _crlb_weights, offset_positions

#: pattern search: the first step as a fraction of the region's width per coordinate, and the last
POLISH_FIRST, POLISH_LAST = 1.0 / 16, 1e-5
#: pattern search: the most moves
POLISH_MAX_MOVES = 400
#: pattern search: moves of all the poses at once per round
POLISH_RANDOM = 32
#: starts of the pattern search from the crlb design shaken: how many, and by how much (a fraction of the
#: region's width per coordinate, normal)
PERTURBED, PERTURB = 3, 0.03


class Objective:
    """The penalised objective of designs drawn from a set of poses: ``Objective(...)(P)(idx)``."""

    def __init__(self, robot, noise, req: Requirement, penalty: float = PENALTY):
        self.robot, self.noise, self.req, self.penalty = robot, noise, req, penalty
        self.sm2 = _noise_terms(noise, robot)[0]
        self.off = offset_positions(robot)
        self.w = _crlb_weights(robot)

    def __call__(self, P):
        T = Terms(self.robot, P, self.noise)

        def fn(idx):
            return self.of_terms(T.take(np.asarray(idx)))[0]

        def lower(idx):  # the crlb objective alone: the objective adds a non-negative penalty to it
            idx = np.asarray(idx)
            return crlb_objective_batch({"aq": T.aq[idx], "v": T.v[idx]}, self.sm2, self.w)

        fn.lower = lower
        return fn

    def of_terms(self, d):
        """``(objective, crlb objective, shortfall)`` of B designs from :meth:`Terms.take` (B, K, ...)."""
        o, oc, short, _, _ = evaluate_batch(self.robot, self.req, d, self.sm2, self.off, self.w, self.penalty)
        return o, oc, short


def polish(robot, P, cons: Constraints, fn: Objective, seed: int = 0):
    """Pattern search on the penalised objective from the feasible design ``P`` (K, n); returns (P, objective).

    Each round tries, at the current step (per coordinate a fraction of the region's width), every move of
    one pose along one direction (:func:`~zerocal_sym.design.certify.directions`) and :data:`POLISH_RANDOM` moves of all the poses at
    once along seeded random directions (they follow a constraint that couples the poses, which single
    moves cannot); the best feasible improvement is taken -- the moved poses feasible
    (:func:`~zerocal_sym.design.constraints._pointwise_ok`), the travel window and the separation kept --,
    else the step is halved.
    """
    P = np.array(P, float)
    K, n = P.shape
    lo, hi = _region_box(cons, P)
    width = np.maximum(hi - lo, 1e-9)
    dirs = directions(n)
    rng = np.random.default_rng(seed)
    T = Terms(robot, P, fn.noise)
    cur = fn.of_terms(T.take(np.arange(K)[None]))[0][0]
    step = POLISH_FIRST
    moves = 0
    while step >= POLISH_LAST and moves < POLISH_MAX_MOVES:
        single = np.clip(P[:, None, :] + step * dirs[None, :, :] * width, lo, hi).reshape(-1, n)  # (K * D, n)
        which = np.repeat(np.arange(K), len(dirs))
        U = rng.normal(size=(POLISH_RANDOM, K, n))
        U /= np.linalg.norm(U.reshape(POLISH_RANDOM, -1), axis=1)[:, None, None] / math.sqrt(K)
        whole = np.clip(P[None] + step * U * width, lo, hi)  # (R, K, n)
        X = np.vstack([single, whole.reshape(-1, n)])
        ok = _pointwise_ok(robot, X, cons)
        # an infeasible pose's terms may not be finite: the current pose stands in for it (its trial is dropped)
        Tx = Terms(robot, np.where(ok[:, None], X, np.vstack([P[which], np.tile(P, (POLISH_RANDOM, 1))])), fn.noise)
        ns = len(single)
        # the trial designs: one pose replaced, or all of them
        idx = np.repeat(np.arange(K)[None], ns + POLISH_RANDOM, axis=0)
        d = T.take(idx)
        rows = np.arange(ns)
        for key in d:
            xv = getattr(Tx, key)
            d[key][rows, which] = xv[:ns]
            d[key][ns:] = xv[ns:].reshape((POLISH_RANDOM, K) + xv.shape[1:])
        keep = np.concatenate([ok[:ns], ok[ns:].reshape(POLISH_RANDOM, K).all(axis=1)]) & _window_ok(d["rho"], cons)
        if cons.min_separation_mm > 0:
            designs = np.concatenate([np.repeat(P[None], ns, axis=0), whole])
            designs[rows, which] = single
            keep &= ~(_closest(robot, designs) < cons.min_separation_mm)
        thr = cur - 1e-12 * max(abs(cur), 1.0)
        o = _objectives(fn, d, keep, thr)
        k = int(np.argmin(o))
        if o[k] < thr:
            P = designs[k].copy() if cons.min_separation_mm > 0 else _design_of(k, P, single, which, whole)
            T = Terms(robot, P, fn.noise)
            cur = o[k]
            moves += 1
        else:
            step /= 2
    return P, float(cur)


def _objectives(fn: Objective, d: dict, keep, thr):
    """The penalised objective of the trial designs ``d`` (:meth:`Terms.take`, B designs) that ``keep`` selects
    and whose crlb objective (a lower bound: the penalty is not negative) is below ``thr``; inf for the others,
    shape (B,).  A design left out can neither improve on ``thr`` nor be the least of those that do."""
    o = np.full(len(keep), np.inf)
    sel = np.flatnonzero(keep)
    if len(sel):
        sel = sel[crlb_objective_batch({"aq": d["aq"][sel], "v": d["v"][sel]}, fn.sm2, fn.w) < thr]
    if len(sel):
        o[sel] = fn.of_terms({k_: v[sel] for k_, v in d.items()})[0]
    return o


def _design_of(k, P, single, which, whole):
    if k < len(single):
        Q = P.copy()
        Q[which[k]] = single[k]
        return Q
    return whole[k - len(single)].copy()


def _closest(robot, designs):
    """The smallest distance between two poses of each design (file units), shape (B,)."""
    from zerocal_sym.design.terms import _user_scale

    U = designs * _user_scale(robot)
    D = np.linalg.norm(U[:, :, None, :] - U[:, None, :, :], axis=3)
    K = designs.shape[1]
    D[:, np.arange(K), np.arange(K)] = np.inf
    return D.min(axis=(1, 2))


def _region_box(cons, P):
    reg = cons.region
    lo = np.asarray(getattr(reg, "lo", P.min(axis=0)), float)
    hi = np.asarray(getattr(reg, "hi", P.max(axis=0)), float)
    finite = np.isfinite(lo) & np.isfinite(hi)
    span = np.ptp(P, axis=0)
    return np.where(finite, lo, P.min(axis=0)), np.where(finite, hi, P.min(axis=0) + np.maximum(span, 1.0))


def _window_ok(rho, cons):
    """The travel constraint of B designs, bool (B,)."""
    if cons.travel_mode == "range":
        return np.ptp(rho, axis=1) <= cons.travel_mm
    return np.max(np.abs(np.diff(rho, axis=1)), axis=1) <= cons.travel_mm


def checked_search(robot, K, cons: Constraints, noise, req: Requirement, starts, seed: int = 0,
                   exchange_starts: int = 8, grid=None):
    """The checked design: exchange on the penalised objective, then order and pattern search from it and
    from ``starts`` (a list of ``(label, poses)``: the crlb-optimal design, the baseline).

    Returns
    -------
    P : ndarray, shape (K, n)
    info : dict
        ``label`` (the path of the winner), ``tried`` (label, crlb objective, shortfall of each end),
        ``exchange`` (the exchange's result).
    """
    from zerocal_sym.design.exchange import candidate_grid, exchange_design
    from zerocal_sym.design.order import best_order

    margin, req.order_margin = req.order_margin, ORDER_MARGIN
    fn = Objective(robot, noise, req)
    cand = candidate_grid(robot, cons, *(grid or cons.region.default_grid))
    if len(cand) > 1:
        req.find_invisible(Terms(robot, cand, noise))
    ex = exchange_design(robot, K, "crlb", cons, noise, seed, exchange_starts, grid, objective=fn)
    tried = []
    best = None
    starts = [("exchange", ex["poses"])] + [(lab, P) for lab, P in starts if P is not None]
    rng = np.random.default_rng(seed)
    lo, hi = _region_box(cons, starts[0][1])
    for j in range(PERTURBED):  # the crlb design shaken (its symmetry is what the requirement breaks)
        P = np.clip(starts[1][1] + rng.normal(scale=PERTURB, size=starts[1][1].shape) * (hi - lo), lo, hi)
        ok = _pointwise_ok(robot, P, cons)
        P[~ok] = starts[1][1][~ok]
        starts.append((f"{starts[1][0]} shaken ({j + 1})", P))
    for label, P0 in starts:
        if P0 is None or check_design(robot, P0, cons):
            continue
        order, _ = best_order(robot, P0, "crlb", noise, cons, objective=fn)
        P1 = np.asarray(P0, float)[order]
        lab = label + (" +order" if np.any(order != np.arange(K)) else "")
        P2, o2 = polish(robot, P1, cons, fn, seed)
        if check_design(robot, P2, cons):
            P2, o2 = P1, fn(P1)(np.arange(K)[None])[0]
        else:
            lab += " +pattern"
        _, oc, short = fn.of_terms(Terms(robot, P2, noise).take(np.arange(K)[None]))
        tried.append({"label": lab, "objective": float(o2), "crlb_objective": float(oc[0]),
                      "shortfall": float(short[0]), "poses": P2})
    req.order_margin = margin
    if not tried:
        from zerocal_sym.design.limits import DesignError

        raise DesignError("no checked design meets the constraints")
    # the best end whose report (the orders refitted on the exact model) meets the requirement, else the best
    tried.sort(key=lambda t: t["objective"])
    best = tried[0]
    for t in tried:
        if t["shortfall"] == 0.0:
            t["meets"] = bool(detection(robot, t["poses"], noise, req)["meets"])
            if t["meets"]:
                best = t
                break
    for t in tried:
        t.pop("poses") if t is not best else None
    P = best.pop("poses")
    return P, {"label": best["label"], "tried": tried, "exchange": ex}


def checked_design(robot, K, cons, noise, seed, n_starts, exchange_starts, grid, tolerances, method, certificate,
                   requirement: Requirement | None = None, progress=None):
    """:func:`zerocal_sym.design.optimize.optimize_design` for ``criterion="checked"``.

    The crlb-optimal design first (the same path, the reference of the trade-off); if its fit check already
    sees what the requirement asks, it is the checked design; else :func:`checked_search` (the exact path,
    K <= :data:`zerocal_sym.design.optimize.EXACT_MAX_K`; beyond, the approximate design is kept and its
    report says what it misses).  The result's ``checked`` entry holds the requirement, the crlb design's
    CRLB and detection summary, the cost in CRLB and the search's ends.
    """
    import time

    from zerocal_sym.design.criteria import CHECKED, evaluate
    from zerocal_sym.design.optimize import EXACT_MAX_K, optimize_design

    from zerocal_sym.design.limits import DesignError
    from zerocal_sym.design.terms import design_params

    p = len(design_params(robot))
    if K < p + 2:
        raise DesignError(f"K = {K} leaves no spare degree of freedom ({p} parameters): the fit check cannot run, so "
                          f"no design can be checked; use K >= {p + 2}, or --criterion crlb")
    t0 = time.perf_counter()
    req = requirement or Requirement(robot, tolerances)
    ref = optimize_design(robot, K, "crlb", cons, noise, seed, n_starts, exchange_starts, grid,
                          tolerances=tolerances, method=method, certificate=certificate, requirement=req,
                          progress=progress)
    req.count_harm_in(robot, ref.poses, noise, "the crlb-optimal design's")
    ref.report = evaluate(robot, ref.poses, "crlb", noise, cons, tolerances, req)
    if ref.baseline_poses is not None:
        ref.paper = evaluate(robot, ref.baseline_poses, CHECKED, noise, cons, tolerances, req)
    ref_det = ref.report["detection"] or {}
    ref_crlb = ref.report["criterion"]["value"]
    info = {"requirement": req.to_dict(), "crlb_design": {"crlb": ref_crlb, "method": ref.method,
                                                          "meets": ref_det.get("meets"), "power": ref_det.get("power"),
                                                          "unmet": ref_det.get("unmet")}}
    P, label = ref.poses, ref.method
    exact = ref.continuous != {} or ref.exchange != {}
    if not ref_det.get("meets") and exact and K <= EXACT_MAX_K:
        t1 = time.perf_counter()
        starts = [("crlb design", ref.poses), ("baseline", ref.baseline_poses)]
        P, s = checked_search(robot, K, cons, noise, req, starts, seed, exchange_starts, grid)
        label = "checked: " + s["label"]
        info["tried"] = s["tried"]
        ref.timing["checked_search"] = time.perf_counter() - t1
    elif not ref_det.get("meets"):
        info["note"] = (f"the {ref.method} design is kept: the checked search runs on the exact path "
                        f"(K <= {EXACT_MAX_K})")
    report = evaluate(robot, P, CHECKED, noise, cons, tolerances, req)
    info["cost"] = report["criterion"]["value"] / ref_crlb if ref_crlb else None
    ref.timing["total"] = time.perf_counter() - t0
    cert = ref.certificate
    if ref.approx_design is not None:
        from zerocal_sym.design.optimize import _certificate

        v = report["criterion"]["value"]
        cert = _certificate(ref.approx_design, "crlb", v, K, v, robot, P)
    ref.poses, ref.criterion, ref.report, ref.method, ref.certificate = P, CHECKED, report, label, cert
    ref.checked = info
    return ref

