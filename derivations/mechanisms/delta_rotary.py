"""The rotary Delta robot with a spherical-joint measuring mechanism (``docs/delta.md``).

Frame: origin O at the centre of the plane of the shoulder axes, z up, the
workspace below the base (z < 0).  Limb i at azimuth ``phi_i`` with
``e_i = (cos phi_i, sin phi_i, 0)``; shoulder ``A_i = R_i e_i + (0, 0, z_i)``;
upper arm ``u_i = (cos th_i cos phi_i, cos th_i sin phi_i, -sin th_i)``
(``th_i = 0`` horizontal and outward, positive downward), elbow
``B_i = A_i + L_i u_i``; the parallelogram forearm of length ``l_i`` reaches
``C_i = P + r e_i`` (the platform translates).  Loop closure
``|C_i - B_i|^2 = l_i^2``.

Given here, the rest derived by :func:`derivations.mechanism.derive`:

* inverse kinematics on the elbow-outward branch (continuous with ``th = 0``):
  ``a cos th + b sin th = K`` with ``D = P + r e_i - A_i``, ``a = D . e_i``,
  ``b = -D_z``, ``K = (|D|^2 + L^2 - l^2) / (2 L)``,
  ``th = atan2(b, a) - acos(K / sqrt(a^2 + b^2))``;
* forward kinematics: the intersection of the spheres centred at
  ``B_i - r e_i`` of radii ``l_i`` with the smaller z (trilateration);
* singularity indicators: per limb ``w_i . du_i/dth_i`` (the sine of the
  transmission angle; zero at a serial singularity) and ``det[w_1; w_2; w_3]``
  of the unit forearm directions (zero at a parallel singularity);
* the gauge: a vertical translation of the robot against the measuring
  mechanism (``dz_i = drMz``) and a rotation about z (``dphi_i`` with the part
  of ``rM`` that moves ``c + d``).

``r`` carries no error: with ``e_i`` of the platform using the actual
``phi_i`` an error of ``r`` is exactly an error of every ``R_i``.
"""
from __future__ import annotations

import sympy as sp

from derivations.geometry import trilaterate
from derivations.mechanism import SKETCH, SourceError, SymbolicMechanism, derive, sketch_output

LIMBS = (1, 2, 3)


