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


def _to_internal(unit: str) -> str:
    """The internal unit of a file unit: ``rad`` for ``deg``, ``mm`` for ``mm``."""
    return "rad" if unit == "deg" else "mm"


def corner_scheme(lo, hi, K: int) -> np.ndarray:
    """K corners of the box ``[lo, hi]`` (shape (n,) each): the corner scheme carried to any K.

    ``K = 2^n``: every corner in binary order (corner k sets coordinate j to its maximum where bit j of k is
    1); in 6-D, K = 32 or 16: the regular fractions of the workspace's corner scheme
    (:data:`zerocal_sym.model.workspace.BOX_FRACTIONS`); any other K: the first K corners of the smallest of
    these with at least K corners (so that every coordinate turns, as far as K allows).

    Returns
    -------
    ndarray, shape (K, n)
    """
    from zerocal_sym.model.workspace import BOX_FRACTIONS, corner_points

    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    n = len(lo)
    sizes = sorted(BOX_FRACTIONS) if n == 6 else [2 ** n]
    N = next((k for k in sizes if k >= K), None)
    if N is None:
        raise DesignError(f"the corner rule has at most {sizes[-1]} corners in {n}-D, got K = {K}")
    gens = BOX_FRACTIONS[N] if n == 6 else {}
    return corner_points(lo, hi, K, gens)


@dataclass(frozen=True)
class BoxRegion(CentredBox):
    """Design region of a box workspace (any dimension; the hexapod's 6-D pose): ``lo <= P <= hi`` per pose
    coordinate.

    ``lo_box``, ``hi_box`` in internal units (mm, rad); ``names`` the pose coordinates, ``units`` their file
    units (mm, deg): a user gives and reads the box in those (``--region X_MIN X_MAX ... YAW_MIN YAW_MAX``).
    """

    lo_box: tuple
    hi_box: tuple
    names: tuple
    units: tuple
    kind = "box"
    #: default candidate grid of the exchange: points per coordinate (3^6 = 729 in 6-D)
    default_grid = (3,)

    @classmethod
    def workspace(cls, robot):
        return workspace_region(robot)

    @classmethod
    def from_user(cls, names, units, values):
        """The box from ``LO1 HI1 LO2 HI2 ...`` in file units (mm, deg)."""
        v = np.asarray(values, float)
        conv = [_to_internal(u) for u in units]
        from zerocal_sym.model.units import from_user

        lo = tuple(float(from_user(x, c)) for x, c in zip(v[0::2], conv))
        hi = tuple(float(from_user(x, c)) for x, c in zip(v[1::2], conv))
        return cls(lo, hi, tuple(names), tuple(units))

    @staticmethod
    def arg_names_of(names):
        """The numbers a user gives: ``X_MIN X_MAX Y_MIN ...`` (file units)."""
        return tuple(f"{nm.upper()}_{b}" for nm in names for b in ("MIN", "MAX"))

    @property
    def arg_names(self):
        return self.arg_names_of(self.names)

    @property
    def n(self):
        return len(self.lo_box)

    @property
    def lo(self):
        """ndarray, shape (n,)"""
        return np.array(self.lo_box, float)

    @property
    def hi(self):
        """ndarray, shape (n,)"""
        return np.array(self.hi_box, float)

    def grid(self, k: int = 3):
        """``k^n`` points on a regular grid over the box (every corner among them), shape (k^n, n)."""
        axes = [np.linspace(a, b, k) for a, b in zip(self.lo_box, self.hi_box)]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, self.n)

    def reach_grid(self):
        """Points checked for reachability: the 3^n grid (the corners, the centres of the faces, ...)."""
        return self.grid(3)

    def design_grid(self, n_target):
        """Candidates of the approximate design: ``k^n`` grid points, ``k = max(3, round(n_target^(1/n)))``
        (3 per coordinate in 6-D: 729), and the spacing per coordinate, shape (n,)."""
        k = max(3, int(round(n_target ** (1.0 / self.n))))
        return self.grid(k), (self.hi - self.lo) / (k - 1)

    def contains(self, P, tol: float = _FEAS_TOL) -> np.ndarray:
        P = np.atleast_2d(P)
        return np.all((P >= self.lo - tol) & (P <= self.hi + tol), axis=1)

    def sample(self, rng, N: int) -> np.ndarray:
        """N uniform random points in the box, shape (N, n)."""
        return self.lo + rng.uniform(size=(N, self.n)) * (self.hi - self.lo)

    def baseline_poses(self, K: int) -> np.ndarray:
        """The corner rule on the box with K poses (:func:`corner_scheme`), shape (K, n)."""
        return corner_scheme(self.lo, self.hi, K)

    def user_values(self):
        """``[lo1, hi1, lo2, ...]`` in file units (mm, deg)."""
        from zerocal_sym.model.units import to_user

        out = []
        for a, b, u in zip(self.lo_box, self.hi_box, self.units):
            c = _to_internal(u)
            out += [float(to_user(a, c)), float(to_user(b, c))]
        return out

    def describe(self) -> str:
        v = self.user_values()
        return ", ".join(f"{nm} in [{v[2 * i]:.6g}, {v[2 * i + 1]:.6g}]{'' if u == 'mm' else ' ' + u}"
                         for i, (nm, u) in enumerate(zip(self.names, self.units)))

    def as_list(self):
        return self.user_values()

    def _check(self):
        v = self.user_values()
        for i, (nm, u) in enumerate(zip(self.names, self.units)):
            if not v[2 * i + 1] - v[2 * i] >= 1.0:
                raise DesignError(f"region {self.describe()} (mm, deg) is empty or thinner than 1 {u} in {nm} "
                                  f"(need {nm.upper()}_MIN < {nm.upper()}_MAX; order: "
                                  f"{' '.join(self.arg_names)})")


