"""Workspace shapes: where a robot is asked to go, and its boundary scheme.

A mechanism declares its workspace shape (its generated ``WORKSPACE``); a robot
file gives the sizes (mm, degrees):

``rectangle`` (2-D, the paper's)
    ``x in [-b/2, b/2]``, ``y in [H, H + h]``; keys ``H b h``.
``cylinder`` (3-D, the Deltas')
    ``x^2 + y^2 <= rw^2`` and either ``z in [-(H + h), -H]`` (keys ``rw H h``:
    a workspace below the base, the rotary Delta's) or ``z in [z_min, z_max]``
    (keys ``rw z_min z_max``: either direction, the linear Delta's);
    optional ``ring_azimuth`` (deg, default 0), where the ring scheme starts.
``box`` (6-D, a platform that translates and turns)
    ``|x|, |y| <= a``, ``z in [z_min, z_max]``, ``|roll|, |pitch| <= tilt_max``,
    ``|yaw| <= yaw_max`` (degrees); keys ``a z_min z_max tilt_max yaw_max``.

Each shape gives its bounding box, a grid and its rims (corners) for
validation, a membership test, and its *boundary scheme* -- the paper's pose
scheme carried to the shape: on the rectangle and the cylinder ``n`` poses on
each of the two boundaries (the paper's two horizontal edges; the top and
bottom circles, the ring scheme), ``K = 2n``, the second boundary visited in
the same order; on the box the corner scheme, ``K = n`` corners of the 6-D box
(all 64, or a regular fraction of 32 or 16).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import PoseError


class _Shape:
    """What every shape shares: the scheme's size and the keys' parsing."""

    #: optional keys (file units) and their defaults
    optional = {}

    @classmethod
    def from_values(cls, values: dict):
        """The shape from its robot-file keys (floats; degrees for angles).

        Raises
        ------
        KeyError
            Naming the missing keys.
        """
        missing = [k for k in cls.keys if k not in values and k not in cls.optional]
        if missing:
            raise KeyError(", ".join(missing))
        return cls(**{k: float(values.get(k, cls.optional.get(k))) for k in cls.keys})

    def scheme_size(self, n: int) -> int:
        """K, the poses of the boundary scheme with parameter ``n`` (2n: n per boundary)."""
        return 2 * n

    def scheme_sizes(self, K: int) -> list:
        """The scheme parameters n whose scheme has at most K poses."""
        return list(range(2, K // 2 + 1))

    def min_scheme_n(self, p: int) -> int:
        """The smallest scheme parameter n whose K - 1 changes are at least p."""
        return max(2, -(-(p + 1) // 2))


@dataclass(frozen=True)
class Rectangle(_Shape):
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

    def centre(self) -> np.ndarray:
        return np.array([0.0, self.H + self.h / 2])

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
class Cylinder(_Shape):
    """``x^2 + y^2 <= rw^2``, ``z in [z_lo, z_hi]`` (mm), given as ``rw H h`` (below the base) or ``rw z_min z_max``.

    Attributes
    ----------
    rw, zlo, zhi : float
        mm.
    ring_azimuth : float
        deg: the azimuth of the ring scheme's first pose.
    given : tuple of (str, float)
        The robot file's keys as given (what :meth:`to_dict` and the robot's hash see).
    """

    rw: float
    zlo: float
    zhi: float
    ring_azimuth: float = 0.0
    given: tuple = ()
    kind = "cylinder"
    keys = ("rw", "H", "h", "z_min", "z_max", "ring_azimuth")
    optional = {"ring_azimuth": 0.0}
    n = 3
    scheme_name = "ring"

    @classmethod
    def from_values(cls, values: dict):
        has_hh, has_z = {"H", "h"} & set(values), {"z_min", "z_max"} & set(values)
        if has_hh and has_z:
            raise KeyError("either H and h or z_min and z_max, not both")
        need = ("rw", "z_min", "z_max") if has_z else ("rw", "H", "h")
        missing = [k for k in need if k not in values]
        if missing:
            raise KeyError(", ".join(missing))
        v = {k: float(values[k]) for k in need + ("ring_azimuth",) if k in values}
        zlo, zhi = (v["z_min"], v["z_max"]) if has_z else (-v["H"] - v["h"], -v["H"])
        return cls(v["rw"], zlo, zhi, v.get("ring_azimuth", cls.optional["ring_azimuth"]), tuple(v.items()))

    @property
    def sizes(self) -> tuple:
        return tuple(k for k in ("rw", "h") if k in dict(self.given)) + (
            ("height",) if "z_min" in dict(self.given) else ())

    @property
    def distances(self) -> tuple:
        """Keys that are distances from the base, positive: ``H`` (the workspace below the base), when given."""
        return ("H",) if "H" in dict(self.given) else ()

    @property
    def height(self) -> float:
        return self.zhi - self.zlo

    @property
    def H(self) -> float:
        return -self.zhi

    @property
    def h(self) -> float:
        return self.zhi - self.zlo

    @property
    def zmin(self) -> float:
        return self.zlo

    @property
    def zmax(self) -> float:
        return self.zhi

    def bounds(self):
        """Bounding box ``(lo, hi)``, ndarray shape (3,) each."""
        return (np.array([-self.rw, -self.rw, self.zlo]), np.array([self.rw, self.rw, self.zhi]))

    def corners(self) -> dict:
        """Label -> (x, y, z): the rims' points at azimuths 0, 90, 180, 270 deg and the axis ends."""
        out = {}
        for zl, z in (("top", self.zhi), ("bottom", self.zlo)):
            out[f"{zl} centre"] = (0.0, 0.0, z)
            for a in (0, 90, 180, 270):
                t = np.radians(a)
                out[f"{zl} rim {a} deg"] = (self.rw * np.cos(t), self.rw * np.sin(t), z)
        return out

    def grid(self, nr: int = 4, na: int = 24, nz: int = 5) -> np.ndarray:
        """Polar grid: the axis and ``nr`` rings of ``na`` points, on ``nz`` levels, shape (N, 3)."""
        pts = []
        for z in np.linspace(self.zlo, self.zhi, nz):
            pts.append((0.0, 0.0, z))
            for rad in np.linspace(self.rw / nr, self.rw, nr):
                for t in np.linspace(0, 2 * np.pi, na, endpoint=False):
                    pts.append((rad * np.cos(t), rad * np.sin(t), z))
        return np.array(pts)

    def contains(self, P, tol: float = 1e-6) -> np.ndarray:
        P = np.atleast_2d(P)
        return ((np.hypot(P[:, 0], P[:, 1]) <= self.rw + tol)
                & (P[:, 2] >= self.zlo - tol) & (P[:, 2] <= self.zhi + tol))

    def describe(self) -> str:
        return f"x^2 + y^2 <= {self.rw:g}^2, z in [{self.zlo:g}, {self.zhi:g}]"

    def ranges(self) -> dict:
        return {"r": [0.0, self.rw], "z": [self.zlo, self.zhi]}

    def centre(self) -> np.ndarray:
        """The centre of the cylinder's axis, shape (3,)."""
        return np.array([0.0, 0.0, (self.zlo + self.zhi) / 2])

    def to_dict(self) -> dict:
        return dict(self.given) if self.given else {"rw": self.rw, "H": self.H, "h": self.h}

    def boundary_scheme(self, n: int) -> np.ndarray:
        """The ring scheme: n poses on the top circle at azimuths ``ring_azimuth + 360 deg j/n``, then on the
        bottom one in the same order.

        Returns
        -------
        ndarray, shape (2n, 3)
        """
        if n < 2:
            raise PoseError(f"the ring scheme needs n >= 2 poses per circle, got n = {n}")
        t = 2 * np.pi * np.arange(n) / n + np.radians(self.ring_azimuth)
        ring = np.column_stack([self.rw * np.cos(t), self.rw * np.sin(t)])
        return np.vstack([np.column_stack([ring, np.full(n, self.zhi)]),
                          np.column_stack([ring, np.full(n, self.zlo)])])


