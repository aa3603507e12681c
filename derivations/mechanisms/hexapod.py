"""A 6-6 Gough-Stewart hexapod (six prismatic legs) with a spherical-joint measuring mechanism.

Frame: the base frame, origin at the centre of the base, z up.  Base joints
``B_i = Rb (cos beta_i, sin beta_i, 0) + b_i``, platform joints
``p_i = Rp (cos pi_i, sin pi_i, 0) + q_i`` in the platform frame (``b_i``,
``q_i``: the joints' corrections, default zero, the carriers of their errors);
the pose ``(x, y, z, roll, pitch, yaw)``: ``P = (x, y, z)`` and
``Rot = Rz(yaw) Ry(pitch) Rx(roll)`` (roll about the fixed x first, then pitch
about the fixed y, then yaw about the fixed z).  Leg i joins ``B_i`` to
``P + Rot p_i``; its length ``L_i`` is the joint variable (mm).

Given here, the rest derived by :func:`derivations.mechanism.derive`:

* inverse kinematics: ``L_i = |P + Rot p_i - B_i|``; the reach ratio is the
  leg's travel from its home length over the stroke, ``|ratio| <= 1`` within
  the stroke;
* forward kinematics: a solve (:class:`~derivations.mechanism.FkSolve`),
  Newton on the six leg equations in the pose coordinates from the home pose
  ``(0, 0, z_home, 0, 0, 0)``;
* the pose error Jacobian solved numerically (``jacobian_form = "solve"``: a
  6 x 6 adjugate is out of reach);
* singularity indicator: ``det M / det M_home`` with ``M`` the rows
  ``[u_i^T, ((Rot p_i) x u_i)^T / 100 mm]`` of the unit leg directions (one at
  home, zero at a parallel singularity; prismatic legs have no serial one);
* the measuring mechanism: ``O1 = c`` on the base, ``O2 = P + Rot d`` on the
  platform; its errors ``rM`` (on ``c``, base frame) and ``dd`` (on ``d``,
  platform frame) cannot be lumped: ``d`` turns with the platform;
* the gauge: 12 rigid motions -- the robot's base side against the measuring
  base point (``db_i = t + w x B_i``, ``rM = t + w x c``) and the platform
  frame redefined (``dq_i = t + w x p_i``, ``dd = t + w x d``).
"""
from __future__ import annotations

import sympy as sp

from derivations.geometry import cross, norm
from derivations.mechanism import (SKETCH, Determinant, FkSolve, SourceError, SymbolicMechanism, derive,
                                   sketch_output)

LEGS = (1, 2, 3, 4, 5, 6)
#: the rotation columns of the singularity indicator's matrix are scaled by this length (mm)
ROTATION_SCALE_MM = 100


