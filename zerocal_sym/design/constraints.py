"""Constraints of a measurement-pose design, their validation and feasibility checks.

Constraints
-----------
* region: the robot's workspace shape (default the workspace itself), every
  pose inside -- a :class:`~zerocal_sym.design.shapes.Region` (axis-aligned
  rectangle ``XMIN XMAX YMIN YMAX``) for a rectangular workspace, a
  :class:`~zerocal_sym.design.shapes.CylinderRegion` (coaxial cylinder
  ``RW ZMIN ZMAX``: ``x^2 + y^2 <= RW^2``, ``z in [ZMIN, ZMAX]``) for a
  cylindrical one (or the reachable set, :mod:`zerocal_sym.design.regions`);
* scale travel ``l0`` (default 350 mm, the paper's scale range): the reading
  head is zeroed after each measurement but it is physically attached to the
  mechanism, so its position along the scale is ``rho`` (up to a constant);
  all K lengths must fit on the scale: ``max rho - min rho <= l0``
  (``travel_mode="range"``, default).  ``travel_mode="consecutive"``
  instead bounds ``|rho_{k+1} - rho_k| <= l0`` (a head re-clamped between
  measurements);
* singularity margin: every ``|sin|`` of a transmission angle (every
  singularity indicator of the mechanism) at least ``singularity_margin``
  (default: the robot's, 0.2);
* optional joint limits (deg) on the inverse-kinematics angles, one
  ``(lo, hi)`` per joint, shape (m, 2);
* distinct poses: pairwise distance at least ``min_separation_mm`` (default
  1 mm; the data loader rejects repeated poses).

This module holds :class:`Constraints`, :func:`make_constraints` and the
feasibility checks (:func:`check_design`, per pose, of the travel); the
regions are in :mod:`zerocal_sym.design.shapes`, the bounds on K, the
defaults and :class:`~zerocal_sym.design.limits.DesignError` in
:mod:`zerocal_sym.design.limits`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.kinematics import fmt_pose
from zerocal_sym.design.terms import _call_ik, _reachable, pose_terms
from zerocal_sym.design.limits import SCALE_RANGE_MM, TRAVEL_MODES, _FEAS_TOL, DesignError, _finite
from zerocal_sym.design.shapes import make_region

#: tolerance of the pointwise checks (poses computed on a rim, rw cos t, may be 1e-13 mm outside)
_POINT_TOL = 1e-9


@dataclass(frozen=True)
class Constraints:
    """What a design must respect (see the module docstring).

    Attributes
    ----------
    region : Region or CylinderRegion
    travel_mm : float
        Scale range ``l0``, mm.
    travel_mode : {"range", "consecutive"}
    singularity_margin : float
        Lower bound on every ``|sin|`` of a transmission angle.
    joint_limits_deg : tuple of m (lo, hi) pairs or None
        Limits of the joints in the mechanism's order, deg.
    min_separation_mm : float
        Lower bound on the distance between any two poses, mm.
    mode_signs : tuple of float or None
        For a reachable region: the signs of the singularity indicators at
        home; the margin is then signed (``sign_i s_i >= margin``) and the
        forward kinematics must return the pose.
    """

    region: object
    travel_mm: float = SCALE_RANGE_MM
    travel_mode: str = "range"
    singularity_margin: float = 0.2
    joint_limits_deg: tuple | None = None
    min_separation_mm: float = 1.0
    mode_signs: tuple | None = None

    def to_dict(self):
        clip = getattr(self.region, "clip", None)
        return {"region_kind": self.region.kind, "region_mm": self.region.as_list(),
                "region_clip": None if clip is None else clip.kind,
                "region": self.region.describe(), "travel_mm": self.travel_mm, "travel_mode": self.travel_mode,
                "singularity_margin": self.singularity_margin,
                "joint_limits_deg": None if self.joint_limits_deg is None else [list(j) for j in self.joint_limits_deg],
                "min_separation_mm": self.min_separation_mm}



def make_constraints(robot, region=None, travel_mm=SCALE_RANGE_MM, travel_mode="range",
                     singularity_margin=None, joint_limits_deg=None, min_separation_mm=1.0,
                     bounds=None) -> Constraints:
    """Validated :class:`Constraints`.

    Parameters
    ----------
    robot : Robot
    region : Region, CylinderRegion, sequence of numbers in mm, "reachable", ("polygon", ...), optional
        ``(XMIN, XMAX, YMIN, YMAX)`` for a rectangular workspace,
        ``(RW, ZMIN, ZMAX)`` for a cylindrical one (:func:`make_region`).
        Default: the robot's workspace.  It must be reachable everywhere (a
        grid is checked: inverse kinematics defined and consistent with
        forward kinematics, i.e. one assembly mode).  ``"reachable"`` (with
        ``bounds``) and a polygon are the reachable non-singular set, clipped
        (:mod:`zerocal_sym.design.regions`).
    bounds : sequence of numbers, optional
        The clip of ``"reachable"``.
    travel_mm : float
    travel_mode : {"range", "consecutive"}
    singularity_margin : float, optional
        Default ``robot.singularity_margin``.
    joint_limits_deg : sequence of m (lo, hi) pairs, deg, optional
    min_separation_mm : float

    Raises
    ------
    DesignError
        With a message saying what is wrong.
    """
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
        m = robot.m
        try:
            jl = np.asarray(joint_limits_deg, dtype=float)
        except (TypeError, ValueError):
            jl = None
        if jl is None or jl.shape != (m, 2) or not np.all(np.isfinite(jl)):
            pairs = ", ".join(f"(lo{i + 1}, hi{i + 1})" for i in range(m))
            raise DesignError(f"joint limits must be ({pairs}) in degrees, finite, one pair per joint "
                              f"({', '.join(robot.mechanism.joint_names)})")
        if np.any(jl[:, 0] >= jl[:, 1]):
            raise DesignError(f"joint limits need lo < hi, got {jl.tolist()} deg")
        joint_limits_deg = tuple(tuple(float(v) for v in row) for row in jl)
    min_sep = _finite("minimum pose separation", min_separation_mm)
    if min_sep < 0:
        raise DesignError(f"minimum pose separation must be >= 0 mm, got {min_sep:g}")
    region = make_region(robot, region, bounds, margin, joint_limits_deg)
    signs = None
    if region.kind == "reachable":
        from zerocal_sym.design.regions import mode_signs

        signs = tuple(float(v) for v in mode_signs(robot))
    cons = Constraints(region, travel_mm, travel_mode, margin, joint_limits_deg, min_sep, signs)
    if signs is None:
        _check_region_reachable(robot, region)
    return cons


def _check_region_reachable(robot, region):
    grid = region.reach_grid()
    th, ratio = _call_ik(robot, grid)
    bad = np.flatnonzero(~_reachable(ratio, th))
    ws = f"the robot's workspace is {robot.workspace.describe()} mm"
    if bad.size:
        raise DesignError(f"region {region.describe()} mm is not reachable: {fmt_pose(grid[bad[0]])} mm cannot "
                          f"be reached ({bad.size} of {len(grid)} grid points unreachable); {ws}")
    back = kin.fk(robot, th)
    off = np.flatnonzero(~(np.linalg.norm(back - grid, axis=1) < 1e-6))
    if off.size:
        raise DesignError(f"region crosses an assembly-mode change at {fmt_pose(grid[off[0]])} mm "
                          f"(forward and inverse kinematics disagree there); {ws}")


def check_design(robot, P, cons: Constraints, tol: float = _FEAS_TOL) -> list:
    """Constraint violations of a design (empty list: feasible).

    Parameters
    ----------
    P : ndarray, shape (K, n)
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
    inside = r.contains(P, tol)
    for k in np.flatnonzero(~inside):
        out.append(f"pose {k} {fmt_pose(np.round(P[k], 3))} mm is outside the region {r.describe()}")
    th, ratio = _call_ik(robot, P)
    unreach = ~_reachable(ratio, th)
    for k in np.flatnonzero(unreach):
        out.append(f"pose {k} {fmt_pose(np.round(P[k], 3))} mm is unreachable")
    if np.any(unreach):
        return out
    t = pose_terms(robot, P)
    if cons.mode_signs is None:
        smin = np.min(np.abs(t["s"]), axis=1)
        for k in np.flatnonzero(smin < cons.singularity_margin - tol):
            out.append(f"pose {k}: min |sin transmission angle| {smin[k]:.4f} < margin {cons.singularity_margin:g}")
    else:
        smin = np.min(t["s"] * np.asarray(cons.mode_signs), axis=1)
        for k in np.flatnonzero(smin < cons.singularity_margin - tol):
            out.append(f"pose {k}: min signed sin transmission angle {smin[k]:.4f} < margin "
                       f"{cons.singularity_margin:g} (the home pose's modes)")
        back = kin.fk(robot, t["theta"])
        for k in np.flatnonzero(~(np.linalg.norm(back - P, axis=1) < 1e-6)):
            out.append(f"pose {k} {fmt_pose(np.round(P[k], 3))} mm: forward kinematics gives another assembly "
                       "mode")
    if cons.joint_limits_deg is not None:
        jl = np.asarray(cons.joint_limits_deg)
        deg = np.degrees(t["theta"])
        names = robot.mechanism.joint_names
        for k in range(len(P)):
            for i, name in enumerate(names):
                if deg[k, i] < jl[i, 0] - tol or deg[k, i] > jl[i, 1] + tol:
                    out.append(f"pose {k}: {name} = {deg[k, i]:.4f} deg outside [{jl[i, 0]:g}, {jl[i, 1]:g}]")
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
    if cons.mode_signs is not None:
        from zerocal_sym.design.regions import _feasible

        ok = cons.region.contains(P, _POINT_TOL)
        if np.any(ok):
            jl = None if cons.joint_limits_deg is None else np.radians(np.asarray(cons.joint_limits_deg))
            ok[np.flatnonzero(ok)] = _feasible(robot, P[ok], cons.singularity_margin, jl,
                                               np.asarray(cons.mode_signs))
        return ok
    th, ratio = _call_ik(robot, P)
    ok = _reachable(ratio, th, 1e-9) & cons.region.contains(P, _POINT_TOL)
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
