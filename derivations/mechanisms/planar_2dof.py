"""The 2-DOF translational parallel robot of Mei et al. (2017), derived in sympy.

Frame (``docs/model.md``): origin O at the base centre, x from A2 towards A1, y from the
base towards the workspace.  Limb i: ``B_i = A_i + L_i u_i`` with
``u_i = (cos th_i, sin th_i)``; ``P = B_i + l_i w_i``, ``|w_i| = 1``.

Given here (the mechanism's particulars), the rest derived generically by
:func:`derivations.mechanism.derive` and written by :mod:`derivations.codegen`
into ``zerocal_sym/generated/planar_2dof.py``:

* closed-form inverse kinematics on the branch continuous with home
  (``th1 = 0``, ``th2 = pi``; elbows outward),
* forward kinematics (intersection of the two distal circles, the solution
  farther from the base),
* the sines of the transmission angles (singularity indicators),
* the gauge: the planar rigid motions of the robot against the measuring
  mechanism,
* the paper's Eq. (12) ``dP = J' dq'`` (2x10) as an extra output, checked
  symbolically (with the generic Eq. 13) against the forms written from the
  paper's text (:func:`check_paper_forms`).

Geometry vector ``g`` (mm): ``e1x e1y e2x e2y L1 L2 l1 l2 cx cy dx dy``.
Source errors (rad, mm): ``theta1 theta2 e1x e1y e2x e2y L1 L2 l1 l2 rMx rMy``;
``rM = dc + dd`` enters the distance only through ``c + d``, so it is carried as
an error on ``c``.
"""
from __future__ import annotations

import sympy as sp

from derivations.mechanism import (SKETCH, SourceError, SymbolicMechanism, derive, implicit_pose_jacobian,
                                   sketch_output)

Q = sp.Matrix([[0, -1], [1, 0]])


def _symbols():
    x, y = sp.symbols("x y", real=True)
    th1, th2 = sp.symbols("theta1 theta2", real=True)
    geo = sp.symbols("e1x e1y e2x e2y L1 L2 l1 l2 cx cy dx dy", real=True)
    return (x, y), (th1, th2), geo


