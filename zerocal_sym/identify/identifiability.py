"""Identifiability of the source errors from distance changes.

A distance measurement cannot see a rigid motion of everything it measures.
For the planar robot, moving the whole robot *and* the measuring mechanism's
effective base point ``c + d + rM`` by a planar rigid motion leaves every
``rho_k`` unchanged, so three combinations of the 12 source errors are never
identifiable (tangent vectors at ``err``, rad / mm)::

    translation x : e1x = e2x = rMx = 1
    translation y : e1y = e2y = rMy = 1
    rotation (about O, per rad) : theta1 = theta2 = 1,
                                  (e_i) = Q (A_i + de_i),  rM = Q (c + d + rM)

(``Q`` the +90 deg rotation).  The rotation mixes the common-mode zero offset
with a tilt of the base line ``A1 A2`` and the MAEMM: the zero offsets are only
defined relative to the base line.  Fixing the frame (the gauge) by the base
joints -- ``e1x = e1y = e2y = 0``, i.e. ``A1`` exact and ``A2`` on the same
horizontal -- leaves the other 9 parameters identifiable from enough poses
(:func:`to_base_gauge` maps any error vector to that gauge exactly).

Scaling: the sensitivity is column-scaled by
:func:`zerocal_sym.identify.fisher.parameter_scale` (zero offsets as the arc
``L_i dtheta_i`` in mm, lengths in mm) and row-whitened by the noise model,
so a singular value ``sigma`` means the corresponding combination (unit
vector in the scaled mm units) is estimated with standard deviation
``1/sigma`` mm.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import SOURCE_ERROR_NAMES, NoiseModel

#: parameters fixed by the base-joint gauge (A1 exact, A2 on the same horizontal)
BASE_GAUGE = ("e1x", "e1y", "e2y")
#: the parameter set that is identifiable in the base-joint gauge
GAUGE_PARAMS = tuple(n for n in SOURCE_ERROR_NAMES if n not in BASE_GAUGE)
_Q = np.array([[0.0, -1.0], [1.0, 0.0]])


def _ix(name):
    return SOURCE_ERROR_NAMES.index(name)


def _points(robot, err):
    """Actual base joints A1, A2 and the effective measuring base point c + d + rM."""
    err = np.zeros(12) if err is None else np.asarray(err, float)
    A1 = np.array([robot.param("e1x") + err[_ix("e1x")], robot.param("e1y") + err[_ix("e1y")]])
    A2 = np.array([robot.param("e2x") + err[_ix("e2x")], robot.param("e2y") + err[_ix("e2y")]])
    M = np.array([robot.param("cx") + robot.param("dx") + err[_ix("rMx")],
                  robot.param("cy") + robot.param("dy") + err[_ix("rMy")]])
    return A1, A2, M


def rigid_motion_generators(robot, err=None) -> np.ndarray:
    """The three directions of the source errors invisible to distance changes.

    Parameters
    ----------
    robot : Robot
        A ``planar_2dof`` robot.
    err : ndarray, shape (12,), optional
        Point at which the (tangent) directions are taken (default zero).

    Returns
    -------
    ndarray, shape (3, 12)
        Rows: translation x, translation y (per mm), rotation about O (per rad).
    """
    if robot.mechanism_name != "planar_2dof":
        raise NotImplementedError(f"rigid motions of mechanism {robot.mechanism_name!r} are not described")
    A1, A2, M = _points(robot, err)
    G = np.zeros((3, 12))
    G[0, [_ix("e1x"), _ix("e2x"), _ix("rMx")]] = 1.0
    G[1, [_ix("e1y"), _ix("e2y"), _ix("rMy")]] = 1.0
    G[2, [_ix("theta1"), _ix("theta2")]] = 1.0
    G[2, [_ix("e1x"), _ix("e1y")]] = _Q @ A1
    G[2, [_ix("e2x"), _ix("e2y")]] = _Q @ A2
    G[2, [_ix("rMx"), _ix("rMy")]] = _Q @ M
    return G


def rigid_motion(robot, err, angle: float, shift=(0.0, 0.0)) -> np.ndarray:
    """Source errors of the same measurements after a finite planar rigid motion.

    ``X -> R(angle) X + shift`` applied to the robot and to the measuring
    base point; every ``rho`` is unchanged (exactly, not to first order).

    Parameters
    ----------
    err : ndarray, shape (12,)
    angle : float
        rad.
    shift : (2,)
        mm.

    Returns
    -------
    ndarray, shape (12,)
    """
    err = np.asarray(err, float).copy()
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    t = np.asarray(shift, float)
    A1, A2, M = _points(robot, err)
    out = err.copy()
    out[[_ix("theta1"), _ix("theta2")]] += angle
    out[[_ix("e1x"), _ix("e1y")]] = R @ A1 + t - np.array([robot.param("e1x"), robot.param("e1y")])
    out[[_ix("e2x"), _ix("e2y")]] = R @ A2 + t - np.array([robot.param("e2x"), robot.param("e2y")])
    cd = np.array([robot.param("cx") + robot.param("dx"), robot.param("cy") + robot.param("dy")])
    out[[_ix("rMx"), _ix("rMy")]] = R @ M + t - cd
    return out


def to_base_gauge(robot, err) -> np.ndarray:
    """The equivalent source errors with ``e1x = e1y = e2y = 0``.

    The rigid motion that puts the actual ``A1`` on its nominal position and
    the actual ``A2`` on the nominal base line (same ``y``); the result gives
    the same distances as ``err`` for every command.

    Parameters
    ----------
    err : ndarray, shape (12,)

    Returns
    -------
    ndarray, shape (12,)
    """
    A1, A2, _ = _points(robot, err)
    A1n = np.array([robot.param("e1x"), robot.param("e1y")])
    A2n = np.array([robot.param("e2x"), robot.param("e2y")])
    d, dn = A2 - A1, A2n - A1n
    angle = np.arctan2(dn[1], dn[0]) - np.arctan2(d[1], d[0])
    angle = (angle + np.pi) % (2 * np.pi) - np.pi
    c, s = np.cos(angle), np.sin(angle)
    shift = A1n - np.array([[c, -s], [s, c]]) @ A1
    out = rigid_motion(robot, err, angle, shift)
    gauge = [_ix(n) for n in BASE_GAUGE]
    out[gauge] = np.where(np.abs(out[gauge]) < 1e-12, 0.0, out[gauge])  # exact zeros, not round-off
    return out


def scaled_sensitivity(robot, theta_cmd, params="paper", noise: NoiseModel | None = None, err0=None):
    """Whitened, column-scaled sensitivity of the K-1 changes, shape (K-1, p).

    ``noise=NoiseModel()`` (zero) means unweighted (mm per scaled mm);
    default: the paper's noise model.
    """
    noise = NoiseModel.paper() if noise is None else noise
    A = fisher.sensitivity(robot, theta_cmd, params, err0) / fisher.parameter_scale(robot, params)
    if noise.is_zero:
        return A
    return fisher.whitener(fisher.measurement_covariance(robot, theta_cmd, noise, err0)) @ A


def _combination(names, v, scale, tol=1e-3):
    """A direction (scaled units) as a readable combination in physical units."""
    v = v / np.max(np.abs(v))
    terms = []
    for n, c, sc in zip(names, v, scale):
        if abs(c) >= tol:
            unit = "rad" if n.startswith("theta") else "mm"
            terms.append({"param": n, "weight": float(c), "per_scaled_mm": float(c / sc), "unit": unit})
    return terms


def identifiability_report(robot, theta_cmd, params="paper", noise: NoiseModel | None = None,
                           err0=None, rtol: float = 1e-8) -> dict:
    """Rank, singular values and the (weakly) non-identifiable combinations.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, 2)
        Commanded joints, rad.
    params : str or sequence of str
    noise : NoiseModel, optional
        Row whitening (default: the paper's noise; zero model: unweighted).
    err0 : ndarray, shape (12,), optional
        Linearisation point.
    rtol : float
        Singular values below ``rtol * sigma_max`` count as zero.

    Returns
    -------
    dict
        ``params``, ``K``, ``n_equations``, ``rank``, ``singular_values``
        (whitened & scaled), ``condition_number``, ``scaling`` (text),
        ``directions``: for each singular value its combination (weights on
        the scaled parameters, largest 1) and ``std_mm = 1/sigma``;
        ``null_space``: the combinations with ``sigma < rtol sigma_max``;
        ``null_space_rigid``: True if every null combination is a rigid motion
        (:func:`rigid_motion_generators`); ``identifiable``: per parameter,
        whether it is orthogonal to the null space; ``crlb_std``: per
        identifiable parameter, its CRLB std (rad / mm) with the others in
        the null space held at ``err0`` (pseudo-inverse), None otherwise.
    """
    names = fisher.param_names(params)
    noise = NoiseModel.paper() if noise is None else noise
    theta_cmd = np.atleast_2d(np.asarray(theta_cmd, float))
    As = scaled_sensitivity(robot, theta_cmd, names, noise, err0)
    scale = fisher.parameter_scale(robot, names)
    U, s, Vt = np.linalg.svd(As, full_matrices=True)
    p = len(names)
    sv = np.zeros(p)
    sv[: s.size] = s
    smax = sv[0] if sv.size else 0.0
    rank = int(np.sum(sv > rtol * smax)) if smax > 0 else 0
    null = Vt[rank:]
    ident = [bool(null.size == 0 or np.max(np.abs(null[:, k])) < 1e-6) for k in range(p)]
    # is the null space made of rigid motions (restricted to the estimated parameters)?
    rigid = None
    if robot.mechanism_name == "planar_2dof" and null.size:
        G = rigid_motion_generators(robot, err0)
        idx = fisher.param_indices(names)
        # a rigid motion is invisible only if all its components are estimated
        full = [g for g in G if np.all(np.isin(np.flatnonzero(np.abs(g) > 0), idx))]
        if full:
            Gs = np.array([g[idx] * scale for g in full])  # scaled units
            Qg, _ = np.linalg.qr(Gs.T)
            rigid = bool(np.allclose(null.T - Qg @ (Qg.T @ null.T), 0.0, atol=1e-6))
        else:
            rigid = False
    crlb_std = [None] * p
    if not noise.is_zero and rank:
        Finv = (Vt[:rank].T / sv[:rank] ** 2) @ Vt[:rank]
        for k in range(p):
            if ident[k]:
                crlb_std[k] = float(np.sqrt(Finv[k, k]) / scale[k])
    directions = [{"sigma": float(sv[k]), "std_mm": (float(1.0 / sv[k]) if sv[k] > rtol * smax else None),
                   "combination": _combination(names, Vt[k], scale)} for k in range(p)]
    return {
        "params": list(names),
        "K": int(theta_cmd.shape[0]),
        "n_equations": int(theta_cmd.shape[0] - 1),
        "rank": rank,
        "singular_values": sv.tolist(),
        "condition_number": float(smax / sv[rank - 1]) if rank else float("inf"),
        "condition_number_full": float(smax / sv[-1]) if sv[-1] > 0 else float("inf"),
        "scaling": ("columns: zero offsets as L_i*dtheta_i (mm), lengths in mm; rows: "
                    + ("unweighted (mm)" if noise.is_zero else "whitened by chol(Cov(s)) (paper noise model "
                       "unless given), so 1/sigma is the std (mm) of that combination")),
        "directions": directions,
        "null_space": [d["combination"] for d in directions[rank:]],
        "null_space_rigid": rigid,
        "identifiable": dict(zip(names, ident)),
        "crlb_std": dict(zip(names, crlb_std)),
    }


def format_report(rep: dict) -> str:
    """Human-readable text of :func:`identifiability_report`."""
    lines = [f"parameters: {', '.join(rep['params'])}   poses K = {rep['K']} "
             f"({rep['n_equations']} measured changes)",
             f"rank {rep['rank']} of {len(rep['params'])};  condition number "
             f"{rep['condition_number']:.4g} (identifiable part)",
             f"scaling: {rep['scaling']}",
             "singular values and their combinations (weights on scaled parameters):"]
    for d in rep["directions"]:
        comb = " ".join(f"{t['weight']:+.3f}*{t['param']}" for t in d["combination"])
        std = f"std {d['std_mm']:.3g} mm" if d["std_mm"] is not None else "NOT IDENTIFIABLE"
        lines.append(f"  sigma {d['sigma']:10.4g}  {std:>18s}  {comb}")
    if rep["null_space"]:
        lines.append(f"null space: {len(rep['null_space'])} combination(s)"
                     + ("; all are rigid motions of robot + measuring base (gauge), fix e.g. "
                        + ", ".join(BASE_GAUGE) if rep["null_space_rigid"] else ""))
    bad = [n for n, ok in rep["identifiable"].items() if not ok]
    lines.append("not identifiable: " + (", ".join(bad) if bad else "none"))
    return "\n".join(lines)


def recovery_error(robot, estimate_err, true_err) -> np.ndarray:
    """Differences in the base gauge, shape (12,) (rad, mm).

    Both error vectors are mapped by :func:`to_base_gauge` before subtracting,
    so the three rigid-motion combinations do not count.
    """
    return to_base_gauge(robot, estimate_err) - to_base_gauge(robot, true_err)


def check_rigid_invariance(robot, theta_cmd, err, angle=1e-3, shift=(0.5, -0.3)) -> float:
    """Largest change of ``rho`` under a rigid motion of ``err`` (should be ~1e-12 mm)."""
    a = kin.distance(robot, theta_cmd, err)
    b = kin.distance(robot, theta_cmd, rigid_motion(robot, err, angle, shift))
    return float(np.max(np.abs(a - b)))
