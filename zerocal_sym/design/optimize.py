"""Measurement-pose design as a constrained optimisation.

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
rectangle, the ring scheme (``docs/delta.md``) on a cylinder.  (The
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
from zerocal_sym.design.limits import MAX_K_EXACT, DesignError, _check_k
from zerocal_sym.design.shapes import BoxRegion, CylinderRegion, Region, workspace_region
from zerocal_sym.design.constraints import Constraints, check_design, make_constraints
from zerocal_sym.design.criteria import CHECKED, DESIGN_CRITERIA, _check_criterion, _noise_terms, _objective, evaluate
from zerocal_sym.design.exchange import exchange_design
from zerocal_sym.design.nlp import continuous_design
from zerocal_sym.design.order import best_order
from zerocal_sym.design.terms import describe_noise, design_params, noise_dict, poses_to_user


# --------------------------------------------------------------------------- baseline
def scheme_parameter(workspace, K: int):
    """The n whose boundary scheme has K poses (``workspace.scheme_size(n) == K``), or None.

    K = 2n on a rectangle and a cylinder (even K); K = n on a box (the corner scheme: 64, 32 or 16).
    """
    return next((n for n in workspace.scheme_sizes(K) if workspace.scheme_size(n) == K), None)


def paper_baseline(robot, K: int, region: Region | CylinderRegion | BoxRegion | None = None) -> np.ndarray:
    """The workspace's boundary scheme with K poses, as the baseline.

    On the whole workspace, a K the scheme has (:func:`scheme_parameter`):
    ``robot.workspace.boundary_scheme(n)`` -- the paper's scheme on a
    rectangle (``n = K/2`` poses on ``y = H`` then on ``y = H + h``), the ring
    scheme on a cylinder (``n`` poses on the top circle, then on the bottom
    one), the corner scheme on a box (``K = n`` = 64, 32 or 16 corners).  On a
    smaller region or for another K the same rule on the region: on a
    rectangle or a cylinder ``ceil(K/2)`` poses on the first boundary
    (``y = ymin``; the top circle) and ``floor(K/2)`` on the second
    (:meth:`Region.boundary_scheme`, :meth:`CylinderRegion.boundary_scheme`);
    on a box the corner rule (:meth:`BoxRegion.baseline_poses`).

    Returns
    -------
    ndarray, shape (K, n)
        Internal units (mm, rad), in visiting order.
    """
    ws = workspace_region(robot)
    region = region or ws
    n = scheme_parameter(robot.workspace, K)
    if n is not None and region == ws:
        return robot.workspace.boundary_scheme(n)
    if hasattr(region, "baseline_poses"):
        return region.baseline_poses(K)
    n1 = (K + 1) // 2
    return region.boundary_scheme(n1, K - n1)


#: the same function under its generic name
boundary_baseline = paper_baseline


def choose_baseline(robot, K: int, cons: Constraints):
    """The baseline at K: the first candidate scheme that meets the constraints and identifies the parameters.

    Candidates: on a rectangle or cylinder region, the boundary rule on the
    region (:func:`paper_baseline`; on the workspace itself the paper's or the
    ring scheme), then, for a smaller region, the workspace's scheme; on the
    reachable set or a polygon, the workspace's scheme.  A candidate that
    breaks a constraint (outside the region, singular, the scale travel, ...)
    or leaves the Fisher information singular is never the baseline.

    Returns
    -------
    P : ndarray, shape (K, n), or None
    label : str
    note : str or None
        Why there is no baseline (or None).
    rejected : list of dict
        ``scheme``, ``poses``, ``violations`` of each rejected candidate.
    """
    from zerocal_sym.design.criteria import criterion_values

    ws = workspace_region(robot)
    scheme = robot.workspace.scheme_name
    region = cons.region
    cands = []
    if hasattr(region, "boundary_scheme") or hasattr(region, "baseline_poses"):
        if hasattr(region, "baseline_poses") and not (region == ws and scheme_parameter(robot.workspace, K)):
            label = f"{scheme} rule on the {'workspace' if region == ws else 'region'} ({K} corners)"
        else:
            label = f"{scheme} scheme" if region == ws else f"{scheme} rule on the region's boundaries"
        cands.append((label, paper_baseline(robot, K, region)))
    if region != ws:
        cands.append((f"{scheme} scheme on the workspace", paper_baseline(robot, K, ws)))
    rejected = []
    for label, P in cands:
        viol = check_design(robot, P, cons)
        if not viol and not math.isfinite(criterion_values(robot, P)["crlb"]):
            viol = ["the Fisher information is singular: the scheme cannot identify the parameters"]
        if not viol:
            return P, label, None, rejected
        rejected.append({"scheme": label, "poses": P.tolist(), "violations": viol})
    parts = []
    for r in rejected:
        more = len(r["violations"]) - 1
        parts.append(f"the {r['scheme']} breaks the constraints ({r['violations'][0]}"
                     + (f"; {more} more)" if more else ")"))
    note = "no baseline: " + "; ".join(parts)
    return None, "", note, rejected


# --------------------------------------------------------------------------- driver
#: ``method="auto"``: the exact path (exchange + Ipopt) up to this K, the approximate design beyond
EXACT_MAX_K = 24
METHODS = ("auto", "exact", "approx")


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
    paper : dict or None
        :func:`evaluate` of the baseline (:func:`choose_baseline`): the
        workspace's boundary scheme with the same K (the paper's scheme on a
        rectangle, the ring scheme on a cylinder) or the rule on the region's
        boundaries; None when no candidate meets the constraints
        (``baseline_note`` says why).
    constraints : Constraints
    exchange : dict
        The discrete exchange's best (poses, value, starts, time); empty on the approximate path.
    continuous : dict
        The Ipopt multi-start (value, runs, time) before ordering and polish; empty on the approximate path.
    method : str
        Which method gave the final design.
    timing : dict
        Seconds per stage.
    noise : NoiseModel
    baseline : str
        Name of the baseline scheme (``paper`` | ``ring``).
    baseline_note : str or None
    baseline_rejected : list of dict
    certificate : dict or None
        The approximate design's bound: the best value any K-pose design on
        the candidates can reach and the design's efficiency lower bound
        (:mod:`zerocal_sym.design.approx`); None for ``cond``.
    approximate : dict or None
        The approximate design (support, weights, counts) on the approximate path.
    tolerances : dict or None
        Tolerances of the omitted errors used (internal units; None: defaults).
    """

    poses: np.ndarray
    criterion: str
    report: dict
    paper: dict | None
    constraints: Constraints
    exchange: dict
    continuous: dict
    method: str
    timing: dict = field(default_factory=dict)
    noise: NoiseModel | None = None
    baseline: str = "paper"
    baseline_note: str | None = None
    baseline_rejected: list = field(default_factory=list)
    baseline_label: str = ""
    certificate: dict | None = None
    approximate: dict | None = None
    tolerances: dict | None = None
    noise_report: dict | None = None
    #: the baseline's poses in internal units (mm, rad), shape (K, n), or None (``paper["poses"]`` is in file
    #: units)
    baseline_poses: np.ndarray | None = None
    #: the checked design's trade-off (:func:`zerocal_sym.design.checked.checked_design`), or None
    checked: dict | None = None
    #: the approximate design behind ``certificate`` (not in the report), or None
    approx_design: object = field(default=None, repr=False)

    def to_dict(self) -> dict:
        """JSON-ready report (non-finite numbers as None)."""
        return json_safe(self._dict())

    def _exchange_user(self) -> dict:
        """The exchange's entry with its poses in file units (as the report's)."""
        ex = dict(self.exchange)
        if "poses" in ex:
            ex["poses"] = _poses_in_units(ex["poses"], self.report.get("pose_units"))
        return ex

    def _dict(self) -> dict:
        rep = dict(self.report)
        pp = self.paper or {}
        crlb_key = f"crlb_rms_{rep.get('joint_unit', 'deg')}"
        rep.update({
            "K": len(self.poses),
            "method": self.method,
            "baseline": self.baseline,
            "baseline_scheme": self.baseline_label or None,
            "baseline_note": self.baseline_note,
            "baseline_rejected": self.baseline_rejected,
            "paper": self.paper,
            "ratio": {
                "crlb_rms_design_over_paper": _ratio(self.report[crlb_key], pp.get(crlb_key)),
                "criterion_design_over_paper": _ratio(self.report["criterion"]["value"],
                                                      pp.get("criterion", {}).get("value")),
                "kappa_design_over_paper": _ratio(self.report["kappa"], pp.get("kappa")),
            },
            "certificate": self.certificate,
            "approximate": self.approximate,
            "constraints": self.constraints.to_dict(),
            "noise": self.noise_report if self.noise_report is not None else (
                None if self.noise is None else {"sigma_scale_mm": self.noise.sigma_scale_mm,
                                                 "sigma_servo_deg": math.degrees(self.noise.sigma_servo_rad)}),
            "exchange": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                         for k, v in self._exchange_user().items() if k != "objective"},
            "continuous": {k: v for k, v in self.continuous.items() if k in ("value", "runs", "time_s", "build_s")},
            "timing_s": self.timing,
        })
        from zerocal_sym.design.replicates import revisits_entry

        rep.update(revisits_entry(self.poses))  # a pose file of the design accepts its replicates
        if self.checked is not None:
            rep["checked"] = self.checked
        return rep


