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
* optional joint limits on the inverse-kinematics joints, in the joints'
  file unit (deg for revolute joints, mm for prismatic ones), one
  ``(lo, hi)`` per joint, shape (m, 2);
* distinct poses: pairwise distance at least ``min_separation_mm`` (default
  1 mm) between distinct poses; a pose may be visited again (a *replicate*,
  equal to :data:`~zerocal_sym.model.revisits.REVISIT_TOL`), never twice in a
  row (a zero change); for a pose with orientations a degree counts as a
  millimetre (:func:`zerocal_sym.design.terms.pose_distances`).

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
from zerocal_sym.model import units
from zerocal_sym.model.kinematics import fmt_user_pose
from zerocal_sym.design.calls import fk
from zerocal_sym.design.feasible import _pointwise
from zerocal_sym.design.terms import (_call_ik, _reachable, pose_distances, pose_terms, pose_units, poses_from_user,
                                      poses_to_user)
from zerocal_sym.design.limits import SCALE_RANGE_MM, TRAVEL_MODES, _FEAS_TOL, DesignError, _finite
from zerocal_sym.design.shapes import make_region

#: tolerance of the pointwise checks (poses computed on a rim, rw cos t, may be 1e-13 mm outside)
_POINT_TOL = 1e-9


def _fp(robot, p) -> str:
    """A pose for messages, file units rounded to 3 decimals, with its unit (``(x, y) mm``)."""
    return fmt_user_pose(robot, poses_from_user(robot, np.round(poses_to_user(robot, p), 3)))


def region_text(region) -> str:
    """A region's description with its unit (``... mm``; a box of mixed units names its own)."""
    u = getattr(region, "units", None)
    return region.describe() + ("" if u is not None and set(u) != {"mm"} else " mm")


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
    joint_limits : tuple of m (lo, hi) pairs or None
        Limits of the joints in the mechanism's order, in the joints' file unit ``joint_unit``.
    min_separation_mm : float
        Lower bound on the distance between any two poses, mm.
    mode_signs : tuple of float or None
        For a reachable region: the signs of the singularity indicators at
        home; the margin is then signed (``sign_i s_i >= margin``) and the
        forward kinematics must return the pose.
    joint_unit : {"deg", "mm"}
        The joints' file unit (of ``joint_limits``).
    """

    region: object
    travel_mm: float = SCALE_RANGE_MM
    travel_mode: str = "range"
    singularity_margin: float = 0.2
    joint_limits: tuple | None = None
    min_separation_mm: float = 1.0
    mode_signs: tuple | None = None
    joint_unit: str = "deg"

    @property
    def joint_limits_deg(self):
        """The joint limits of revolute joints, deg (their former name; None for prismatic joints)."""
        return self.joint_limits if self.joint_unit == "deg" else None

    def joint_limits_internal(self):
        """The joint limits in internal units (rad, mm), ndarray shape (m, 2), or None."""
        if self.joint_limits is None:
            return None
        from zerocal_sym.model.units import from_user

        return from_user(np.asarray(self.joint_limits, float), "rad" if self.joint_unit == "deg" else "mm")

    def to_dict(self):
        clip = getattr(self.region, "clip", None)
        units_ = getattr(self.region, "units", None)
        values = ({"region_mm": self.region.as_list()} if units_ is None or set(units_) == {"mm"}
                  else {"region_values": self.region.as_list(), "region_units": list(units_)})
        return {"region_kind": self.region.kind, **values,
                "region_clip": None if clip is None else clip.kind,
                "region": self.region.describe(), "travel_mm": self.travel_mm, "travel_mode": self.travel_mode,
                "singularity_margin": self.singularity_margin,
                f"joint_limits_{self.joint_unit}": None if self.joint_limits is None
                else [list(j) for j in self.joint_limits],
                "min_separation_mm": self.min_separation_mm}



def make_constraints(robot, region=None, travel_mm=SCALE_RANGE_MM, travel_mode="range",
                     singularity_margin=None, joint_limits_deg=None, min_separation_mm=1.0,
                     bounds=None, joint_limits=None) -> Constraints:
    """Validated :class:`Constraints`.

    Parameters
    ----------
    robot : Robot
    region : Region, CylinderRegion, BoxRegion, sequence of numbers, "reachable", ("polygon", ...), optional
        ``(XMIN, XMAX, YMIN, YMAX)`` (mm) for a rectangular workspace,
        ``(RW, ZMIN, ZMAX)`` (mm) for a cylindrical one, ``(X_MIN, X_MAX, ...,
        YAW_MIN, YAW_MAX)`` (mm, deg for orientations) for a box (:func:`make_region`).
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
    joint_limits : sequence of m (lo, hi) pairs, optional
        In the joints' file unit: deg for revolute joints, mm for prismatic ones.
    joint_limits_deg : sequence of m (lo, hi) pairs, optional
        The same for revolute joints (its former name); for prismatic joints an error naming ``joint_limits``.
    min_separation_mm : float
        mm; for a pose with orientations a degree counts as a mm.

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
    ju = units.joint_unit(robot)
    if joint_limits_deg is not None:
        if ju != "deg":
            raise DesignError(f"joint limits in degrees do not fit robot {robot.name!r}: its joints "
                              f"{', '.join(robot.mechanism.joint_names)} are prismatic: give joint_limits in mm")
        if joint_limits is not None:
            raise DesignError("joint limits given twice (joint_limits and joint_limits_deg)")
        joint_limits = joint_limits_deg
    if joint_limits is not None:
        m = robot.m
        try:
            jl = np.asarray(joint_limits, dtype=float)
        except (TypeError, ValueError):
            jl = None
        if jl is None or jl.shape != (m, 2) or not np.all(np.isfinite(jl)):
            pairs = ", ".join(f"(lo{i + 1}, hi{i + 1})" for i in range(m))
            what = "degrees" if ju == "deg" else "mm"
            raise DesignError(f"joint limits must be ({pairs}) in {what}, finite, one pair per joint "
                              f"({', '.join(robot.mechanism.joint_names)})")
        if np.any(jl[:, 0] >= jl[:, 1]):
            raise DesignError(f"joint limits need lo < hi, got {jl.tolist()} {ju}")
        joint_limits = tuple(tuple(float(v) for v in row) for row in jl)
    min_sep = _finite("minimum pose separation", min_separation_mm)
    if min_sep < 0:
        raise DesignError(f"minimum pose separation must be >= 0 mm, got {min_sep:g}")
    jl_int = None if joint_limits is None else units.joints_from_user(robot, np.asarray(joint_limits, float))
    region = make_region(robot, region, bounds, margin, jl_int)
    signs = None
    if region.kind == "reachable":
        from zerocal_sym.design.regions import mode_signs

        signs = tuple(float(v) for v in mode_signs(robot))
    cons = Constraints(region, travel_mm, travel_mode, margin, joint_limits, min_sep, signs, ju)
    if signs is None:
        _check_region_reachable(robot, region)
    return cons


