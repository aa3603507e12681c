"""Workspace shapes: where a robot is asked to go, and its boundary scheme.

A mechanism declares its workspace shape (its generated ``WORKSPACE``); a robot
file gives the sizes (mm):

``rectangle`` (2-D, the paper's)
    ``x in [-b/2, b/2]``, ``y in [H, H + h]``; keys ``H b h``.
``cylinder`` (3-D, the Delta's)
    ``x^2 + y^2 <= rw^2``, ``z in [-(H + h), -H]``; keys ``rw H h``.

Each shape gives its bounding box, a grid and its rims for validation, a
membership test, and its *boundary scheme* -- the paper's pose scheme carried
to the shape: ``n`` poses on each of the two boundaries (the paper's two
horizontal edges; the Delta's top and bottom circles, the ring scheme of
``DELTA.md``), ``K = 2n``, the second boundary visited in the same order.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import PoseError


@dataclass(frozen=True)
class Rectangle:
    """``x in [-b/2, b/2]``, ``y in [H, H + h]`` (mm)."""

    H: float
    b: float
    h: float
    kind = "rectangle"
    keys = ("H", "b", "h")
    sizes = ("b", "h")
    #: keys that are distances from the base, positive (the workspace is on the side the mechanism works)
    distances = ("H",)
    n = 2
    scheme_name = "paper"

    def bounds(self):
        """``(lo, hi)``, ndarray shape (2,) each."""
        return np.array([-self.b / 2, self.H]), np.array([self.b / 2, self.H + self.h])

    def corners(self) -> dict:
        """Label -> (x, y): the four corners."""
        x0, x1, y0, y1 = -self.b / 2, self.b / 2, self.H, self.H + self.h
        return {"(-b/2, H)": (x0, y0), "(b/2, H)": (x1, y0), "(-b/2, H+h)": (x0, y1), "(b/2, H+h)": (x1, y1)}

    def grid(self, nx: int = 25, ny: int = 9) -> np.ndarray:
        """Grid over the rectangle, shape (nx*ny, 2), row-major in y."""
        lo, hi = self.bounds()
        X, Y = np.meshgrid(np.linspace(lo[0], hi[0], nx), np.linspace(lo[1], hi[1], ny))
        return np.column_stack([X.ravel(), Y.ravel()])

    def contains(self, P, tol: float = 1e-6) -> np.ndarray:
        """Bool per pose, shape (K,)."""
        lo, hi = self.bounds()
        P = np.atleast_2d(P)
        return np.all((P >= lo - tol) & (P <= hi + tol), axis=1)

    def describe(self) -> str:
        lo, hi = self.bounds()
        return f"x in [{lo[0]:g}, {hi[0]:g}], y in [{lo[1]:g}, {hi[1]:g}]"

    def ranges(self) -> dict:
        lo, hi = self.bounds()
        return {"x": [lo[0], hi[0]], "y": [lo[1], hi[1]]}

    def to_dict(self) -> dict:
        return {"H": self.H, "b": self.b, "h": self.h}

    def boundary_scheme(self, n: int) -> np.ndarray:
        """The paper's scheme: n poses on ``y = H`` from ``x = -b/2`` to ``b/2``, then on ``y = H + h``.

        Returns
        -------
        ndarray, shape (2n, 2)
        """
        if n < 2:
            raise PoseError(f"the paper's scheme needs n >= 2 poses per boundary, got n = {n}")
        xs = np.linspace(-self.b / 2, self.b / 2, n)
        return np.vstack([np.column_stack([xs, np.full(n, self.H)]),
                          np.column_stack([xs, np.full(n, self.H + self.h)])])


@dataclass(frozen=True)
class Cylinder:
    """``x^2 + y^2 <= rw^2``, ``z in [-(H + h), -H]`` (mm)."""

    rw: float
    H: float
    h: float
    kind = "cylinder"
    keys = ("rw", "H", "h")
    sizes = ("rw", "h")
    #: keys that are distances from the base, positive (the workspace is below the base)
    distances = ("H",)
    n = 3
    scheme_name = "ring"

    def bounds(self):
        """Bounding box ``(lo, hi)``, ndarray shape (3,) each."""
        return (np.array([-self.rw, -self.rw, -self.H - self.h]), np.array([self.rw, self.rw, -self.H]))

    def corners(self) -> dict:
        """Label -> (x, y, z): the rims' points at azimuths 0, 90, 180, 270 deg and the axis ends."""
        out = {}
        for zl, z in (("top", -self.H), ("bottom", -self.H - self.h)):
            out[f"{zl} centre"] = (0.0, 0.0, z)
            for a in (0, 90, 180, 270):
                t = np.radians(a)
                out[f"{zl} rim {a} deg"] = (self.rw * np.cos(t), self.rw * np.sin(t), z)
        return out

    def grid(self, nr: int = 4, na: int = 24, nz: int = 5) -> np.ndarray:
        """Polar grid: the axis and ``nr`` rings of ``na`` points, on ``nz`` levels, shape (N, 3)."""
        pts = []
        for z in np.linspace(-self.H - self.h, -self.H, nz):
            pts.append((0.0, 0.0, z))
            for rad in np.linspace(self.rw / nr, self.rw, nr):
                for t in np.linspace(0, 2 * np.pi, na, endpoint=False):
                    pts.append((rad * np.cos(t), rad * np.sin(t), z))
        return np.array(pts)

    def contains(self, P, tol: float = 1e-6) -> np.ndarray:
        P = np.atleast_2d(P)
        return ((np.hypot(P[:, 0], P[:, 1]) <= self.rw + tol)
                & (P[:, 2] >= -self.H - self.h - tol) & (P[:, 2] <= -self.H + tol))

    def describe(self) -> str:
        return f"x^2 + y^2 <= {self.rw:g}^2, z in [{-self.H - self.h:g}, {-self.H:g}]"

    def ranges(self) -> dict:
        return {"r": [0.0, self.rw], "z": [-self.H - self.h, -self.H]}

    def to_dict(self) -> dict:
        return {"rw": self.rw, "H": self.H, "h": self.h}

    def boundary_scheme(self, n: int) -> np.ndarray:
        """The ring scheme: n poses on the top circle at azimuths ``360 deg j/n``, then on the bottom one.

        Returns
        -------
        ndarray, shape (2n, 3)
        """
        if n < 2:
            raise PoseError(f"the ring scheme needs n >= 2 poses per circle, got n = {n}")
        t = 2 * np.pi * np.arange(n) / n
        ring = np.column_stack([self.rw * np.cos(t), self.rw * np.sin(t)])
        return np.vstack([np.column_stack([ring, np.full(n, -self.H)]),
                          np.column_stack([ring, np.full(n, -self.H - self.h)])])


SHAPES = {"rectangle": Rectangle, "cylinder": Cylinder}


def make_workspace(kind: str, values: dict):
    """The workspace of shape ``kind`` from its keys (floats, mm)."""
    cls = SHAPES[kind]
    return cls(**{k: float(values[k]) for k in cls.keys})
