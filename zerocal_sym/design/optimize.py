"""Measurement-pose design as a constrained optimisation (issue 5).

The K measurement poses are chosen to make the identification of the zero
offsets as accurate as possible, within what the robot and the measuring
mechanism allow.  Two methods, each a check on the other:

* **continuous** (:func:`continuous_design`): the K poses (scaled to
  ``[-1, 1]^2`` over the design region) are the decision variables of a
  CasADi/Ipopt NLP built symbolically from the generated mechanism functions
  (inverse kinematics, transmission sines, exact distance and its AD
  derivatives); multi-start from seeded random feasible designs and from the
  paper's scheme;
* **discrete exchange** (:func:`exchange_design`): coordinate exchange
  (Fedorov / DETMAX family) over a candidate grid of feasible poses, every
  slot of the ordered design swapped against every candidate until no swap
  improves; several seeded random starts.

:func:`optimize_design` runs both, improves the visiting order of the best
design (exhaustively for K <= 8, by pair swaps and segment reversals
otherwise), polishes it with Ipopt and returns it with the paper's scheme at
the same K as the baseline.

Model
-----
Parameters: the paper's four ``p = (dth1, dth2, drMx, drMy)``, linearised at
zero source errors.  Per pose k, ``a_k = d rho_k / d p`` (exact, AD of the
generated distance model) and ``v_k = sigma_xi^2 |d rho_k / d theta|^2``
(servo error).  The K-1 measured changes have sensitivity ``A = D a`` and
covariance ``C = sigma_m^2 I + D diag(v) D^T`` (``D`` first differences, see
:mod:`zerocal_sym.identify.fisher`); ``F = A^T C^-1 A``.

Scaling ("q-units"): the offsets are expressed as arc lengths
``q = (L1 dth1, L2 dth2, drMx, drMy)`` in mm, the units of the paper's
identification matrix G (whose rows are exactly the rows of ``A`` in these
units).  ``F_q = T F T`` with ``T = diag(1/L1, 1/L2, 1, 1)``, in 1/mm^2.

Criteria (all minimised internally as a log)
--------------------------------------------
``cond``
    the paper's condition number ``kappa(G)`` of the identification matrix
    (rows ``g_{k+1} - g_k``, no MAEMM prior; noise-free, scale-dependent).
``D``
    ``log det F_q`` (maximised; invariant to the scaling).
``A``
    ``trace F_q^-1`` (mm^2, minimised): the summed variances of the two
    arc-length offsets and the two MAEMM components.
``E``
    ``lambda_min(F_q)`` (1/mm^2, maximised).
``crlb``
    ``sqrt(trace([F^-1]_offsets) / 2)`` in degrees (minimised): the RMS
    Cramér-Rao bound of the two zero offsets under the full noise model,
    MAEMM as nuisance parameters.

Smooth reformulations (NLP): ``D``, ``A`` and ``crlb`` are smooth as they
stand (log det, log trace of the symbolic 4 x 4 inverse).  ``E`` and ``cond``
are non-smooth where eigenvalues coalesce, so they use auxiliary variables
and LMI-free eigenvalue constraints: ``max log t`` s.t. ``F_n - t I >= 0``,
and ``min log(t_hi / t_lo) / 2`` s.t. ``M - t_lo I >= 0``, ``t_hi I - M >= 0``
(``F_n``, ``M = G^T G`` normalised by their mean eigenvalue at a reference
design; ``kappa = sqrt(t_hi / t_lo)`` at the optimum).  A 4 x 4 matrix
inequality ``X >= 0`` is written in one of two exact forms (``psd_form``):

* ``"minors"``: all 15 principal minors >= 0 (used for ``E``);
* ``"chol"``: ``X = L L^T`` with an auxiliary lower-triangular ``L``
  (10 variables, ``diag(L) >= 0``, 10 polynomial equalities, linear in
  ``X``; used for ``cond``, where the minors of ``M - t_lo I``, with
  ``kappa^2 ~ 1e4``, are badly scaled and most starts hit the iteration limit).

(Only the four *leading* minors would not do: they admit spurious points
where two minors vanish -- Ipopt stopped at ``t = lambda_2 > lambda_min``.)
For these two criteria Ipopt starts with a small barrier parameter
(``mu_init = 1e-6``) so that the auxiliary variables are not pushed away
from a good start.  See docs/design.md for the measurements.

Constraints
-----------
* region: a rectangle (default the workspace), every pose inside;
* scale travel ``l0`` (default 350 mm, the paper's scale range): the reading
  head is zeroed after each measurement but it is physically attached to the
  mechanism, so its position along the scale is ``rho`` (up to a constant);
  all K lengths must fit on the scale: ``max rho - min rho <= l0``
  (``travel_mode="range"``, default).  ``travel_mode="consecutive"``
  instead bounds ``|rho_{k+1} - rho_k| <= l0`` (a head re-clamped between
  measurements);
* singularity margin: every ``|sin|`` of a transmission angle at least
  ``singularity_margin`` (default: the robot's, 0.2);
* optional joint limits (deg) on the inverse-kinematics angles;
* distinct poses: pairwise distance at least ``min_separation_mm`` (default
  1 mm; the data loader rejects repeated poses).

Order: the visiting order matters (G differences consecutive rows; the scale
noise is on consecutive changes, the servo noise on poses, which makes the
Fisher information of servo-dominated noise almost order-free).  The NLP
keeps the labels of its start, so the multi-start explores orders; the best
design's order is then optimised over permutations (see above).
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import PoseError, ZerocalError
from zerocal_sym.io.files import json_safe
from zerocal_sym.model.noise import NoiseModel

#: criterion name -> (description, units, better: "min" | "max")
CRITERIA = {
    "cond": ("condition number kappa of the identification matrix G (paper)", "", "min"),
    "D": ("log det of the Fisher information F_q (q = L1 dth1, L2 dth2, rMx, rMy)", "log(1/mm^8)", "max"),
    "A": ("trace of F_q^-1", "mm^2", "min"),
    "E": ("smallest eigenvalue of F_q", "1/mm^2", "max"),
    "crlb": ("RMS Cramer-Rao bound of the two zero offsets (full noise model)", "deg", "min"),
}
MIN_K = 5
#: largest K accepted (design time grows roughly as K^2: ~15 s at K = 40 with 3 starts)
MAX_K = 100
#: the paper's scale range l0, mm
SCALE_RANGE_MM = 350.0
TRAVEL_MODES = ("range", "consecutive")
#: formulation of the matrix inequalities per criterion (measured best, see module docstring)
PSD_FORM = {"E": "minors", "cond": "chol"}
#: paper parameter indices in the source-error vector
_PAPER = (0, 1, 10, 11)
_FEAS_TOL = 1e-6


class DesignError(ZerocalError):
    """A design request that cannot be met (bad K, region, criterion, constraints)."""


# --------------------------------------------------------------------------- constraints
@dataclass(frozen=True)
class Region:
    """Axis-aligned design region, mm: ``x in [xmin, xmax]``, ``y in [ymin, ymax]``."""

    xmin: float
    xmax: float
    ymin: float
    ymax: float

    @classmethod
    def workspace(cls, robot) -> "Region":
        lo, hi = robot.workspace_bounds()
        return cls(float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))

    @property
    def lo(self):
        """ndarray, shape (2,)"""
        return np.array([self.xmin, self.ymin])

    @property
    def hi(self):
        """ndarray, shape (2,)"""
        return np.array([self.xmax, self.ymax])

    @property
    def center(self):
        return (self.lo + self.hi) / 2

    @property
    def half(self):
        return (self.hi - self.lo) / 2

    def grid(self, nx: int, ny: int):
        """Grid over the region, ndarray shape (nx*ny, 2), row-major in y."""
        X, Y = np.meshgrid(np.linspace(self.xmin, self.xmax, nx), np.linspace(self.ymin, self.ymax, ny))
        return np.column_stack([X.ravel(), Y.ravel()])

    def as_list(self):
        return [self.xmin, self.xmax, self.ymin, self.ymax]


@dataclass(frozen=True)
class Constraints:
    """What a design must respect (see the module docstring).

    Attributes
    ----------
    region : Region
    travel_mm : float
        Scale range ``l0``, mm.
    travel_mode : {"range", "consecutive"}
    singularity_margin : float
        Lower bound on every ``|sin|`` of a transmission angle.
    joint_limits_deg : tuple of two (lo, hi) pairs or None
        Limits of ``theta1`` and ``theta2``, deg.
    min_separation_mm : float
        Lower bound on the distance between any two poses, mm.
    """

    region: Region
    travel_mm: float = SCALE_RANGE_MM
    travel_mode: str = "range"
    singularity_margin: float = 0.2
    joint_limits_deg: tuple | None = None
    min_separation_mm: float = 1.0

    def to_dict(self):
        return {"region_mm": self.region.as_list(), "travel_mm": self.travel_mm, "travel_mode": self.travel_mode,
                "singularity_margin": self.singularity_margin,
                "joint_limits_deg": None if self.joint_limits_deg is None else [list(j) for j in self.joint_limits_deg],
                "min_separation_mm": self.min_separation_mm}


def _finite(name, v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise DesignError(f"{name} must be a number, got {v!r}") from None
    if not math.isfinite(v):
        raise DesignError(f"{name} must be finite, got {v!r}")
    return v


def make_constraints(robot, region=None, travel_mm=SCALE_RANGE_MM, travel_mode="range",
                     singularity_margin=None, joint_limits_deg=None, min_separation_mm=1.0) -> Constraints:
    """Validated :class:`Constraints`.

    Parameters
    ----------
    robot : Robot
    region : Region or sequence (xmin, xmax, ymin, ymax) in mm, optional
        Default: the robot's workspace.  It must be reachable everywhere (a
        21 x 21 grid is checked: inverse kinematics defined and consistent with
        forward kinematics, i.e. one assembly mode).
    travel_mm : float
    travel_mode : {"range", "consecutive"}
    singularity_margin : float, optional
        Default ``robot.singularity_margin``.
    joint_limits_deg : ((lo1, hi1), (lo2, hi2)), optional
    min_separation_mm : float

    Raises
    ------
    DesignError
        With a message saying what is wrong.
    """
    if region is None:
        region = Region.workspace(robot)
    elif not isinstance(region, Region):
        vals = list(region)
        if len(vals) != 4:
            raise DesignError(f"region needs 4 numbers XMIN XMAX YMIN YMAX (mm), got {len(vals)}")
        vals = [_finite(n, v) for n, v in zip(("XMIN", "XMAX", "YMIN", "YMAX"), vals)]
        region = Region(*vals)
    if not region.xmax - region.xmin >= 1.0 or not region.ymax - region.ymin >= 1.0:
        raise DesignError(f"region x in [{region.xmin:g}, {region.xmax:g}], y in [{region.ymin:g}, "
                          f"{region.ymax:g}] mm is empty or thinner than 1 mm (need XMIN < XMAX and "
                          "YMIN < YMAX; order: XMIN XMAX YMIN YMAX)")
    travel_mm = _finite("travel (scale range l0, mm)", travel_mm)
    if travel_mm <= 0:
        raise DesignError(f"the scale range l0 must be positive, got {travel_mm:g} mm")
    if travel_mode not in TRAVEL_MODES:
        raise DesignError(f"unknown travel mode {travel_mode!r} (known: {', '.join(TRAVEL_MODES)})")
    margin = robot.singularity_margin if singularity_margin is None else _finite("singularity margin",
                                                                                 singularity_margin)
    if not 0 <= margin < 1:
        raise DesignError(f"singularity margin must be in [0, 1) (a |sin|), got {margin:g}")
    if joint_limits_deg is not None:
        jl = np.asarray(joint_limits_deg, dtype=float)
        if jl.shape != (2, 2) or not np.all(np.isfinite(jl)):
            raise DesignError("joint limits must be ((lo1, hi1), (lo2, hi2)) in degrees, finite")
        if np.any(jl[:, 0] >= jl[:, 1]):
            raise DesignError(f"joint limits need lo < hi, got {jl.tolist()} deg")
        joint_limits_deg = tuple(tuple(float(v) for v in row) for row in jl)
    min_sep = _finite("minimum pose separation", min_separation_mm)
    if min_sep < 0:
        raise DesignError(f"minimum pose separation must be >= 0 mm, got {min_sep:g}")
    cons = Constraints(region, travel_mm, travel_mode, margin, joint_limits_deg, min_sep)
    _check_region_reachable(robot, region)
    return cons


def _check_region_reachable(robot, region: Region, n: int = 21):
    grid = region.grid(n, n)
    th, ratio = _call_ik(robot, grid)
    bad = np.flatnonzero(~np.all(np.abs(ratio) <= 1.0, axis=1) | ~np.all(np.isfinite(th), axis=1))
    lo, hi = Region.workspace(robot).lo, Region.workspace(robot).hi
    ws = (f"the robot's workspace is x in [{lo[0]:g}, {hi[0]:g}], y in [{lo[1]:g}, {hi[1]:g}] mm")
    if bad.size:
        x, y = grid[bad[0]]
        raise DesignError(f"region x in [{region.xmin:g}, {region.xmax:g}], y in [{region.ymin:g}, "
                          f"{region.ymax:g}] mm is not reachable: ({x:g}, {y:g}) mm cannot be reached "
                          f"({bad.size} of {len(grid)} grid points unreachable); {ws}")
    back = kin.fk(robot, th)
    off = np.flatnonzero(~(np.linalg.norm(back - grid, axis=1) < 1e-6))
    if off.size:
        x, y = grid[off[0]]
        raise DesignError(f"region crosses an assembly-mode change at ({x:g}, {y:g}) mm "
                          f"(forward and inverse kinematics disagree there); {ws}")


def _call_ik(robot, P):
    f = robot.mechanism["ik"]
    theta, ratio = f(np.asarray(P, float).T, robot.geometry)
    return theta.full().T, ratio.full().T


# --------------------------------------------------------------------------- per-pose terms
@lru_cache(maxsize=None)
def _pose_terms_fn(mech_name: str):
    """CasADi Function (P[2], g[12]) -> theta[2], ratio[2], s[3], rho, a[4], dth[2].

    ``a = d rho / d (dth1, dth2, drMx, drMy)`` (per rad, per mm) and
    ``dth = d rho / d theta`` (per rad), exact derivatives at zero source
    errors, joints from the inverse kinematics.
    """
    import casadi as ca

    from zerocal_sym.model.mechanism import get_mechanism

    mech = get_mechanism(mech_name)
    P = ca.SX.sym("P", 2)
    g = ca.SX.sym("g", mech["ik"].size1_in(1))
    theta, ratio = mech["ik"](P, g)
    s = mech["transmission"](P, theta, g)
    th = ca.SX.sym("th", 2)
    ne = mech["distance"].size1_in(2)
    err = ca.SX.sym("err", ne)
    rho = mech["distance"](th, g, err)
    de = ca.jacobian(rho, err)
    dt = ca.jacobian(rho, th)
    sub = ca.Function("drho", [th, g, err], [rho, de, dt])
    r, de_v, dt_v = sub(theta, g, ca.DM.zeros(ne))
    a = ca.vertcat(*[de_v[0, i] for i in _PAPER])
    return ca.Function("design_pose_terms", [P, g], [theta, ratio, s, r, a, dt_v.T],
                       ["P", "g"], ["theta", "ratio", "s", "rho", "a", "dth"])


def pose_terms(robot, P) -> dict:
    """Per-pose quantities of the design model.

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses, mm.

    Returns
    -------
    dict
        ``theta`` (K, 2) rad, ``ratio`` (K, 2), ``s`` (K, 3) transmission
        sines, ``rho`` (K,) mm, ``a`` (K, 4) d rho / d p (per rad, per mm),
        ``dth`` (K, 2) d rho / d theta (mm/rad).
    """
    P = np.atleast_2d(np.asarray(P, float))
    f = _pose_terms_fn(robot.mechanism_name)
    out = f(P.T, robot.geometry)
    names = ("theta", "ratio", "s", "rho", "a", "dth")
    res = {n: o.full().T for n, o in zip(names, out)}
    res["rho"] = res["rho"][:, 0]
    return res


def _qscale(robot):
    """``1 / fisher.parameter_scale``: q-unit sensitivities are ``a * qs``, shape (4,)."""
    L1, L2 = robot.link_lengths
    return np.array([1.0 / L1, 1.0 / L2, 1.0, 1.0])


def _noise_terms(noise: NoiseModel):
    if noise is None:
        noise = NoiseModel.paper()
    if noise.is_zero:
        raise DesignError("the noise model is zero: the Fisher information is unbounded")
    return float(noise.sigma_scale_mm) ** 2, float(noise.sigma_servo_rad) ** 2


# --------------------------------------------------------------------------- numeric criteria
def _fisher_batch(aq, v, sm2):
    """Fisher information in q-units for a batch of ordered designs.

    Parameters
    ----------
    aq : ndarray, shape (B, K, 4)
        Per-pose sensitivities in q-units (mm per mm).
    v : ndarray, shape (B, K)
        Per-pose variance of rho from the servo error, mm^2.
    sm2 : float
        Scale-error variance per change, mm^2.

    Returns
    -------
    ndarray, shape (B, 4, 4)
    """
    A = np.diff(aq, axis=1)
    K = aq.shape[1]
    C = np.zeros((aq.shape[0], K - 1, K - 1))
    i = np.arange(K - 1)
    C[:, i, i] = sm2 + v[:, :-1] + v[:, 1:]
    j = np.arange(K - 2)
    C[:, j, j + 1] = -v[:, 1:-1]
    C[:, j + 1, j] = -v[:, 1:-1]
    X = np.linalg.solve(C, A)
    F = np.einsum("bki,bkj->bij", A, X)
    return (F + np.swapaxes(F, 1, 2)) / 2


def _objective_batch(criterion, aq, v, sm2, qs):
    """Internal objective (smaller is better; ``inf`` for rank-deficient designs), shape (B,)."""
    B = aq.shape[0]
    out = np.full(B, np.inf)
    if criterion == "cond":
        s = np.linalg.svd(np.diff(aq, axis=1), compute_uv=False)
        ok = s[:, -1] > 1e-12 * s[:, 0]
        out[ok] = np.log(s[ok, 0] / s[ok, -1])
        return out
    F = _fisher_batch(aq, v, sm2)
    w = np.linalg.eigvalsh(F)
    ok = w[:, 0] > 1e-12 * np.maximum(w[:, -1], 1e-300)
    if not np.any(ok):
        return out
    F, w = F[ok], w[ok]
    if criterion == "D":
        out[ok] = -np.sum(np.log(w), axis=1)
    elif criterion == "E":
        out[ok] = -np.log(w[:, 0])
    else:
        Finv = np.linalg.inv(F)
        if criterion == "A":
            out[ok] = np.log(np.trace(Finv, axis1=1, axis2=2))
        elif criterion == "crlb":
            out[ok] = np.log(Finv[:, 0, 0] * qs[0] ** 2 + Finv[:, 1, 1] * qs[1] ** 2)
        else:
            raise DesignError(f"unknown criterion {criterion!r}")
    return out


def criterion_values(robot, P, noise: NoiseModel | None = None) -> dict:
    """Every criterion of an ordered design, in the user's units.

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses in visiting order, mm.

    Returns
    -------
    dict
        ``cond`` (-), ``D`` (log det F_q), ``A`` (mm^2), ``E`` (1/mm^2),
        ``crlb`` (deg, RMS over the two offsets); ``inf``/``-inf`` where the
        design is rank-deficient.
    """
    sm2, _ = _noise_terms(noise)
    qs = _qscale(robot)
    aq, v = _terms_batch(robot, P, noise)
    res = {}
    for c in CRITERIA:
        o = float(_objective_batch(c, aq, v, sm2, qs)[0])
        res[c] = _user_value(c, o)
    return res


def _user_value(criterion, obj):
    """Internal objective -> user-facing value."""
    if not np.isfinite(obj):
        return {"cond": math.inf, "D": -math.inf, "A": math.inf, "E": 0.0, "crlb": math.inf}[criterion]
    if criterion == "cond":
        return math.exp(obj)
    if criterion == "D":
        return -obj
    if criterion == "A":
        return math.exp(obj)
    if criterion == "E":
        return math.exp(-obj)
    return math.degrees(math.sqrt(math.exp(obj) / 2))


def check_design(robot, P, cons: Constraints, tol: float = _FEAS_TOL) -> list:
    """Constraint violations of a design (empty list: feasible).

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses in visiting order, mm.
    tol : float
        Tolerance (mm, or |sin|, or deg).

    Returns
    -------
    list of str
    """
    P = np.atleast_2d(np.asarray(P, float))
    out = []
    r = cons.region
    for k, p in enumerate(P):
        if np.any(p < r.lo - tol) or np.any(p > r.hi + tol):
            out.append(f"pose {k} ({p[0]:.3f}, {p[1]:.3f}) mm is outside the region "
                       f"x in [{r.xmin:g}, {r.xmax:g}], y in [{r.ymin:g}, {r.ymax:g}]")
    th, ratio = _call_ik(robot, P)
    unreach = ~np.all(np.abs(ratio) <= 1.0, axis=1)
    for k in np.flatnonzero(unreach):
        out.append(f"pose {k} is unreachable")
    if np.any(unreach):
        return out
    t = pose_terms(robot, P)
    smin = np.min(np.abs(t["s"]), axis=1)
    for k in np.flatnonzero(smin < cons.singularity_margin - tol):
        out.append(f"pose {k}: min |sin transmission angle| {smin[k]:.4f} < margin {cons.singularity_margin:g}")
    if cons.joint_limits_deg is not None:
        jl = np.asarray(cons.joint_limits_deg)
        deg = np.degrees(t["theta"])
        for k in range(len(P)):
            for i in range(2):
                if deg[k, i] < jl[i, 0] - tol or deg[k, i] > jl[i, 1] + tol:
                    out.append(f"pose {k}: theta{i + 1} = {deg[k, i]:.4f} deg outside [{jl[i, 0]:g}, {jl[i, 1]:g}]")
    rho = t["rho"]
    if cons.travel_mode == "range":
        if np.ptp(rho) > cons.travel_mm + tol:
            out.append(f"scale travel: rho spans {np.ptp(rho):.3f} mm > l0 = {cons.travel_mm:g} mm")
    else:
        d = np.abs(np.diff(rho))
        for k in np.flatnonzero(d > cons.travel_mm + tol):
            out.append(f"scale travel: |rho_{k + 1} - rho_{k}| = {d[k]:.3f} mm > l0 = {cons.travel_mm:g} mm")
    if cons.min_separation_mm > 0 and len(P) > 1:
        dist = np.linalg.norm(P[:, None] - P[None], axis=2)
        iu = np.triu_indices(len(P), 1)
        close = np.flatnonzero(dist[iu] < cons.min_separation_mm - tol)
        for c in close:
            out.append(f"poses {iu[0][c]} and {iu[1][c]} are {dist[iu][c]:.3f} mm apart "
                       f"< {cons.min_separation_mm:g} mm")
    return out


def _pointwise_ok(robot, P, cons: Constraints):
    """Per-pose feasibility (region, reach, margin, joint limits), bool shape (K,)."""
    P = np.atleast_2d(P)
    th, ratio = _call_ik(robot, P)
    ok = np.all(np.abs(ratio) <= 1.0 - 1e-9, axis=1) & np.all((P >= cons.region.lo) & (P <= cons.region.hi), axis=1)
    if not np.any(ok):
        return ok
    t = pose_terms(robot, P[ok])
    good = np.min(np.abs(t["s"]), axis=1) >= cons.singularity_margin + 1e-9
    if cons.joint_limits_deg is not None:
        jl = np.radians(np.asarray(cons.joint_limits_deg))
        good &= np.all((t["theta"] >= jl[:, 0] + 1e-9) & (t["theta"] <= jl[:, 1] - 1e-9), axis=1)
    ok[np.flatnonzero(ok)] = good
    return ok


# --------------------------------------------------------------------------- baseline
def paper_baseline(robot, K: int, region: Region | None = None) -> np.ndarray:
    """The paper's scheme with K poses, as the baseline.

    Even K: :func:`zerocal_sym.paper.scheme.paper_poses` with ``n = K/2`` (on the
    region's lower and upper edges when a region is given).  Odd K (the paper
    has none): ``ceil(K/2)`` evenly spaced poses on ``y = ymin`` then
    ``floor(K/2)`` on ``y = ymax``, each from ``xmin`` to ``xmax``.

    Returns
    -------
    ndarray, shape (K, 2)
        mm, in visiting order.
    """
    from zerocal_sym.paper.scheme import paper_poses

    ws = Region.workspace(robot)
    region = region or ws
    if K % 2 == 0 and region == ws:
        return paper_poses(robot, K // 2)
    n1 = (K + 1) // 2
    n2 = K - n1
    return np.vstack([np.column_stack([np.linspace(region.xmin, region.xmax, n1), np.full(n1, region.ymin)]),
                      np.column_stack([np.linspace(region.xmin, region.xmax, n2), np.full(n2, region.ymax)])])


# --------------------------------------------------------------------------- evaluation
def evaluate(robot, P, criterion: str = "crlb", noise: NoiseModel | None = None,
             cons: Constraints | None = None) -> dict:
    """Report of one ordered design.

    Returns
    -------
    dict
        ``poses`` (K x 2 mm), ``joints_deg``, ``criterion`` {``name``,
        ``value``, ``units``, ``values`` (all five)}, ``crlb_zero_offsets_deg``
        (2,) from :func:`zerocal_sym.identify.fisher.crlb_zero_offsets_deg`, ``kappa``
        (the paper's kappa_1 of G, no MAEMM prior), ``rho_span_mm``,
        ``min_transmission_sine`` and, with ``cons``, ``violations``.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.paper import scheme

    P = np.atleast_2d(np.asarray(P, float))
    noise = noise or NoiseModel.paper()
    vals = criterion_values(robot, P, noise)
    t = pose_terms(robot, P)
    try:
        crlb = fisher.crlb_zero_offsets_deg(robot, t["theta"], "paper", noise).tolist()
    except PoseError:
        crlb = [math.inf, math.inf]
    G, _ = scheme.identification_matrix(robot, P, theta=t["theta"])
    rep = {
        "poses": P.tolist(),
        "joints_deg": np.degrees(t["theta"]).tolist(),
        "criterion": {"name": criterion, "value": vals[criterion], "units": CRITERIA[criterion][1],
                      "values": vals, "units_all": {c: CRITERIA[c][1] for c in CRITERIA}},
        "crlb_zero_offsets_deg": crlb,
        "crlb_rms_deg": float(np.sqrt(np.mean(np.square(crlb)))),
        "kappa": scheme.condition_number(G),
        "rho_span_mm": float(np.ptp(t["rho"])),
        "min_transmission_sine": float(np.min(np.abs(t["s"]))),
    }
    if cons is not None:
        rep["violations"] = check_design(robot, P, cons)
    return rep


# --------------------------------------------------------------------------- ordering
def _permute_terms(t, perms, qs, sx2):
    aq = (t["a"] * qs)[perms]
    v = (sx2 * np.sum(t["dth"] ** 2, axis=1))[perms]
    return aq, v


def best_order(robot, P, criterion, noise=None, cons: Constraints | None = None, exhaustive_max: int = 8):
    """Visiting order of the poses that minimises the criterion.

    Exhaustive over all K! orders for ``K <= exhaustive_max``; otherwise a
    local search over pair swaps and segment reversals (2-opt) from the
    given order, best improvement first.  With the ``consecutive`` travel
    mode, orders that break it are skipped.

    Returns
    -------
    order : ndarray of int, shape (K,)
    objective : float
        Internal objective of the best order.
    """
    P = np.atleast_2d(np.asarray(P, float))
    K = len(P)
    sm2, sx2 = _noise_terms(noise)
    qs = _qscale(robot)
    t = pose_terms(robot, P)
    rho = t["rho"]

    def objective(perms):
        aq, v = _permute_terms(t, perms, qs, sx2)
        o = _objective_batch(criterion, aq, v, sm2, qs)
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


# --------------------------------------------------------------------------- discrete exchange
def candidate_grid(robot, cons: Constraints, nx: int = 25, ny: int = 11):
    """Feasible candidate poses on a grid over the region, ndarray shape (N, 2)."""
    grid = cons.region.grid(nx, ny)
    return grid[_pointwise_ok(robot, grid, cons)]


def _feasible_random_subset(rng, rho, K, cons, tries=200, close=None):
    """Random ordered K-subset meeting the travel and separation constraints (None if not found).

    ``close`` : bool ndarray, shape (N, N), pairs closer than the minimum separation.
    """
    N = len(rho)
    for _ in range(tries):
        if cons.travel_mode == "range" and np.ptp(rho) > cons.travel_mm:
            lo = rng.uniform(rho.min(), rho.max() - cons.travel_mm)
            pool = np.flatnonzero((rho >= lo) & (rho <= lo + cons.travel_mm))
        else:
            pool = np.arange(N)
        if len(pool) < K:
            continue
        if close is None:
            idx = rng.choice(pool, K, replace=False)
        else:  # greedy in random order
            idx = []
            for c in rng.permutation(pool):
                if not idx or not np.any(close[c, idx]):
                    idx.append(c)
                    if len(idx) == K:
                        break
            if len(idx) < K:
                continue
            idx = rng.permutation(np.array(idx))
        if _travel_ok(rho[idx], cons):
            return idx
    return None


def _travel_ok(rho, cons):
    if cons.travel_mode == "range":
        return np.ptp(rho) <= cons.travel_mm
    return np.all(np.abs(np.diff(rho)) <= cons.travel_mm)


def exchange_design(robot, K, criterion="crlb", cons: Constraints | None = None, noise=None, seed=0,
                    n_starts: int = 8, grid=(25, 11), max_sweeps: int = 50):
    """Discrete coordinate exchange over a candidate grid.

    Each start is a random ordered set of K distinct feasible candidates
    (seeded); each sweep tries, for every slot, every unused candidate and
    keeps the best improvement (Fedorov-type exchange, one slot at a time);
    sweeps repeat until none improves.

    Returns
    -------
    dict
        ``poses`` (K, 2), ``objective``, ``value`` (user units), ``starts``
        (list of per-start objectives), ``n_candidates``, ``time_s``.
    """
    t0 = time.perf_counter()
    cons = cons or make_constraints(robot)
    _check_k(K)
    _check_criterion(criterion)
    cand = candidate_grid(robot, cons, *grid)
    if len(cand) < K:
        raise DesignError(f"only {len(cand)} feasible candidate poses in the region on a {grid[0]} x {grid[1]} "
                          f"grid (K = {K} needed): relax the singularity margin or joint limits, or enlarge "
                          "the region")
    sm2, sx2 = _noise_terms(noise)
    qs = _qscale(robot)
    t = pose_terms(robot, cand)
    aq_all = t["a"] * qs
    v_all = sx2 * np.sum(t["dth"] ** 2, axis=1)
    rho = t["rho"]
    rng = np.random.default_rng(seed)
    N = len(cand)
    close = None
    if cons.min_separation_mm > 0:
        close = np.linalg.norm(cand[:, None] - cand[None], axis=2) < cons.min_separation_mm
        np.fill_diagonal(close, False)
    best_idx, best_o, starts = None, np.inf, []
    for _ in range(n_starts):
        idx = _feasible_random_subset(rng, rho, K, cons, close=close)
        if idx is None:
            raise DesignError(f"no {K} candidate poses fit the scale travel l0 = {cons.travel_mm:g} mm "
                              f"({cons.travel_mode}) and the minimum separation {cons.min_separation_mm:g} mm")
        cur = _objective_batch(criterion, aq_all[idx][None], v_all[idx][None], sm2, qs)[0]
        for _sweep in range(max_sweeps):
            improved = False
            for pos in rng.permutation(K):
                free = np.setdiff1d(np.arange(N), idx)
                trial = np.repeat(idx[None], len(free), axis=0)
                trial[:, pos] = free
                o = _objective_batch(criterion, aq_all[trial], v_all[trial], sm2, qs)
                if cons.travel_mode == "range":
                    o[np.ptp(rho[trial], axis=1) > cons.travel_mm] = np.inf
                else:
                    o[np.max(np.abs(np.diff(rho[trial], axis=1)), axis=1) > cons.travel_mm] = np.inf
                if close is not None:
                    others = np.delete(idx, pos)
                    o[np.any(close[np.ix_(free, others)], axis=1)] = np.inf
                k = int(np.argmin(o))
                if o[k] < cur - 1e-10 * max(abs(cur), 1.0):
                    idx, cur, improved = trial[k], o[k], True
            if not improved:
                break
        starts.append(float(cur))
        if cur < best_o:
            best_idx, best_o = idx.copy(), cur
    if not np.isfinite(best_o):
        raise DesignError("every exchange start is rank-deficient: the region cannot identify the parameters")
    return {"poses": cand[best_idx], "objective": float(best_o), "value": _user_value(criterion, best_o),
            "starts": starts, "n_candidates": int(N), "grid": list(grid), "time_s": time.perf_counter() - t0}


# --------------------------------------------------------------------------- continuous (Ipopt)
def _minors(M):
    """All principal minors of a symbolic 4 x 4 matrix (15): all >= 0 <=> PSD."""
    import casadi as ca

    out = []
    for r in range(1, 5):
        for idx in itertools.combinations(range(4), r):
            idx = list(idx)
            out.append(ca.det(M[idx, idx]))
    return out


class _NLP:
    """The symbolic design NLP for one (robot, K, criterion, constraints, noise)."""

    def __init__(self, robot, K, criterion, cons: Constraints, noise, fscale, mscale, max_iter=500,
                 psd_form=None, ipopt_options=None):
        import casadi as ca

        self.robot, self.K, self.criterion, self.cons = robot, K, criterion, cons
        psd_form = psd_form or PSD_FORM.get(criterion, "chol")
        sm2, sx2 = _noise_terms(noise)
        qs = _qscale(robot)
        c, h = cons.region.center, cons.region.half
        z = ca.SX.sym("z", 2, K)
        P = ca.repmat(ca.DM(c), 1, K) + ca.repmat(ca.DM(h), 1, K) * z
        f = _pose_terms_fn(robot.mechanism_name).map(K)
        theta, ratio, s, rho, a, dth = f(P, robot.geometry)
        aq = ca.repmat(ca.DM(qs), 1, K) * a
        v = sx2 * ca.sum1(dth ** 2)
        g, lbg, ubg = [], [], []

        def add(expr, lo, hi):
            expr = ca.vec(expr)
            g.append(expr)
            lbg.append(np.broadcast_to(lo, expr.shape[0]).astype(float))
            ubg.append(np.broadcast_to(hi, expr.shape[0]).astype(float))

        add(ratio, -1 + 1e-9, 1 - 1e-9)
        if cons.singularity_margin > 0:
            add(s ** 2, (cons.singularity_margin + 1e-7) ** 2, np.inf)
        if cons.joint_limits_deg is not None:
            jl = np.radians(np.asarray(cons.joint_limits_deg))
            add(theta[0, :], jl[0, 0] + 1e-9, jl[0, 1] - 1e-9)
            add(theta[1, :], jl[1, 0] + 1e-9, jl[1, 1] - 1e-9)
        aux = []  # (name, symbol column, lb, ub, init(nums) -> values)
        l0 = cons.travel_mm
        if cons.travel_mode == "range":
            r = ca.SX.sym("r", 2)  # rho window, scaled by 1/l0
            aux.append(("rho window", r, -np.inf, np.inf,
                        lambda n: np.array([n["rho"].min(), n["rho"].max()]) / l0))
            add(rho / l0 - r[0], 0, np.inf)
            add(r[1] - rho / l0, 0, np.inf)
            add(r[1] - r[0], -np.inf, 1 - 1e-9)
        else:
            add((rho[1:] - rho[:-1]) / l0, -1 + 1e-9, 1 - 1e-9)
        if cons.min_separation_mm > 0:
            d2 = [ca.sumsqr(P[:, i] - P[:, j]) / 1e4 for i in range(K) for j in range(i + 1, K)]
            add(ca.vertcat(*d2), (cons.min_separation_mm + 1e-6) ** 2 / 1e4, np.inf)

        def psd(name, X, X0):
            """X (symbolic 4 x 4) >= 0 as X = L L^T with L lower-triangular (auxiliary)."""
            if psd_form == "minors":
                add(ca.vertcat(*_minors(X)), 0, np.inf)
                return
            tri = [(i, j) for i in range(4) for j in range(i + 1)]
            lv = ca.SX.sym(name, len(tri))
            Lm = ca.SX.zeros(4, 4)
            for k, (i, j) in enumerate(tri):
                Lm[i, j] = lv[k]
            R = X - Lm @ Lm.T
            add(ca.vertcat(*[R[i, j] for i, j in tri]), 0, 0)
            lb = np.array([0.0 if i == j else -np.inf for i, j in tri])

            def init(n):
                Xn = X0(n)
                Lc = np.linalg.cholesky(Xn + 1e-12 * max(np.trace(Xn), 1e-12) * np.eye(4))
                return np.array([Lc[i, j] for i, j in tri])

            aux.append((name, lv, lb, np.inf, init))

        # differences and Fisher information (LDL^T of the tridiagonal covariance)
        b = [aq[:, i + 1] - aq[:, i] for i in range(K - 1)]
        if criterion == "cond":
            M = sum((bi @ bi.T for bi in b), ca.SX.zeros(4, 4)) / mscale
            tl = ca.SX.sym("tlo")
            th_ = ca.SX.sym("thi")
            aux.append(("tlo", tl, 1e-12, np.inf, lambda n: max(0.5 * n["wM"][0], 1e-12)))
            aux.append(("thi", th_, 1e-12, np.inf, lambda n: 1.5 * n["wM"][-1]))
            psd("Llo", M - tl * ca.SX.eye(4), lambda n: n["M"] - 0.5 * n["wM"][0] * np.eye(4))
            psd("Lhi", th_ * ca.SX.eye(4) - M, lambda n: 1.5 * n["wM"][-1] * np.eye(4) - n["M"])
            obj = 0.5 * (ca.log(th_) - ca.log(tl))
        else:
            d = [sm2 + v[i] + v[i + 1] for i in range(K - 1)]
            e = [-v[i + 1] for i in range(K - 2)]
            Dp, w = d[0], b[0]
            F = w @ w.T / Dp
            for i in range(1, K - 1):
                m = e[i - 1] / Dp
                Dp = d[i] - m * e[i - 1]
                w = b[i] - m * w
                F = F + w @ w.T / Dp
            Fn = F / fscale
            if criterion == "D":
                obj = -ca.log(ca.det(Fn))
            elif criterion == "E":
                tt = ca.SX.sym("t")
                aux.append(("t", tt, 1e-12, np.inf, lambda n: max(0.5 * n["wF"][0], 1e-12)))
                psd("L", Fn - tt * ca.SX.eye(4), lambda n: n["Fn"] - 0.5 * n["wF"][0] * np.eye(4))
                obj = -ca.log(tt)
            else:
                Finv = ca.inv(Fn)
                if criterion == "A":
                    obj = ca.log(ca.trace(Finv))
                else:
                    obj = ca.log(Finv[0, 0] * qs[0] ** 2 + Finv[1, 1] * qs[1] ** 2)
        self.aux = aux
        x = ca.vertcat(ca.vec(z), *[a_[1] for a_ in aux])
        self.lbx = np.concatenate([-np.ones(2 * K)] + [np.broadcast_to(a_[2], a_[1].shape[0]) for a_ in aux])
        self.ubx = np.concatenate([np.ones(2 * K)] + [np.broadcast_to(a_[3], a_[1].shape[0]) for a_ in aux])
        self.lbg = np.concatenate(lbg)
        self.ubg = np.concatenate(ubg)
        self.fscale, self.mscale = fscale, mscale
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": max_iter,
                "ipopt.tol": 1e-10, "ipopt.acceptable_tol": 1e-7, "ipopt.constr_viol_tol": 1e-9,
                "ipopt.bound_relax_factor": 0.0, "error_on_fail": False}
        if criterion in ("cond", "E"):
            opts["ipopt.mu_init"] = 1e-6
        opts.update(ipopt_options or {})
        self.solver = ca.nlpsol("design", "ipopt", {"x": x, "f": obj, "g": ca.vertcat(*g)}, opts)
        #: objective and constraints as a Function of x (for checks)
        self.fg = ca.Function("design_fg", [x], [obj, ca.vertcat(*g)])
        self.sm2, self.sx2, self.qs = sm2, sx2, qs

    def x0(self, P0):
        """Initial point from a design (auxiliary variables from its numeric values)."""
        cons = self.cons
        z0 = np.clip((np.asarray(P0) - cons.region.center) / cons.region.half, -1, 1)
        t = pose_terms(self.robot, P0)
        aq = t["a"] * self.qs
        G = np.diff(aq, axis=0)
        v = self.sx2 * np.sum(t["dth"] ** 2, axis=1)
        nums = {"rho": t["rho"], "M": G.T @ G / self.mscale,
                "Fn": _fisher_batch(aq[None], v[None], self.sm2)[0] / self.fscale}
        nums["wM"] = np.linalg.eigvalsh(nums["M"])
        nums["wF"] = np.linalg.eigvalsh(nums["Fn"])
        aux = [np.atleast_1d(a_[4](nums)) for a_ in self.aux]
        return np.concatenate([z0.ravel()] + aux)  # z is (2, K) column-major == P0 row-major

    def solve(self, P0):
        """Run Ipopt from ``P0`` (K, 2); returns (P, status, iterations)."""
        sol = self.solver(x0=self.x0(P0), lbx=self.lbx, ubx=self.ubx, lbg=self.lbg, ubg=self.ubg)
        st = self.solver.stats()
        x = sol["x"].full().ravel()
        z = np.clip(x[:2 * self.K].reshape(self.K, 2), -1, 1)
        P = self.cons.region.center + self.cons.region.half * z
        return P, st.get("return_status", "?"), int(st.get("iter_count", -1))


