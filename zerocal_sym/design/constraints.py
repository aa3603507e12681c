"""Constraints of a measurement-pose design, their validation and feasibility checks.

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
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import ZerocalError
from zerocal_sym.design.terms import _call_ik, pose_terms

MIN_K = 5
#: largest K accepted (design time grows roughly as K^2: ~15 s at K = 40 with 3 starts)
MAX_K = 100
#: the paper's scale range l0, mm
SCALE_RANGE_MM = 350.0
TRAVEL_MODES = ("range", "consecutive")
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


def _check_k(K):
    if isinstance(K, bool) or not isinstance(K, (int, np.integer)):
        raise DesignError(f"K must be an integer number of poses, got {K!r}")
    if K < MIN_K:
        raise DesignError(f"K = {K} is too small: at least {MIN_K} poses are needed to identify the 4 "
                          "parameters (K - 1 >= 4 measured changes)")
    if K > MAX_K:
        raise DesignError(f"K = {K} is too large (at most {MAX_K})")
