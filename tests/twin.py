"""An independent numpy twin of the planar robot's kinematics for tests.

Written from the SPEC's statement, not from the derivation: IK by solving
``X cos th + Y sin th = K`` through the half-angle substitution of the paper's
Eq. (3), FK by the paper's Eqs. (5)-(8) elimination.
"""
import numpy as np


def geometry_parts(g):
    e = [np.array(g[0:2]), np.array(g[2:4])]
    return e, g[4:6], g[6:8]


def ik(g, P):
    """Paper Eq. (3): th_i = 2 atan((-C -+ sqrt(C^2 - D^2... )) -- with the outward branch."""
    e, L, l = geometry_parts(g)
    out = []
    for i, sgn in ((0, +1), (1, -1)):
        X, Y = P[0] - e[i][0], P[1] - e[i][1]
        # X cos t + Y sin t = K;  with t = 2 atan(z): (K + X) z^2 - 2 Y z + (K - X) = 0
        K = (X * X + Y * Y + L[i] ** 2 - l[i] ** 2) / (2 * L[i])
        a, b, c = K + X, -2 * Y, K - X
        disc = np.sqrt(b * b - 4 * a * c)
        z = (-b - sgn * disc) / (2 * a)
        t = 2 * np.arctan(z)
        out.append(t)
    th = np.array(out)
    th[1] = np.mod(th[1], 2 * np.pi)  # limb 2 lives around pi
    return th


def fk(g, th):
    """Paper Eqs. (5)-(8): subtract the two circle equations, solve the quadratic in y."""
    e, L, l = geometry_parts(g)
    B = [e[i] + L[i] * np.array([np.cos(th[i]), np.sin(th[i])]) for i in range(2)]
    F = 2 * (B[1][0] - B[0][0])
    M = 2 * (B[1][1] - B[0][1])
    S = B[0] @ B[0] - B[1] @ B[1] - (l[0] ** 2 - l[1] ** 2)
    # x = -(M y + S) / F ; substitute into |P - B1|^2 = l1^2
    a = 1 + (M / F) ** 2
    bq = 2 * (M / F) * (S / F + B[0][0]) - 2 * B[0][1]
    c = (S / F + B[0][0]) ** 2 + B[0][1] ** 2 - l[0] ** 2
    y = (-bq + np.sqrt(bq * bq - 4 * a * c)) / (2 * a)
    x = -(M * y + S) / F
    return np.array([x, y])