def _random_start(robot, K, cons, rng, tries=50):
    """A random design of K feasible, separated poses (None if none found)."""
    for _ in range(tries):
        pts = cons.region.lo + rng.uniform(size=(40 * K, 2)) * (cons.region.hi - cons.region.lo)
        pts = pts[_pointwise_ok(robot, pts, cons)]
        if len(pts) < K:
            continue
        rho = pose_terms(robot, pts)["rho"]
        close = None
        if cons.min_separation_mm > 0:
            close = np.linalg.norm(pts[:, None] - pts[None], axis=2) < cons.min_separation_mm
            np.fill_diagonal(close, False)
        idx = _feasible_random_subset(rng, rho, K, cons, tries=20, close=close)
        if idx is None:
            continue
        P = pts[idx]
        if not check_design(robot, P, cons):
            return P
    return None


def _check_k(K):
    if isinstance(K, bool) or not isinstance(K, (int, np.integer)):
        raise DesignError(f"K must be an integer number of poses, got {K!r}")
    if K < MIN_K:
        raise DesignError(f"K = {K} is too small: at least {MIN_K} poses are needed to identify the 4 "
                          "parameters (K - 1 >= 4 measured changes)")
    if K > MAX_K:
        raise DesignError(f"K = {K} is too large (at most {MAX_K})")