def rotation(roll, pitch, yaw):
    """``Rz(yaw) Ry(pitch) Rx(roll)``."""
    cr, sr, cp, sp_, cyw, syw = sp.cos(roll), sp.sin(roll), sp.cos(pitch), sp.sin(pitch), sp.cos(yaw), sp.sin(yaw)
    Rx = sp.Matrix([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = sp.Matrix([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    Rz = sp.Matrix([[cyw, -syw, 0], [syw, cyw, 0], [0, 0, 1]])
    return Rz * Ry * Rx


def _leg_matrix(P, Rot, B, p):
    """Rows ``[u_i^T, ((Rot p_i) x u_i)^T / ROTATION_SCALE_MM]``, the unit leg vectors u_i."""
    rows = []
    for Bi, pi in zip(B, p):
        w = P + Rot * pi - Bi
        u = w / norm(w)
        rows.append(list(u) + list(cross(Rot * pi, u) / ROTATION_SCALE_MM))
    return sp.Matrix(rows)


def build() -> SymbolicMechanism:
    """The mechanism with every output derived."""
    x, y, z, roll, pitch, yaw = sp.symbols("x y z roll pitch yaw", real=True)
    L = list(sp.symbols("L1:7", real=True))
    Rb, Rp, z_home, stroke = sp.symbols("Rb Rp z_home stroke", real=True)
    beta = list(sp.symbols("beta1:7", real=True))
    pis = list(sp.symbols("pi1:7", real=True))
    b = [list(sp.symbols(f"b{i}x b{i}y b{i}z", real=True)) for i in LEGS]
    q = [list(sp.symbols(f"q{i}x q{i}y q{i}z", real=True)) for i in LEGS]
    cx, cy, cz, dx, dy, dz = sp.symbols("cx cy cz dx dy dz", real=True)
    geometry = ([Rb, Rp, z_home, stroke] + beta + pis + [v for bi in b for v in bi] + [v for qi in q for v in qi]
                + [cx, cy, cz, dx, dy, dz])
    P = sp.Matrix([x, y, z])
    Rot = rotation(roll, pitch, yaw)
    c, d = sp.Matrix([cx, cy, cz]), sp.Matrix([dx, dy, dz])
    B = [Rb * sp.Matrix([sp.cos(beta[i]), sp.sin(beta[i]), 0]) + sp.Matrix(b[i]) for i in range(6)]
    p = [Rp * sp.Matrix([sp.cos(pis[i]), sp.sin(pis[i]), 0]) + sp.Matrix(q[i]) for i in range(6)]
    legs = [P + Rot * p[i] - B[i] for i in range(6)]
    loop = [legs[i].dot(legs[i]) - L[i] ** 2 for i in range(6)]

    home = sp.Matrix([0, 0, z_home, 0, 0, 0])
    P_home = sp.Matrix([0, 0, z_home])
    home_length = [norm(P_home + p[i] - B[i]) for i in range(6)]
    ik = sp.Matrix([norm(w) for w in legs])
    ratio = sp.Matrix([(ik[i] - home_length[i]) / stroke for i in range(6)])

    det, det_home = sp.Symbol("det_M", real=True), sp.Symbol("det_M_home", real=True)
    dets = (Determinant(sp.Matrix([det]), _leg_matrix(P, Rot, B, p)),
            Determinant(sp.Matrix([det_home]), _leg_matrix(P_home, sp.eye(3), B, p)))
    trans = sp.Matrix([det / det_home])

    offsets = [SourceError(f"L{k}", L[k - 1], "zero_offset", "mm") for k in LEGS]
    geo_err = ([SourceError(str(v), v, "geometry", "mm") for bi in b for v in bi]
               + [SourceError(str(v), v, "geometry", "mm") for qi in q for v in qi])
    meas = ([SourceError(nm, v, "measuring", "mm") for nm, v in (("rMx", cx), ("rMy", cy), ("rMz", cz))]
            + [SourceError(nm, v, "measuring", "mm") for nm, v in (("ddx", dx), ("ddy", dy), ("ddz", dz))])
    source_errors = offsets + geo_err + meas
    names = [v.name for v in source_errors]

    def rigid(points, carriers, extra, extra_names, t, w):
        kw = {}
        for pt, car in zip(points, carriers):
            mv = t + cross(w, pt)
            kw.update({str(car[k]): mv[k] for k in range(3)})
        mv = t + cross(w, extra)
        kw.update({extra_names[k]: mv[k] for k in range(3)})
        return [kw.get(nm, 0) for nm in names]

    axes = {"x": sp.Matrix([1, 0, 0]), "y": sp.Matrix([0, 1, 0]), "z": sp.Matrix([0, 0, 1])}
    zero = sp.zeros(3, 1)
    gauge = {}
    for side, pts, car, extra, enames in (("base", B, b, c, ("rMx", "rMy", "rMz")),
                                          ("platform", p, q, d, ("ddx", "ddy", "ddz"))):
        for ax, v in axes.items():
            gauge[f"{side} translation {ax}"] = rigid(pts, car, extra, enames, v, zero)
        for ax, v in axes.items():
            gauge[f"{side} rotation about {ax}"] = rigid(pts, car, extra, enames, zero, v)

    mech = SymbolicMechanism(
        name="hexapod",
        description="6-6 Gough-Stewart hexapod (six prismatic legs) with a spherical-joint measuring mechanism",
        pose=[x, y, z, roll, pitch, yaw],
        pose_units={"roll": "rad", "pitch": "rad", "yaw": "rad"},
        joints=L,
        joint_kinds=["prismatic"] * 6,
        geometry=geometry,
        geometry_units={str(v): "rad" for v in beta + pis},
        loop_closure=loop,
        ik=ik,
        ratio=ratio,
        # 5 Newton steps reach the round-off floor from home over the box and 1 mm beyond (the corners, 3000
        # random poses, joints perturbed by 1 mm); 7 leave two to spare
        fk=FkSolve(start=home, iterations=7, tol=1e-6),
        transmission=trans,
        transmission_solves=dets,
        home_joints=None,
        home_pose=home,
        base_point=c,
        platform_offset=d,
        measuring_vector=P + Rot * d - c,
        source_errors=source_errors,
        gauge=gauge,
        workspace="box",
        jacobian_form="solve",
        list_aliases={"base_angles": tuple(str(v) for v in beta), "platform_angles": tuple(str(v) for v in pis)},
        defaults={**{f"beta{i}": v for i, v in zip(LEGS, (345.0, 15.0, 105.0, 135.0, 225.0, 255.0))},
                  **{f"pi{i}": v for i, v in zip(LEGS, (315.0, 45.0, 75.0, 165.0, 195.0, 285.0))},
                  **{str(v): 0.0 for bi in b + q for v in bi}},
        param_sets={"base": tuple(str(v) for bi in b for v in bi),
                    "platform": tuple(str(v) for qi in q for v in qi),
                    "rM": ("rMx", "rMy", "rMz"), "dd": ("ddx", "ddy", "ddz")},
        positive=("Rb", "Rp", "z_home", "stroke"),
        # 3-2-1 on each side: three heights (t_z, w_x, w_y), then x, y of joint 1 and x of joint 2 (t_x, t_y, w_z)
        gauge_fix=("b1x", "b1y", "b1z", "b2x", "b2z", "b3z", "q1x", "q1y", "q1z", "q2x", "q2z", "q3z"),
        noise={"scale": 0.001, "joint": 0.002},
    )
    # the drawing: the base's and the platform's hexagons (the joints in leg order) and the six legs
    T = [P + Rot * p[i] for i in range(6)]
    ring = [(i, (i + 1) % 6) for i in range(6)]
    mech.extra_outputs = {SKETCH: sketch_output(mech, [(B[i], B[j]) for i, j in ring] + [(T[i], T[j]) for i, j in ring]
                                                + [(B[i], T[i]) for i in range(6)])}
    return derive(mech)
