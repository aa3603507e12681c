"""The mechanism contract and the parts of the model derived once for every mechanism.

A closed-loop mechanism with a distance-measuring mechanism is described by a
:class:`SymbolicMechanism` that its derivation module
(``derivations/mechanisms/<name>.py``) fills in:

* pose coordinates ``P`` (n: positions in mm, orientations in rad), actuated
  joints ``theta`` (m, each of a :data:`JOINT_KINDS` kind: revolute in rad,
  prismatic in mm) and the geometry vector ``g`` (mm, or rad for angles), in
  robot-file order;
* the loop closure ``f(P, theta, g) = 0`` (one equation per limb);
* the closed-form inverse kinematics on the chosen branch with its reach
  ratios (``|ratio| <= 1`` where a limb can close), the forward kinematics on
  the chosen assembly mode -- a closed form, or a solve (:class:`FkSolve`:
  Newton on the loop closure from a start pose, generated as a fixed number of
  steps whose derivative is the implicit-function one) -- and the home (joints,
  a pose in the geometry, or the workspace's centre);
* the singularity indicators ``transmission(P, theta, g)`` (``|s| >= margin``
  away from a singular configuration);
* the measuring mechanism: base point ``c``, platform point ``d`` and the
  measuring vector ``lambda(P, g)`` from ``O1`` to ``O2`` (default
  ``P - c - d``; a platform that turns gives ``P + Rot d - c``);
* the source errors (:class:`SourceError`), each with a role (``zero_offset``,
  ``geometry``, ``measuring``), a unit and, for an angular zero offset, the
  lever arm that makes it a length (the paper's ``L_i dtheta_i``; a prismatic
  joint's offset is a length already); measuring errors are carried on entries
  of ``c`` or ``d``;
* the gauge motions: directions in source-error space that no distance
  change can see (rigid motions of the robot against the measuring mechanism);
* the identified sets: the default (what the data identify on this
  mechanism; e.g. a common carriage offset of a linear Delta is the MAEMM's
  vertical component, so that one is held) and named ones;
* what a robot file may say: aliases (``L`` for ``L1 = L2``), defaults, the
  workspace shape.

:func:`derive` then writes, the same way for every mechanism, the outputs
every numeric layer uses (the names of :data:`CONTRACT`): the pose error
Jacobian by implicit differentiation of the loop closure, the error Jacobian
of the lever-arm-scaled zero offsets, the measuring vector, the
identification row ``g_k = d rho / d(offsets, measuring errors)`` (the paper's
Eq. 28, ``lambda_hat^T [J, -I]`` where ``lambda = P - c - d``) and the exact
distance ``rho(theta_cmd, g, err)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

ROLES = ("zero_offset", "geometry", "measuring")
UNITS = ("rad", "mm")
WORKSPACES = ("rectangle", "cylinder", "box")
#: joint kind -> the internal unit of its variable (and of its zero offset)
JOINT_KINDS = {"revolute": "rad", "prismatic": "mm"}
#: how the home configuration is given
HOME_WORKSPACE_CENTRE = "workspace centre"

#: The generated functions every mechanism provides: name -> (inputs, outputs).
#: Sizes in the glossary letters: n pose coordinates, m joints, G geometry,
#: q source errors, r robot source errors (q minus the measuring ones),
#: s singularity indicators, z gauge motions, l the measuring vector's dimension
#: (2 or 3), u the measuring errors.
CONTRACT = {
    "ik": (("P:n", "g:G"), ("theta:m", "ratio:m")),
    "fk": (("theta:m", "g:G"), ("P:n",)),
    "transmission": (("P:n", "theta:m", "g:G"), ("s:s",)),
    "pose_error_jacobian": (("P:n", "theta:m", "g:G"), ("J_src:n x r",)),
    "error_jacobian": (("P:n", "theta:m", "g:G"), ("J:n x m",)),
    "measuring": (("P:n", "g:G"), ("lam:1", "lam_hat:l")),
    "g_row": (("P:n", "theta:m", "g:G"), ("row:1 x (m+u)",)),
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
        measuring-mechanism error is carried on an entry of the base point
        ``c`` or of the platform point ``d``.
    role : str
        ``zero_offset`` | ``geometry`` | ``measuring``.
    unit : str
        ``rad`` | ``mm``; a zero offset has its joint kind's unit.
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


@dataclass(frozen=True)
class FkSolve:
    """Forward kinematics as a solve: Newton on the loop closure in the pose coordinates.

    The generated ``fk`` takes ``iterations`` full Newton steps from ``start``
    and returns NaN where the loop closure's largest residual is then above
    ``tol`` (no silent wrong pose).  Its derivative (CasADi's, through the
    steps) is the implicit-function one ``-(df/dP)^-1 df/dtheta`` at the
    converged pose: a Newton step's derivative with respect to its start
    vanishes at the root.

    Attributes
    ----------
    start : Matrix (n, 1)
        Start pose in the geometry symbols (e.g. the home pose).
    iterations : int
    tol : float
        On the loop closure's residuals (their unit: mm^2 for squared lengths).
    """

    start: sp.Matrix
    iterations: int = 12
    tol: float = 1e-6


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
        n pose coordinates, m actuated joints, geometry (robot-file order).
    joint_kinds : list of str
        One :data:`JOINT_KINDS` key per joint (default: every joint revolute).
    pose_units : dict of str -> str
        ``rad`` for orientation coordinates (roll, pitch, yaw; degrees in files);
        ``mm`` otherwise (the default).
    geometry_units : dict of str -> str
        ``rad`` for angular geometry (given in degrees in robot files); ``mm`` otherwise.
    loop_closure : list of Expr, length m
    ik, ratio : Matrix (m, 1)
        Inverse kinematics on the chosen branch; ``|ratio| <= 1`` where reachable.
    fk : Matrix (n, 1) or FkSolve
        Forward kinematics on the chosen assembly mode: a closed form or a solve.
    transmission : Matrix (s, 1)
        Singularity indicators, ``|s| >= margin`` in a usable configuration.
    home_joints : list of float, or None
        Internal units (rad, mm); or None with ``home_pose``.
    home_pose : Matrix (n, 1), str or None
        The home pose in the geometry symbols, or :data:`HOME_WORKSPACE_CENTRE`
        (the centre of the robot file's workspace); the home joints are then its IK.
    base_point, platform_offset : Matrix (l, 1)
        ``c`` and ``d`` of the measuring mechanism.
    measuring_vector : Matrix (l, 1) or None
        ``O2 - O1`` in the pose and geometry symbols; default ``P - c - d``.
    source_errors : list of SourceError
        Zero offsets first (joint order), then geometry, then measuring (on
        entries of ``c`` or ``d``).
    gauge : dict of str -> list of Expr
        Name -> generator (length q, in the geometry symbols): a direction of
        the source errors that leaves every distance unchanged to first order.
    workspace : str
        ``rectangle`` (2-D: x in [-b/2, b/2], y in [H, H + h]), ``cylinder``
        (3-D: x^2 + y^2 <= rw^2 and z in [-(H + h), -H] or [z_min, z_max]) or
        ``box`` (6-D: position and roll, pitch, yaw in a box).
    workspace_defaults : dict of str -> float
        Workspace keys a robot file may leave out (file units).
    aliases : dict of str -> dict of str -> float
        Robot-file keys standing for several geometry entries (value times factor).
    list_aliases : dict of str -> tuple of str
        Robot-file keys holding a list, one value per entry (``base_angles = [...]``).
    defaults : dict of str -> float
        Geometry entries a robot file may leave out (file units: mm, degrees).
    param_sets : dict of str -> tuple of str
        Named parameter sets particular to this mechanism (beside the generic ones).
    default_set : tuple of str
        The parameters identified by default (design, TSVD, verify, compensate):
        default the zero offsets and every measuring error.
    positive : tuple of str
        Geometry entries that must be positive (link lengths, radii).
    gauge_fix : tuple of str
        Source errors held at zero to fix the gauge (one per gauge motion):
        the rest of ``all`` is identifiable from enough poses.
    transmission_solves : tuple of Determinant or LinearSolve
        Numeric steps the singularity indicators use (their symbols stand in ``transmission``).
    jacobian_form : str
        ``adjugate`` (closed-form ``-adj(df/dP) df/dq / det``, small n) or
        ``solve`` (``-(df/dP)^-1 df/dq`` solved by CasADi: six-DOF platforms).
    noise : dict of str -> float
        The default noise of the robot files: ``scale`` (mm per change) and
        ``joint`` (per joint per pose, file units: deg or mm); empty: the paper's.
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
    fk: object
    transmission: sp.Matrix
    home_joints: list | None
    base_point: sp.Matrix
    platform_offset: sp.Matrix
    source_errors: list
    gauge: dict
    workspace: str
    joint_kinds: list = None
    pose_units: dict = field(default_factory=dict)
    home_pose: object = None
    measuring_vector: sp.Matrix | None = None
    workspace_defaults: dict = field(default_factory=dict)
    geometry_units: dict = field(default_factory=dict)
    aliases: dict = field(default_factory=dict)
    list_aliases: dict = field(default_factory=dict)
    defaults: dict = field(default_factory=dict)
    param_sets: dict = field(default_factory=dict)
    default_set: tuple = ()
    positive: tuple = ()
    gauge_fix: tuple = ()
    jacobian_form: str = "adjugate"
    transmission_solves: tuple = ()
    noise: dict = field(default_factory=dict)
    extra_outputs: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.joint_kinds is None:
            self.joint_kinds = ["revolute"] * len(self.joints)
        if self.measuring_vector is None:
            self.measuring_vector = sp.Matrix(self.pose) - self.base_point - self.platform_offset
        if not self.default_set:
            self.default_set = tuple(e.name for e in self.source_errors if e.role in ("zero_offset", "measuring"))

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
        """Assert the description is complete and consistent (shapes, roles, names, units)."""
        n, m = self.n, self.m
        geo = set(self.geometry)
        assert len(self.loop_closure) == m, "one loop-closure equation per actuated joint"
        assert self.ik.shape == (m, 1) and self.ratio.shape == (m, 1), "ik and ratio are (m, 1)"
        if isinstance(self.fk, FkSolve):
            assert self.fk.start.shape == (n, 1) and self.fk.start.free_symbols <= geo, "fk start: (n, 1) in g"
            assert self.fk.iterations >= 1 and self.fk.tol > 0
        else:
            assert self.fk.shape == (n, 1), "fk is (n, 1) or an FkSolve"
        nl = self.measuring_vector.shape[0]
        assert self.measuring_vector.shape == (nl, 1) and nl in (2, 3), "the measuring vector is 2-D or 3-D"
        assert self.base_point.shape == (nl, 1) and self.platform_offset.shape == (nl, 1), "c and d: (l, 1)"
        assert len(self.joint_kinds) == m and set(self.joint_kinds) <= set(JOINT_KINDS), self.joint_kinds
        assert len(set(self.joint_kinds)) == 1, "a mechanism's actuated joints share one kind (one unit)"
        assert set(self.pose_units) <= {str(s) for s in self.pose} and set(self.pose_units.values()) <= set(UNITS)
        if self.home_pose is None:
            assert self.home_joints is not None and len(self.home_joints) == m, "home joints: one per joint"
        else:
            assert self.home_joints is None, "home_joints or home_pose, not both"
            assert self.home_pose == HOME_WORKSPACE_CENTRE or (
                self.home_pose.shape == (n, 1) and self.home_pose.free_symbols <= geo), "home_pose"
        assert self.workspace in WORKSPACES, self.workspace
        assert self.jacobian_form in ("adjugate", "solve"), self.jacobian_form
        assert set(self.noise) <= {"scale", "joint"}, self.noise
        names = [e.name for e in self.source_errors]
        assert len(set(names)) == len(names), "source-error names must be unique"
        for e in self.source_errors:
            assert e.role in ROLES and e.unit in UNITS, e
            assert (e.lever in geo) if e.unit == "rad" else e.lever is None, f"{e.name}: lever arm iff rad"
        offsets = self.errors("zero_offset")
        assert [e.target for e in offsets] == list(self.joints), "one zero offset per joint, in joint order"
        for e, kind in zip(offsets, self.joint_kinds):
            assert e.unit == JOINT_KINDS[kind], f"zero offset {e.name}: unit {e.unit} of a {kind} joint"
        mpoints = set(self.base_point) | set(self.platform_offset)
        assert all(e.target in mpoints for e in self.errors("measuring")), "measuring errors are carried on c or d"
        assert all(e.target in geo for e in self.errors("geometry")), "geometry errors target geometry symbols"
        roles = [e.role for e in self.source_errors]
        assert roles == sorted(roles, key=ROLES.index), "order: zero offsets, geometry, measuring"
        assert len(self.gauge_fix) == len(self.gauge) and set(self.gauge_fix) <= set(names), "one fix per gauge"
        for gname, gen in self.gauge.items():
            assert len(gen) == len(self.source_errors), f"gauge {gname}: one entry per source error"
        known = {str(s) for s in self.geometry}
        for alias, parts in list(self.aliases.items()) + list(self.list_aliases.items()):
            assert alias not in known and set(parts) <= known, alias
        assert set(self.defaults) <= known and set(self.positive) <= known
        for pset in list(self.param_sets.values()) + [self.default_set]:
            assert set(pset) <= set(names), pset
        assert set(e.name for e in offsets) <= set(self.default_set), "the default set holds the zero offsets"
        assert set(self.default_set) <= set(e.name for e in offsets + self.errors("measuring")), \
            "the default set: zero offsets and measuring errors (the linear model's unknowns)"


def loop_jacobians(mech: SymbolicMechanism, wrt):
    """``df/dP`` (m x n) and ``df/dq`` (m x len(wrt)) of the loop closure."""
    f = sp.Matrix(mech.loop_closure)
    return f.jacobian(sp.Matrix(mech.pose)), (f.jacobian(sp.Matrix(wrt)) if wrt else sp.zeros(len(f), 0))


def implicit_pose_jacobian(mech: SymbolicMechanism, wrt):
    """dP/dq from the loop closure by implicit differentiation, in closed form.

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
    fP, fq = loop_jacobians(mech, wrt)
    # adjugate / determinant: the only division is by det(df/dP), which vanishes
    # exactly at the parallel singularities. (LU pivoting would divide by a
    # pivot entry too and put a spurious singularity where that entry is zero.)
    return -(fP.adjugate() * fq) / fP.det()