def _check_criterion(criterion):
    if criterion not in CRITERIA:
        raise DesignError(f"unknown criterion {criterion!r} (known: {', '.join(CRITERIA)})")


def _scales(robot, P, noise):
    """Normalisations of F_q and G^T G (mean eigenvalue at a reference design)."""
    sm2, sx2 = _noise_terms(noise)
    t = pose_terms(robot, P)
    aq = t["a"] * _qscale(robot)
    v = sx2 * np.sum(t["dth"] ** 2, axis=1)
    F = _fisher_batch(aq[None], v[None], sm2)[0]
    G = np.diff(aq, axis=0)
    return max(np.trace(F) / 4, 1e-300), max(np.trace(G.T @ G) / 4, 1e-300)


def continuous_design(robot, K, criterion="crlb", cons: Constraints | None = None, noise=None, seed=0,
                      n_starts: int = 8, starts=None, max_iter: int = 500):
    """Multi-start Ipopt over the K poses.

    Parameters
    ----------
    robot : Robot
    K : int
    criterion : {"cond", "D", "A", "E", "crlb"}
    cons : Constraints, optional
    noise : NoiseModel, optional
        Default: the paper's (scale and servo errors).
    seed : int
        Seed of the random starts.
    n_starts : int
        Number of random starts.
    starts : list of (label, ndarray shape (K, 2)), optional
        Extra starts (e.g. the paper's scheme, an exchange design).

    Returns
    -------
    dict
        ``poses`` (K, 2) of the best feasible local optimum, ``objective``,
        ``value`` (user units), ``runs`` (label, value, status, iterations,
        feasible, time per start), ``time_s``, ``build_s``.
    """
    t0 = time.perf_counter()
    cons = cons or make_constraints(robot)
    _check_k(K)
    _check_criterion(criterion)
    rng = np.random.default_rng(seed)
    all_starts = list(starts or [])
    for i in range(n_starts):
        P0 = _random_start(robot, K, cons, rng)
        if P0 is not None:
            all_starts.append((f"random {i}", P0))
    if not all_starts:
        raise DesignError("could not find a feasible random start: the constraints leave (almost) no room")
    ref = next((P for _, P in all_starts if np.isfinite(_objective_batch(
        "D", *_terms_batch(robot, P, noise), _noise_terms(noise)[0], _qscale(robot))[0])), all_starts[0][1])
    fscale, mscale = _scales(robot, ref, noise)
    nlp = _NLP(robot, K, criterion, cons, noise, fscale, mscale, max_iter)
    build_s = time.perf_counter() - t0
    best, runs = None, []
    sm2 = _noise_terms(noise)[0]
    qs = _qscale(robot)
    for label, P0 in all_starts:
        ts = time.perf_counter()
        P, status, iters = nlp.solve(P0)
        viol = check_design(robot, P, cons)
        o = float(_objective_batch(criterion, *_terms_batch(robot, P, noise), sm2, qs)[0])
        runs.append({"start": label, "value": _user_value(criterion, o), "status": status, "iterations": iters,
                     "feasible": not viol, "time_s": time.perf_counter() - ts})
        if not viol and np.isfinite(o) and (best is None or o < best[1]):
            best = (P, o)
    if best is None:
        raise DesignError("no Ipopt start ended at a feasible design; statuses: "
                          + ", ".join(sorted({r["status"] for r in runs})))
    return {"poses": best[0], "objective": best[1], "value": _user_value(criterion, best[1]), "runs": runs,
            "time_s": time.perf_counter() - t0, "build_s": build_s, "nlp": nlp}


