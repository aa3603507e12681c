"""Measurement-pose design as a constrained optimisation (issue 5).

The K measurement poses are chosen to make the identification of the zero
offsets as accurate as possible, within what the robot and the measuring
mechanism allow.  Two methods, each a check on the other:

* **continuous** (:func:`continuous_design`): the K poses (scaled to
  ``[-1, 1]^n`` over the design region) are the decision variables of a
  CasADi/Ipopt NLP built symbolically from the generated mechanism functions
  (inverse kinematics, transmission sines, exact distance and its AD
  derivatives); multi-start from seeded random feasible designs and from the
  boundary scheme;
* **discrete exchange** (:func:`exchange_design`): coordinate exchange
  (Fedorov / DETMAX family) over a candidate grid of feasible poses, every
  slot of the ordered design swapped against every candidate until no swap
  improves; several seeded random starts.

:func:`optimize_design` runs both, improves the visiting order of the best
design (exhaustively for K <= 8, by pair swaps and segment reversals
otherwise), polishes it with Ipopt and returns it with the workspace's
boundary scheme at the same K as the baseline: the paper's scheme on a
rectangle, the ring scheme (``DELTA.md``) on a cylinder.  (The
result keeps the name ``paper`` for the baseline's report.)

Everything is generic over the mechanism: poses (K, n), joints (K, m), the
p = m + n parameters of the paper's Eq. (28).

The model and the criteria are in :mod:`zerocal_sym.design.criteria`, the
constraints in :mod:`zerocal_sym.design.constraints`, the Ipopt NLP in
:mod:`zerocal_sym.design.nlp`.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.io.files import json_safe
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.constraints import (Constraints, CylinderRegion, DesignError, Region, _check_k,
                                            check_design, make_constraints, workspace_region)
from zerocal_sym.design.criteria import _check_criterion, _noise_terms, _objective, evaluate
from zerocal_sym.design.exchange import exchange_design
from zerocal_sym.design.nlp import continuous_design
from zerocal_sym.design.order import best_order


# --------------------------------------------------------------------------- baseline
def paper_baseline(robot, K: int, region: Region | CylinderRegion | None = None) -> np.ndarray:
    """The workspace's boundary scheme with K poses, as the baseline.

    Even K on the whole workspace: ``robot.workspace.boundary_scheme(K // 2)``
    -- the paper's scheme on a rectangle (``n = K/2`` poses on ``y = H`` then
    on ``y = H + h``), the ring scheme on a cylinder (``n`` poses on the top
    circle at azimuths ``360 deg j/n``, then on the bottom one).  On a smaller
    region or for odd K (the paper has none) the same rule on the region's
    boundaries with ``ceil(K/2)`` poses on the first (``y = ymin``; the top
    circle) and ``floor(K/2)`` on the second (``y = ymax``; the bottom
    circle): :meth:`Region.boundary_scheme`, :meth:`CylinderRegion.boundary_scheme`.

    Returns
    -------
    ndarray, shape (K, n)
        mm, in visiting order.
    """
    ws = workspace_region(robot)
    region = region or ws
    if K % 2 == 0 and region == ws:
        return robot.workspace.boundary_scheme(K // 2)
    n1 = (K + 1) // 2
    return region.boundary_scheme(n1, K - n1)


#: the same function under its generic name
boundary_baseline = paper_baseline


# --------------------------------------------------------------------------- driver
@dataclass
class DesignResult:
    """An optimised design and its baseline.

    Attributes
    ----------
    poses : ndarray, shape (K, n)
        mm, in visiting order.
    criterion : str
    report : dict
        :func:`evaluate` of the design.
    paper : dict
        :func:`evaluate` of the baseline: the workspace's boundary scheme
        with the same K (:func:`paper_baseline`; the paper's scheme on a
        rectangle, the ring scheme on a cylinder).
    constraints : Constraints
    exchange : dict
        The discrete exchange's best (poses, value, starts, time).
    continuous : dict
        The Ipopt multi-start (value, runs, time) before ordering and polish.
    method : str
        Which method gave the final design.
    timing : dict
        Seconds per stage.
    noise : NoiseModel
    baseline : str
        Name of the baseline scheme (``paper`` | ``ring``).
    """

    poses: np.ndarray
    criterion: str
    report: dict
    paper: dict
    constraints: Constraints
    exchange: dict
    continuous: dict
    method: str
    timing: dict = field(default_factory=dict)
    noise: NoiseModel | None = None
    baseline: str = "paper"

    def to_dict(self) -> dict:
        """JSON-ready report (non-finite numbers as None)."""
        return json_safe(self._dict())

    def _dict(self) -> dict:
        rep = dict(self.report)
        rep.update({
            "K": len(self.poses),
            "method": self.method,
            "baseline": self.baseline,
            "paper": self.paper,
            "ratio": {
                "crlb_rms_design_over_paper": _ratio(self.report["crlb_rms_deg"], self.paper["crlb_rms_deg"]),
                "criterion_design_over_paper": _ratio(self.report["criterion"]["value"],
                                                      self.paper["criterion"]["value"]),
                "kappa_design_over_paper": _ratio(self.report["kappa"], self.paper["kappa"]),
            },
            "constraints": self.constraints.to_dict(),
            "noise": None if self.noise is None else {"sigma_scale_mm": self.noise.sigma_scale_mm,
                                                      "sigma_servo_deg": math.degrees(self.noise.sigma_servo_rad)},
            "exchange": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                         for k, v in self.exchange.items() if k != "objective"},
            "continuous": {k: v for k, v in self.continuous.items() if k in ("value", "runs", "time_s", "build_s")},
            "timing_s": self.timing,
        })
        return rep


def _ratio(a, b):
    try:
        r = a / b
    except ZeroDivisionError:
        return None
    return float(r) if math.isfinite(r) else None


def optimize_design(robot, K: int = 6, criterion: str = "crlb", cons: Constraints | None = None,
                    noise: NoiseModel | None = None, seed: int = 0, n_starts: int = 8,
                    exchange_starts: int = 8, grid=None, reorder: bool = True, tolerances=None) -> DesignResult:
    """Optimal measurement poses for a criterion, with the boundary scheme as baseline.

    Stages: discrete exchange (``exchange_starts`` seeded starts over the
    candidate grid); Ipopt multi-start from the boundary scheme (if feasible)
    and ``n_starts`` seeded random feasible designs; the better of the two,
    re-ordered (:func:`best_order`) and, if re-ordered, polished by Ipopt
    from the exchange design as well; the best feasible design wins.

    Parameters
    ----------
    robot : Robot
    K : int
        Number of poses (>= p + 1: 5 for the planar robot, 7 for the Delta).
    criterion : {"cond", "D", "A", "E", "crlb"}
    cons : Constraints, optional
        Default :func:`make_constraints` (workspace, l0 = 350 mm range,
        the robot's margin, no joint limits).
    noise : NoiseModel, optional
        Default the paper's.
    seed : int
    n_starts, exchange_starts : int
    grid : tuple of int, optional
        Candidate grid of the exchange (default the region's, see
        :func:`zerocal_sym.design.exchange.candidate_grid`).

    Returns
    -------
    DesignResult
    """
    _check_k(K, robot)
    _check_criterion(criterion)
    noise = noise or NoiseModel.paper()
    _noise_terms(noise)
    cons = cons or make_constraints(robot)
    timing = {}
    t0 = time.perf_counter()
    ex = exchange_design(robot, K, criterion, cons, noise, seed, exchange_starts, grid, tolerances=tolerances)
    timing["exchange"] = time.perf_counter() - t0
    base = paper_baseline(robot, K, cons.region)
    scheme = robot.workspace.scheme_name
    starts = [(f"{scheme} scheme", base)] if not check_design(robot, base, cons) else []
    t1 = time.perf_counter()
    cont = continuous_design(robot, K, criterion, cons, noise, seed, n_starts, starts, tolerances=tolerances)
    timing["continuous"] = time.perf_counter() - t1
    nlp = cont.pop("nlp")
    cands = [("continuous", cont["poses"], cont["objective"]), ("exchange", ex["poses"], ex["objective"])]
    t2 = time.perf_counter()
    polished = []
    for label, P, o in cands:
        if reorder:
            order, _ = best_order(robot, P, criterion, noise, cons, tolerances=tolerances)
            if np.any(order != np.arange(K)):
                P = P[order]
                label = label + " +order"
        Pp, status, _ = nlp.solve(P)
        op = _objective(robot, criterion, Pp, noise, tolerances)
        if not check_design(robot, Pp, cons) and op <= _objective(robot, criterion, P, noise, tolerances):
            polished.append((label + " +ipopt", Pp, op))
        else:
            polished.append((label, P, _objective(robot, criterion, P, noise, tolerances)))
    timing["order_polish"] = time.perf_counter() - t2
    polished = [c for c in polished if not check_design(robot, c[1], cons)]
    if not polished:
        raise DesignError("neither method produced a design that meets the constraints")
    label, P, _ = min(polished, key=lambda c: c[2])
    timing["total"] = time.perf_counter() - t0
    return DesignResult(poses=P, criterion=criterion, report=evaluate(robot, P, criterion, noise, cons, tolerances),
                        paper=evaluate(robot, base, criterion, noise, cons, tolerances), constraints=cons, exchange=ex,
                        continuous=cont, method=label, timing=timing, noise=noise, baseline=scheme)
