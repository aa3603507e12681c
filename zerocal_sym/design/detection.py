"""The requirement of a checked design and the detection report of any design (:func:`detection`).

A *checked* design (criterion ``checked``, the command line's default) is the design of least RMS CRLB of
the zero offsets whose fit check sees the gross errors a calibration is likely to meet
(:mod:`zerocal_sym.design.power`: the scenarios, the non-centrality ``lambda`` and the harm of each).
:class:`Requirement` (decision):

* at least one spare degree of freedom (``K >= p + 2``): with none the fit check cannot run;
* **order** (the poses visited in reverse, two consecutive poses swapped): power >= the target (default
  0.9) at the fit check's level (default 0.001), i.e. ``lambda >= lambda_req(dof)``, for every reordering
  that changes the commanded joints (a swap of two identical poses is no error);
* **the robot file's scale** (every length 1 % off) and **one bad reading** (each reading in turn, default
  0.1 mm): power >= the target, unless the error moves no offset by ``harm_sigma`` (default 1) standard
  deviations -- those of the crlb-optimal design in the checked search (:meth:`Requirement.count_harm_in`),
  so that a design cannot excuse an error by being less precise.

**Single robot-file entries at their tolerances are reported, not required** (``entries=True``, the command
line's ``--require-entries``, asks them too).  The report gives each one's power at its tolerance, its harm
there and the size the check sees (``seen_from``).  On the paper's robot no design's check sees any entry
at its tolerance (set A's) and none moves an offset by a tenth of its standard deviation; with the
tolerances of a robot measured by hand, asking costs 1.02 times the CRLB on the linear Delta at K = 12 and
sees them all, but 3.42 times on the rotary Delta and still misses three (``benchmarks/design_detection.py``).
An entry whose effect on every pose is one the identified parameters make
(:func:`~zerocal_sym.design.power.invisible_entries`: the planar robot's ``e1y``, ``e2y``) is listed as
seen by no design.

The search minimises ``log(mean CRLB^2) + PENALTY * shortfall`` (:meth:`Requirement.terms_short`: per
scenario, ``log(lambda_req / lambda)`` where the rule fails, ended by the harm where that may excuse it,
each capped).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design import power as pw

#: weight of the requirement's shortfall against the log of the mean CRLB^2 in the search
PENALTY = 10.0
#: a scenario's shortfall term is capped at this (a design that sees nothing still has a finite objective)
SHORTFALL_CAP = 50.0
#: order scenarios whose first-order non-centrality is below this multiple of the required one are refitted on
#: the exact model (:func:`detection`)
EXACT_REFIT_BELOW = 1e3
#: at most this many order scenarios are refitted exactly per report (the least visible)
MAX_EXACT_REFITS = 8
#: the checked search asks an order error's first-order non-centrality for this multiple of the required one:
#: a swap the fit absorbs by moving the offsets far is absorbed further by the exact model (on the paper's
#: robot a swap of first-order 21 left 7.3 to the exact refit)
ORDER_MARGIN = 10.0


class Requirement:
    """What a checked design must see (module docstring).

    Attributes
    ----------
    alpha, target, harm_sigma, bad_reading_mm, scale_error : float
    tolerances : dict name -> value (internal units)
    tol : ndarray, shape (r,)
        The tolerances of :func:`zerocal_sym.design.terms.omitted_params`, in their order.
    invisible : tuple of str or None
        Entries no design can see (set by :meth:`find_invisible`; None until then).
    """

    def __init__(self, robot, tolerances=None, alpha: float = pw.DEFAULT_ALPHA, target: float = pw.DEFAULT_POWER,
                 harm_sigma: float = pw.DEFAULT_HARM_SIGMA, bad_reading_mm: float = pw.DEFAULT_BAD_READING_MM,
                 scale_error: float = pw.DEFAULT_SCALE_ERROR, entries: bool = False):
        from zerocal_sym.design.limits import DesignError
        from zerocal_sym.design.terms import design_params, omitted_params
        from zerocal_sym.identify.budget import bias

        checks = (("the fit check's level alpha", alpha, 0.0, 1.0), ("the power", target, 0.0, 1.0),
                  ("the harm in standard deviations", harm_sigma, 0.0, math.inf),
                  ("the bad reading's size (mm)", bad_reading_mm, 0.0, math.inf),
                  ("the robot-file scale error", scale_error, 0.0, math.inf))
        for what, v, lo, hi in checks:
            try:
                ok = lo < float(v) < hi
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise DesignError(f"{what} must be in ({lo:g}, {hi:g}), got {v!r}")
        self.robot = robot
        self.alpha, self.target, self.harm_sigma = float(alpha), float(target), float(harm_sigma)
        self.bad_reading_mm, self.scale_error = float(bad_reading_mm), float(scale_error)
        #: require the single entries too (not the default: module docstring), those some design can see
        self.entries = bool(entries)
        # the tolerances as every design report resolves them (the mechanism's, the robot file's, the options')
        self.tolerances = (bias.make_tolerances(robot, params=design_params(robot)) if tolerances is None
                           else tolerances)
        self.tol = bias.tolerance_vector(robot, self.tolerances, omitted_params(robot))
        self.invisible = None  # unknown until :meth:`find_invisible`
        #: the zero offsets' range an order error's harm is judged over (q-units): what the fit check's
        #: plausibility accepts (:data:`zerocal_sym.identify.check.plausibility.DEFAULT_MAX_OFFSET`, 10 deg or 10 mm)
        from zerocal_sym.design.terms import _qscale, offset_positions
        from zerocal_sym.identify.check.plausibility import DEFAULT_MAX_OFFSET
        from zerocal_sym.model import units

        unit = robot.errors.offset_user_unit
        self.offset_range = DEFAULT_MAX_OFFSET[unit]
        self.offset_range_q = (float(units.from_user(self.offset_range, robot.errors.offset_unit))
                               / _qscale(robot)[offset_positions(robot)])
        #: the search asks this many times the required non-centrality of an order error's first order
        #: (:data:`ORDER_MARGIN`); the report judges the exact refit's (1)
        self.order_margin = 1.0
        #: the standard deviations the harm is counted in (q-units, one per zero offset): None for each design's
        #: own; the checked search counts in the crlb-optimal design's (:meth:`count_harm_in`), so that a design
        #: cannot excuse an error by being less precise
        self.sigma_q = None
        self.sigma_from = "the design's own"
        self._lam = {}

    def lam_required(self, dof: int) -> float:
        """The non-centrality that gives the target power on ``dof`` degrees of freedom."""
        if dof not in self._lam:
            self._lam[dof] = pw.required_noncentrality(dof, self.alpha, self.target)
        return self._lam[dof]

    def count_harm_in(self, robot, P, noise, what: str):
        """Count the harm in the CRLB of the zero offsets of the design ``P`` (q-units), called ``what``."""
        from zerocal_sym.design.criteria import _fisher, _noise_terms
        from zerocal_sym.design.terms import offset_positions

        T = Terms(robot, P, noise)
        F = _fisher(T.aq[None], T.v[None], _noise_terms(noise, robot)[0])[0]
        off = offset_positions(robot)
        self.sigma_q = np.sqrt(np.diag(np.linalg.inv(F))[off])
        self.sigma_from = what
        return self

    def find_invisible(self, terms):
        """Set :attr:`invisible` from the per-pose terms of many poses (:class:`Terms`, e.g. the candidates)."""
        self.invisible = tuple(pw.invisible_entries(self.robot, terms.ao, terms.aq))
        return self

    def required(self, K: int) -> np.ndarray:
        """Which scenarios the rule covers: the orders, the bad readings and the robot file's scale error (the
        single entries are reported, not required: module docstring), bool shape (S,)."""
        return np.array([k != "entry" or n == "scale" or (self.entries and n not in (self.invisible or ()))
                         for n, k, _ in pw.scenario_names(self.robot, K)])

    def terms_short(self, lam, harm, K: int, p: int):
        """Each scenario's shortfall, shape (B, S): 0 where the rule holds (or is not required).

        ``log(lambda_req / lambda)`` (an order's with :attr:`order_margin`), ended where the error is
        harmless: ``min(that, log(harm / harm_sigma))``, at least 0, at most :data:`SHORTFALL_CAP`.
        """
        dof = K - 1 - p
        if dof <= 0:
            return np.full(lam.shape, SHORTFALL_CAP)
        kinds = pw.scenario_kinds(self.robot, K)
        with np.errstate(divide="ignore", invalid="ignore"):
            short = math.log(self.lam_required(dof)) - np.log(np.maximum(lam, 1e-300))
            if self.order_margin != 1.0:  # the first order overstates what the exact fit leaves of an order error
                short = short + np.where(kinds == "order", math.log(self.order_margin), 0.0)
            short = np.minimum(short, np.log(np.maximum(harm, 1e-300) / self.harm_sigma))
        short = np.where(np.isnan(short), 0.0, short)
        short = np.clip(short, 0.0, SHORTFALL_CAP)
        short[:, ~self.required(K)] = 0.0
        return short

    def to_dict(self) -> dict:
        return {"alpha": self.alpha, "power": self.target, "harm_sigma": self.harm_sigma,
                "harm_counted_in": f"{self.sigma_from} standard deviations",
                "bad_reading_mm": self.bad_reading_mm, "scale_error": self.scale_error,
                "entries_required": self.entries, "invisible_entries": list(self.invisible or ())}


class Terms:
    """Per-pose terms of the detection model for N poses: ``aq`` (N, p) q-units, ``v`` (N,) mm^2, ``ao`` (N, r),
    ``gs`` (N,) (:func:`~zerocal_sym.design.power.scale_column`), ``rho`` (N,), ``theta`` (N, m)."""

    def __init__(self, robot, P, noise):
        from zerocal_sym.design.criteria import _noise_terms
        from zerocal_sym.design.terms import _qscale, pose_terms

        P = np.atleast_2d(np.asarray(P, float))
        _, sx2 = _noise_terms(noise, robot)
        t = pose_terms(robot, P)
        self.P = P
        self.aq = t["a"] * _qscale(robot)
        self.v = sx2 * np.sum(t["dth"] ** 2, axis=1)
        self.ao, self.rho, self.theta = t["ao"], t["rho"], t["theta"]
        self.gs = pw.scale_column(robot, self.theta) if len(P) else np.zeros(0)

    def take(self, idx):
        """The terms of designs ``idx`` (B, K): a dict of arrays (B, K, ...)."""
        return {"aq": self.aq[idx], "v": self.v[idx], "ao": self.ao[idx], "gs": self.gs[idx],
                "rho": self.rho[idx], "theta": self.theta[idx]}


def evaluate_batch(robot, req: Requirement, d: dict, sm2: float, offsets, crlb_weights, penalty: float = PENALTY):
    """``(objective, crlb objective, shortfall, lam, harm)`` of B designs from :meth:`Terms.take`.

    The objective is ``log(sum_j w_j [F_q^-1]_jj) + penalty * shortfall`` (smaller is better; the crlb
    criterion's internal objective plus the penalty).  An order scenario's harm is the larger of its harm at
    zero offsets and at offsets within :attr:`Requirement.offset_range_q`
    (:func:`~zerocal_sym.design.power.noncentralities`' ``order_harm``).
    """
    B, K, p = d["aq"].shape
    delta = pw.scenario_effects(d["ao"], d["gs"], d["rho"], req.tol, req.scale_error, req.bad_reading_mm)
    lam, harm, var, order_harm = pw.noncentralities(d["aq"], d["v"], sm2, delta, offsets, req.sigma_q,
                                                    req.offset_range_q)
    o = _crlb_objective(var, crlb_weights)
    kinds = pw.scenario_kinds(robot, K)
    harm[:, kinds == "order"] = np.maximum(harm[:, kinds == "order"], order_harm)
    short = req.terms_short(lam, harm, K, p).sum(axis=1)
    return o + penalty * short, o, short, lam, harm


def _crlb_objective(var, crlb_weights):
    """The crlb criterion's objective (:func:`zerocal_sym.design.criteria._objective_fisher`) from ``diag(F^-1)``
    (B, p): inf where not finite."""
    with np.errstate(invalid="ignore", divide="ignore"):
        o = np.log(var @ crlb_weights)
    o[~np.isfinite(o)] = np.inf
    return o


def crlb_objective_batch(d: dict, sm2: float, crlb_weights):
    """The crlb objective of :func:`evaluate_batch` alone (its ``crlb objective``, the same numbers) of B designs
    from ``aq`` and ``v`` (B, K, ...): a lower bound of its objective, which adds a non-negative penalty."""
    return _crlb_objective(pw.crlb_variances(d["aq"], d["v"], sm2), crlb_weights)


#: up to this K every scenario is listed in a report; beyond, the entries and the worst order and reading
LIST_ALL_MAX_K = 24


def detection(robot, P, noise=None, requirement: Requirement | None = None, tolerances=None) -> dict:
    """What the fit check of the design ``P`` can see: the non-centrality, power and harm of every scenario.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Poses in visiting order (internal units).
    requirement : Requirement, optional
        Default ``Requirement(robot, tolerances)``.

    Returns
    -------
    dict
        ``alpha``, ``dof``, ``critical_chi2``, ``power_target``, ``noncentrality_required``, ``harm_sigma``,
        ``scenarios`` (per scenario: ``name``, ``kind``, ``what``, ``size`` and ``unit`` (the stated size:
        the tolerance, the scale fraction in %, the bad reading in mm; None for an order),
        ``noncentrality``, ``power`` (at that size), ``harm_sigma`` (the largest offset shift there, in its
        standard deviations), ``seen_from`` (entries, readings: the size the check sees with the target
        power) and ``harm_at_seen_from``, ``required``, ``met``, ``exact`` (an order's non-centrality from
        the exact model's refit)), ``power`` (the smallest per kind), ``meets``, ``unmet``,
        ``invisible_entries``, ``model``.
    """
    from zerocal_sym.design.criteria import _noise_terms
    from zerocal_sym.design.terms import _crlb_weights, offset_positions
    from zerocal_sym.model.noise import NoiseModel

    noise = NoiseModel.coerce(noise, robot=robot)
    req = requirement or Requirement(robot, tolerances)
    if req.invisible is None:
        req.find_invisible(Terms(robot, np.asarray(robot.workspace_grid(), float), noise))
    P = np.atleast_2d(np.asarray(P, float))
    K = len(P)
    T = Terms(robot, P, noise)
    p = T.aq.shape[1]
    dof = K - 1 - p
    sm2, _ = _noise_terms(noise, robot)
    d = T.take(np.arange(K)[None])
    _, _, _, lam, harm = evaluate_batch(robot, req, d, sm2, offset_positions(robot), _crlb_weights(robot))
    lam, harm = lam[0], harm[0]
    names = pw.scenario_names(robot, K)
    kinds = np.array([k for _, k, _ in names])
    harmless = harm < req.harm_sigma
    lam_req = req.lam_required(dof) if dof > 0 else math.inf
    exact = _exact_orders(robot, T, noise, lam, kinds, harmless, lam_req)
    lam = np.where(np.isfinite(exact), np.minimum(lam, exact), lam)
    short = req.terms_short(lam[None], harm[None], K, p)[0]
    required = req.required(K)
    x = pw.chi2_isf(req.alpha, dof) if dof > 0 else math.inf
    rows = []
    for j, (name, kind, what) in enumerate(names):
        pwr = pw.ncx2_sf(x, dof, lam[j]) if dof > 0 else 0.0
        size, unit = _size(robot, req, name, kind)
        row = {"name": name, "kind": kind, "what": what, "size": size, "unit": unit,
               "noncentrality": float(lam[j]), "power": float(pwr), "harm_sigma": float(harm[j]),
               "required": bool(required[j]), "met": bool(short[j] <= 0.0), "exact": bool(np.isfinite(exact[j]))}
        if kind != "order":
            f = math.sqrt(lam_req / lam[j]) if lam[j] > 0 and math.isfinite(lam_req) else math.inf
            row["seen_from"] = size * f if size is not None else None
            row["harm_at_seen_from"] = float(harm[j]) * f
        rows.append(row)
    unmet = [r["name"] for r in rows if r["required"] and not r["met"]]
    out = {"alpha": req.alpha, "dof": dof, "critical_chi2": x, "power_target": req.target,
           "noncentrality_required": lam_req, "harm_sigma": req.harm_sigma,
           "harm_counted_in": f"{req.sigma_from} standard deviations", "entries_required": req.entries,
           "power": _smallest(rows, req), "meets": dof > 0 and not unmet, "unmet": unmet,
           "invisible_entries": list(req.invisible or ()),
           "scenarios": rows if K <= LIST_ALL_MAX_K else _worst_rows(rows),
           "listed": "all" if K <= LIST_ALL_MAX_K else "the entries, the reversed order, the worst swap and reading",
           "model": "chi2 of the fit check non-central with lambda = |(I - H) L^-1 delta|^2 (first order at zero "
                    "source errors; orders also refitted on the exact model); harm: the largest shift of a zero "
                    "offset in its standard deviations"}
    if dof <= 0:
        out["note"] = f"K = {K} leaves no spare degree of freedom (p = {p}): the fit check cannot run"
    return out


def _size(robot, req, name, kind):
    """The stated size of a scenario and its unit."""
    if kind == "order":
        return None, None
    if kind == "reading":
        return req.bad_reading_mm, "mm"
    if name == "scale":
        return 100.0 * req.scale_error, "%"
    errors = robot.errors
    return float(errors.to_user_value(name, req.tolerances.get(name, 0.0))), errors[name].user_unit


def _exact_orders(robot, T, noise, lam, kinds, harmless, lam_req):
    """The exact model's non-centrality of the harmful order scenarios the first order finds below
    :data:`EXACT_REFIT_BELOW` times ``lam_req``, the :data:`MAX_EXACT_REFITS` least visible of them (inf
    elsewhere, and where the refit fails)."""
    out = np.full(len(kinds), np.inf)
    rows = [j for j in np.flatnonzero(kinds == "order") if not harmless[j] and lam[j] < EXACT_REFIT_BELOW * lam_req]
    rows = sorted(rows, key=lambda j: lam[j])[:MAX_EXACT_REFITS]  # the least visible first
    if not rows or not math.isfinite(lam_req):
        return out
    from zerocal_sym.identify.estimate.exact_model import _Exact

    K = len(T.rho)
    readings = np.concatenate([[0.0], np.diff(T.rho)])
    try:
        from zerocal_sym.design.terms import design_params

        ex = _Exact(robot, T.theta, readings, design_params(robot), robot.errors.zeros(), noise)
    except Exception:  # noqa: BLE001 - no exact model: the first order stands
        return out
    perms = [pi for _, _, pi in pw.order_permutations(K)]
    first = int(np.flatnonzero(kinds == "order")[0])
    for j in rows:
        pi = perms[j - first]
        try:
            chi2, _ = ex.chi2_fit(readings=np.concatenate([[0.0], np.diff(T.rho[pi])]))
        except (FloatingPointError, np.linalg.LinAlgError, ValueError):
            continue
        out[j] = chi2 if math.isfinite(chi2) else np.inf
    return out


def _smallest(rows, req):
    """The smallest power per kind: entries at their tolerance, the scale error, order, bad readings."""
    def least(sel):
        v = [r["power"] for r in rows if sel(r)]
        return min(v) if v else None

    return {"entries_at_tolerance": least(lambda r: r["kind"] == "entry" and r["name"] != "scale"
                                          and r["name"] not in req.invisible),
            "scale_error": least(lambda r: r["name"] == "scale"),
            "reversed": least(lambda r: r["name"] == "reversed"),
            "swaps": least(lambda r: r["name"].startswith("swap") and r["required"]),
            "bad_reading": least(lambda r: r["kind"] == "reading")}


def _worst_rows(rows):
    entries = [r for r in rows if r["kind"] == "entry"]
    rev = [r for r in rows if r["name"] == "reversed"]
    swaps = [r for r in rows if r["name"].startswith("swap")]
    reads = [r for r in rows if r["kind"] == "reading"]
    worst = [min(g, key=lambda r: r["noncentrality"]) for g in (swaps, reads) if g]
    return entries + rev + worst
