"""Design regions beyond the workspace's shape: the reachable set, clipped.

:class:`ReachableRegion` is the set of poses the robot reaches in the assembly
and working mode of its home pose with every singularity indicator at least
the margin (signed: ``sign_i s_i >= margin`` with the signs at home, so a
pose on the other side of a singularity is excluded even if ``|s|`` is
large), within the joint limits and with forward kinematics returning the
pose (the assembly mode the model uses), clipped by optional bounds:

* :class:`Box` -- ``lo <= P <= hi`` per coordinate, open sides as ``-inf`` /
  ``inf`` (planar ``XMIN XMAX YMIN YMAX``; 3-D ``XMIN XMAX YMIN YMAX ZMIN ZMAX``);
* :class:`~zerocal_sym.design.shapes.CylinderRegion` -- ``RW ZMIN ZMAX``
  on the z axis (3-D);
* :class:`Polygon` -- a simple polygon ``(x1, y1), (x2, y2), ...`` (planar;
  convex or not).

Unlike a rectangle or cylinder region (which must be reachable everywhere),
the clip need not be: the region is what of it is feasible.  It is found on a
grid (about :data:`GRID_POINTS` points over the clip's box, or over a box
found by a coarse search around the home pose where the clip is open), and
only the connected part containing the workspace's centre (or the nearest
feasible point to it) is kept: a pose in another component would need a
path through a singularity.  The scale travel (``max rho - min rho <= l0``)
couples the poses and stays a design constraint.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.design.shapes import CentredBox
from zerocal_sym.errors import ZerocalError

#: grid points used to find the reachable set (per region; 3-D uses about as many)
GRID_POINTS = 40000
_TOL = 1e-9


class RegionError(ZerocalError):
    """A region description that cannot be used (see :class:`zerocal_sym.design.DesignError`)."""


# --------------------------------------------------------------------------- clips
@dataclass(frozen=True)
class Box:
    """``lo <= P <= hi`` per coordinate (mm), sides may be infinite."""

    lo: tuple
    hi: tuple
    kind = "box"

    @property
    def n(self):
        return len(self.lo)

    def contains(self, P, tol=1e-6):
        P = np.atleast_2d(P)
        return np.all((P >= np.array(self.lo) - tol) & (P <= np.array(self.hi) + tol), axis=1)

    def bbox(self):
        return np.array(self.lo, float), np.array(self.hi, float)

    def describe(self):
        names = "xyz"[:self.n] if self.n <= 3 else [f"P{i}" for i in range(self.n)]
        return ", ".join(f"{c} in [{lo:g}, {hi:g}]" for c, lo, hi in zip(names, self.lo, self.hi))

    def as_list(self):
        return [v for pair in zip(self.lo, self.hi) for v in pair]

    def nlp_constraints(self, P, K):
        return []


@dataclass(frozen=True)
class Polygon:
    """A simple polygon in the plane (mm), vertices counter-clockwise (normalised on creation)."""

    vertices: tuple
    kind = "polygon"
    n = 2

    @classmethod
    def make(cls, coords):
        v = np.asarray(coords, float).reshape(-1, 2)
        if len(v) < 3:
            raise RegionError(f"a polygon needs at least 3 vertices (X1 Y1 X2 Y2 X3 Y3 ...), got {len(v)}")
        if not np.all(np.isfinite(v)):
            raise RegionError("polygon vertices must be finite")
        if np.allclose(v[0], v[-1]):
            v = v[:-1]
        if _self_intersects(v):
            raise RegionError("polygon edges cross each other (give the vertices in order around it)")
        area = _signed_area(v)
        if abs(area) < 1.0:
            raise RegionError(f"polygon is degenerate (area {abs(area):.3g} mm^2)")
        if area < 0:
            v = v[::-1]
        return cls(tuple(map(tuple, v.tolist())))

    @property
    def V(self):
        return np.array(self.vertices, float)

    @property
    def convex(self):
        V = self.V
        e = np.roll(V, -1, axis=0) - V
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        return bool(np.all(cross >= -1e-9))

    def contains(self, P, tol=1e-6):
        """Even-odd rule, points within ``tol`` of an edge count as inside, shape (K,)."""
        P = np.atleast_2d(P)
        V = self.V
        A, B = V, np.roll(V, -1, axis=0)
        x, y = P[:, 0][:, None], P[:, 1][:, None]
        cond = (A[:, 1] > y) != (B[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xin = A[:, 0] + (y - A[:, 1]) * (B[:, 0] - A[:, 0]) / (B[:, 1] - A[:, 1])
        inside = np.sum(cond & (x < xin), axis=1) % 2 == 1
        return inside | (_edge_distance(P, V) <= tol)

    def bbox(self):
        V = self.V
        return V.min(axis=0), V.max(axis=0)

    def describe(self):
        return "polygon " + " ".join(f"({x:g}, {y:g})" for x, y in self.vertices)

    def as_list(self):
        return [c for xy in self.vertices for c in xy]

    def cells(self):
        """Convex cells covering the polygon, each a list of half-planes ``a x + b y <= c``, shape (3,) rows.

        A convex polygon is one cell (its edges); otherwise the triangles of
        an ear-clipping triangulation.
        """
        V = self.V
        if self.convex:
            return [_halfplanes(V)]
        return [_halfplanes(V[list(t)]) for t in _triangulate(V)]

    def cell_of(self, P):
        """Index of a cell containing each point (the nearest one if none), shape (K,)."""
        P = np.atleast_2d(P)
        cells = self.cells()
        viol = np.stack([np.max(P @ H[:, :2].T - H[:, 2], axis=1) for H in cells], axis=1)
        return np.argmin(viol, axis=1)

    def nlp_constraints(self, P, K):
        """Half-planes of each pose's cell as NLP parameters (see :class:`ReachableRegion`)."""
        return []