@dataclass(frozen=True)
class LinearSolve:
    """``X = A^-1 B``, solved numerically by CasADi inside a generated function.

    Outputs of that function may use ``X``'s entries (the symbols of ``X``):
    the codegen evaluates ``A`` and ``B``, solves, then the outputs.
    """

    X: sp.Matrix
    A: sp.Matrix
    B: sp.Matrix


@dataclass(frozen=True)
class Determinant:
    """``X = det(A)`` (X a 1 x 1 Matrix of a symbol), evaluated numerically by CasADi inside a generated function
    (a 6 x 6 symbolic determinant is out of reach of sympy's printing)."""

    X: sp.Matrix
    A: sp.Matrix

    @property
    def B(self):
        return sp.zeros(0, 0)


def numeric_value(solve, A, B):
    """The value of a :class:`LinearSolve` or :class:`Determinant` for numeric ``A`` and ``B`` (for tests)."""
    import numpy as np

    if isinstance(solve, Determinant):
        return np.array([[np.linalg.det(A)]])
    return np.linalg.solve(A, B)


#: the name of the optional drawing output (:func:`sketch_output`): the report draws the robot with it
SKETCH = "sketch"


def sketch_output(mech: SymbolicMechanism, segments) -> dict:
    """The optional ``sketch`` output: the robot drawn as line segments, for the calibration report.

    ``segments``: ``[(start, end)]``, each end a point (``sp.Matrix`` of l coordinates, mm: the measuring
    mechanism's dimension, 2 or 3) in the pose, the joints and the geometry.  The generated function
    ``sketch(P, theta, g)`` returns them as one (l, 2 s) matrix: columns ``2k`` and ``2k + 1`` are the ends of
    segment ``k``.  Put it in ``extra_outputs``; a mechanism without one is drawn by its measuring mechanism
    and its poses alone.
    """
    cols = [pt for seg in segments for pt in seg]
    return dict(inputs=[("P", list(mech.pose)), ("theta", list(mech.joints)), ("g", list(mech.geometry))],
                outputs=[("segments", sp.Matrix.hstack(*cols))],
                doc="The robot drawn as line segments (columns 2k and 2k+1: the ends of segment k), mm.")