#: the corner scheme's fractions of the 6-D box: K -> the coordinates set by XOR of others' bits (a regular
#: fraction: every coordinate still at both of its limits, the design balanced)
BOX_FRACTIONS = {
    64: {},
    32: {5: (0, 1, 2, 3, 4)},             # yaw = x ^ y ^ z ^ roll ^ pitch
    16: {4: (0, 1, 2), 5: (1, 2, 3)},     # pitch = x ^ y ^ z, yaw = y ^ z ^ roll
}


def corner_points(lo, hi, K: int, gens: dict) -> np.ndarray:
    """K corners of the box ``[lo, hi]`` (n-D): k runs over the free coordinates' bits (coordinate j at its
    maximum where its bit is 1), each coordinate of ``gens`` (j -> source coordinates) the XOR of its sources'.

    Returns
    -------
    ndarray, shape (K, n)
    """
    n = len(lo)
    free = [j for j in range(n) if j not in gens]
    out = []
    for k in range(K):
        bits = [0] * n
        for i, j in enumerate(free):
            bits[j] = (k >> i) & 1
        for j, src in gens.items():
            bits[j] = int(np.bitwise_xor.reduce([bits[i] for i in src]))
        out.append(np.where(bits, hi, lo))
    return np.array(out)


@dataclass(frozen=True)
class Box(_Shape):
    """The 6-D box ``|x|, |y| <= a``, ``z in [z_min, z_max]``, ``|roll|, |pitch| <= tilt_max``, ``|yaw| <= yaw_max``.

    Lengths in mm; ``tilt_max`` and ``yaw_max`` in degrees (as in the robot file).
    """

    a: float
    z_min: float
    z_max: float
    tilt_max: float
    yaw_max: float
    kind = "box"
    keys = ("a", "z_min", "z_max", "tilt_max", "yaw_max")
    sizes = ("a", "tilt_max", "yaw_max")
    angles = ("tilt_max", "yaw_max")
    n = 6
    scheme_name = "corners"

    def bounds(self):
        """``(lo, hi)``, ndarray shape (6,) each (mm, rad)."""
        t, y = np.radians(self.tilt_max), np.radians(self.yaw_max)
        return (np.array([-self.a, -self.a, self.z_min, -t, -t, -y]),
                np.array([self.a, self.a, self.z_max, t, t, y]))

    def corner(self, k: int) -> np.ndarray:
        """Corner ``k`` (0..63): coordinate j at its maximum where bit j of k is 1, shape (6,)."""
        lo, hi = self.bounds()
        return np.where([(k >> j) & 1 for j in range(6)], hi, lo)

    def corners(self) -> dict:
        """Label -> pose: the 64 corners."""
        return {f"corner {k}": tuple(self.corner(k)) for k in range(64)}

    def grid(self, k: int = 3) -> np.ndarray:
        """``k^6`` poses on a regular grid, shape (k^6, 6)."""
        lo, hi = self.bounds()
        axes = [np.linspace(lo[i], hi[i], k) for i in range(6)]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 6)

    def contains(self, P, tol: float = 1e-6) -> np.ndarray:
        lo, hi = self.bounds()
        P = np.atleast_2d(P)
        return np.all((P >= lo - tol) & (P <= hi + tol), axis=1)

    def describe(self) -> str:
        return (f"|x|, |y| <= {self.a:g}, z in [{self.z_min:g}, {self.z_max:g}], |roll|, |pitch| <= "
                f"{self.tilt_max:g} deg, |yaw| <= {self.yaw_max:g} deg")

    def ranges(self) -> dict:
        return {"x": [-self.a, self.a], "y": [-self.a, self.a], "z": [self.z_min, self.z_max],
                "roll_deg": [-self.tilt_max, self.tilt_max], "pitch_deg": [-self.tilt_max, self.tilt_max],
                "yaw_deg": [-self.yaw_max, self.yaw_max]}

    def centre(self) -> np.ndarray:
        return np.array([0.0, 0.0, (self.z_min + self.z_max) / 2, 0.0, 0.0, 0.0])

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.keys}

    def scheme_size(self, n: int) -> int:
        """The corner scheme has K = n corners."""
        return n

    def scheme_sizes(self, K: int) -> list:
        return [k for k in sorted(BOX_FRACTIONS) if k <= K]

    def min_scheme_n(self, p: int) -> int:
        fit = [k for k in sorted(BOX_FRACTIONS) if k - 1 >= p]
        if not fit:
            raise PoseError(f"the corner scheme's {max(BOX_FRACTIONS)} corners give too few changes for {p} "
                            "parameters")
        return fit[0]

    def boundary_scheme(self, n: int) -> np.ndarray:
        """The corner scheme: the 64 corners in binary order, or the regular fraction of 32 or 16.

        Corner k sets coordinate j of ``(x, y, z, roll, pitch, yaw)`` to its maximum where bit j of k is 1; a
        fraction runs k over the free coordinates' bits and sets the others to the XOR of the bits
        :data:`BOX_FRACTIONS` names (16: pitch = x ^ y ^ z, yaw = y ^ z ^ roll; 32: yaw = x ^ ... ^ pitch).

        Returns
        -------
        ndarray, shape (n, 6)
        """
        if n not in BOX_FRACTIONS:
            raise PoseError(f"the corner scheme has n = {', '.join(str(k) for k in sorted(BOX_FRACTIONS))} corners "
                            f"(all 64 or a regular fraction), got n = {n}")
        gens = BOX_FRACTIONS[n]
        lo, hi = self.bounds()
        return corner_points(lo, hi, n, gens)


SHAPES = {"rectangle": Rectangle, "cylinder": Cylinder, "box": Box}


def make_workspace(kind: str, values: dict):
    """The workspace of shape ``kind`` from its keys (floats; mm, degrees)."""
    return SHAPES[kind].from_values(values)