def _poses_in_units(P, pose_units):
    """Poses (internal units) in the file units ``pose_units`` names per coordinate (deg: from rad)."""
    from zerocal_sym.model import units

    P = np.array(P, float)
    for i, u in enumerate(pose_units or ()):
        if u == "deg":
            P[..., i] = units.to_user(P[..., i], "rad")
    return P


def _ratio(a, b):
    if a is None or b is None:
        return None
    try:
        r = a / b
    except ZeroDivisionError:
        return None
    return float(r) if math.isfinite(r) else None


def _certificate(ad, criterion, value, K, design_value_crlb=None, robot=None, P=None):
    """The certificate block of a design from an approximate design of the same criterion (or crlb for mse).

    With the design's poses ``P`` the bound covers them too (:meth:`ApproxDesign.covered`): the efficiency
    is never one against a candidate set the design lies outside; ``certificate`` says over how many poses.
    """
    if ad is None:
        return None
    if robot is not None and P is not None:
        ad = ad.covered(robot, P)
    d = {"criterion": ad.criterion, "K": K, "bound": ad.bound(K), "certificate": f"over {ad.n_candidates} candidates",
         "region_search": ad.info.get("region_search"),
         "measure_efficiency_lower_bound": ad.eff_lb, "n_candidates": ad.n_candidates,
         "rho_window_mm": list(ad.window), "windows": ad.windows, "candidates": ad.info.get("candidates"),
         "model": "order-free pose model (servo variance + sigma_m^2/4 per pose): its optimum bounds every "
                  "ordered K-pose design on the candidates"}
    if criterion == ad.criterion:
        d["design_value"] = value
        d["efficiency_lower_bound"] = ad.efficiency(value, K)
    else:  # mse: the variance part alone is bounded
        d["note"] = ("the mse criterion is not convex: no certificate; bound = the smallest RMS CRLB of any "
                     "K-pose design (a lower bound on the RMS error)")
        d["design_value"] = design_value_crlb
        d["efficiency_lower_bound"] = None if design_value_crlb is None else ad.efficiency(design_value_crlb, K)
    return d