def build() -> SymbolicMechanism:
    """The mechanism with every output derived."""
    (x, y), (th1, th2), geo = _symbols()
    e1x, e1y, e2x, e2y, L1, L2, l1, l2, cx, cy, dx, dy = geo
    P = sp.Matrix([x, y])
    e = [sp.Matrix([e1x, e1y]), sp.Matrix([e2x, e2y])]
    L = [L1, L2]
    ll = [l1, l2]
    th = [th1, th2]
    u = [sp.Matrix([sp.cos(t), sp.sin(t)]) for t in th]
    arm = [P - e[i] - L[i] * u[i] for i in range(2)]  # = l_i w_i on the robot
    loop = [sp.expand((arm[i].T * arm[i])[0] - ll[i] ** 2) for i in range(2)]

    # --- inverse kinematics: X cos th + Y sin th = K, branch continuous with home
    # (limb 1: th1 = atan2(Y, X) - acos(K/r) ; limb 2: th2 = atan2(Y, X) + acos(K/r))
    ik = []
    ratio = []
    for i, branch in enumerate((-1, +1)):
        X, Y = P[0] - e[i][0], P[1] - e[i][1]
        K = (X**2 + Y**2 + L[i] ** 2 - ll[i] ** 2) / (2 * L[i])
        r = sp.sqrt(X**2 + Y**2)
        ratio.append(K / r)
        ik.append(sp.atan2(Y, X) + branch * sp.acos(K / r))

    # --- forward kinematics: circle intersection, the solution with larger y
    B = [e[i] + L[i] * u[i] for i in range(2)]
    D = B[1] - B[0]
    dist = sp.sqrt(D[0] ** 2 + D[1] ** 2)
    a = (l1**2 - l2**2 + dist**2) / (2 * dist)
    hgt = sp.sqrt(l1**2 - a**2)
    # (Q D)_y = D_x: the sign of D_x picks the intersection with the larger y
    fk = B[0] + a * D / dist + sp.sign(D[0]) * hgt * (Q * D) / dist

    # --- conditioning: sines of the transmission angles and of the distal angle
    w = [arm[i] / ll[i] for i in range(2)]
    trans = sp.Matrix([
        (w[0].T * Q * u[0])[0],
        (w[1].T * Q * u[1])[0],
        w[0][0] * w[1][1] - w[0][1] * w[1][0],
    ])

    names = ["theta1", "theta2", "e1x", "e1y", "e2x", "e2y", "L1", "L2", "l1", "l2", "rMx", "rMy"]
    source_errors = (
        [SourceError("theta1", th1, "zero_offset", "rad", L1), SourceError("theta2", th2, "zero_offset", "rad", L2)]
        + [SourceError(str(s), s, "geometry", "mm") for s in (e1x, e1y, e2x, e2y, L1, L2, l1, l2)]
        + [SourceError("rMx", cx, "measuring", "mm"), SourceError("rMy", cy, "measuring", "mm")]
    )
    assert [s.name for s in source_errors] == names

    # --- gauge: planar rigid motions of the robot and the measuring base point c + d + rM
    def gen(**kw):
        return [kw.get(nm, 0) for nm in names]
    gauge = {
        "translation x": gen(e1x=1, e2x=1, rMx=1),
        "translation y": gen(e1y=1, e2y=1, rMy=1),
        # rotation about O (per rad): A_i -> Q A_i, theta_i + 1, c + d -> Q (c + d)
        "rotation about O": gen(theta1=1, theta2=1, e1x=-e1y, e1y=e1x, e2x=-e2y, e2y=e2x,
                                rMx=-(cy + dy), rMy=cx + dx),
    }

    mech = SymbolicMechanism(
        name="planar_2dof",
        description="2-DOF translational parallel robot of Mei et al. 2017 (two RR limbs, planar)",
        pose=[x, y],
        joints=[th1, th2],
        geometry=list(geo),
        loop_closure=loop,
        ik=sp.Matrix(ik),
        ratio=sp.Matrix(ratio),
        fk=fk,
        transmission=trans,
        home_joints=[0.0, float(sp.pi)],
        base_point=sp.Matrix([cx, cy]),
        platform_offset=sp.Matrix([dx, dy]),
        source_errors=source_errors,
        gauge=gauge,
        workspace="rectangle",
        aliases={"ex": {"e1x": 1.0, "e2x": -1.0}, "ey": {"e1y": 1.0, "e2y": 1.0},
                 "L": {"L1": 1.0, "L2": 1.0}, "l": {"l1": 1.0, "l2": 1.0}},
        param_sets={"lengths": ("L1", "L2", "l1", "l2"), "base": ("e1x", "e1y", "e2x", "e2y")},
        positive=("L1", "L2", "l1", "l2"),
        gauge_fix=("e1x", "e1y", "e2y"),  # A1 exact, A2 on the same horizontal
    )

    # --- the paper's Eq. (12): per limb (L_i dth_i, de_ix, de_iy, dL_i, dl_i)
    robot_errors = [s.target for s in source_errors if s.role != "measuring"]
    J_src = implicit_pose_jacobian(mech, robot_errors)
    cols = {s: J_src[:, k] for k, s in enumerate(robot_errors)}
    J_full = sp.Matrix.hstack(
        cols[th1] / L1, cols[e1x], cols[e1y], cols[L1], cols[l1],
        cols[th2] / L2, cols[e2x], cols[e2y], cols[L2], cols[l2],
    )
    mech.extra_outputs = {
        "error_jacobian_full": dict(
            inputs=[("P", [x, y]), ("theta", [th1, th2]), ("g", list(geo))], outputs=[("J_full", J_full)],
            doc="Paper Eq. (12): dP = J' dq', dq' = (L1 dth1, de1x, de1y, dL1, dl1, L2 dth2, ...)."),
        # the drawing: the base A1 A2, each limb's proximal link A_i B_i and distal link B_i P
        SKETCH: sketch_output(mech, [(e[0], e[1])] + [seg for i in range(2) for seg in ((e[i], B[i]), (B[i], P))]),
    }
    derive(mech)
    mech.paper_forms = paper_forms(P, th, e, L, ll)
    return mech


def paper_forms(P, th, e, L, ll):
    """The paper's Eq. (12) and (13), written directly from their text."""
    u = [sp.Matrix([sp.cos(t), sp.sin(t)]) for t in th]
    w = [(P - e[i] - L[i] * u[i]) / ll[i] for i in range(2)]
    W = sp.Matrix.vstack(w[0].T, w[1].T)
    Jp = []
    for i in range(2):
        Jp.append(sp.Matrix([[(w[i].T * Q * u[i])[0], w[i][0], w[i][1], (w[i].T * u[i])[0], 1]]))
    blk = sp.diag(Jp[0], Jp[1])
    W_inv = W.adjugate() / W.det()  # explicit 2x2 inverse (no pivoting simplifications)
    J_full = W_inv * blk
    J_simple = W_inv * sp.diag((w[0].T * Q * u[0])[0], (w[1].T * Q * u[1])[0])
    return {"error_jacobian_full": J_full, "error_jacobian": J_simple}


def check_paper_forms(mech: SymbolicMechanism) -> None:
    """Assert that the derived Jacobians reduce to the paper's Eq. (12)/(13).

    Raises
    ------
    AssertionError
        If ``simplify(derived - paper)`` is not the zero matrix.
    """
    for name, paper in mech.paper_forms.items():
        derived = mech.outputs[name]["outputs"][0][1]
        # both sides are rational in (x, y, cos, sin, geometry): cancel decides zero
        diff = (derived - paper).applyfunc(lambda e: sp.cancel(sp.together(e)))
        if diff != sp.zeros(*paper.shape):
            diff = sp.simplify(diff)
        assert diff == sp.zeros(*paper.shape), f"{name} does not reduce to the paper's form: {diff}"
