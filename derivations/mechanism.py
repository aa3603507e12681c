"""The mechanism contract and the parts of the model derived once for every mechanism.

A closed-loop mechanism with a distance-measuring mechanism is described by a
:class:`SymbolicMechanism` that its derivation module
(``derivations/mechanisms/<name>.py``) fills in:

* pose coordinates ``P`` (n, mm), actuated joints ``theta`` (m, rad) and the
  geometry vector ``g`` (mm, or rad for angles), in robot-file order;
* the loop closure ``f(P, theta, g) = 0`` (one equation per limb);
* the closed-form inverse kinematics on the chosen branch with its reach
  ratios (``|ratio| <= 1`` where a limb can close), the forward kinematics on
  the chosen assembly mode, the home joints;
* the singularity indicators ``transmission(P, theta, g)`` (``|s| >= margin``
  away from a singular configuration);
* the measuring mechanism: base point ``c`` and platform offset ``d``
  (``lambda = P - c - d``);
* the source errors (:class:`SourceError`), each with a role (``zero_offset``,
  ``geometry``, ``measuring``), a unit and, for a zero offset, the lever arm
  that makes it a length (the paper's ``L_i dtheta_i``);
* the gauge motions: directions in source-error space that no distance
  change can see (rigid motions of the robot against the measuring mechanism);
* what a robot file may say: aliases (``L`` for ``L1 = L2``), defaults, the
  workspace shape.

:func:`derive` then writes, the same way for every mechanism, the outputs
every numeric layer uses (the names of :data:`CONTRACT`): the pose error
Jacobian by implicit differentiation of the loop closure, the error Jacobian
of the lever-arm-scaled zero offsets, the measuring vector, the
identification row ``g_k = lambda_hat^T [J, -I]`` (the paper's Eq. 28 in n
dimensions) and the exact distance ``rho(theta_cmd, g, err)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

ROLES = ("zero_offset", "geometry", "measuring")
UNITS = ("rad", "mm")
WORKSPACES = ("rectangle", "cylinder")

#: The generated functions every mechanism provides: name -> (inputs, outputs).
#: Sizes in the glossary letters: n pose coordinates, m joints, G geometry,
#: q source errors, r robot source errors (q minus the measuring ones),
#: s singularity indicators, z gauge motions.
CONTRACT = {
    "ik": (("P:n", "g:G"), ("theta:m", "ratio:m")),
    "fk": (("theta:m", "g:G"), ("P:n",)),
    "transmission": (("P:n", "theta:m", "g:G"), ("s:s",)),
    "pose_error_jacobian": (("P:n", "theta:m", "g:G"), ("J_src:n x r",)),
    "error_jacobian": (("P:n", "theta:m", "g:G"), ("J:n x m",)),
    "measuring": (("P:n", "g:G"), ("lam:1", "lam_hat:n")),
    "g_row": (("P:n", "theta:m", "g:G"), ("row:1 x (m+n)",)),
    "distance": (("theta_cmd:m", "g:G", "err:q"), ("rho:1",)),
    "gauge": (("g:G",), ("Z:q x z",)),
}


@dataclass(frozen=True)
class SourceError:
    """One source error: an additive error on a joint or a geometric parameter.

    Attributes
    ----------
    name : str
    target : Symbol
        The joint (zero offset) or geometry symbol the error is added to.  A
        measuring-mechanism error is carried on the base point ``c``.
    role : str
        ``zero_offset`` | ``geometry`` | ``measuring``.
    unit : str
        ``rad`` | ``mm``.
    lever : Symbol or None
        Angular (rad) errors only, and required there: the geometry symbol
        whose value (mm) turns the angle into a length, ``lever * dtheta``
        (the paper's ``L_i dtheta_i`` for a zero offset).
    """

    name: str
    target: sp.Symbol
    role: str
    unit: str
    lever: sp.Symbol | None = None


@dataclass
class SymbolicMechanism:
    """Symbolic description of a closed-loop mechanism with a measuring mechanism.

    Attributes
    ----------
    name : str
        Module name of the generated code (``zerocal_sym/generated/<name>.py``).
    description : str
        One line for ``zerocal robot`` and the docs.
    pose, joints, geometry : list of Symbol
        n pose coordinates (mm), m actuated joints (rad), geometry (robot-file order).
    geometry_units : dict of str -> str
        ``rad`` for angular geometry (given in degrees in robot files); ``mm`` otherwise.
    loop_closure : list of Expr, length m
    ik, ratio : Matrix (m, 1)
        Inverse kinematics on the chosen branch; ``|ratio| <= 1`` where reachable.
    fk : Matrix (n, 1)
        Forward kinematics on the chosen assembly mode.
    transmission : Matrix (s, 1)
        Singularity indicators, ``|s| >= margin`` in a usable configuration.
    home_joints : list of float
        rad.
    base_point, platform_offset : Matrix (n, 1)
        ``c`` and ``d``: ``lambda = P - c - d``.
    source_errors : list of SourceError
        Zero offsets first (joint order), then geometry, then measuring (pose order).
    gauge : dict of str -> list of Expr
        Name -> generator (length q, in the geometry symbols): a direction of
        the source errors that leaves every distance unchanged to first order.
    workspace : str
        ``rectangle`` (2-D: x in [-b/2, b/2], y in [H, H + h]) or ``cylinder``
        (3-D: x^2 + y^2 <= rw^2, z in [-(H + h), -H]).
    aliases : dict of str -> dict of str -> float
        Robot-file keys standing for several geometry entries (value times factor).
    defaults : dict of str -> float
        Geometry entries a robot file may leave out (file units: mm, degrees).
    param_sets : dict of str -> tuple of str
        Named parameter sets particular to this mechanism (beside the generic ones).
    positive : tuple of str
        Geometry entries that must be positive (link lengths, radii).
    gauge_fix : tuple of str
        Source errors held at zero to fix the gauge (one per gauge motion):
        the rest of ``all`` is identifiable from enough poses.
    extra_outputs : dict
        Mechanism-specific outputs (name -> spec, as in :func:`derive`).
    """

    name: str
    description: str
    pose: list
    joints: list
    geometry: list
    loop_closure: list
    ik: sp.Matrix
    ratio: sp.Matrix
    fk: sp.Matrix
    transmission: sp.Matrix
    home_joints: list
    base_point: sp.Matrix
    platform_offset: sp.Matrix
    source_errors: list
    gauge: dict
    workspace: str
    geometry_units: dict = field(default_factory=dict)
    aliases: dict = field(default_factory=dict)
    defaults: dict = field(default_factory=dict)
    param_sets: dict = field(default_factory=dict)
    positive: tuple = ()
    gauge_fix: tuple = ()
    extra_outputs: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)

    # ------------------------------------------------------------------ views
    @property
    def n(self) -> int:
        return len(self.pose)

    @property
    def m(self) -> int:
        return len(self.joints)

    def errors(self, role=None) -> list:
        """Source errors, optionally of one role."""
        return [e for e in self.source_errors if role is None or e.role == role]

    def error_symbols(self):
        """Symbols standing for the source errors, in order."""
        return [sp.Symbol("d_" + e.name, real=True) for e in self.source_errors]

    def check(self) -> None:
        """Assert the description is complete and consistent (shapes, roles, names)."""
        n, m = self.n, self.m
        geo = set(self.geometry)
        assert len(self.loop_closure) == m, "one loop-closure equation per actuated joint"
        assert self.ik.shape == (m, 1) and self.ratio.shape == (m, 1), "ik and ratio are (m, 1)"
        assert self.fk.shape == (n, 1), "fk is (n, 1)"
        assert self.base_point.shape == (n, 1) and self.platform_offset.shape == (n, 1)
        assert len(self.home_joints) == m
        assert self.workspace in WORKSPACES, self.workspace
        names = [e.name for e in self.source_errors]
        assert len(set(names)) == len(names), "source-error names must be unique"
        for e in self.source_errors:
            assert e.role in ROLES and e.unit in UNITS, e
            assert (e.lever in geo) if e.unit == "rad" else e.lever is None, f"{e.name}: lever arm iff rad"
        offsets = self.errors("zero_offset")
        assert [e.target for e in offsets] == list(self.joints), "one zero offset per joint, in joint order"
        assert all(e.unit == "rad" for e in offsets), "zero offsets are angles (rad)"
        meas = self.errors("measuring")
        assert [e.target for e in meas] == list(self.base_point), "measuring errors are carried on c, in order"
        assert all(e.target in geo for e in self.errors("geometry")), "geometry errors target geometry symbols"
        roles = [e.role for e in self.source_errors]
        assert roles == sorted(roles, key=ROLES.index), "order: zero offsets, geometry, measuring"
        assert len(self.gauge_fix) == len(self.gauge) and set(self.gauge_fix) <= set(names), "one fix per gauge"
        for gname, gen in self.gauge.items():
            assert len(gen) == len(self.source_errors), f"gauge {gname}: one entry per source error"
        known = {str(s) for s in self.geometry}
        for alias, parts in self.aliases.items():
            assert alias not in known and set(parts) <= known, alias
        assert set(self.defaults) <= known and set(self.positive) <= known
        for pset in self.param_sets.values():
            assert set(pset) <= set(names), pset


def implicit_pose_jacobian(mech: SymbolicMechanism, wrt):
    """dP/dq from the loop closure by implicit differentiation.

    ``f(P(q), q) = 0``  =>  ``dP/dq = -(df/dP)^-1 df/dq``.

    Parameters
    ----------
    mech : SymbolicMechanism
    wrt : list of Symbol
        The joint or geometric symbols to differentiate with respect to.

    Returns
    -------
    Matrix, shape (n, len(wrt))
        In terms of the pose, the joints and the geometry (no solved kinematics
        inside, so it is valid on every branch).
    """
    f = sp.Matrix(mech.loop_closure)
    fP = f.jacobian(sp.Matrix(mech.pose))
    fq = f.jacobian(sp.Matrix(wrt))
    # adjugate / determinant: the only division is by det(df/dP), which vanishes
    # exactly at the parallel singularities. (LU pivoting would divide by a
    # pivot entry too and put a spurious singularity where that entry is zero.)
    return -(fP.adjugate() * fq) / fP.det()


def measuring_vector(mech: SymbolicMechanism):
    """The nominal measuring-mechanism vector ``lambda = P - c - d``."""
    return sp.Matrix(mech.pose) - mech.base_point - mech.platform_offset


def _norm(v):
    return sp.sqrt(sum(x**2 for x in v))


def derive(mech: SymbolicMechanism) -> SymbolicMechanism:
    """Fill ``mech.outputs`` with every function of :data:`CONTRACT` (and the extras).

    Each output is ``dict(inputs=[(name, [symbols])], outputs=[(name, Matrix)], doc=str)``.
    """
    mech.check()
    P, th, g = list(mech.pose), list(mech.joints), list(mech.geometry)
    n, m = mech.n, mech.m

    robot_errors = [e for e in mech.source_errors if e.role != "measuring"]
    J_src = implicit_pose_jacobian(mech, [e.target for e in robot_errors])  # (n, r)
    cols = {e.target: J_src[:, k] for k, e in enumerate(robot_errors)}
    J = sp.Matrix.hstack(*[cols[e.target] / e.lever for e in mech.errors("zero_offset")])  # (n, m)

    lam_vec = measuring_vector(mech)
    lam = _norm(lam_vec)
    lam_hat = lam_vec / lam
    g_row = lam_hat.T * sp.Matrix.hstack(J, -sp.eye(n))  # (1, m + n)

    # exact distance: rho = |FK(th + dth; g + dg) - (c + drM) - d|
    err = mech.error_symbols()
    subs = {e.target: e.target + d for e, d in zip(mech.source_errors, err)}
    # xreplace: structural, simultaneous, and far faster than subs on large trees
    fk_actual = mech.fk.xreplace(subs)
    lam_actual = lam_vec.xreplace(subs).xreplace(dict(zip(P, fk_actual)))
    rho = _norm(lam_actual)

    gauge = (sp.Matrix.hstack(*[sp.Matrix(v) for v in mech.gauge.values()])
             if mech.gauge else sp.zeros(len(err), 0))

    Pin, Tin, Gin = ("P", P), ("theta", th), ("g", g)
    unit_names = " ".join(e.name for e in robot_errors)
    mech.outputs = {
        "ik": dict(inputs=[Pin, Gin], outputs=[("theta", mech.ik), ("ratio", mech.ratio)],
                   doc="Inverse kinematics on the chosen branch and the reach ratios (|ratio| <= 1 where reachable)."),
        "fk": dict(inputs=[Tin, Gin], outputs=[("P", mech.fk)],
                   doc="Forward kinematics on the chosen assembly mode."),
        "transmission": dict(inputs=[Pin, Tin, Gin], outputs=[("s", mech.transmission)],
                             doc="Singularity indicators: |s| >= margin away from a singular configuration."),
        "pose_error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J_src", J_src)],
            doc=f"dP/d(robot source errors {unit_names}), per rad or mm (implicit differentiation)."),
        "error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J", J)],
            doc="dP/d(lever_i dtheta_i): the zero offsets as lengths (paper Eq. 13 in n dimensions)."),
        "measuring": dict(
            inputs=[Pin, Gin], outputs=[("lam", sp.Matrix([lam])), ("lam_hat", lam_hat)],
            doc="Nominal measuring-mechanism length |P - c - d| and its unit vector."),
        "g_row": dict(inputs=[Pin, Tin, Gin], outputs=[("row", g_row)],
                      doc="Identification row g_k = lam_hat^T [J, -I] (paper Eq. 28)."),
        "distance": dict(
            inputs=[("theta_cmd", th), Gin, ("err", err)], outputs=[("rho", sp.Matrix([rho]))],
            doc="Exact distance O1'O2' for commanded joints, nominal geometry and source errors."),
        "gauge": dict(inputs=[Gin], outputs=[("Z", gauge)],
                      doc="Gauge motions (columns): source-error directions no distance change can see."),
    }
    mech.outputs.update(mech.extra_outputs)
    return mech