def _signed_area(V):
    x, y = V[:, 0], V[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _segments_cross(p1, p2, p3, p4):
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
    d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
    return (d1 * d2 < 0) and (d3 * d4 < 0)


def _self_intersects(V):
    n = len(V)
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue
            if _segments_cross(V[i], V[(i + 1) % n], V[j], V[(j + 1) % n]):
                return True
    return False


def _edge_distance(P, V):
    A, B = V, np.roll(V, -1, axis=0)
    AB = B - A
    t = np.clip(np.einsum("kej,ej->ke", P[:, None, :] - A[None], AB) / np.sum(AB ** 2, axis=1), 0, 1)
    Q = A[None] + t[..., None] * AB[None]
    return np.min(np.linalg.norm(P[:, None, :] - Q, axis=2), axis=1)


def _halfplanes(V):
    """Rows ``(a, b, c)``: ``a x + b y <= c`` for each edge of a counter-clockwise convex polygon, unit normals."""
    A, B = V, np.roll(V, -1, axis=0)
    e = B - A
    nrm = np.column_stack([e[:, 1], -e[:, 0]])  # outward for CCW
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    return np.column_stack([nrm, np.sum(nrm * A, axis=1)])


def _triangulate(V):
    """Ear clipping of a simple counter-clockwise polygon: list of vertex-index triples."""
    idx = list(range(len(V)))
    tris = []
    guard = 0
    while len(idx) > 3 and guard < 10 * len(V) ** 2:
        guard += 1
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = V[i0], V[i1], V[i2]
            if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) <= 1e-12:
                continue  # reflex
            others = [j for j in idx if j not in (i0, i1, i2)]
            if others and np.any(Polygon(tuple(map(tuple, (a, b, c)))).contains(V[others], 0.0)):
                continue
            tris.append((i0, i1, i2))
            idx.pop(k)
            break
    tris.append(tuple(idx))
    return tris


# --------------------------------------------------------------------------- the reachable set
@dataclass(frozen=True)
class ReachableRegion(CentredBox):
    """The reachable, non-singular set of the robot (home's modes), clipped; see the module docstring.

    Attributes
    ----------
    clip : Box, CylinderRegion, Polygon or None
    lo_box, hi_box : tuple
        Bounding box of the region (the feasible grid's, grown by one cell).
    h : float
        Spacing of the grid it was found on, mm.
    """

    clip: object
    lo_box: tuple
    hi_box: tuple
    h: float
    n: int
    origin: tuple = field(repr=False)
    mask: np.ndarray = field(repr=False, compare=False, hash=False)
    kind = "reachable"
    arg_names = ()
    #: exchange candidates (about this many)
    default_grid = (300,)

    @property
    def lo(self):
        return np.array(self.lo_box, float)

    @property
    def hi(self):
        return np.array(self.hi_box, float)

    def in_component(self, P):
        """Bool per pose: the nearest grid node (of the component grown by one cell) is in the region's component."""
        P = np.atleast_2d(P)
        idx = np.rint((P - np.array(self.origin)) / self.h).astype(int)
        shape = np.array(self.mask.shape)
        ok = np.all((idx >= 0) & (idx < shape), axis=1)
        out = np.zeros(len(P), bool)
        out[ok] = self.mask[tuple(idx[ok].T)]
        return out

    def contains(self, P, tol=1e-6):
        P = np.atleast_2d(P)
        ok = np.all((P >= self.lo - tol) & (P <= self.hi + tol), axis=1) & self.in_component(P)
        if self.clip is not None:
            ok &= self.clip.contains(P, tol)
        return ok

    def design_grid(self, n_target):
        """A grid of about ``n_target`` points over the region (before the per-pose checks), and its spacing."""
        lo, hi = self.lo, self.hi
        frac = max(float(np.mean(self.mask)), 1e-3)
        h = (float(np.prod(hi - lo)) * frac / n_target) ** (1.0 / self.n)
        axes = [np.linspace(lo[i], hi[i], max(2, int(round((hi[i] - lo[i]) / h)) + 1)) for i in range(self.n)]
        X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, self.n)
        return X[self.contains(X, 1e-9)], h

    def grid(self, n_target=300):
        """About ``n_target`` grid points over the region (exchange candidates), shape (N, n)."""
        return self.design_grid(n_target)[0]

    def reach_grid(self):
        return self.grid(300)

    def sample(self, rng, N):
        """N points uniform in the bounding box, kept if inside (may return fewer), shape (M, n)."""
        frac = max(float(np.mean(self.mask)), 0.02)
        X = self.lo + rng.uniform(size=(int(N / frac) + 10, self.n)) * (self.hi - self.lo)
        return X[self.contains(X, 0.0)][:N]

    def describe(self):
        c = "" if self.clip is None else f" within {self.clip.describe()}"
        return f"reachable set{c} (bounding box {', '.join(f'[{a:.6g}, {b:.6g}]' for a, b in zip(self.lo_box, self.hi_box))})"

    def as_list(self):
        return [] if self.clip is None else self.clip.as_list()

    def _check(self):
        pass

    def nlp_cells(self):
        """Convex cells of a polygon clip (None otherwise)."""
        return self.clip.cells() if isinstance(self.clip, Polygon) else None