#: workspace kind -> design region class
REGIONS = {"rectangle": Region, "cylinder": CylinderRegion, "box": BoxRegion}


def region_arg_names(robot):
    """The numbers ``--region`` takes for the robot's workspace shape (``XMIN XMAX YMIN YMAX``, ``RW ZMIN ZMAX``,
    ``X_MIN X_MAX ... YAW_MIN YAW_MAX``)."""
    cls = REGIONS[robot.workspace.kind]
    if cls is BoxRegion:
        return BoxRegion.arg_names_of(robot.mechanism.pose_names)
    return cls.arg_names


def region_units(robot) -> str:
    """The units of ``--region``'s numbers: ``mm``, or ``mm, deg for orientations``."""
    from zerocal_sym.model import units

    return "mm" if all(units.pose_unit(robot, nm) == "mm" for nm in robot.mechanism.pose_names) else \
        "mm; deg for orientations"


def workspace_region(robot):
    """The robot's workspace as a design region (:class:`Region`, :class:`CylinderRegion`, :class:`BoxRegion`)."""
    ws = robot.workspace
    if ws.kind == "rectangle":
        lo, hi = ws.bounds()
        return Region(float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))
    if ws.kind == "cylinder":
        lo, hi = ws.bounds()
        return CylinderRegion(float(ws.rw), float(lo[2]), float(hi[2]))
    if ws.kind == "box":
        from zerocal_sym.model import units

        lo, hi = ws.bounds()
        names = tuple(robot.mechanism.pose_names)
        return BoxRegion(tuple(float(v) for v in lo), tuple(float(v) for v in hi), names,
                         tuple(units.pose_unit(robot, nm) for nm in names))
    raise DesignError(f"no design region for a {ws.kind} workspace (known: {', '.join(REGIONS)})")


REGION_KINDS = ("reachable", "polygon")


def make_region(robot, region=None, bounds=None, singularity_margin=None, joint_limits=None):
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
    singularity_margin, joint_limits
        For the reachable set (default the robot's margin, no limits); the limits in internal units (rad, mm),
        shape (m, 2).

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
                if region_units(robot) != "mm":
                    raise DesignError(f"--region reachable is found on a grid of positions; robot {robot.name!r} "
                                      "has orientation coordinates: give the box's numbers "
                                      f"{' '.join(region_arg_names(robot))} ({region_units(robot)})")
                if len(vals) > 1:
                    raise DesignError("--region reachable takes no numbers (give the clip with --bounds)")
                clip = _make_bounds(robot, bounds)
                return rg.make_reachable(robot, clip, margin, joint_limits)
            if kind == "polygon":
                if robot.n != 2:
                    raise DesignError(f"a polygon region is planar; robot {robot.name!r} has {robot.n} pose "
                                      "coordinates (use --region reachable --bounds ...)")
                if bounds is not None:
                    raise DesignError("--bounds clips --region reachable; a polygon is its own bound")
                nums = [_finite(f"polygon coordinate {i + 1}", v) for i, v in enumerate(vals[1:])]
                if len(nums) % 2:
                    raise DesignError(f"a polygon needs pairs X Y, got {len(nums)} numbers")
                return rg.make_reachable(robot, rg.Polygon.make(nums), margin, joint_limits)
        except rg.RegionError as exc:
            raise DesignError(str(exc)) from None
        raise DesignError(f"unknown region {vals[0]!r} (known: reachable, polygon, or numbers: "
                          f"{' '.join(region_arg_names(robot))})")
    if isinstance(region, rg.Polygon):
        return rg.make_reachable(robot, region, robot.singularity_margin if singularity_margin is None
                                 else singularity_margin, joint_limits)
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
        names = region_arg_names(robot)
        if len(vals) != len(names):
            raise DesignError(f"region needs {len(names)} numbers {' '.join(names)} ({region_units(robot)}) for a "
                              f"{kind} workspace, got {len(vals)}")
        nums = [_finite(nm, v) for nm, v in zip(names, vals)]
        if cls is BoxRegion:
            ws = workspace_region(robot)
            region = BoxRegion.from_user(ws.names, ws.units, nums)
        else:
            region = cls(*nums)
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

