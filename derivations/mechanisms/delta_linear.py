"""The linear Delta robot (three prismatic towers) with a spherical-joint measuring mechanism.

Frame: origin at the centre of the bed, z up, the workspace above the bed.
Tower i at azimuth ``phi_i`` with ``e_i = (cos phi_i, sin phi_i, 0)``; the
carriage pivot ``A_i = R_i e_i + s_i e_z`` (``s_i`` the carriage height, the
joint variable, mm); the effector translates, its pivot ``C_i = P + r e_i``;
two parallel rods of length ``l_i``: ``|A_i - C_i| = l_i``.  Equivalently
``|P - S_i| = l_i`` with the sphere centre ``S_i = (R_i - r) e_i + s_i e_z``.

Given here, the rest derived by :func:`derivations.mechanism.derive`:

* inverse kinematics, carriage above the effector:
  ``s_i = z + sqrt(l_i^2 - |(R_i - r) e_i - (x, y, 0)|^2)``, with the reach
  ratio ``|(R_i - r) e_i - (x, y, 0)| / l_i``;
* forward kinematics: trilateration of the three spheres, the solution with
  the effector below the carriages (smaller z);
* singularity indicators: per tower the vertical component of the unit rod
  direction (zero when a rod lies horizontal, where ``ds/dP`` is unbounded)
  and ``det[w_1; w_2; w_3]`` of the unit rod directions (parallel singularity);
* the measuring mechanism: ``O1 = c`` on the bed, ``O2 = P + d`` on the
  effector, ``lambda = P + d - c``; its errors ``rM`` are carried on ``c``
  (the actual vector ``P' + d - c - rM``: ``rM`` lumps ``dc - dd``);
* the gauge: the vertical translation of the robot against ``c``
  (``ds_1 = ds_2 = ds_3 = rMz``), the two horizontal translations of the
  towers with ``c``, and the rotation about z (``dphi_i = alpha``,
  ``rM = alpha e_z x (c - d)``).  The default identified set therefore holds
  ``rMz``: a common carriage offset *is* a vertical shift against ``c``, and
  the offsets found are relative to ``c``.

``r`` carries no error: with ``e_i`` of the effector using the actual
``phi_i`` an error of ``r`` is exactly an error of every ``R_i``.
"""
from __future__ import annotations

import sympy as sp

from derivations.geometry import trilaterate
from derivations.mechanism import (HOME_WORKSPACE_CENTRE, SKETCH, SourceError, SymbolicMechanism, derive,
                                   sketch_output)

TOWERS = (1, 2, 3)