def _check_region_reachable(robot, region):
    grid = region.reach_grid()
    th, ratio = _call_ik(robot, grid)
    bad = np.flatnonzero(~_reachable(ratio, th))
    mm = set(pose_units(robot)) == {"mm"}
    ws = f"the robot's workspace is {robot.workspace.describe()}{' mm' if mm else ''}"
    if bad.size:
        raise DesignError(f"region {region_text(region)} is not reachable: {_fp(robot, grid[bad[0]])} cannot "
                          f"be reached ({bad.size} of {len(grid)} grid points unreachable); {ws}")
    back = kin.fk(robot, th)
    off = np.flatnonzero(~(np.linalg.norm(back - grid, axis=1) < 1e-6))
    if off.size:
        raise DesignError(f"region crosses an assembly-mode change at {_fp(robot, grid[off[0]])} "
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
        out.append(f"pose {k} {_fp(robot, P[k])} is outside the region {r.describe()}")
    t = pose_terms(robot, P)
    unreach = ~_reachable(t["ratio"], t["theta"])
    for k in np.flatnonzero(unreach):
        out.append(f"pose {k} {_fp(robot, P[k])} is unreachable")
    if np.any(unreach):
        return out
    if cons.mode_signs is None:
        smin = np.min(np.abs(t["s"]), axis=1)
        for k in np.flatnonzero(smin < cons.singularity_margin - tol):
            out.append(f"pose {k}: min |sin transmission angle| {smin[k]:.4f} < margin {cons.singularity_margin:g}")
    else:
        smin = np.min(t["s"] * np.asarray(cons.mode_signs), axis=1)
        for k in np.flatnonzero(smin < cons.singularity_margin - tol):
            out.append(f"pose {k}: min signed sin transmission angle {smin[k]:.4f} < margin "
                       f"{cons.singularity_margin:g} (the home pose's modes)")
        back = fk(robot, t["theta"])
        for k in np.flatnonzero(~(np.linalg.norm(back - P, axis=1) < 1e-6)):
            out.append(f"pose {k} {_fp(robot, P[k])}: forward kinematics gives another assembly "
                       "mode")
    if cons.joint_limits is not None:
        jl = np.asarray(cons.joint_limits)
        ju = cons.joint_unit
        val = units.joints_to_user(robot, t["theta"])
        names = robot.mechanism.joint_names
        for k in range(len(P)):
            for i, name in enumerate(names):
                if val[k, i] < jl[i, 0] - tol or val[k, i] > jl[i, 1] + tol:
                    out.append(f"pose {k}: {name} = {val[k, i]:.4f} {ju} outside [{jl[i, 0]:g}, {jl[i, 1]:g}]")
    rho = t["rho"]
    if cons.travel_mode == "range":
        if np.ptp(rho) > cons.travel_mm + tol:
            out.append(f"scale travel: rho spans {np.ptp(rho):.3f} mm > l0 = {cons.travel_mm:g} mm")
    else:
        d = np.abs(np.diff(rho))
        for k in np.flatnonzero(d > cons.travel_mm + tol):
            out.append(f"scale travel: |rho_{k + 1} - rho_{k}| = {d[k]:.3f} mm > l0 = {cons.travel_mm:g} mm")
    if len(P) > 1:
        from zerocal_sym.model.revisits import REVISIT_TOL, consecutive_repeat, pose_groups

        U = poses_to_user(robot, P)
        k = consecutive_repeat(U, REVISIT_TOL)
        if k is not None:
            out.append(f"pose {k} repeats pose {k - 1} (a zero change: no information)")
        if cons.min_separation_mm > 0:  # between distinct poses (a replicate is the same pose again)
            lab = pose_groups(U, REVISIT_TOL)
            first = np.unique(lab, return_index=True)[1]
            dist = pose_distances(robot, P[first])
            iu = np.triu_indices(len(first), 1)
            close = np.flatnonzero(dist[iu] < cons.min_separation_mm - tol)
            for c in close:
                out.append(f"poses {first[iu[0][c]]} and {first[iu[1][c]]} are {dist[iu][c]:.3f} mm apart "
                           f"< {cons.min_separation_mm:g} mm")
    return out


def _pointwise_ok(robot, P, cons: Constraints):
    """Per-pose feasibility (region, reach, margin, joint limits), bool shape (K,)."""
    return _pointwise(robot, P, cons)[0]


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
