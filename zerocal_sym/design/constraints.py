"""Constraints of a measurement-pose design, their validation and feasibility checks.

Constraints
-----------
* region: the robot's workspace shape (default the workspace itself), every
  pose inside -- a :class:`Region` (axis-aligned rectangle ``XMIN XMAX YMIN
  YMAX``) for a rectangular workspace, a :class:`CylinderRegion` (coaxial
  cylinder ``RW ZMIN ZMAX``: ``x^2 + y^2 <= RW^2``, ``z in [ZMIN, ZMAX]``) for
  a cylindrical one;
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
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.kinematics import fmt_pose
from zerocal_sym.errors import ZerocalError
from zerocal_sym.design.terms import _call_ik, _reachable, design_params, pose_terms

#: smallest K for the planar robot (p = 4 parameters; in general p + 1, see :func:`min_k`)
MIN_K = 5
#: largest K accepted (the approximate design; K = 1000 takes seconds)
MAX_K = 5000
#: largest K of the exact method (exchange + Ipopt: time grows roughly as K^2, ~15 s at K = 40 with 3 starts,
#: 1207 s at K = 100 with the default 8 + 8 starts)
MAX_K_EXACT = 100
#: the paper's scale range l0, mm
SCALE_RANGE_MM = 350.0
TRAVEL_MODES = ("range", "consecutive")
_FEAS_TOL = 1e-6
#: tolerance of the pointwise checks (poses computed on a rim, rw cos t, may be 1e-13 mm outside)
_POINT_TOL = 1e-9


class DesignError(ZerocalError):
    """A design request that cannot be met (bad K, region, criterion, constraints)."""


# --------------------------------------------------------------------------- regions
@dataclass(frozen=True)
class Region:
    """Axis-aligned design region of a rectangular workspace, mm: ``x in [xmin, xmax]``, ``y in [ymin, ymax]``."""

    xmin: float
    xmax: float
    ymin: float
    ymax: float
    kind = "rectangle"
    n = 2
    #: the numbers a user gives (``--region``)
    arg_names = ("XMIN", "XMAX", "YMIN", "YMAX")
    #: default candidate grid of the exchange (nx, ny)
    default_grid = (25, 11)

    @classmethod
    def workspace(cls, robot):
        """The robot's workspace as a design region (a :class:`CylinderRegion` for a cylinder)."""
        return workspace_region(robot)

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
        """Centre of the bounding box, shape (n,)."""
        return (self.lo + self.hi) / 2

    @property
    def half(self):
        """Half sizes of the bounding box, shape (n,)."""
        return (self.hi - self.lo) / 2

    def grid(self, nx: int, ny: int):
        """Grid over the region, ndarray shape (nx*ny, 2), row-major in y."""
        X, Y = np.meshgrid(np.linspace(self.xmin, self.xmax, nx), np.linspace(self.ymin, self.ymax, ny))
        return np.column_stack([X.ravel(), Y.ravel()])

    def reach_grid(self):
        """Points checked for reachability (21 x 21 grid), shape (N, 2)."""
        return self.grid(21, 21)

    def contains(self, P, tol: float = _FEAS_TOL) -> np.ndarray:
        """Bool per pose, shape (K,)."""
        P = np.atleast_2d(P)
        return np.all((P >= self.lo - tol) & (P <= self.hi + tol), axis=1)

    def sample(self, rng, N: int) -> np.ndarray:
        """N uniform random points in the region, shape (N, 2)."""
        return self.lo + rng.uniform(size=(N, 2)) * (self.hi - self.lo)

    def boundary_scheme(self, n1: int, n2: int | None = None) -> np.ndarray:
        """The paper's rule on the region's edges: n1 poses on ``y = ymin`` then n2 on ``y = ymax``.

        Each edge from ``xmin`` to ``xmax``, evenly spaced (``n2 = n1``: the
        paper's scheme, :meth:`zerocal_sym.model.workspace.Rectangle.boundary_scheme`).

        Returns
        -------
        ndarray, shape (n1 + n2, 2)
        """
        n2 = n1 if n2 is None else n2
        return np.vstack([np.column_stack([np.linspace(self.xmin, self.xmax, n1), np.full(n1, self.ymin)]),
                          np.column_stack([np.linspace(self.xmin, self.xmax, n2), np.full(n2, self.ymax)])])

    def describe(self) -> str:
        return f"x in [{self.xmin:g}, {self.xmax:g}], y in [{self.ymin:g}, {self.ymax:g}]"

    def as_list(self):
        return [self.xmin, self.xmax, self.ymin, self.ymax]

    def _check(self):
        if not self.xmax - self.xmin >= 1.0 or not self.ymax - self.ymin >= 1.0:
            raise DesignError(f"region {self.describe()} mm is empty or thinner than 1 mm (need XMIN < XMAX and "
                              "YMIN < YMAX; order: XMIN XMAX YMIN YMAX)")