def build() -> SymbolicMechanism:
    """The mechanism with every output derived."""
    x, y, z = sp.symbols("x y z", real=True)
    s = list(sp.symbols("s1 s2 s3", real=True))
    R = list(sp.symbols("R1 R2 R3", real=True))
    phi = list(sp.symbols("phi1 phi2 phi3", real=True))
    ll = list(sp.symbols("l1 l2 l3", real=True))
    r = sp.Symbol("r", real=True)
    cx, cy, cz, dx, dy, dz = sp.symbols("cx cy cz dx dy dz", real=True)
    geometry = R + phi + ll + [r, cx, cy, cz, dx, dy, dz]
    P = sp.Matrix([x, y, z])
    ez = sp.Matrix([0, 0, 1])
    c, d = sp.Matrix([cx, cy, cz]), sp.Matrix([dx, dy, dz])

    e = [sp.Matrix([sp.cos(p), sp.sin(p), 0]) for p in phi]
    S = [(R[i] - r) * e[i] + s[i] * ez for i in range(3)]  # sphere centres
    rod = [P - S[i] for i in range(3)]  # = l_i w_i on the robot
    loop = [sp.expand(rod[i].dot(rod[i]) - ll[i] ** 2) for i in range(3)]

    # --- inverse kinematics: carriage above the effector
    ik, ratio = [], []
    for i in range(3):
        hor = (R[i] - r) * e[i] - sp.Matrix([x, y, 0])
        rho2 = hor[0] ** 2 + hor[1] ** 2
        ratio.append(sp.sqrt(rho2) / ll[i])
        ik.append(z + sp.sqrt(ll[i] ** 2 - rho2))

    # --- forward kinematics: trilateration, the effector below the carriages
    fk = trilaterate(S, ll)

    # --- singularity indicators
    w = [rod[i] / ll[i] for i in range(3)]
    trans = sp.Matrix([-w[i][2] for i in range(3)] + [sp.Matrix.hstack(w[0], w[1], w[2]).T.det()])

    offsets = [SourceError(f"s{k}", s[k - 1], "zero_offset", "mm") for k in TOWERS]
    geo_err = ([SourceError(str(v), v, "geometry", "mm") for v in R]
               + [SourceError(str(phi[i]), phi[i], "geometry", "rad", R[i]) for i in range(3)]
               + [SourceError(str(v), v, "geometry", "mm") for v in ll])
    meas = [SourceError(nm, v, "measuring", "mm") for nm, v in (("rMx", cx), ("rMy", cy), ("rMz", cz))]
    source_errors = offsets + geo_err + meas
    names = [v.name for v in source_errors]

    def gen(**kw):
        return [kw.get(nm, 0) for nm in names]

    def shift(t):
        """The towers and c translated horizontally by t (R_i and phi_i of the sphere centres)."""
        kw = {}
        for i in range(3):
            eperp = sp.Matrix([-sp.sin(phi[i]), sp.cos(phi[i]), 0])
            kw[f"R{i + 1}"] = e[i].dot(t)
            kw[f"phi{i + 1}"] = eperp.dot(t) / (R[i] - r)
        return gen(**kw, rMx=t[0], rMy=t[1])

    gauge = {
        "translation z": gen(s1=1, s2=1, s3=1, rMz=1),
        "translation x": shift(sp.Matrix([1, 0, 0])),
        "translation y": shift(sp.Matrix([0, 1, 0])),
        "rotation about z": gen(phi1=1, phi2=1, phi3=1, rMx=-(cy - dy), rMy=cx - dx),
    }

    mech = SymbolicMechanism(
        name="delta_linear",
        description="linear Delta robot (three prismatic towers, parallel rods) with a spherical-joint "
                    "measuring mechanism",
        pose=[x, y, z],
        joints=s,
        joint_kinds=["prismatic"] * 3,
        geometry=geometry,
        geometry_units={str(v): "rad" for v in phi},
        loop_closure=loop,
        ik=sp.Matrix(ik),
        ratio=sp.Matrix(ratio),
        fk=fk,
        transmission=trans,
        home_joints=None,
        home_pose=HOME_WORKSPACE_CENTRE,
        base_point=c,
        platform_offset=d,
        measuring_vector=P + d - c,
        source_errors=source_errors,
        gauge=gauge,
        workspace="cylinder",
        workspace_defaults={"ring_azimuth": 90.0},
        aliases={"R": {"R1": 1.0, "R2": 1.0, "R3": 1.0}, "l": {"l1": 1.0, "l2": 1.0, "l3": 1.0}},
        defaults={"phi1": 90.0, "phi2": 210.0, "phi3": 330.0},
        param_sets={"lengths": ("l1", "l2", "l3"), "base": ("R1", "R2", "R3", "phi1", "phi2", "phi3")},
        default_set=("s1", "s2", "s3", "rMx", "rMy"),
        positive=("R1", "R2", "R3", "l1", "l2", "l3", "r"),
        gauge_fix=("rMz", "R1", "phi1", "phi2"),
        noise={"scale": 0.002, "joint": 0.005},
    )
    # the drawing: the towers' feet on the bed, each tower up to its carriage A_i, the rod A_i C_i, the effector
    foot = [R[i] * e[i] for i in range(3)]
    A = [foot[i] + s[i] * ez for i in range(3)]
    C = [P + r * e[i] for i in range(3)]
    ring = [(i, (i + 1) % 3) for i in range(3)]
    mech.extra_outputs = {SKETCH: sketch_output(mech, [(foot[i], foot[j]) for i, j in ring]
                                                + [seg for i in range(3) for seg in ((foot[i], A[i]), (A[i], C[i]))]
                                                + [(C[i], C[j]) for i, j in ring])}
    return derive(mech)