def _terms_batch(robot, P, noise):
    _, sx2 = _noise_terms(noise)
    t = pose_terms(robot, P)
    return (t["a"] * _qscale(robot))[None], (sx2 * np.sum(t["dth"] ** 2, axis=1))[None]


def _objective(robot, criterion, P, noise):
    return float(_objective_batch(criterion, *_terms_batch(robot, P, noise), _noise_terms(noise)[0],
                                  _qscale(robot))[0])


# --------------------------------------------------------------------------- driver
@dataclass
class DesignResult:
    """An optimised design and its baseline.

    Attributes
    ----------
    poses : ndarray, shape (K, 2)
        mm, in visiting order.
    criterion : str
    report : dict
        :func:`evaluate` of the design.
    paper : dict
        :func:`evaluate` of the paper's scheme with the same K.
    constraints : Constraints
    exchange : dict
        The discrete exchange's best (poses, value, starts, time).
    continuous : dict
        The Ipopt multi-start (value, runs, time) before ordering and polish.
    method : str
        Which method gave the final design.
    timing : dict
        Seconds per stage.
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

    def to_dict(self) -> dict:
        """JSON-ready report (non-finite numbers as None)."""
        return json_safe(self._dict())

    def _dict(self) -> dict:
        rep = dict(self.report)
        rep.update({
            "K": len(self.poses),
            "method": self.method,
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
                    exchange_starts: int = 8, grid=(25, 11), reorder: bool = True) -> DesignResult:
    """Optimal measurement poses for a criterion, with the paper's scheme as baseline.

    Stages: discrete exchange (``exchange_starts`` seeded starts over the
    candidate grid); Ipopt multi-start from the paper's scheme (if feasible)
    and ``n_starts`` seeded random feasible designs; the better of the two,
    re-ordered (:func:`best_order`) and, if re-ordered, polished by Ipopt
    from the exchange design as well; the best feasible design wins.

    Parameters
    ----------
    robot : Robot
    K : int
        Number of poses (>= 5).
    criterion : {"cond", "D", "A", "E", "crlb"}
    cons : Constraints, optional
        Default :func:`make_constraints` (workspace, l0 = 350 mm range,
        the robot's margin, no joint limits).
    noise : NoiseModel, optional
        Default the paper's.
    seed : int
    n_starts, exchange_starts : int
    grid : (int, int)
        Candidate grid of the exchange.

    Returns
    -------
    DesignResult
    """
    _check_k(K)
    _check_criterion(criterion)
    noise = noise or NoiseModel.paper()
    _noise_terms(noise)
    cons = cons or make_constraints(robot)
    timing = {}
    t0 = time.perf_counter()
    ex = exchange_design(robot, K, criterion, cons, noise, seed, exchange_starts, grid)
    timing["exchange"] = time.perf_counter() - t0
    base = paper_baseline(robot, K, cons.region)
    starts = [("paper scheme", base)] if not check_design(robot, base, cons) else []
    t1 = time.perf_counter()
    cont = continuous_design(robot, K, criterion, cons, noise, seed, n_starts, starts)
    timing["continuous"] = time.perf_counter() - t1
    nlp = cont.pop("nlp")
    cands = [("continuous", cont["poses"], cont["objective"]), ("exchange", ex["poses"], ex["objective"])]
    t2 = time.perf_counter()
    polished = []
    for label, P, o in cands:
        if reorder:
            order, _ = best_order(robot, P, criterion, noise, cons)
            if np.any(order != np.arange(K)):
                P = P[order]
                label = label + " +order"
        Pp, status, _ = nlp.solve(P)
        op = _objective(robot, criterion, Pp, noise)
        if not check_design(robot, Pp, cons) and op <= _objective(robot, criterion, P, noise):
            polished.append((label + " +ipopt", Pp, op))
        else:
            polished.append((label, P, _objective(robot, criterion, P, noise)))
    timing["order_polish"] = time.perf_counter() - t2
    polished = [c for c in polished if not check_design(robot, c[1], cons)]
    if not polished:
        raise DesignError("neither method produced a design that meets the constraints")
    label, P, _ = min(polished, key=lambda c: c[2])
    timing["total"] = time.perf_counter() - t0
    return DesignResult(poses=P, criterion=criterion, report=evaluate(robot, P, criterion, noise, cons),
                        paper=evaluate(robot, base, criterion, noise, cons), constraints=cons, exchange=ex,
                        continuous=cont, method=label, timing=timing, noise=noise)


# --------------------------------------------------------------------------- verification
def verify_design(robot, P, n_trials: int, noise: NoiseModel | None = None, err_true=None, seed: int = 0) -> dict:
    """Monte Carlo check of a design's CRLB with the Ipopt estimator.

    Each trial simulates the K scale readings of the virtual plant
    (:class:`~zerocal_sym.model.noise.VirtualPlant`) with fresh noise and
    identifies the paper's four parameters with
    :func:`zerocal_sym.identify.nlls.identify_nlls` (same noise model for weighting).

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses in visiting order, mm (commanded by nominal inverse kinematics).
    n_trials : int
    noise : NoiseModel, optional
        Default the paper's.
    err_true : ndarray, shape (12,), optional
        True source errors; default Table 2 group 1 without geometric errors
        (zero offsets 2 and -1 deg, MAEMM (1, 0.5) mm), so that the four
        identified parameters are the whole truth and the CRLB applies.
    seed : int

    Returns
    -------
    dict
        ``rms_error_deg`` (2,) per offset and ``rms_error_rms_deg`` (over
        both), ``mean_error_deg`` (2,), ``crlb_at_truth_deg`` (2,) and its
        RMS, ``n_trials``, ``n_failed`` (Ipopt not converged, excluded),
        ``time_s``.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.io.measurements import Measurements
    from zerocal_sym.model.noise import VirtualPlant, table2_errors
    from zerocal_sym.identify.nlls import identify_nlls

    if isinstance(n_trials, bool) or not isinstance(n_trials, (int, np.integer)) or n_trials < 1:
        raise DesignError(f"the number of Monte Carlo trials must be a positive integer, got {n_trials!r}")
    t0 = time.perf_counter()
    noise = noise or NoiseModel.paper()
    err = table2_errors(1, geometric=False) if err_true is None else np.asarray(err_true, float)
    theta = kin.ik(robot, np.asarray(P, float))
    plant = VirtualPlant(robot, err)
    rng = np.random.default_rng(seed)
    E, failed = [], 0
    for _ in range(n_trials):
        res = identify_nlls(robot, Measurements(theta, plant.measure(theta, noise, rng)), "paper", noise=noise)
        if not res.success:
            failed += 1
            continue
        E.append([res.value("theta1") - err[0], res.value("theta2") - err[1]])
    E = np.degrees(np.array(E).reshape(-1, 2))
    crlb = fisher.crlb_zero_offsets_deg(robot, theta, "paper", noise, err0=err)
    return {"n_trials": int(n_trials), "n_failed": failed,
            "rms_error_deg": np.sqrt(np.mean(E ** 2, axis=0)).tolist() if len(E) else [math.nan] * 2,
            "rms_error_rms_deg": float(np.sqrt(np.mean(E ** 2))) if len(E) else math.nan,
            "mean_error_deg": E.mean(axis=0).tolist() if len(E) else [math.nan] * 2,
            "crlb_at_truth_deg": crlb.tolist(), "crlb_at_truth_rms_deg": float(np.sqrt(np.mean(crlb ** 2))),
            "true_errors": {"zero_offsets_deg": np.degrees(err[:2]).tolist(), "maemm_mm": err[10:12].tolist(),
                            "geometric_mm": err[2:10].tolist()},
            "time_s": time.perf_counter() - t0}


# --------------------------------------------------------------------------- plot
def plot_design(path, robot, result: DesignResult) -> None:
    """PNG of the design and the paper's scheme in the workspace (atomic write).

    Shows the workspace and design region, the area excluded by the
    singularity margin (if any), the design poses numbered in visiting order
    with the path between them, and the paper's scheme with the same K.
    """
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from zerocal_sym.io.files import atomic_write_bytes

    cons = result.constraints
    ws = Region.workspace(robot)
    reg = cons.region
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    try:
        lo = np.minimum(ws.lo, reg.lo) - 20
        hi = np.maximum(ws.hi, reg.hi) + 20
        box = Region(lo[0], hi[0], lo[1], hi[1])
        grid = box.grid(97, 49)
        th, ratio = _call_ik(robot, grid)
        smin = np.full(len(grid), np.nan)
        okr = np.all(np.abs(ratio) < 1, axis=1)
        if np.any(okr):
            smin[okr] = np.min(np.abs(pose_terms(robot, grid[okr])["s"]), axis=1)
        Z = smin.reshape(49, 97)
        X, Y = grid[:, 0].reshape(49, 97), grid[:, 1].reshape(49, 97)
        if np.nanmin(Z) < cons.singularity_margin:
            ax.contourf(X, Y, Z, levels=[0, cons.singularity_margin], colors=["#f4c7c3"])
            ax.contour(X, Y, Z, levels=[cons.singularity_margin], colors=["#c0392b"], linewidths=0.8)
        ax.add_patch(plt.Rectangle(ws.lo, *(ws.hi - ws.lo), fill=False, ec="k", lw=1.2, label="workspace"))
        if reg != ws:
            ax.add_patch(plt.Rectangle(reg.lo, *(reg.hi - reg.lo), fill=False, ec="tab:green", ls="--", lw=1.2,
                                       label="design region"))
        Pp = np.asarray(result.paper["poses"])
        ax.plot(Pp[:, 0], Pp[:, 1], "s", mfc="none", mec="tab:gray", ms=10,
                label=f"paper's scheme (CRLB {result.paper['crlb_rms_deg']:.3f} deg)")
        P = result.poses
        ax.plot(P[:, 0], P[:, 1], "-", color="tab:blue", lw=0.6, alpha=0.6)
        ax.plot(P[:, 0], P[:, 1], "o", color="tab:blue",
                label=f"{result.criterion}-optimal (CRLB {result.report['crlb_rms_deg']:.3f} deg)")
        for k, p in enumerate(P):
            ax.annotate(str(k + 1), p, textcoords="offset points", xytext=(4, 4 + 8 * (k % 2)), fontsize=8,
                        color="tab:blue")
        ax.set_aspect("equal")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ratio = result.to_dict()["ratio"]["crlb_rms_design_over_paper"]
        ax.set_title(f"K = {len(P)}, criterion {result.criterion}; CRLB ratio design/paper "
                     f"{'-' if ratio is None else format(ratio, '.3f')}", fontsize=10)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=120)
    finally:
        plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())