def measuring_vector(mech: SymbolicMechanism):
    """The nominal measuring-mechanism vector ``O2 - O1`` (default ``lambda = P - c - d``)."""
    return mech.measuring_vector


def _norm(v):
    return sp.sqrt(sum(x**2 for x in v))


def _pose_jacobian(mech, robot_errors):
    """``J_src`` (n x r) and the solves it needs (none for the adjugate form)."""
    targets = [e.target for e in robot_errors]
    if mech.jacobian_form == "adjugate":
        return implicit_pose_jacobian(mech, targets), []
    fP, fq = loop_jacobians(mech, targets)
    X = sp.Matrix(mech.n, len(targets), lambda i, j: sp.Symbol(f"J_{i}_{j}", real=True))
    return X, [LinearSolve(X, fP, -fq)]


def derive(mech: SymbolicMechanism) -> SymbolicMechanism:
    """Fill ``mech.outputs`` with every function of :data:`CONTRACT` (and the extras).

    Each output is ``dict(inputs=[(name, [symbols])], outputs=[(name, Matrix)], doc=str)``, with
    ``solves=[LinearSolve]`` where its outputs use a solve's result; the forward kinematics of an
    :class:`FkSolve` mechanism is ``dict(newton=FkSolve, ...)`` and its distance ``dict(compose=...)``.
    """
    mech.check()
    P, th, g = list(mech.pose), list(mech.joints), list(mech.geometry)

    robot_errors = [e for e in mech.source_errors if e.role != "measuring"]
    J_src, solves = _pose_jacobian(mech, robot_errors)  # (n, r)
    cols = {e.target: J_src[:, k] for k, e in enumerate(robot_errors)}
    J = sp.Matrix.hstack(*[cols[e.target] / (e.lever if e.lever is not None else 1)
                           for e in mech.errors("zero_offset")])  # (n, m)

    lam_vec = measuring_vector(mech)
    lam = _norm(lam_vec)
    lam_hat = lam_vec / lam
    dlam_dP = lam_vec.jacobian(sp.Matrix(P))
    dlam_dmeas = lam_vec.jacobian(sp.Matrix([e.target for e in mech.errors("measuring")]))
    pose_part = J if dlam_dP == sp.eye(len(P)) else dlam_dP * J
    g_row = lam_hat.T * sp.Matrix.hstack(pose_part, dlam_dmeas)  # (1, m + u)

    err = mech.error_symbols()
    gauge = (sp.Matrix.hstack(*[sp.Matrix(v) for v in mech.gauge.values()])
             if mech.gauge else sp.zeros(len(err), 0))

    Pin, Tin, Gin = ("P", P), ("theta", th), ("g", g)
    unit_names = " ".join(e.name for e in robot_errors)
    outputs = {
        "ik": dict(inputs=[Pin, Gin], outputs=[("theta", mech.ik), ("ratio", mech.ratio)],
                   doc="Inverse kinematics on the chosen branch and the reach ratios (|ratio| <= 1 where reachable)."),
    }
    distance_doc = "Exact distance O1'O2' for commanded joints, nominal geometry and source errors."
    if isinstance(mech.fk, FkSolve):
        fP, _ = loop_jacobians(mech, [])
        outputs["fk_residual"] = dict(
            inputs=[Pin, Tin, Gin], outputs=[("f", sp.Matrix(mech.loop_closure)), ("f_P", fP)],
            doc="Loop closure f(P, theta, g) and df/dP: the forward kinematics' Newton steps.")
        outputs["fk_start"] = dict(inputs=[Gin], outputs=[("P0", mech.fk.start)],
                                   doc="Start pose of the forward kinematics' Newton steps.")
        outputs["fk"] = dict(inputs=[Tin, Gin], outputs=[("P", sp.zeros(len(P), 1))], newton=mech.fk,
                             doc=f"Forward kinematics: {mech.fk.iterations} Newton steps on the loop closure "
                                 f"from fk_start; NaN where max|f| > {mech.fk.tol:g} then.")
        distance = dict(inputs=[("theta_cmd", th), Gin, ("err", err)], outputs=[("rho", sp.zeros(1, 1))],
                        compose=[(e.role == "zero_offset", [*th, *g].index(e.target)) for e in mech.source_errors],
                        doc=distance_doc + " (fk of the actual joints and geometry, then |measuring|).")
    else:
        outputs["fk"] = dict(inputs=[Tin, Gin], outputs=[("P", mech.fk)],
                             doc="Forward kinematics on the chosen assembly mode.")
        # exact distance: rho = |lambda(FK(th + dth; g + dg); g + dg)|
        subs = {e.target: e.target + d for e, d in zip(mech.source_errors, err)}
        # xreplace: structural, simultaneous, and far faster than subs on large trees
        fk_actual = mech.fk.xreplace(subs)
        lam_actual = lam_vec.xreplace(subs).xreplace(dict(zip(P, fk_actual)))
        distance = dict(inputs=[("theta_cmd", th), Gin, ("err", err)],
                        outputs=[("rho", sp.Matrix([_norm(lam_actual)]))], doc=distance_doc)
    outputs.update({
        "transmission": dict(inputs=[Pin, Tin, Gin], outputs=[("s", mech.transmission)],
                             solves=list(mech.transmission_solves),
                             doc="Singularity indicators: |s| >= margin away from a singular configuration."),
        "pose_error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J_src", J_src)], solves=solves,
            doc=f"dP/d(robot source errors {unit_names}), per rad or mm (implicit differentiation)."),
        "error_jacobian": dict(
            inputs=[Pin, Tin, Gin], outputs=[("J", J)], solves=solves,
            doc="dP/d(offsets as lengths: lever_i dtheta_i for a revolute joint, ds_i for a prismatic one) "
                "(paper Eq. 13 in n dimensions)."),
        "measuring": dict(
            inputs=[Pin, Gin], outputs=[("lam", sp.Matrix([lam])), ("lam_hat", lam_hat)],
            doc="Nominal measuring-mechanism length |O2 - O1| and its unit vector."),
        "g_row": dict(inputs=[Pin, Tin, Gin], outputs=[("row", g_row)], solves=solves,
                      doc="Identification row g_k = d rho / d(offsets as lengths, measuring errors) "
                          "(paper Eq. 28: lam_hat^T [J, -I] for lambda = P - c - d)."),
        "distance": distance,
        "gauge": dict(inputs=[Gin], outputs=[("Z", gauge)],
                      doc="Gauge motions (columns): source-error directions no distance change can see."),
    })
    if mech.home_pose is not None and mech.home_pose != HOME_WORKSPACE_CENTRE:
        outputs["home_pose"] = dict(inputs=[Gin], outputs=[("P0", mech.home_pose)],
                                    doc="Home pose in the geometry.")
    outputs.update(mech.extra_outputs)
    mech.outputs = outputs
    return mech
