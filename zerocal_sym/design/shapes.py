"""Design regions of the workspace's shape, and the validation of any design region.

* :class:`Region` -- an axis-aligned rectangle ``XMIN XMAX YMIN YMAX`` (mm),
  for a rectangular workspace;
* :class:`CylinderRegion` -- a coaxial cylinder ``RW ZMIN ZMAX``:
  ``x^2 + y^2 <= RW^2``, ``z in [ZMIN, ZMAX]``, for a cylindrical one.

Both must be reachable everywhere (checked by
:func:`zerocal_sym.design.constraints.make_constraints`).
:func:`make_region` turns any region argument -- none (the workspace), one
of these or its numbers, ``"reachable"`` clipped by ``bounds``, a polygon --
into a validated region; the reachable set and the polygon are in
:mod:`zerocal_sym.design.regions` (imported lazily).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from zerocal_sym.design.limits import _FEAS_TOL, DesignError, _finite


class CentredBox:
    """``center`` and ``half`` of a region's bounding box (``lo``, ``hi``: shape (n,) each)."""

    @property
    def center(self):
        """Centre of the bounding box, shape (n,)."""
        return (self.lo + self.hi) / 2

    @property
    def half(self):
        """Half sizes of the bounding box, shape (n,)."""
        return (self.hi - self.lo) / 2


@dataclass(frozen=True)
class Region(CentredBox):
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
class CylinderRegion(CentredBox):
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