@dataclass(frozen=True)
class CylinderRegion:
    """Design region of a cylindrical workspace, mm: ``x^2 + y^2 <= rw^2``, ``z in [zmin, zmax]`` (on the z axis)."""

    rw: float
    zmin: float
    zmax: float
    kind = "cylinder"
    n = 3
    arg_names = ("RW", "ZMIN", "ZMAX")
    #: default candidate grid of the exchange (rings, points on the rim, levels)
    default_grid = (4, 24, 5)

    @classmethod
    def workspace(cls, robot):
        return workspace_region(robot)

    @property
    def lo(self):
        """Bounding box, shape (3,)."""
        return np.array([-self.rw, -self.rw, self.zmin])

    @property
    def hi(self):
        """Bounding box, shape (3,)."""
        return np.array([self.rw, self.rw, self.zmax])

    @property
    def center(self):
        return (self.lo + self.hi) / 2

    @property
    def half(self):
        return (self.hi - self.lo) / 2

    def grid(self, nr: int = 4, na: int = 24, nz: int = 5):
        """Polar grid, shape (N, 3): on each of ``nz`` levels the axis and ``nr`` rings.

        Ring j (radius ``rw j / nr``) has ``max(4, round(na j / nr))`` points
        from azimuth 0 (the rim ``na``), so the points are about evenly spread.
        """
        pts = []
        for z in np.linspace(self.zmin, self.zmax, nz):
            pts.append((0.0, 0.0, z))
            for j in range(1, nr + 1):
                rad = self.rw * j / nr
                na_j = max(4, int(round(na * j / nr)))
                for t in 2 * np.pi * np.arange(na_j) / na_j:
                    pts.append((rad * np.cos(t), rad * np.sin(t), z))
        return np.array(pts)

    def reach_grid(self):
        """Points checked for reachability (6 rings, 36 on the rim, 9 levels), shape (N, 3)."""
        return self.grid(6, 36, 9)

    def contains(self, P, tol: float = _FEAS_TOL) -> np.ndarray:
        P = np.atleast_2d(P)
        return ((np.hypot(P[:, 0], P[:, 1]) <= self.rw + tol)
                & (P[:, 2] >= self.zmin - tol) & (P[:, 2] <= self.zmax + tol))

    def sample(self, rng, N: int) -> np.ndarray:
        """N uniform random points in the cylinder, shape (N, 3)."""
        u = rng.uniform(size=(N, 3))
        rad, t = self.rw * np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
        return np.column_stack([rad * np.cos(t), rad * np.sin(t), self.zmin + u[:, 2] * (self.zmax - self.zmin)])

    def boundary_scheme(self, n1: int, n2: int | None = None) -> np.ndarray:
        """The ring scheme on the region: n1 poses on the top circle (``z = zmax``), then n2 on the bottom one.

        Azimuths ``360 deg j / n`` on each circle, radius ``rw`` (``n2 = n1``:
        :meth:`zerocal_sym.model.workspace.Cylinder.boundary_scheme`).

        Returns
        -------
        ndarray, shape (n1 + n2, 3)
        """
        n2 = n1 if n2 is None else n2

        def ring(k, z):
            t = 2 * np.pi * np.arange(k) / k
            return np.column_stack([self.rw * np.cos(t), self.rw * np.sin(t), np.full(k, z)])

        return np.vstack([ring(n1, self.zmax), ring(n2, self.zmin)])

    def describe(self) -> str:
        return f"x^2 + y^2 <= {self.rw:g}^2, z in [{self.zmin:g}, {self.zmax:g}]"

    def as_list(self):
        return [self.rw, self.zmin, self.zmax]

    def _check(self):
        if not self.rw >= 1.0 or not self.zmax - self.zmin >= 1.0:
            raise DesignError(f"region {self.describe()} mm is empty or thinner than 1 mm (need RW >= 1 and "
                              "ZMIN < ZMAX; order: RW ZMIN ZMAX)")


