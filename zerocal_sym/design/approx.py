"""Approximate (continuous) designs with an optimality certificate.

An *approximate design* is a probability measure ``xi`` on a finite set of
candidate poses: weight ``w_x`` on pose ``x``.  K poses realise ``K w_x``
visits of ``x``.  The optimal measure is a convex problem; the
equivalence theorem gives, at any measure, a bound on how far it is from the
optimum -- a certificate.

This module holds the driver (:func:`approximate_design`: candidates, travel
windows, refinement, the bound) and its result (:class:`ApproxDesign`).  The
pose model, the criteria and what the certificate is for are in
:mod:`zerocal_sym.design.posemodel`; the solver of the measure in
:mod:`zerocal_sym.design.measure`; the K poses realised from a measure in
:mod:`zerocal_sym.design.rounding`; the bias-aware measure in
:mod:`zerocal_sym.design.mse`; the fewest poses for a target CRLB in
:mod:`zerocal_sym.design.fewest`.

Candidates: a grid over the region (about :data:`N_CANDIDATES` feasible
poses); after the measure is solved the support is refined (local grids
around it, finer each round, added to the candidates).  The certificate is
over the final candidate set (the coarse grid plus the refinements), not
over the continuum.

Travel range (``max rho - min rho <= l0``): the candidates' ``rho`` is
covered by windows ``[r, r + l0]`` every ``delta`` = l0 / 8; the design is the
best over these windows, and the bound is the largest over the enlarged
windows ``[r, r + l0 + delta]``, each of which contains every l0-window
starting in ``[r, r + delta]`` -- so the bound covers every window.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.design.constraints import Constraints, _pointwise_ok, make_constraints
from zerocal_sym.design.criteria import _check_criterion, _criterion_weights, _user_value
from zerocal_sym.design.fewest import fewest_poses  # noqa: F401 - kept importable from here (benchmarks)
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.certify import boundary_points, search_region
from zerocal_sym.design.measure import TOL, e_certificate, solve_measure
from zerocal_sym.design.posemodel import E_Q, PoseModel, _crit, _schur, _sens, _stats
from zerocal_sym.design.terms import Weights

#: criteria with an approximate design and a certificate
APPROX_CRITERIA = ("D", "A", "E", "crlb", "position")
#: default number of coarse candidate poses
N_CANDIDATES = 1500
#: windows per scale range l0 (delta = l0 / WINDOW_STEPS)
WINDOW_STEPS = 8


# --------------------------------------------------------------------------- candidates
def candidate_poses(robot, cons: Constraints, n_target: int = N_CANDIDATES) -> tuple:
    """Feasible candidate poses over the region, about ``n_target`` of them.

    Returns
    -------
    X : ndarray, shape (N, n)
    h : float
        Grid spacing, mm (the refinement's starting scale).
    """
    reg = cons.region
    X, h = reg.design_grid(n_target) if hasattr(reg, "design_grid") else _box_grid(reg, n_target)
    ok = _pointwise_ok(robot, X, cons)
    X = X[ok]
    if len(X) == 0:
        raise DesignError("no feasible candidate pose in the region: relax the singularity margin or joint "
                          "limits, or enlarge the region")
    return X, h


def _box_grid(reg, n_target):
    """A grid of about ``n_target`` points over the region's bounding box, kept inside the region."""
    lo, hi = np.asarray(reg.lo, float), np.asarray(reg.hi, float)
    vol = float(np.prod(hi - lo))
    n = len(lo)
    h = (vol / n_target) ** (1.0 / n)
    axes = [np.linspace(lo[i], hi[i], max(2, int(round((hi[i] - lo[i]) / h)) + 1)) for i in range(n)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, n)
    X = X[reg.contains(X, 1e-9)]
    if getattr(reg, "kind", "") == "cylinder":  # the rims themselves
        k = max(8, int(round(2 * np.pi * reg.rw / h)))
        t = 2 * np.pi * np.arange(k) / k
        rims = [np.column_stack([reg.rw * np.cos(t), reg.rw * np.sin(t), np.full(k, z)]) for z in axes[2]]
        X = np.vstack([X] + rims)
    return X, h


#: points of a local refinement grid around a support point, at most (:func:`_local_grid`)
LOCAL_GRID_MAX = 1000


def _local_grid(x, h, n, steps=None):
    """Points ``x + h * (i, j[, k])`` for integer offsets in ``[-steps, steps]``, shape (M, n).

    ``h``: the spacing, a number or one per coordinate.  ``steps`` default: 3, fewer where ``(2 steps + 1)^n``
    would pass :data:`LOCAL_GRID_MAX` (in 6-D: 1, the 729 neighbours of the point).
    """
    if steps is None:
        steps = 3
        while steps > 1 and (2 * steps + 1) ** n > LOCAL_GRID_MAX:
            steps -= 1
    r = np.arange(-steps, steps + 1)
    off = np.stack(np.meshgrid(*([r] * n), indexing="ij"), axis=-1).reshape(-1, n) * h
    return x + off


# --------------------------------------------------------------------------- windows
def _windows(rho, cons: Constraints):
    """Travel windows: list of (lo, hi) ranges of rho the design may use, and the enlarged ones for the bound."""
    if cons.travel_mode != "range" or np.ptp(rho) <= cons.travel_mm:
        r = (float(rho.min()) - 1e-9, float(rho.max()) + 1e-9)
        return [r], [r]
    l0 = cons.travel_mm
    delta = l0 / WINDOW_STEPS
    starts = np.arange(rho.min(), rho.max() - l0 + delta, delta)
    exact = [(float(s), float(s + l0)) for s in starts]
    enlarged = [(float(s), float(s + l0 + delta)) for s in starts]
    return exact, enlarged


@dataclass
class ApproxDesign:
    """An optimal design measure and its certificate.

    Attributes
    ----------
    criterion : str
    X : ndarray, shape (N, n)
        The candidates of the chosen window (coarse grid and refinements).
    w : ndarray, shape (N,)
        The measure (sums to 1).
    support : ndarray, shape (s, n)
        Support points (clusters of the measure's weight).
    support_w : ndarray, shape (s,)
    eff_lb : float
        Efficiency lower bound of the measure against the best measure on the
        candidates of *every* window (the certificate).
    loss : float
        Criterion of the measure (internal, mass 1).
    bound_loss : float
        The certified bound on the best loss of any measure (mass 1): no
        ordered design of K poses on the candidates does better than this at
        mass K.
    window : tuple
        The rho range used.
    """

    criterion: str
    X: np.ndarray
    w: np.ndarray
    support: np.ndarray
    support_w: np.ndarray
    eff_lb: float
    loss: float
    bound_loss: float
    window: tuple
    n_candidates: int
    iterations: int
    windows: int
    p: int
    time_s: float
    info: dict = field(default_factory=dict)
    #: the zero offsets' internal unit (rad, mm): the crlb criterion's value is in its file unit (deg, mm)
    unit: str = "rad"
    #: ``(window, candidates (N_w, n), measure)`` of each window the bound is the least over (:meth:`covered`)
    bound_windows: list = field(default_factory=list, repr=False, compare=False)
    noise: object = field(default=None, repr=False, compare=False)
    weights: object = field(default=None, repr=False, compare=False)

    def covered(self, robot, P) -> "ApproxDesign":
        """The same measure with the bound over the candidates *and* the poses ``P`` (K, n): a design's own
        poses, so its efficiency is certified on a set it lies in.

        Each window's bound (the equivalence theorem's, :func:`_loss_bound`) takes the largest sensitivity
        over its candidates and the poses of ``P`` with ``rho`` in it (one window: all of them); E: its
        certificate over both (:func:`~zerocal_sym.design.measure.e_certificate`).
        """
        from dataclasses import replace

        from zerocal_sym.design.certify import with_poses

        P = np.atleast_2d(np.asarray(P, float))
        if not self.bound_windows or not len(P):
            return self
        sols = with_poses(robot, self.criterion, self.noise, self.weights, self.bound_windows, P)
        out = min(_loss_bound(self.criterion, sol) for sol in sols)
        info = dict(self.info, design_poses=len(P))
        info["candidates"] = str(info.get("candidates", "")).replace(
            ": the bound covers", f", and the design's {len(P)} poses: the bound covers")
        eff = _efficiency(self.criterion, _mass_value(self.criterion, self.loss, 1, self.p),
                          _mass_value(self.criterion, out, 1, self.p), self.p)
        return replace(self, bound_loss=out, n_candidates=self.n_candidates + len(P), info=info,
                       eff_lb=float(eff) if eff is not None else self.eff_lb)

    def sensitivity(self, robot, noise=None):
        """``d(x) / s`` of the measure at new poses: a function of ``X`` (M, n) -> (M,) (1 on the support)."""
        from zerocal_sym.model.noise import NoiseModel

        noise = NoiseModel.coerce(noise, robot=robot)
        crit = "crlb" if self.criterion == "mse" else self.criterion  # mse: the variance part's sensitivity
        wts = Weights(robot)
        m0 = PoseModel(robot, self.X, noise, crit, wts)
        M, c = _schur(*_stats(self.w / m0.vt, m0.aq))
        _, G, s = _crit(crit, M, m0.W, self.info.get("q", E_Q))

        def score(Y):
            m = PoseModel(robot, Y, noise, crit, wts)
            return _sens(G, m.aq, c, m.vt) / s

        return score

    def value(self, K):
        """The measure's criterion for K poses in user units (the order-free pose model)."""
        return _mass_value(self.criterion, self.loss, K, self.p, self.unit)

    def bound(self, K):
        """Best value any ordered K-pose design on the candidates can reach (user units)."""
        return _mass_value(self.criterion, self.bound_loss, K, self.p, self.unit)

    def efficiency(self, value, K):
        """Lower bound on the efficiency of a design with user value ``value`` at K poses (1 = optimal)."""
        return _efficiency(self.criterion, value, self.bound(K), self.p)

    def to_dict(self, K=None):
        d = {"criterion": self.criterion, "efficiency_lower_bound": self.eff_lb,
             "support": self.support.tolist(), "support_weights": self.support_w.tolist(),
             "n_candidates": self.n_candidates, "iterations": self.iterations, "windows": self.windows,
             "rho_window_mm": list(self.window), "time_s": self.time_s,
             "model": "order-free pose model, servo variance + sigma_m^2/4 per pose: an upper bound on the "
                      "information of every ordered design"}
        if K is not None:
            d["K"] = K
            d["measure_value"] = self.value(K)
            d["bound"] = self.bound(K)
        d.update(self.info)
        return d


def _mass_value(criterion, loss, K, p, unit="rad"):
    """User value at mass K from the internal loss at mass 1 (``unit``: the zero offsets' internal unit)."""
    if not math.isfinite(loss):
        return _user_value(criterion, math.inf, unit)
    if criterion == "D":
        return -loss + p * math.log(K)
    if criterion == "E":  # loss = -log lambda_min after e_certificate conversion
        return math.exp(-loss) * K
    return _user_value(criterion, loss - math.log(K), unit)


def _efficiency(criterion, value, bound, p):
    """Efficiency lower bound of a user value against the bound (1 = as good as the bound)."""
    if value is None or bound is None or not math.isfinite(bound):
        return None
    if criterion == "D":
        return math.exp((value - bound) / p) if math.isfinite(value) else 0.0
    if criterion == "E":
        return value / bound
    if criterion in ("crlb", "position"):
        return (bound / value) ** 2 if value > 0 else None
    return bound / value if value > 0 else None


def _loss_bound(criterion, sol):
    """Certified bound on the best loss (mass 1) from a solved measure."""
    if criterion == "D":
        return sol["loss"] - model_p(sol) * math.log(1.0 / sol["eff_lb"])
    if criterion == "E":
        return -math.log(sol["E_bound"])
    return sol["loss"] + math.log(sol["eff_lb"])


def model_p(sol):
    return sol["M"].shape[0]


def _e_loss(sol):
    """E: the reported loss is -log lambda_min (the algorithm's is the smooth one)."""
    return -math.log(float(np.linalg.eigvalsh(sol["M"])[0]))


def _clusters(X, w, radius, min_frac=1e-4):
    """Support clusters: weights above ``min_frac`` of the largest, merged within ``radius`` into the heaviest.

    ``radius``: a number (mm), or one per coordinate (a box of mixed units: the points within the ellipsoid of
    these half-axes).
    """
    order = np.argsort(-w)
    keep = order[w[order] >= min_frac * w[order[0]]]
    reps, ws = [], []
    per_axis = np.ndim(radius) > 0
    for k in keep:
        if reps:
            if per_axis:
                dist = np.linalg.norm((np.array(reps) - X[k]) / radius, axis=1)
            else:
                dist = np.linalg.norm(np.array(reps) - X[k], axis=1)
            j = int(np.argmin(dist))
            if dist[j] <= (1.0 if per_axis else radius):
                ws[j] += w[k]
                continue
        reps.append(X[k])
        ws.append(w[k])
    ws = np.array(ws)
    return np.array(reps), ws / ws.sum()


def approximate_design(robot, criterion="crlb", cons: Constraints | None = None, noise=None,
                       n_candidates: int = N_CANDIDATES, tol: float = TOL, refine: int = 2,
                       tolerances=None, search: bool = True) -> ApproxDesign:
    """The optimal design measure over feasible candidate poses, with its certificate.

    Parameters
    ----------
    criterion : {"D", "A", "E", "crlb", "position"}
    cons : Constraints, optional
    noise : NoiseModel, optional
    n_candidates : int
        Size of the coarse candidate grid.
    tol : float
        Target efficiency gap of the measure.
    refine : int
        Rounds of local refinement of the support (grid spacing / 3 each).
    search : bool
        Add the local maxima of the sensitivity over the region to the candidates, for the measure and
        for each window's bound (:func:`zerocal_sym.design.certify.search_region`).

    Returns
    -------
    ApproxDesign
    """
    from zerocal_sym.model.noise import NoiseModel

    t0 = time.perf_counter()
    _check_criterion(criterion)
    if criterion not in APPROX_CRITERIA:
        raise DesignError(f"criterion {criterion!r} has no approximate design (known: {', '.join(APPROX_CRITERIA)}; "
                          "cond is not concave, mse not convex)")
    noise = NoiseModel.coerce(noise, robot=robot)
    cons = cons or make_constraints(robot)
    wts = _criterion_weights(robot, criterion, tolerances) if criterion == "position" else Weights(robot, tolerances)
    X, h = candidate_poses(robot, cons, n_candidates)
    n_boundary = 0
    if search:  # the grid's cells closed at the feasible set's boundary
        B = boundary_points(robot, cons, X, h)
        X, n_boundary = np.vstack([X, B]), len(B)
    if np.ndim(h):
        k = int(round(float((cons.region.hi[0] - cons.region.lo[0]) / h[0]))) + 1
        grid = f"a {k}-per-coordinate grid over the {robot.n}-D region ({len(X) - n_boundary} feasible poses)"
    else:
        grid = f"a grid over the region, {h:.3g} mm apart ({len(X) - n_boundary} feasible poses)"
    closed = f", {n_boundary} points on the boundary of the feasible set next to it" if n_boundary else ""
    candidates = (f"{grid}{closed} and {refine} round{'s' if refine != 1 else ''} of local refinement around the "
                  "measure's support")
    model = PoseModel(robot, X, noise, criterion, wts)
    p = model.aq.shape[1]
    exact, enlarged = _windows(model.rho, cons)
    iters = 0
    refused = []  # why a window had no measure (solve_measure's DesignError)

    def solve_in(mod, win, w0=None, tol_=tol, certify=True):
        idx = np.flatnonzero((mod.rho >= win[0]) & (mod.rho <= win[1]))
        if len(idx) < p + 1:
            return idx, None
        sub = mod.subset(idx)
        try:
            sol = solve_measure(sub, criterion, None if w0 is None else w0[idx], tol_, certify=certify)
        except DesignError as exc:
            refused.append(str(exc))
            return idx, None
        return idx, sol

    def user_loss(sol):
        return _e_loss(sol) if criterion == "E" else sol["loss"]

    # the best exact window (coarse)
    best = None
    for win in exact:
        idx, sol = solve_in(model, win, tol_=max(tol, 1e-2) if len(exact) > 1 else tol, certify=False)
        if sol is None:
            continue
        iters += sol["iterations"]
        if best is None or user_loss(sol) < user_loss(best[2]):
            best = (win, idx, sol)
    if best is None:
        why = f" ({refused[-1]})" if refused else ""
        raise DesignError(f"no travel window of the candidate poses can identify the parameters{why}")
    win, idx, sol = best
    # refine the support of the chosen window
    for r in range(refine):
        hr = h / 3 ** (r + 1)
        sub = model.subset(idx)
        reps, _ = _clusters(sub.X, sol["w"], 1.5 * h)
        new = np.vstack([_local_grid(x, hr, robot.n) for x in reps])
        new = new[_pointwise_ok(robot, new, cons)]
        if len(new):
            nm = PoseModel(robot, new, noise, criterion, wts)
            keep = (nm.rho >= win[0]) & (nm.rho <= win[1])
            nm = nm.subset(np.flatnonzero(keep))
            model = model.extend(nm)
        w0 = np.zeros(len(model.X))
        w0[idx] = sol["w"]
        idx = np.flatnonzero((model.rho >= win[0]) & (model.rho <= win[1]))
        w0 = w0[idx]
        w0 = 0.9 * w0 / w0.sum() + 0.1 / len(w0)
        sol = solve_measure(model.subset(idx), criterion, w0, tol, certify=r == refine - 1)
        iters += sol["iterations"]
    n_grid = len(model.X)
    region = {"starts": 0, "added": 0, "rounds": 0, "max_ratio": None}

    def resolve(mod, ix, w0):
        return solve_measure(mod.subset(ix), criterion, w0, tol)

    def searched(mod, ix, sl, wn):
        """The measure of a window with the local maxima of its sensitivity over the region added."""
        if not search:
            return mod, ix, sl
        mod, ix, sl, inf = search_region(robot, cons, noise, criterion, wts, mod, ix, sl, wn, h, resolve, mod.W)
        for k_ in ("starts", "added", "rounds"):
            region[k_] += inf[k_]
        region["max_ratio"] = max(region["max_ratio"] or 0.0, inf["max_ratio"])
        return mod, ix, sl

    model, idx, sol = searched(model, idx, sol, win)
    if criterion == "E" and sol.get("E_bound") is None:
        sol["eff_lb"], sol["E_bound"] = e_certificate(model.subset(idx), sol["M"], sol["c"])
    # the bound over every window (enlarged windows cover all l0-windows)
    bounds = []  # (window, indices, measure) of each window the bound is the least over
    if len(enlarged) == 1:
        bounds.append((win, idx, sol))
    else:
        for ew in enlarged:
            bidx, bsol = solve_in(model, ew)
            if bsol is None:
                continue
            iters += bsol["iterations"]
            model, bidx, bsol = searched(model, bidx, bsol, ew)
            bounds.append((ew, bidx, bsol))
        bounds.append((win, idx, sol))
    bound_loss = min(_loss_bound(criterion, b[2]) for b in bounds)
    if search:
        candidates += (f", and {region['added']} local maxima of the sensitivity over the region (a pattern search "
                       f"from {region['starts']} starts, the cells a Lipschitz-type screen flags)")
    candidates += ": the bound covers designs on these candidates, not a proof over every pose of the region"
    sub = model.subset(idx)
    reps, ws = _clusters(sub.X, sol["w"], 1.5 * h / 3 ** refine)
    loss = user_loss(sol)
    eff = _efficiency(criterion, _mass_value(criterion, loss, 1, p), _mass_value(criterion, bound_loss, 1, p), p)
    return ApproxDesign(criterion=criterion, X=sub.X, w=sol["w"], support=reps, support_w=ws, eff_lb=float(eff),
                        loss=loss, bound_loss=bound_loss, window=win, n_candidates=len(model.X), iterations=iters,
                        windows=len(exact), p=p, time_s=time.perf_counter() - t0,
                        info={"grid_mm": h if np.ndim(h) == 0 else np.asarray(h).tolist(), "refine_rounds": refine,
                              "q": sol["q"], "candidates": candidates, "region_search": region if search else None,
                              "n_grid_and_refinements": n_grid},
                        unit=robot.errors.offset_unit,
                        bound_windows=[(b[0], model.X[b[1]], b[2]) for b in bounds], noise=noise, weights=wts)