def _feasible(robot, P, margin, jl_rad, signs):
    """Per-pose feasibility of the reachable set (no clip), bool shape (K,)
    (:func:`zerocal_sym.design.feasible.reachable_terms`)."""
    from zerocal_sym.design.feasible import reachable_terms

    return reachable_terms(robot, P, margin, jl_rad, signs)[0]


def mode_signs(robot) -> np.ndarray:
    """Signs of the singularity indicators at the home pose (the modes the reachable set keeps), shape (s,)."""
    from zerocal_sym.model import kinematics as kin

    home = robot.home_pose()
    s = kin.transmission(robot, home[None])[0]
    return np.where(s >= 0, 1.0, -1.0)


def _grid(lo, hi, npts):
    n = len(lo)
    h = (float(np.prod(hi - lo)) / npts) ** (1.0 / n)
    axes = [np.arange(lo[i], hi[i] + 0.5 * h, h) for i in range(n)]
    return axes, h


def make_reachable(robot, clip=None, margin=0.2, joint_limits=None, grid_points=GRID_POINTS):
    """The :class:`ReachableRegion` of a robot for a margin and joint limits (internal units, rad or mm,
    shape (m, 2)), clipped.

    Raises
    ------
    RegionError
        If no feasible pose is found.
    """
    from scipy import ndimage

    from zerocal_sym.design.shapes import workspace_region

    n = robot.n
    signs = mode_signs(robot)
    jl = None if joint_limits is None else np.asarray(joint_limits, float)
    if clip is not None:
        clo, chi = clip.bbox() if hasattr(clip, "bbox") else (clip.lo, clip.hi)
    else:
        clo, chi = np.full(n, -np.inf), np.full(n, np.inf)
    clo, chi = np.asarray(clo, float), np.asarray(chi, float)
    ws = workspace_region(robot)
    seed = np.asarray(ws.center, float)
    R = 2.5 * float(np.max(np.abs(robot.geometry)))
    lo = np.where(np.isfinite(clo), clo, seed - R)
    hi = np.where(np.isfinite(chi), chi, seed + R)

    def feasible_on(axes):
        X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, n)
        ok = _feasible(robot, X, margin, jl, signs)
        if clip is not None:
            ok &= clip.contains(X, 1e-9)
        return X, ok.reshape([len(a) for a in axes])

    # coarse pass: the box of the feasible set, then the fine grid over it
    for npts in (grid_points // 8, grid_points):
        axes, h = _grid(lo, hi, npts)
        X, ok = feasible_on(axes)
        if not np.any(ok):
            raise RegionError(f"no reachable pose with every |sin transmission| >= {margin:g} in the same modes "
                              f"as home{'' if jl is None else ' within the joint limits'}"
                              f"{'' if clip is None else ' inside ' + clip.describe()}")
        lab, _ = ndimage.label(ok, structure=np.ones((3,) * n))
        flat = X.reshape(-1, n)
        cand = np.flatnonzero(ok.ravel())
        k = cand[np.argmin(np.linalg.norm(flat[cand] - seed, axis=1))]
        comp = lab.ravel() == lab.ravel()[k]
        pts = flat[comp]
        lo = np.maximum(pts.min(axis=0) - 1.5 * h, np.where(np.isfinite(clo), clo, -np.inf))
        hi = np.minimum(pts.max(axis=0) + 1.5 * h, np.where(np.isfinite(chi), chi, np.inf))
    mask = ndimage.binary_dilation(comp.reshape(ok.shape), structure=np.ones((3,) * n))
    origin = tuple(float(a[0]) for a in axes)
    return ReachableRegion(clip=clip, lo_box=tuple(lo.tolist()), hi_box=tuple(hi.tolist()), h=float(h), n=n,
                           origin=origin, mask=mask)