def build() -> SymbolicMechanism:
    """The mechanism with every output derived."""
    x, y, z = sp.symbols("x y z", real=True)
    th = list(sp.symbols("theta1 theta2 theta3", real=True))
    R = list(sp.symbols("R1 R2 R3", real=True))
    phi = list(sp.symbols("phi1 phi2 phi3", real=True))
    zs = list(sp.symbols("z1 z2 z3", real=True))
    L = list(sp.symbols("L1 L2 L3", real=True))
    ll = list(sp.symbols("l1 l2 l3", real=True))
    r = sp.Symbol("r", real=True)
    cx, cy, cz, dx, dy, dz = sp.symbols("cx cy cz dx dy dz", real=True)
    geometry = R + phi + zs + L + ll + [r, cx, cy, cz, dx, dy, dz]
    P = sp.Matrix([x, y, z])
    ez = sp.Matrix([0, 0, 1])

    e = [sp.Matrix([sp.cos(p), sp.sin(p), 0]) for p in phi]
    A = [R[i] * e[i] + zs[i] * ez for i in range(3)]
    u = [sp.Matrix([sp.cos(th[i]) * sp.cos(phi[i]), sp.cos(th[i]) * sp.sin(phi[i]), -sp.sin(th[i])])
         for i in range(3)]
    du = [sp.diff(u[i], th[i]) for i in range(3)]
    B = [A[i] + L[i] * u[i] for i in range(3)]
    C = [P + r * e[i] for i in range(3)]
    fore = [C[i] - B[i] for i in range(3)]  # = l_i w_i on the robot
    loop = [sp.expand(fore[i].dot(fore[i]) - ll[i] ** 2) for i in range(3)]

    # --- inverse kinematics, elbow outward
    ik, ratio = [], []
    for i in range(3):
        D = P + r * e[i] - A[i]
        a, b = D.dot(e[i]), -D[2]
        K = (D.dot(D) + L[i] ** 2 - ll[i] ** 2) / (2 * L[i])
        ratio.append(K / sp.sqrt(a**2 + b**2))
        ik.append(sp.atan2(b, a) - sp.acos(ratio[-1]))

    # --- forward kinematics: trilateration of the spheres (B_i - r e_i, l_i), smaller z
    p = [B[i] - r * e[i] for i in range(3)]
    fk = trilaterate(p, ll)

    # --- singularity indicators
    w = [fore[i] / ll[i] for i in range(3)]
    trans = sp.Matrix([w[i].dot(du[i]) for i in range(3)]
                      + [sp.Matrix.hstack(w[0], w[1], w[2]).T.det()])

    offsets = [SourceError(f"theta{k}", th[k - 1], "zero_offset", "rad", L[k - 1]) for k in LIMBS]
    geo_err = ([SourceError(str(s), s, "geometry", "mm") for s in R]
               + [SourceError(str(phi[i]), phi[i], "geometry", "rad", R[i]) for i in range(3)]
               + [SourceError(str(s), s, "geometry", "mm") for s in zs + L + ll])
    meas = [SourceError(n, s, "measuring", "mm") for n, s in (("rMx", cx), ("rMy", cy), ("rMz", cz))]
    source_errors = offsets + geo_err + meas
    names = [s.name for s in source_errors]

    def gen(**kw):
        return [kw.get(nm, 0) for nm in names]

    gauge = {
        "translation z": gen(z1=1, z2=1, z3=1, rMz=1),
        "rotation about z": gen(phi1=1, phi2=1, phi3=1, rMx=-(cy + dy), rMy=cx + dx),
    }

    mech = SymbolicMechanism(
        name="delta_rotary",
        description="rotary Delta robot (three RSS limbs, parallelogram forearms) with a spherical-joint "
                    "measuring mechanism",
        pose=[x, y, z],
        joints=th,
        geometry=geometry,
        geometry_units={str(s): "rad" for s in phi},
        loop_closure=loop,
        ik=sp.Matrix(ik),
        ratio=sp.Matrix(ratio),
        fk=fk,
        transmission=trans,
        home_joints=[0.0, 0.0, 0.0],
        base_point=sp.Matrix([cx, cy, cz]),
        platform_offset=sp.Matrix([dx, dy, dz]),
        source_errors=source_errors,
        gauge=gauge,
        workspace="cylinder",
        aliases={"R": {"R1": 1.0, "R2": 1.0, "R3": 1.0}, "L": {"L1": 1.0, "L2": 1.0, "L3": 1.0},
                 "l": {"l1": 1.0, "l2": 1.0, "l3": 1.0}},
        defaults={"phi1": 0.0, "phi2": 120.0, "phi3": 240.0, "z1": 0.0, "z2": 0.0, "z3": 0.0},
        param_sets={"lengths": ("L1", "L2", "L3", "l1", "l2", "l3"),
                    "base": ("R1", "R2", "R3", "phi1", "phi2", "phi3", "z1", "z2", "z3")},
        positive=("R1", "R2", "R3", "L1", "L2", "L3", "l1", "l2", "l3", "r"),
        gauge_fix=("z1", "phi1"),  # shoulder 1 at its nominal height and azimuth
    )
    # the drawing: the shoulders' triangle, each upper arm A_i B_i and forearm B_i C_i, the platform's triangle
    ring = [(i, (i + 1) % 3) for i in range(3)]
    mech.extra_outputs = {SKETCH: sketch_output(mech, [(A[i], A[j]) for i, j in ring]
                                                + [seg for i in range(3) for seg in ((A[i], B[i]), (B[i], C[i]))]
                                                + [(C[i], C[j]) for i, j in ring])}
    return derive(mech)