def optimize_design(robot, K: int = 6, criterion: str = "crlb", cons: Constraints | None = None,
                    noise: NoiseModel | None = None, seed: int = 0, n_starts: int = 8,
                    exchange_starts: int = 8, grid=None, reorder: bool = True, tolerances=None,
                    method: str = "auto", certificate: bool = True, progress=None,
                    requirement=None) -> DesignResult:
    """Optimal measurement poses for a criterion, with the boundary scheme as baseline.

    Two paths (``method``):

    * ``exact`` -- discrete exchange (``exchange_starts`` seeded starts over
      the candidate grid); Ipopt multi-start from the boundary scheme (if
      feasible) and ``n_starts`` seeded random feasible designs; the better
      of the two, re-ordered (:func:`best_order`) and, if re-ordered,
      polished by Ipopt from the exchange design as well; the best feasible
      design wins;
    * ``approx`` -- the optimal design measure over candidate poses
      (:func:`zerocal_sym.design.approx.approximate_design`), rounded to K
      poses with replicates around its support and a visiting order
      (:func:`zerocal_sym.design.rounding.realize`); seconds for K in the
      hundreds.  ``mse``: the measure is improved locally for the bias
      (:func:`zerocal_sym.design.mse.mse_measure`); ``cond``: exact only.
    * ``auto`` (default) -- ``exact`` for K <= :data:`EXACT_MAX_K` (and for
      ``cond``), ``approx`` beyond; ``approx`` at any K for a robot that
      identifies more than its mechanism's default set
      (``robot.identifying("paper+L1,L2,L3")``): there the exact path's
      local search ends at designs that identify the offsets at zero errors
      only, leaving the extra entries nearly free (the rotary Delta with its
      upper arms freed: ``python examples/delta_arms.py``, docs/trust.md);
      the design measure's support does not.

    With ``certificate`` the approximate design of the criterion (of crlb for
    mse) also gives the bound on what any K-pose design on the candidates
    can reach and the design's efficiency lower bound (``cond``: none).

    Parameters
    ----------
    robot : Robot
    K : int
        Number of poses (>= p + 1: 5 for the planar robot, 7 for the Delta).
    criterion : {"cond", "D", "A", "E", "crlb", "position", "mse", "checked"}
        ``checked``: the crlb among designs whose fit check sees what they assume
        (:func:`zerocal_sym.design.checked.checked_design`).
    cons : Constraints, optional
        Default :func:`make_constraints` (workspace, l0 = 350 mm range,
        the robot's margin, no joint limits).
    noise : NoiseModel, optional
        Default the robot's (``Robot.noise``).
    seed : int
    n_starts, exchange_starts : int
    grid : tuple of int, optional
        Candidate grid of the exchange (default the region's, see
        :func:`zerocal_sym.design.exchange.candidate_grid`).
    tolerances : dict name -> value (internal units), optional
        Tolerances of the omitted errors (``mse`` and the bias report;
        default :func:`zerocal_sym.identify.budget.bias.default_tolerances`).
    method : {"auto", "exact", "approx"}
    certificate : bool
    progress : callable, optional
        ``progress(done, total)`` after each step (the approximate design, each exchange and Ipopt start, each
        polish); ``done == total`` at the end.
    requirement : zerocal_sym.design.detection.Requirement, optional
        What a ``checked`` design must see (default: its defaults with ``tolerances``).

    Returns
    -------
    DesignResult
    """
    from zerocal_sym.design.approx import approximate_design
    from zerocal_sym.design.mse import mse_measure
    from zerocal_sym.design.rounding import realize

    _check_k(K, robot)
    _check_criterion(criterion, DESIGN_CRITERIA)
    if criterion == CHECKED:
        from zerocal_sym.design.checked import checked_design

        return checked_design(robot, K, cons or make_constraints(robot), NoiseModel.coerce(noise, robot=robot),
                              seed, n_starts, exchange_starts, grid, tolerances, method, certificate, requirement,
                              progress)
    if method not in METHODS:
        raise DesignError(f"unknown design method {method!r} (known: {', '.join(METHODS)})")
    if method == "auto":
        default_set = set(design_params(robot)) == set(robot.errors.resolve("paper"))
        method = "exact" if (K <= EXACT_MAX_K and default_set) or criterion == "cond" else "approx"
    if method == "approx" and criterion == "cond":
        raise DesignError("the condition number has no approximate design (it is not concave): use the exact "
                          f"method (K <= {MAX_K_EXACT})")
    if method == "exact" and K > MAX_K_EXACT:
        raise DesignError(f"K = {K} is too large for the exact method (at most {MAX_K_EXACT}; the approximate "
                          "method takes any K)")
    noise = NoiseModel.coerce(noise, robot=robot)
    _noise_terms(noise, robot)
    cons = cons or make_constraints(robot)
    timing = {}
    t0 = time.perf_counter()
    ad = None
    mcrit = "crlb" if criterion == "mse" else criterion
    base, base_label, base_note, rejected = choose_baseline(robot, K, cons)
    with_ad = method == "approx" or (certificate and criterion != "cond")
    total = int(with_ad) + ((criterion == "mse") + 1 if method == "approx" else
                            exchange_starts + n_starts + (base is not None) + 2)
    done = [0]

    def step():
        done[0] = min(done[0] + 1, total)
        if progress is not None:
            progress(done[0], total)

    if with_ad:
        ad = approximate_design(robot, mcrit, cons, noise, tolerances=tolerances)
        timing["approximate"] = time.perf_counter() - t0
        step()
    scheme = robot.workspace.scheme_name
    ex, cont, approx_info = {}, {}, None
    if method == "approx":
        t1 = time.perf_counter()
        mad = ad
        if criterion == "mse":
            mad = mse_measure(robot, ad, K, cons, noise, tolerances)
            step()
        P, info = realize(robot, mad, K, cons, noise, tolerances, criterion)
        step()
        timing["round_order"] = time.perf_counter() - t1
        label = "approximate +round +order"
        approx_info = mad.to_dict(K)
        approx_info["support"] = poses_to_user(robot, mad.support).tolist()  # file units, as the poses
        approx_info["counts"] = info["counts"]
        approx_info["orders_tried"] = info["orders_tried"]
    else:
        t1 = time.perf_counter()
        ex = exchange_design(robot, K, criterion, cons, noise, seed, exchange_starts, grid, tolerances=tolerances,
                             step=step)
        timing["exchange"] = time.perf_counter() - t1
        starts = [(f"{scheme} scheme", base)] if base is not None else []
        t1 = time.perf_counter()
        cont = continuous_design(robot, K, criterion, cons, noise, seed, n_starts, starts, tolerances=tolerances,
                                 step=step)
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
            step()
        timing["order_polish"] = time.perf_counter() - t2
        polished = [c for c in polished if not check_design(robot, c[1], cons)]
        if not polished:
            raise DesignError("neither method produced a design that meets the constraints")
        label, P, _ = min(polished, key=lambda c: c[2])
    if progress is not None and done[0] < total:  # a random start that found no feasible design: done anyway
        progress(total, total)
    report = evaluate(robot, P, criterion, noise, cons, tolerances, requirement)
    timing["total"] = time.perf_counter() - t0
    cert = None
    if ad is not None:
        cert = _certificate(ad, criterion, report["criterion"]["value"], K, report["criterion"]["values"]["crlb"],
                            robot, P)
    paper = None if base is None else evaluate(robot, base, criterion, noise, cons, tolerances, requirement)
    return DesignResult(poses=P, criterion=criterion, report=report, paper=paper, constraints=cons, exchange=ex,
                        continuous=cont, method=label, timing=timing, noise=noise, baseline=scheme,
                        baseline_note=base_note, baseline_rejected=rejected, baseline_label=base_label,
                        certificate=cert, approximate=approx_info, tolerances=tolerances,
                        noise_report=dict(noise_dict(robot, noise), description=describe_noise(robot, noise)),
                        baseline_poses=base, approx_design=ad)
