"""The 2-DOF translational parallel robot of Mei et al. (2017), derived in sympy.

Frame (SPEC.md): origin O at the base centre, x from A2 towards A1, y from the
base towards the workspace.  Limb i: ``B_i = A_i + L_i u_i`` with
``u_i = (cos th_i, sin th_i)``; ``P = B_i + l_i w_i``, ``|w_i| = 1``.

Derived here, and written by :mod:`derivations.codegen` into
``zerocal_sym/generated/planar_2dof.py``:

* closed-form inverse kinematics on the branch continuous with home
  (``th1 = 0``, ``th2 = pi``; elbows outward),
* forward kinematics (intersection of the two distal circles, the solution
  farther from the base),
* the full first-order error model ``dP = J' dq'`` (2x10) and the simplified
  ``dP = J dq`` (2x2) by implicit differentiation of the loop closure, checked
  symbolically against the paper's Eq. (12)/(13) forms,
* the measuring-mechanism vector and length, the identification row ``g_k``
  and the exact (non-linearised) distance ``rho(theta_cmd, source errors)``.

Geometry vector ``g`` (mm): ``e1x e1y e2x e2y L1 L2 l1 l2 cx cy dx dy``.
Source errors (mm, rad): ``theta1 theta2 e1x e1y e2x e2y L1 L2 l1 l2 rMx rMy``;
``rM = dc + dd`` enters the distance only through ``c + d``, so it is carried as
an error on ``c``.
"""
from __future__ import annotations

import sympy as sp

from derivations.mechanism import (
    SymbolicMechanism,
    implicit_pose_jacobian,
    measuring_vector,
)

Q = sp.Matrix([[0, -1], [1, 0]])


def _symbols():
    x, y = sp.symbols("x y", real=True)
    th1, th2 = sp.symbols("theta1 theta2", real=True)
    geo = sp.symbols("e1x e1y e2x e2y L1 L2 l1 l2 cx cy dx dy", real=True)
    return (x, y), (th1, th2), geo


def build() -> SymbolicMechanism:
    """Derive every output of the mechanism.

    Returns
    -------
    SymbolicMechanism
        With ``outputs`` filled: name -> dict(inputs=[(name, [symbols])],
        outputs=[(name, Matrix)], doc=str).
    """
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

    mech = SymbolicMechanism(
        name="planar_2dof",
        pose=[x, y],
        joints=[th1, th2],
        geometry=list(geo),
        loop_closure=loop,
        source_errors=[
            ("theta1", th1), ("theta2", th2),
            ("e1x", e1x), ("e1y", e1y), ("e2x", e2x), ("e2y", e2y),
            ("L1", L1), ("L2", L2), ("l1", l1), ("l2", l2),
            ("rMx", cx), ("rMy", cy),
        ],
        base_point=sp.Matrix([cx, cy]),
        platform_offset=sp.Matrix([dx, dy]),
    )

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
    ik = sp.Matrix(ik)

    # --- forward kinematics: circle intersection, the solution with larger y
    B = [e[i] + L[i] * u[i] for i in range(2)]
    D = B[1] - B[0]
    dist = sp.sqrt(D[0] ** 2 + D[1] ** 2)
    a = (l1**2 - l2**2 + dist**2) / (2 * dist)
    hgt = sp.sqrt(l1**2 - a**2)
    # (Q D)_y = D_x: the sign of D_x picks the intersection with the larger y
    fk = B[0] + a * D / dist + sp.sign(D[0]) * hgt * (Q * D) / dist

    # --- first-order error model by implicit differentiation of the loop closure
    robot_errors = [s for n, s in mech.source_errors if not n.startswith("rM")]
    J_src = implicit_pose_jacobian(mech, robot_errors)  # (2, 10), order as source_errors
    # paper order and scaling: per limb (L_i dth_i, de_ix, de_iy, dL_i, dl_i)
    cols = {s: J_src[:, k] for k, s in enumerate(robot_errors)}
    J_full = sp.Matrix.hstack(
        cols[th1] / L1, cols[e1x], cols[e1y], cols[L1], cols[l1],
        cols[th2] / L2, cols[e2x], cols[e2y], cols[L2], cols[l2],
    )
    J_simple = sp.Matrix.hstack(cols[th1] / L1, cols[th2] / L2)

    # --- measuring mechanism
    lam_vec = measuring_vector(mech)
    lam = sp.sqrt(lam_vec[0] ** 2 + lam_vec[1] ** 2)
    lam_hat = lam_vec / lam
    g_row = lam_hat.T * sp.Matrix.hstack(J_simple, -sp.eye(2))  # (1, 4)

    # --- exact distance with source errors: rho = |FK(th + dth; g + dg) - c' - d|
    err = mech.error_symbols()
    subs = {s: s + d for (n, s), d in zip(mech.source_errors, err)}
    fk_actual = fk.subs(subs, simultaneous=True)
    lam_actual = lam_vec.subs(subs, simultaneous=True).subs(
        {x: fk_actual[0], y: fk_actual[1]}, simultaneous=True)
    rho = sp.sqrt(lam_actual[0] ** 2 + lam_actual[1] ** 2)

    # --- conditioning: sines of the transmission angles and of the distal angle
    w = [arm[i] / ll[i] for i in range(2)]
    trans = sp.Matrix([
        (w[0].T * Q * u[0])[0],
        (w[1].T * Q * u[1])[0],
        w[0][0] * w[1][1] - w[0][1] * w[1][0],
    ])

    Pin = ("P", [x, y])
    Tin = ("theta", [th1, th2])
    Gin = ("g", list(geo))
    mech.outputs = {
        "ik": dict(inputs=[Pin, Gin], outputs=[("theta", ik), ("ratio", sp.Matrix(ratio))],
                   doc="Inverse kinematics (branch continuous with home) and |K_i/r_i| <= 1 reach ratios."),
        "fk": dict(inputs=[Tin, Gin], outputs=[("P", fk)],
                   doc="Forward kinematics: circle intersection with the larger y."),
        "pose_error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J_src", J_src)],
            doc="dP/d(source errors theta1 theta2 e1x e1y e2x e2y L1 L2 l1 l2), rad and mm."),
        "error_jacobian_full": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J_full", J_full)],
            doc="Paper Eq. (12): dP = J' dq', dq' = (L1 dth1, de1x, de1y, dL1, dl1, L2 dth2, ...)."),
        "error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J", J_simple)],
            doc="Paper Eq. (13): dP = J dq, dq = (L1 dth1, L2 dth2)."),
        "measuring": dict(
            inputs=[Pin, Gin], outputs=[("lam", sp.Matrix([lam])), ("lam_hat", lam_hat)],
            doc="Nominal measuring-mechanism length |P - c - d| and its unit vector."),
        "g_row": dict(inputs=[Pin, Tin, Gin], outputs=[("row", g_row)],
                      doc="Identification row g_k = lam_hat^T [J, -I] (paper Eq. 28)."),
        "distance": dict(
            inputs=[("theta_cmd", [th1, th2]), Gin, ("err", err)],
            outputs=[("rho", sp.Matrix([rho]))],
            doc="Exact distance O1'O2' for commanded joints, nominal geometry and source errors."),
        "transmission": dict(
            inputs=[Pin, Tin, Gin], outputs=[("s", trans)],
            doc="sin of the transmission angles (u_i, w_i) and of the angle (w_1, w_2)."),
    }
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
