"""Per-pose terms of the design model, for every mechanism.

For each pose: the inverse-kinematics joints, the singularity indicators
(transmission sines), the distance ``rho`` and its exact derivatives (CasADi
AD of the generated mechanism functions, at zero source errors), and the
q-unit scaling of the sensitivities (see :mod:`zerocal_sym.design.criteria`).

The design parameters are the robot's identified set
``robot.errors.resolve(robot.identified_set)``: by default ``"paper"`` (the
alias of ``"default"``), the m zero offsets then the measuring errors it
identifies, in the mechanism's source-error order; a design for another set
(``zerocal design --params paper+L1,L2,L3``) is made for
``robot.identifying("paper+L1,L2,L3")``.  The units of the reports: joint quantities (joints, zero
offsets, their CRLB and bias, joint limits) in the joints' file unit, keys named
after it (:func:`okey`); poses in file units (:func:`poses_to_user`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from zerocal_sym.model import units


def _call_ik(robot, P):
    """Inverse kinematics and reach ratios without checks, shapes (K, m) each."""
    from zerocal_sym.design.calls import ik

    return ik(robot, P)


def _reachable(ratio, theta, tol: float = 0.0) -> np.ndarray:
    """Bool per pose: every limb closes (|ratio| <= 1 - tol) and the joints are finite, shape (K,)."""
    return np.all(np.abs(ratio) <= 1.0 - tol, axis=1) & np.all(np.isfinite(theta), axis=1)


def design_params(robot) -> tuple:
    """Names of the design parameters: the robot's identified set (default the paper's: the zero offsets and the
    MAEMM, p = m + n; :attr:`Robot.identified_set <zerocal_sym.model.robot.Robot.identified_set>`)."""
    return robot.errors.resolve(getattr(robot, "identified_set", "paper"))


# --------------------------------------------------------------------------- units of the reports
def offset_unit(robot) -> str:
    """The zero offsets' file unit (``deg`` for revolute joints, ``mm`` for prismatic ones): the unit of the
    ``crlb`` and ``mse`` criteria, of the CRLB and the bias of the offsets, of the joints and their limits."""
    return units.joint_unit(robot)


def okey(robot, stem: str) -> str:
    """``<stem>_deg`` or ``<stem>_mm`` after the joints' kind (``crlb_zero_offsets_deg``, ``joints_mm``)."""
    return units.joint_key(robot, stem)


def offsets_to_user(robot, values):
    """Zero offsets (or joint values), internal units -> file units (deg or mm), shape kept."""
    return units.joints_to_user(robot, values)


def offsets_from_user(robot, values):
    """Zero offsets (or joint values), file units (deg or mm) -> internal units (rad or mm), shape kept."""
    return units.joints_from_user(robot, values)


def noise_dict(robot, noise) -> dict:
    """The noise of a report: ``sigma_scale_mm`` and the joint term in the joints' file unit
    (``sigma_servo_deg`` for revolute joints, ``sigma_joint_mm`` for prismatic ones)."""
    j = float(offsets_to_user(robot, noise.sigma_joint))
    name = "sigma_servo_deg" if robot.mechanism.joint_kind == "revolute" else okey(robot, "sigma_joint")
    out = {"sigma_scale_mm": float(noise.sigma_scale_mm), name: j}
    if noise.sigma_revisit_mm:
        out["sigma_revisit_mm"] = float(noise.sigma_revisit_mm)
    return out


def joint_sigma(robot, noise_d: dict) -> float:
    """The joint term of a :func:`noise_dict` (file units)."""
    return next(v for k, v in noise_d.items() if k.startswith("sigma_") and k not in ("sigma_scale_mm",
                                                                                        "sigma_revisit_mm"))


def noise_source(robot, noise) -> str:
    """Where a noise model comes from: ``paper, Eqs. 34-35``, ``robot file [noise]``, ``mechanism X's default``,
    or ``""`` (neither: a scaled or partial model)."""
    from zerocal_sym.model.noise import NoiseModel

    if noise == NoiseModel.paper():
        return "paper, Eqs. 34-35"
    if noise == robot.noise:
        return ("robot file [noise]" if dict(getattr(robot, "noise_values", ()) or {})
                else f"mechanism {robot.mechanism_name}'s default")
    return ""


def describe_noise(robot, noise) -> str:
    """What a noise model is, for a report: the paper's Eqs. 34-35 when it is theirs, else its two terms and
    where they come from (the robot file's ``[noise]``, the mechanism's default)."""
    from zerocal_sym.model.noise import NoiseModel

    if noise == NoiseModel.paper():
        return "paper (Eq. 34 scale + Eq. 35 servo)"
    j = float(offsets_to_user(robot, noise.sigma_joint))
    terms = (f"scale {noise.sigma_scale_mm:g} mm per change + joint {j:g} {offset_unit(robot)} per joint per "
             "pose" + (f" + {noise.sigma_revisit_mm:g} mm per pose shared by its revisits" if noise.has_shared
                       else ""))
    src = noise_source(robot, noise)
    return f"the robot's ({src}): {terms}" if src else terms


