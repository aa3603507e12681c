"""Design criteria of an ordered design (numeric, batched) and the report of one design.

Model
-----
Parameters: the mechanism's identified set, the m zero offsets and its
measuring errors (:func:`zerocal_sym.design.terms.design_params`; four for the
planar robot, six for the rotary Delta, five for the linear Delta, twelve for
the hexapod), linearised at zero source errors.  Per pose
k, ``a_k = d rho_k / d p`` (exact, AD of the generated distance model) and
``v_k = sigma_xi^2 |d rho_k / d theta|^2`` (the joint error, in the joints' unit).  The K-1 measured
changes have sensitivity ``A = D a`` and covariance
``C = sigma_m^2 I + D diag(v) D^T`` (``D`` first differences, see
:mod:`zerocal_sym.identify.fisher`); ``F = A^T C^-1 A``.

Scaling ("q-units"): the offsets are expressed as arc lengths
``q = (L_1 dtheta_1, ..., L_m dtheta_m, drM)`` in mm (lever arms from
``robot.error_scale``; a prismatic joint's offset is a length, its scale 1), the units of the paper's
identification matrix G
(whose rows are exactly the rows of ``A`` in these units).  ``F_q = T F T``
with ``T = diag(1/L_1, ..., 1/L_m, 1, ..., 1)``, in 1/mm^2.

Criteria (all minimised internally as a log)
--------------------------------------------
``cond``
    the paper's condition number ``kappa(G)`` of the identification matrix
    (rows ``g_{k+1} - g_k``, no MAEMM prior; noise-free, scale-dependent).
``D``
    ``log det F_q`` (maximised; invariant to the scaling), in
    ``log(1/mm^(2p))``.
``A``
    ``trace F_q^-1`` (mm^2, minimised): the summed variances of the m
    arc-length offsets and the n MAEMM components.
``E``
    ``lambda_min(F_q)`` (1/mm^2, maximised).
``crlb``
    ``sqrt(trace([F^-1]_offsets) / m)`` in the offsets' file unit, deg or mm (minimised): the RMS
    Cramér-Rao bound of the m zero offsets under the full noise model,
    MAEMM as nuisance parameters.
``position``
    ``sqrt(tr(W [F_q^-1]_offsets))`` in mm (minimised): the RMS position
    error over the robot's workspace grid after compensating with the
    identified offsets, ``W = mean_x J_x^T J_x`` (``J_x`` the error Jacobian
    ``kin.error_jacobian``, ``dP = J dq``); the worst grid point is reported
    beside it (:func:`evaluate`).
``mse``
    ``sqrt(mean_i (CRLB_i^2 + E[b_i^2]))`` in the offsets' file unit (minimised): the RMS
    error of the m zero offsets including the first-order bias ``b`` from the
    source errors the model leaves out, each uniform within its tolerance
    (:mod:`zerocal_sym.identify.budget.bias`; ``E[b_i^2] = sum_j S_ij^2 t_j^2 / 3``);
    with the ``worst`` bias model (:class:`zerocal_sym.identify.budget.bias.Tolerances`)
    the squared worst case ``(sum_j |S_ij| t_j)^2`` instead.  The bias does
    not shrink with K; the variance does.

``position`` and ``mse`` take :class:`zerocal_sym.design.terms.Weights`
(the position weight, the tolerances); ``mse`` works on the sensitivities
with the omitted errors' columns appended (``Weights.extend``).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import PoseError
from zerocal_sym.model import units
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.constraints import Constraints, check_design
from zerocal_sym.design.replicates import revisit_terms
from zerocal_sym.design.terms import (Weights, _crlb_weights, _qscale, design_params, noise_dict, offset_unit,
                                      offsets_to_user, okey, pose_terms, pose_units, poses_to_user)

#: criterion name -> (description, units, better: "min" | "max"); p = m + n parameters
#: (:func:`criteria_table` gives the table of one robot, with its names and p)
CRITERIA = {
    "cond": ("condition number kappa of the identification matrix G (paper)", "", "min"),
    "D": ("log det of the Fisher information F_q (q = zero offsets as arcs L_i dtheta_i, MAEMM)",
          "log(1/mm^2p)", "max"),
    "A": ("trace of F_q^-1", "mm^2", "min"),
    "E": ("smallest eigenvalue of F_q", "1/mm^2", "max"),
    "crlb": ("RMS Cramer-Rao bound of the zero offsets (full noise model)", "deg", "min"),
    "position": ("RMS position error over the workspace after compensation (offsets' CRLB through the error "
                 "Jacobian)", "mm", "min"),
    "mse": ("RMS zero-offset error: CRLB and the bias from the omitted errors' tolerances", "deg", "min"),
}
#: criteria that need the omitted errors' sensitivities (``Weights.extend``)
EXTENDED = ("mse",)
#: the checked design's criterion: the crlb's value among the designs whose fit check sees what they assume
#: (:mod:`zerocal_sym.design.detection`); not a Fisher criterion of its own (not in :data:`CRITERIA`)
CHECKED = "checked"
CHECKED_DESCRIPTION = ("RMS Cramer-Rao bound of the zero offsets among designs whose fit check sees reversed or "
                       "swapped poses, a bad reading and the robot file's errors")
#: every criterion a design can be optimised for
DESIGN_CRITERIA = tuple(CRITERIA) + (CHECKED,)


def criteria_table(robot) -> dict:
    """:data:`CRITERIA` for one robot: the q-units by name and the units of ``D`` with its p.

    Returns
    -------
    dict
        criterion name -> (description, units, better).  Planar robot: ``D``
        in ``log(1/mm^8)``, q = (L1 dtheta1, L2 dtheta2, rMx, rMy).
    """
    errors = robot.errors
    names = design_params(robot)
    q = ", ".join(f"{errors[nm].lever} d{nm}" if errors[nm].lever else nm for nm in names)
    m = len(errors.zero_offsets)
    u = offset_unit(robot)
    out = dict(CRITERIA)
    out["D"] = (f"log det of the Fisher information F_q (q = {q})", f"log(1/mm^{2 * len(names)})", "max")
    out["crlb"] = (f"RMS Cramer-Rao bound of the {m} zero offsets (full noise model)", u, "min")
    out["mse"] = (CRITERIA["mse"][0], u, "min")
    return out


def _noise_terms(noise: NoiseModel, robot=None):
    """``(sigma_m^2, sigma_joint^2)`` (mm^2; the joints' internal unit squared); ``noise`` None: the robot's
    (:attr:`Robot.noise`; the paper's without a robot)."""
    if noise is None:
        noise = NoiseModel.paper() if robot is None else robot.noise
    if noise.is_zero:
        raise DesignError("the noise model is zero: the Fisher information is unbounded")
    return float(noise.sigma_scale_mm) ** 2, float(noise.sigma_servo_rad) ** 2


# --------------------------------------------------------------------------- numeric criteria
def _fisher_batch(aq, v, sm2):
    """Fisher information in q-units for a batch of ordered designs.

    Parameters
    ----------
    aq : ndarray, shape (B, K, p)
        Per-pose sensitivities in q-units (mm per mm).
    v : ndarray, shape (B, K)
        Per-pose variance of rho from the servo error, mm^2.
    sm2 : float
        Scale-error variance per change, mm^2.

    Returns
    -------
    ndarray, shape (B, p, p)
    """
    A = np.diff(aq, axis=1)
    K = aq.shape[1]
    C = np.zeros((aq.shape[0], K - 1, K - 1))
    i = np.arange(K - 1)
    C[:, i, i] = sm2 + v[:, :-1] + v[:, 1:]
    j = np.arange(K - 2)
    C[:, j, j + 1] = -v[:, 1:-1]
    C[:, j + 1, j] = -v[:, 1:-1]
    X = np.linalg.solve(C, A)
    F = np.einsum("bki,bkj->bij", A, X)
    return (F + np.swapaxes(F, 1, 2)) / 2


def _fisher_banded(aq, v, sm2):
    """:func:`_fisher_batch` of one long ordered design by a banded solve, O(K), shape (p, p).

    ``aq`` (K, p), ``v`` (K,).
    """
    from scipy.linalg import solveh_banded

    A = np.diff(aq, axis=0)
    K = aq.shape[0]
    ab = np.zeros((2, K - 1))
    ab[1] = sm2 + v[:-1] + v[1:]
    ab[0, 1:] = -v[1:-1]
    X = solveh_banded(ab, A)
    F = A.T @ X
    return (F + F.T) / 2


#: from this K on, one design's Fisher information is computed by a banded solve (smaller K: dense, as before)
BANDED_K = 60


def _fisher(aq, v, sm2, shared=None):
    """:func:`_fisher_batch`, banded for one design with K >= :data:`BANDED_K`; with ``shared`` (the revisited
    poses' part of one design, :func:`zerocal_sym.design.replicates.revisit_terms`) exact with it."""
    if shared is not None:
        from zerocal_sym.design.replicates import shared_fisher

        return shared_fisher(aq[0], v[0], sm2, shared)[None]
    if aq.shape[0] == 1 and aq.shape[1] >= BANDED_K:
        return _fisher_banded(aq[0], v[0], sm2)[None]
    return _fisher_batch(aq, v, sm2)


def _objective_batch(criterion, aq, v, sm2, w, shared=None):
    """Internal objective (smaller is better; ``inf`` for rank-deficient designs), shape (B,).

    Parameters
    ----------
    aq : ndarray, shape (B, K, p) or (B, K, p + r)
        Per-pose sensitivities in q-units; for ``mse`` with the omitted
        errors' columns appended (:meth:`Weights.extend`).
    v : ndarray, shape (B, K)
    sm2 : float
    w : ndarray, shape (p,), or Weights
        Weights of the crlb criterion (:func:`zerocal_sym.design.terms._crlb_weights`):
        its objective is ``log sum_j w_j [F_q^-1]_jj``, the log of the mean
        variance of the zero offsets (rad^2); a :class:`Weights` for every
        criterion (``position`` and ``mse`` need one).
    shared : ndarray, shape (K-1, G), optional
        The revisited poses' shared error of one design (:func:`_fisher`).
    """
    B = aq.shape[0]
    out = np.full(B, np.inf)
    if criterion == "cond":
        p = w.p if isinstance(w, Weights) else len(w)
        s = np.linalg.svd(np.diff(aq[..., :p], axis=1), compute_uv=False)
        ok = s[:, -1] > 1e-12 * s[:, 0]
        out[ok] = np.log(s[ok, 0] / s[ok, -1])
        return out
    return _objective_fisher(criterion, _fisher(aq, v, sm2, shared), w)


def _objective_fisher(criterion, F, w):
    """Internal objective from Fisher informations (q-units), shape (B,).

    ``F`` : (B, p, p), or (B, p + r, p + r) for ``mse`` (the omitted errors'
    block scaled by their RMS tolerances: ``H = F[:p, p:]`` gives the bias
    ``F_pp^-1 H``).
    """
    B = F.shape[0]
    out = np.full(B, np.inf)
    wt = w if isinstance(w, Weights) else None
    wc = wt.crlb if wt is not None else np.asarray(w, float)
    p = len(wc)
    if criterion in ("position", "mse") and wt is None:
        raise DesignError(f"criterion {criterion!r} needs design weights (design.terms.Weights)")
    H = None
    if criterion == "mse":
        H = F[:, :p, p:]
    F = F[:, :p, :p]
    ev = np.linalg.eigvalsh(F)
    ok = ev[:, 0] > 1e-12 * np.maximum(ev[:, -1], 1e-300)
    if not np.any(ok):
        return out
    F, ev = F[ok], ev[ok]
    if criterion == "D":
        out[ok] = -np.sum(np.log(ev), axis=1)
    elif criterion == "E":
        out[ok] = -np.log(ev[:, 0])
    else:
        Finv = np.linalg.inv(F)
        if criterion == "A":
            out[ok] = np.log(np.trace(Finv, axis1=1, axis2=2))
        elif criterion == "crlb":
            out[ok] = np.log(np.diagonal(Finv, axis1=1, axis2=2) @ wc)
        elif criterion == "position":
            out[ok] = np.log(np.einsum("ij,bji->b", wt.position, Finv))
        elif criterion == "mse":
            Bm = Finv @ H[ok]
            b2 = np.sum(np.abs(Bm), axis=2) ** 2 if wt.bias_model == "worst" else np.sum(Bm ** 2, axis=2)
            out[ok] = np.log((np.diagonal(Finv, axis1=1, axis2=2) + b2) @ wc)
        else:
            raise DesignError(f"unknown criterion {criterion!r}")
    return out


def criterion_values(robot, P, noise: NoiseModel | None = None, tolerances=None) -> dict:
    """Every criterion of an ordered design, in the user's units.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Poses in visiting order, mm.
    tolerances : dict name -> value (internal units), optional
        Tolerances of the omitted errors for ``mse`` (default
        :func:`zerocal_sym.identify.budget.bias.default_tolerances`).

    Returns
    -------
    dict
        ``cond`` (-), ``D`` (log det F_q), ``A`` (mm^2), ``E`` (1/mm^2),
        ``crlb`` (deg, RMS over the m offsets), ``position`` (mm), ``mse``
        (deg); ``inf``/``-inf`` where the design is rank-deficient.
    """
    sm2, _ = _noise_terms(noise, robot)
    w = _crlb_weights(robot)
    wt = Weights(robot, tolerances)
    aq, v, ao = _terms_batch(robot, P, noise, omitted=True)
    v, B = revisit_terms(robot, P, noise, v)
    res = {}
    for c in CRITERIA:
        if c in EXTENDED:
            o = float(_objective_batch(c, wt.extend(aq, ao), v, sm2, wt, B)[0])
        else:
            o = float(_objective_batch(c, aq, v, sm2, wt if c == "position" else w, B)[0])
        res[c] = _user_value(c, o, robot.errors.offset_unit)
    return res


def _user_value(criterion, obj, unit: str = "rad"):
    """Internal objective -> user-facing value (``unit``: the zero offsets' internal unit, rad or mm, of the
    ``crlb`` and ``mse`` criteria; their values are in its file unit, deg or mm)."""
    if not np.isfinite(obj):
        return {"cond": math.inf, "D": -math.inf, "A": math.inf, "E": 0.0, "crlb": math.inf,
                "position": math.inf, "mse": math.inf}[criterion]
    if criterion == "position":
        return math.sqrt(math.exp(obj))
    if criterion == "cond":
        return math.exp(obj)
    if criterion == "D":
        return -obj
    if criterion == "A":
        return math.exp(obj)
    if criterion == "E":
        return math.exp(-obj)
    return float(units.to_user(math.sqrt(math.exp(obj)), unit))


# --------------------------------------------------------------------------- evaluation
def evaluate(robot, P, criterion: str = "crlb", noise: NoiseModel | None = None,
             cons: Constraints | None = None, tolerances=None, requirement=None) -> dict:
    """Report of one ordered design.

    Parameters
    ----------
    criterion : str
        One of :data:`DESIGN_CRITERIA` (``checked``: the value is the crlb's).
    tolerances : dict name -> value (internal units), optional
        Tolerances of the omitted errors (``mse`` and the ``bias`` entry;
        default :func:`zerocal_sym.identify.budget.bias.default_tolerances`).
    requirement : zerocal_sym.design.detection.Requirement, optional
        What the ``detection`` entry judges (default: its defaults with ``tolerances``).

    Returns
    -------
    dict
        ``poses`` (K x n, file units: mm, deg for orientations, as
        ``pose_units`` says), ``joints_deg`` (K x m; ``joints_mm`` for
        prismatic joints: every key of a joint quantity names the joints'
        file unit, :func:`zerocal_sym.design.terms.okey`), ``pose_names``,
        ``joint_names``, ``joint_unit``, ``criterion`` {``name``, ``value``, ``units``,
        ``values`` (all seven), ``units_all``}, ``crlb_zero_offsets_deg`` (m,)
        from :func:`zerocal_sym.identify.fisher.crlb_zero_offsets_user` and
        its RMS ``crlb_rms_deg``, ``bias`` (worst-case and RMS bias of the
        zero offsets from the tolerances, :func:`zerocal_sym.identify.budget.bias.tolerance_bias`,
        and the RMS error ``sqrt(CRLB^2 + RMS bias^2)`` per offset),
        ``position`` (RMS and worst position error over the workspace grid
        after compensation, mm), ``kappa`` (the paper's kappa_1 of G, no
        MAEMM prior), ``rho_span_mm``, ``min_transmission_sine``,
        ``detection`` (what the fit check sees: :func:`zerocal_sym.design.detection.detection`) and, with
        ``cons``, ``violations``.
    """
    from zerocal_sym.identify.budget import bias
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.linear import condition_number, identification_matrix

    P = np.atleast_2d(np.asarray(P, float))
    noise = NoiseModel.coerce(noise, robot=robot)
    table = criteria_table(robot)
    vals = criterion_values(robot, P, noise, tolerances)
    t = pose_terms(robot, P)
    try:
        crlb = fisher.crlb_zero_offsets_user(robot, t["theta"], design_params(robot), noise).tolist()
    except PoseError:
        crlb = [math.inf] * robot.m
    bias_rep = _bias_report(robot, t["theta"], noise, tolerances, crlb)
    pos = position_report(robot, P, noise)
    G, _ = identification_matrix(robot, P, theta=t["theta"])
    name = "crlb" if criterion == CHECKED else criterion
    rep = {
        "poses": poses_to_user(robot, P).tolist(),
        "pose_units": pose_units(robot),
        okey(robot, "joints"): offsets_to_user(robot, t["theta"]).tolist(),
        "pose_names": list(robot.mechanism.pose_names),
        "joint_names": list(robot.mechanism.joint_names),
        "joint_unit": offset_unit(robot),
        "criterion": {"name": criterion, "value": vals[name], "units": table[name][1],
                      "values": vals, "units_all": {c: table[c][1] for c in table}},
        okey(robot, "crlb_zero_offsets"): crlb,
        okey(robot, "crlb_rms"): float(np.sqrt(np.mean(np.square(crlb)))),
        "bias": bias_rep,
        "position": pos,
        "kappa": condition_number(G),
        "rho_span_mm": float(np.ptp(t["rho"])),
        "min_transmission_sine": float(np.min(np.abs(t["s"]))),
        "detection": _detection(robot, P, noise, tolerances, requirement),
    }
    if cons is not None:
        rep["violations"] = check_design(robot, P, cons)
    return rep


def _detection(robot, P, noise, tolerances, requirement):
    """:func:`zerocal_sym.design.detection.detection` of a design, None where it cannot identify the parameters."""
    from zerocal_sym.design.detection import Requirement, detection

    try:
        return detection(robot, P, noise, requirement or Requirement(robot, tolerances))
    except (np.linalg.LinAlgError, PoseError):
        return None


def _bias_report(robot, theta, noise, tolerances, crlb):
    """The zero offsets' bias from the tolerances and the RMS error with the CRLB (the offsets' file unit:
    keys ``worst_case_deg`` ... for revolute joints, ``worst_case_mm`` ... for prismatic ones)."""
    from zerocal_sym.identify.budget import bias

    try:
        b = bias.tolerance_bias(robot, theta, tolerances, design_params(robot), noise)
    except (np.linalg.LinAlgError, ValueError):
        return None
    off = [b["params"].index(z) for z in robot.errors.zero_offsets]
    worst = np.asarray(b["worst_case"], float)[off]
    rms = np.asarray(b["rms"], float)[off]
    rms_err = np.sqrt(np.square(crlb) + np.square(rms))
    k = lambda stem: okey(robot, stem)  # noqa: E731
    return {k("worst_case"): worst.tolist(), k("rms"): rms.tolist(),
            k("worst_case_rms"): float(np.sqrt(np.mean(np.square(worst)))),
            k("rms_rms"): float(np.sqrt(np.mean(np.square(rms)))),
            k("rms_error"): rms_err.tolist(), k("rms_error_rms"): float(np.sqrt(np.mean(rms_err ** 2))),
            "tolerances": b["tolerances"], "tolerance_units": b["tolerance_units"], "model": b["model"]}


def position_report(robot, P, noise=None) -> dict:
    """Predicted position error over the workspace after compensating with offsets identified from ``P``.

    The offsets' covariance (CRLB, q-units) propagated through the error
    Jacobian at each point of the workspace grid
    (:func:`zerocal_sym.design.terms.position_grid`): ``sqrt(tr(J Sigma J^T))``
    per point (mm, the RMS length of the position error there).

    Returns
    -------
    dict
        ``rms_mm`` (over the grid), ``max_mm`` (worst grid point),
        ``worst_pose`` (n,), ``grid_points``.
    """
    from zerocal_sym.design.terms import offset_positions, position_jacobians

    P = np.atleast_2d(np.asarray(P, float))
    sm2, _ = _noise_terms(noise, robot)
    aq, v = _terms_batch(robot, P, noise)
    v, B = revisit_terms(robot, P, noise, v)
    F = _fisher(aq, v, sm2, B)[0]
    grid, J = position_jacobians(robot)
    try:
        Fi = np.linalg.inv(F)
    except np.linalg.LinAlgError:
        return {"rms_mm": math.inf, "max_mm": math.inf, "worst_pose": None, "grid_points": len(grid)}
    off = offset_positions(robot)
    S = Fi[np.ix_(off, off)]
    e2 = np.einsum("gni,ij,gnj->g", J, S, J)
    if not np.all(np.isfinite(e2)) or np.any(e2 < 0):
        return {"rms_mm": math.inf, "max_mm": math.inf, "worst_pose": None, "grid_points": len(grid)}
    k = int(np.argmax(e2))
    return {"rms_mm": float(np.sqrt(np.mean(e2))), "max_mm": float(np.sqrt(e2[k])), "worst_pose": grid[k].tolist(),
            "grid_points": len(grid)}


def _check_criterion(criterion, known=CRITERIA):
    if criterion not in known:
        raise DesignError(f"unknown criterion {criterion!r} (known: {', '.join(known)})")


def _terms_batch(robot, P, noise, omitted=False):
    """``aq`` (1, K, p), ``v`` (1, K) [, ``ao`` (1, K, r) with ``omitted``]."""
    _, sx2 = _noise_terms(noise, robot)
    t = pose_terms(robot, P)
    out = (t["a"] * _qscale(robot))[None], (sx2 * np.sum(t["dth"] ** 2, axis=1))[None]
    return out + (t["ao"][None],) if omitted else out


def _criterion_terms(robot, criterion, t, qs, sx2, wt):
    """Per-pose ``aq`` (K, p or p + r) and ``v`` (K,) of a criterion from :func:`pose_terms` output."""
    aq = t["a"] * qs
    if criterion in EXTENDED:
        aq = wt.extend(aq, t["ao"])
    return aq, sx2 * np.sum(t["dth"] ** 2, axis=1)


def _criterion_weights(robot, criterion, tolerances=None):
    """The ``w`` argument of :func:`_objective_batch` for a criterion: the crlb weights, or :class:`Weights`."""
    if criterion in ("position",) + EXTENDED:
        return Weights(robot, tolerances)
    return _crlb_weights(robot)


def _objective(robot, criterion, P, noise, tolerances=None):
    if criterion in ("position",) + EXTENDED:
        wt = Weights(robot, tolerances)
        aq, v, ao = _terms_batch(robot, P, noise, omitted=True)
        if criterion in EXTENDED:
            aq = wt.extend(aq, ao)
        v, B = revisit_terms(robot, P, noise, v)
        return float(_objective_batch(criterion, aq, v, _noise_terms(noise, robot)[0], wt, B)[0])
    aq, v = _terms_batch(robot, P, noise)
    v, B = revisit_terms(robot, P, noise, v)
    return float(_objective_batch(criterion, aq, v, _noise_terms(noise, robot)[0], _crlb_weights(robot), B)[0])