#: workspace kind -> design region class
REGIONS = {"rectangle": Region, "cylinder": CylinderRegion}


def workspace_region(robot):
    """The robot's workspace as a design region (:class:`Region` or :class:`CylinderRegion`)."""
    ws = robot.workspace
    if ws.kind == "rectangle":
        lo, hi = ws.bounds()
        return Region(float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    if ws.kind == "cylinder":
        lo, hi = ws.bounds()
        return CylinderRegion(float(ws.rw), float(lo[2]), float(hi[2]))
    raise DesignError(f"no design region for a {ws.kind} workspace (known: {', '.join(REGIONS)})")


REGION_KINDS = ("reachable", "polygon")


def make_region(robot, region=None, bounds=None, singularity_margin=None, joint_limits_deg=None):
    """A validated design region.

    Parameters
    ----------
    region : optional
        * ``None``: the workspace;
        * a :class:`Region`, :class:`CylinderRegion` or
          :class:`~zerocal_sym.design.regions.ReachableRegion`;
        * a sequence of numbers (mm) of the workspace's shape, reachable
          everywhere: ``XMIN XMAX YMIN YMAX`` (rectangle), ``RW ZMIN ZMAX``
          (cylinder);
        * ``"reachable"``: the reachable non-singular set (the margin, the
          joint limits, the home pose's modes), clipped by ``bounds``;
        * ``("polygon", x1, y1, x2, y2, ...)`` or a
          :class:`~zerocal_sym.design.regions.Polygon` (planar): the
          reachable set inside the polygon.
    bounds : sequence of numbers, optional
        With ``"reachable"``: a box ``XMIN XMAX YMIN YMAX [ZMIN ZMAX]`` (2n
        numbers, ``-inf``/``inf`` for open sides) or, in 3-D, a cylinder
        ``RW ZMIN ZMAX`` (3 numbers).
    singularity_margin, joint_limits_deg
        For the reachable set (default the robot's margin, no limits).

    Raises
    ------
    DesignError
    """
    from zerocal_sym.design import regions as rg

    if isinstance(region, str) or (isinstance(region, (list, tuple)) and region and isinstance(region[0], str)):
        vals = [region] if isinstance(region, str) else list(region)
        kind = str(vals[0]).lower()
        margin = robot.singularity_margin if singularity_margin is None else singularity_margin
        try:
            if kind == "reachable":
                if len(vals) > 1:
                    raise DesignError("--region reachable takes no numbers (give the clip with --bounds)")
                clip = _make_bounds(robot, bounds)
                return rg.make_reachable(robot, clip, margin, joint_limits_deg)
            if kind == "polygon":
                if robot.n != 2:
                    raise DesignError(f"a polygon region is planar; robot {robot.name!r} has {robot.n} pose "
                                      "coordinates (use --region reachable --bounds ...)")
                if bounds is not None:
                    raise DesignError("--bounds clips --region reachable; a polygon is its own bound")
                nums = [_finite(f"polygon coordinate {i + 1}", v) for i, v in enumerate(vals[1:])]
                if len(nums) % 2:
                    raise DesignError(f"a polygon needs pairs X Y, got {len(nums)} numbers")
                return rg.make_reachable(robot, rg.Polygon.make(nums), margin, joint_limits_deg)
        except rg.RegionError as exc:
            raise DesignError(str(exc)) from None
        raise DesignError(f"unknown region {vals[0]!r} (known: reachable, polygon, or numbers: "
                          f"{' '.join(REGIONS[robot.workspace.kind].arg_names)})")
    if isinstance(region, rg.Polygon):
        return rg.make_reachable(robot, region, robot.singularity_margin if singularity_margin is None
                                 else singularity_margin, joint_limits_deg)
    if isinstance(region, rg.ReachableRegion):
        return region
    if bounds is not None:
        raise DesignError("--bounds clips the reachable set: use it with --region reachable")
    if region is None:
        return workspace_region(robot)
    kind = robot.workspace.kind
    cls = REGIONS.get(kind)
    if cls is None:
        raise DesignError(f"no design region for a {kind} workspace (known: {', '.join(REGIONS)})")
    if isinstance(region, tuple(REGIONS.values())):
        if not isinstance(region, cls):
            raise DesignError(f"a {region.kind} region does not fit robot {robot.name!r} (its workspace is a {kind})")
    else:
        vals = list(region)
        names = cls.arg_names
        if len(vals) != len(names):
            raise DesignError(f"region needs {len(names)} numbers {' '.join(names)} (mm) for a {kind} workspace, "
                              f"got {len(vals)}")
        region = cls(*[_finite(nm, v) for nm, v in zip(names, vals)])
    region._check()
    return region


# --------------------------------------------------------------------------- constraints
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


def _make_bounds(robot, bounds):
    """The clip of a reachable region from ``--bounds`` numbers (None: unclipped)."""
    from zerocal_sym.design import regions as rg

    if bounds is None:
        return None
    if isinstance(bounds, (rg.Box, rg.Polygon, CylinderRegion)):
        return bounds
    vals = list(bounds)
    n = robot.n
    if robot.n == 3 and len(vals) == 3:
        rw, zmin, zmax = (_finite(nm, v) for nm, v in zip(("RW", "ZMIN", "ZMAX"), vals))
        c = CylinderRegion(rw, zmin, zmax)
        c._check()
        return c
    names = [f"{a}{b}" for a in "XYZ"[:n] for b in ("MIN", "MAX")]
    if len(vals) != 2 * n:
        alt = " or a cylinder RW ZMIN ZMAX (3)" if n == 3 else ""
        raise DesignError(f"--bounds needs {2 * n} numbers {' '.join(names)} (mm, inf for an open side){alt}, "
                          f"got {len(vals)}")
    out = []
    for nm, v in zip(names, vals):
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise DesignError(f"{nm} must be a number, got {v!r}") from None
        if math.isnan(v):
            raise DesignError(f"{nm} must be a number or +-inf, got nan")
        out.append(v)
    lo, hi = out[0::2], out[1::2]
    for i in range(n):
        if not hi[i] - lo[i] >= 1.0:
            raise DesignError(f"--bounds {names[2 * i]} {lo[i]:g} {names[2 * i + 1]} {hi[i]:g}: need MIN < MAX "
                              "by at least 1 mm")
    return rg.Box(tuple(lo), tuple(hi))


def _finite(name, v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise DesignError(f"{name} must be a number, got {v!r}") from None
    if not math.isfinite(v):
        raise DesignError(f"{name} must be finite, got {v!r}")
    return v


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


def min_k(robot=None) -> int:
    """Smallest K: ``p + 1`` poses for the p = m + n parameters (K - 1 >= p changes); :data:`MIN_K` without a robot."""
    return MIN_K if robot is None else max(MIN_K, len(design_params(robot)) + 1)


def _check_k(K, robot=None):
    """Raise :class:`DesignError` unless K is an integer in [:func:`min_k`, :data:`MAX_K`]."""
    if isinstance(K, bool) or not isinstance(K, (int, np.integer)):
        raise DesignError(f"K must be an integer number of poses, got {K!r}")
    kmin = min_k(robot)
    p = kmin - 1 if robot is not None else 4
    if K < kmin:
        raise DesignError(f"K = {K} is too small: at least {kmin} poses are needed to identify the {p} "
                          f"parameters (K - 1 >= {p} measured changes)")
    if K > MAX_K:
        raise DesignError(f"K = {K} is too large (at most {MAX_K})")