def pose_units(robot) -> list:
    """The file unit of each pose coordinate (``mm``, ``deg``), shape (n,)."""
    return [units.pose_unit(robot, name) for name in robot.mechanism.pose_names]


def poses_to_user(robot, P):
    """Poses in file units (orientations in degrees), shape kept."""
    return units.pose_to_user(robot, P)


def poses_from_user(robot, P):
    """Poses from file units (orientations in degrees) to internal units, shape kept."""
    return units.pose_from_user(robot, P)


def _user_scale(robot) -> np.ndarray:
    """File units per internal unit of each pose coordinate (1 for mm, 180/pi for an angle), shape (n,)."""
    return units.pose_to_user(robot, np.ones(robot.n))


def pose_distances(robot, P, Q=None):
    """Distances between poses in file units (mm; a degree of an orientation counts as a mm), shape (K, L).

    The minimum separation of a design is measured so: two poses of a platform that turns are apart when
    their positions differ by the separation in mm or their orientations by as many degrees.  For a pose of
    positions alone it is the Euclidean distance in mm.
    """
    A = poses_to_user(robot, np.atleast_2d(P))
    B = A if Q is None else poses_to_user(robot, np.atleast_2d(Q))
    return np.linalg.norm(A[:, None, :] - B[None], axis=2)


def omitted_params(robot) -> tuple:
    """The source errors the design model leaves out (held at zero by the identification), shape (r,)."""
    keep = set(design_params(robot))
    return tuple(n for n in robot.errors.names if n not in keep)


def offset_positions(robot) -> list:
    """Positions of the zero offsets among :func:`design_params`, shape (m,)."""
    names = design_params(robot)
    return [names.index(z) for z in robot.errors.zero_offsets]


# --------------------------------------------------------------------------- per-pose terms
def pose_terms_fn(robot):
    """:func:`_pose_terms_fn` of the robot's mechanism and identified set (:func:`design_params`)."""
    return _pose_terms_fn(robot.mechanism_name, design_params(robot))


@lru_cache(maxsize=None)
def _pose_terms_fn(mech_name: str, params: tuple | None = None):
    """CasADi Function (P[n], g[G]) -> theta[m], ratio[m], s[s], rho, a[p], dth[m], ao[r].

    ``a = d rho / d (params)`` (per rad, per mm; default the paper's
    parameter set, the zero offsets and the MAEMM, p = m + n), ``dth = d rho / d theta`` (per rad) and
    ``ao = d rho / d (omitted errors)`` (the r source errors not in
    ``params``, :func:`omitted_params`), exact derivatives at zero source
    errors, joints from the inverse kinematics.
    """
    import casadi as ca

    from zerocal_sym.model.mechanism import get_mechanism

    mech = get_mechanism(mech_name)
    n, m = mech.n, mech.m
    idx = mech.errors.indices("paper" if params is None else params)
    P = ca.SX.sym("P", n)
    g = ca.SX.sym("g", mech["ik"].size1_in(1))
    theta, ratio = mech["ik"](P, g)
    s = mech["transmission"](P, theta, g)
    th = ca.SX.sym("th", m)
    ne = mech["distance"].size1_in(2)
    err = ca.SX.sym("err", ne)
    rho = mech["distance"](th, g, err)
    de = ca.jacobian(rho, err)
    dt = ca.jacobian(rho, th)
    sub = ca.Function("drho", [th, g, err], [rho, de, dt])
    r, de_v, dt_v = sub(theta, g, ca.DM.zeros(ne))
    a = ca.vertcat(*[de_v[0, i] for i in idx])
    ao = ca.vertcat(*[de_v[0, i] for i in range(ne) if i not in idx])
    return ca.Function("design_pose_terms", [P, g], [theta, ratio, s, r, a, dt_v.T, ao],
                       ["P", "g"], ["theta", "ratio", "s", "rho", "a", "dth", "ao"])


#: the outputs of :func:`_pose_terms_fn`, in order
TERM_NAMES = ("theta", "ratio", "s", "rho", "a", "dth", "ao")


def pose_terms(robot, P) -> dict:
    """Per-pose quantities of the design model.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Poses, mm.

    Returns
    -------
    dict
        ``theta`` (K, m) rad, ``ratio`` (K, m), ``s`` (K, s) singularity
        indicators, ``rho`` (K,) mm, ``a`` (K, p) d rho / d p (per rad, per
        mm; p = m + n, :func:`design_params`), ``dth`` (K, m) d rho / d theta
        (mm/rad), ``ao`` (K, r) d rho / d (omitted errors) (:func:`omitted_params`).
    """
    from zerocal_sym.design.calls import calls

    P = np.atleast_2d(np.asarray(P, float))
    return terms_dict(calls(robot)("design_pose_terms", P.T, robot.geometry), len(P))


