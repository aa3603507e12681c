"""Vector helpers the derivation modules share (sympy): cross product, norm, trilateration."""
from __future__ import annotations

import sympy as sp


def cross(a, b):
    """``a x b`` of two 3-vectors (Matrix (3, 1))."""
    return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def norm(v):
    """``|v|``."""
    return sp.sqrt(v.dot(v))


def trilaterate(p, radii):
    """The intersection of three spheres (centres ``p``, ``radii``) below the plane of the centres.

    The sign of the normal's z picks the intersection below the plane of the three centres (a Delta's platform
    hangs below its elbows or carriages).
    """
    d21, d31 = p[1] - p[0], p[2] - p[0]
    dd = norm(d21)
    ex_ = d21 / dd
    ii = ex_.dot(d31)
    ey_raw = d31 - ii * ex_
    ey_ = ey_raw / norm(ey_raw)
    ez_ = cross(ex_, ey_)
    jj = ey_.dot(d31)
    xs = (radii[0] ** 2 - radii[1] ** 2 + dd**2) / (2 * dd)
    ys = (radii[0] ** 2 - radii[2] ** 2 + ii**2 + jj**2) / (2 * jj) - ii * xs / jj
    hs = sp.sqrt(radii[0] ** 2 - xs**2 - ys**2)
    return p[0] + xs * ex_ + ys * ey_ - sp.sign(ez_[2]) * hs * ez_