def terms_dict(out, K: int) -> dict:
    """The design terms of K poses from the outputs of :func:`_pose_terms_fn` over their columns (rows, K)."""
    res = {nm: o.T.reshape(K, -1) for nm, o in zip(TERM_NAMES, out)}
    res["rho"] = res["rho"][:, 0]
    return res


def _qscale(robot):
    """``1 / fisher.parameter_scale``: q-unit sensitivities are ``a * qs``, shape (p,).

    An angle's q-unit is its arc on the lever arm (``L_i dtheta_i``, mm), a
    length is its own (mm): ``qs = 1 / robot.error_scale(names)``.
    """
    return 1.0 / robot.error_scale(design_params(robot))


def _crlb_weights(robot):
    """Weights ``w`` of the crlb criterion: ``mean_i var(dtheta_i) = sum_j w_j [F_q^-1]_jj``, shape (p,).

    ``w_j = qs_j^2 / m`` on the zero offsets (q-units back to rad), 0 on the MAEMM.
    """
    qs = _qscale(robot)
    w = np.zeros_like(qs)
    off = offset_positions(robot)
    w[off] = qs[off] ** 2 / len(off)
    return w


# --------------------------------------------------------------------------- position and bias weights
_POSITION_CACHE: dict = {}


def position_grid(robot) -> np.ndarray:
    """Where the position criterion averages: the robot's workspace grid (``robot.workspace_grid()``), shape (G, n).

    A rectangle: 25 x 9 points; a cylinder: the axis and 4 rings of 24 points on 5 levels.
    """
    return np.asarray(robot.workspace_grid(), float)


def position_jacobians(robot):
    """Error Jacobians ``dP = J dq`` (q = lever-arm arcs of the zero offsets, mm) over :func:`position_grid`.

    Only the position coordinates (those in mm) are kept: a platform's orientation error is not a position
    error (for a pose of positions alone, every coordinate).

    Returns
    -------
    grid : ndarray, shape (G, n)
    J : ndarray, shape (G, n_pos, m)
    """
    from zerocal_sym.model import kinematics as kin

    key = robot.sha256
    if key not in _POSITION_CACHE:
        grid = position_grid(robot)
        pos = [i for i, u in enumerate(pose_units(robot)) if u == "mm"]
        _POSITION_CACHE[key] = (grid, kin.error_jacobian(robot, grid)[:, pos, :])
    return _POSITION_CACHE[key]


def _position_weight(robot):
    """``W`` of the position criterion, shape (p, p): ``mean_x J_x^T J_x`` on the zero offsets' block (q-units).

    The mean squared position error over the grid after compensating with
    offsets of covariance ``Sigma`` (q-units) is ``tr(W Sigma)``.
    """
    _, J = position_jacobians(robot)
    names = design_params(robot)
    p = len(names)
    off = offset_positions(robot)
    W = np.zeros((p, p))
    W[np.ix_(off, off)] = np.einsum("gni,gnj->ij", J, J) / len(J)
    return W


def _tolerance_columns(robot, tolerances):
    """Scale of the omitted-error sensitivities for the bias, shape (r,).

    ``t_j / sqrt(3)`` (the RMS of a uniform error) for the ``rms`` bias model,
    ``t_j`` for ``worst`` (:class:`zerocal_sym.identify.budget.bias.Tolerances`).
    ``tolerances``: dict name -> value (internal units) or None for the
    defaults (:func:`zerocal_sym.identify.budget.bias.default_tolerances`).
    """
    from zerocal_sym.identify.budget import bias

    tol = bias.default_tolerances(robot, design_params(robot)) if tolerances is None else tolerances
    t = bias.tolerance_vector(robot, tol, omitted_params(robot))
    return t if _bias_model(tolerances) == "worst" else t / np.sqrt(3.0)


def _bias_model(tolerances):
    return getattr(tolerances, "bias_model", "rms")


class Weights:
    """What the criteria need besides the Fisher information, for one robot.

    Attributes
    ----------
    crlb : ndarray, shape (p,)
        :func:`_crlb_weights`.
    position : ndarray, shape (p, p)
        :func:`_position_weight`.
    tol : ndarray, shape (r,)
        RMS of each omitted error (``t / sqrt(3)``; ``t`` for the worst case), internal units.
    bias_model : {"rms", "worst"}
    p, r : int
    """

    def __init__(self, robot, tolerances=None):
        self.crlb = _crlb_weights(robot)
        self.position = _position_weight(robot)
        self.tol = _tolerance_columns(robot, tolerances)
        self.bias_model = _bias_model(tolerances)
        self.p, self.r = len(self.crlb), len(self.tol)

    def extend(self, aq, ao):
        """Sensitivities with the omitted errors' columns appended (``ao * t / sqrt(3)``), shape (..., p + r)."""
        return np.concatenate([aq, ao * self.tol], axis=-1)
