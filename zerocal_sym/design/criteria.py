"""Design criteria of an ordered design (numeric, batched) and the report of one design.

Model
-----
Parameters: the paper's set ``p = (dtheta_1 .. dtheta_m, drM_1 .. drM_n)``
(:func:`zerocal_sym.design.terms.design_params`; p = m + n, four for the
planar robot, six for the Delta), linearised at zero source errors.  Per pose
k, ``a_k = d rho_k / d p`` (exact, AD of the generated distance model) and
``v_k = sigma_xi^2 |d rho_k / d theta|^2`` (servo error).  The K-1 measured
changes have sensitivity ``A = D a`` and covariance
``C = sigma_m^2 I + D diag(v) D^T`` (``D`` first differences, see
:mod:`zerocal_sym.identify.fisher`); ``F = A^T C^-1 A``.

Scaling ("q-units"): the offsets are expressed as arc lengths
``q = (L_1 dtheta_1, ..., L_m dtheta_m, drM)`` in mm (lever arms from
``robot.error_scale``), the units of the paper's identification matrix G
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
    ``sqrt(trace([F^-1]_offsets) / m)`` in degrees (minimised): the RMS
    Cramér-Rao bound of the m zero offsets under the full noise model,
    MAEMM as nuisance parameters.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import PoseError
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.constraints import Constraints, DesignError, check_design
from zerocal_sym.design.terms import _crlb_weights, _qscale, design_params, pose_terms

#: criterion name -> (description, units, better: "min" | "max"); p = m + n parameters
#: (:func:`criteria_table` gives the table of one robot, with its names and p)
CRITERIA = {
    "cond": ("condition number kappa of the identification matrix G (paper)", "", "min"),
    "D": ("log det of the Fisher information F_q (q = zero offsets as arcs L_i dtheta_i, MAEMM)",
          "log(1/mm^2p)", "max"),
    "A": ("trace of F_q^-1", "mm^2", "min"),
    "E": ("smallest eigenvalue of F_q", "1/mm^2", "max"),
    "crlb": ("RMS Cramer-Rao bound of the zero offsets (full noise model)", "deg", "min"),
}


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
    out = dict(CRITERIA)
    out["D"] = (f"log det of the Fisher information F_q (q = {q})", f"log(1/mm^{2 * len(names)})", "max")
    out["crlb"] = (f"RMS Cramer-Rao bound of the {m} zero offsets (full noise model)", "deg", "min")
    return out


def _noise_terms(noise: NoiseModel):
    if noise is None:
        noise = NoiseModel.paper()
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


def _objective_batch(criterion, aq, v, sm2, w):
    """Internal objective (smaller is better; ``inf`` for rank-deficient designs), shape (B,).

    Parameters
    ----------
    aq : ndarray, shape (B, K, p)
    v : ndarray, shape (B, K)
    sm2 : float
    w : ndarray, shape (p,)
        Weights of the crlb criterion (:func:`zerocal_sym.design.terms._crlb_weights`):
        its objective is ``log sum_j w_j [F_q^-1]_jj``, the log of the mean
        variance of the zero offsets (rad^2).
    """
    B = aq.shape[0]
    out = np.full(B, np.inf)
    if criterion == "cond":
        s = np.linalg.svd(np.diff(aq, axis=1), compute_uv=False)
        ok = s[:, -1] > 1e-12 * s[:, 0]
        out[ok] = np.log(s[ok, 0] / s[ok, -1])
        return out
    F = _fisher_batch(aq, v, sm2)
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
            out[ok] = np.log(np.diagonal(Finv, axis1=1, axis2=2) @ np.asarray(w, float))
        else:
            raise DesignError(f"unknown criterion {criterion!r}")
    return out


def criterion_values(robot, P, noise: NoiseModel | None = None) -> dict:
    """Every criterion of an ordered design, in the user's units.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Poses in visiting order, mm.

    Returns
    -------
    dict
        ``cond`` (-), ``D`` (log det F_q), ``A`` (mm^2), ``E`` (1/mm^2),
        ``crlb`` (deg, RMS over the m offsets); ``inf``/``-inf`` where the
        design is rank-deficient.
    """
    sm2, _ = _noise_terms(noise)
    w = _crlb_weights(robot)
    aq, v = _terms_batch(robot, P, noise)
    res = {}
    for c in CRITERIA:
        o = float(_objective_batch(c, aq, v, sm2, w)[0])
        res[c] = _user_value(c, o)
    return res


def _user_value(criterion, obj):
    """Internal objective -> user-facing value."""
    if not np.isfinite(obj):
        return {"cond": math.inf, "D": -math.inf, "A": math.inf, "E": 0.0, "crlb": math.inf}[criterion]
    if criterion == "cond":
        return math.exp(obj)
    if criterion == "D":
        return -obj
    if criterion == "A":
        return math.exp(obj)
    if criterion == "E":
        return math.exp(-obj)
    return math.degrees(math.sqrt(math.exp(obj)))


# --------------------------------------------------------------------------- evaluation
def evaluate(robot, P, criterion: str = "crlb", noise: NoiseModel | None = None,
             cons: Constraints | None = None) -> dict:
    """Report of one ordered design.

    Returns
    -------
    dict
        ``poses`` (K x n mm), ``joints_deg`` (K x m), ``pose_names``,
        ``joint_names``, ``criterion`` {``name``, ``value``, ``units``,
        ``values`` (all five), ``units_all``}, ``crlb_zero_offsets_deg`` (m,)
        from :func:`zerocal_sym.identify.fisher.crlb_zero_offsets_deg` and
        its RMS ``crlb_rms_deg``, ``kappa`` (the paper's kappa_1 of G, no
        MAEMM prior), ``rho_span_mm``, ``min_transmission_sine`` and, with
        ``cons``, ``violations``.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.linear import condition_number, identification_matrix

    P = np.atleast_2d(np.asarray(P, float))
    noise = noise or NoiseModel.paper()
    table = criteria_table(robot)
    vals = criterion_values(robot, P, noise)
    t = pose_terms(robot, P)
    try:
        crlb = fisher.crlb_zero_offsets_deg(robot, t["theta"], "paper", noise).tolist()
    except PoseError:
        crlb = [math.inf] * robot.m
    G, _ = identification_matrix(robot, P, theta=t["theta"])
    rep = {
        "poses": P.tolist(),
        "joints_deg": np.degrees(t["theta"]).tolist(),
        "pose_names": list(robot.mechanism.pose_names),
        "joint_names": list(robot.mechanism.joint_names),
        "criterion": {"name": criterion, "value": vals[criterion], "units": table[criterion][1],
                      "values": vals, "units_all": {c: table[c][1] for c in table}},
        "crlb_zero_offsets_deg": crlb,
        "crlb_rms_deg": float(np.sqrt(np.mean(np.square(crlb)))),
        "kappa": condition_number(G),
        "rho_span_mm": float(np.ptp(t["rho"])),
        "min_transmission_sine": float(np.min(np.abs(t["s"]))),
    }
    if cons is not None:
        rep["violations"] = check_design(robot, P, cons)
    return rep


def _check_criterion(criterion):
    if criterion not in CRITERIA:
        raise DesignError(f"unknown criterion {criterion!r} (known: {', '.join(CRITERIA)})")


def _terms_batch(robot, P, noise):
    _, sx2 = _noise_terms(noise)
    t = pose_terms(robot, P)
    return (t["a"] * _qscale(robot))[None], (sx2 * np.sum(t["dth"] ** 2, axis=1))[None]


def _objective(robot, criterion, P, noise):
    return float(_objective_batch(criterion, *_terms_batch(robot, P, noise), _noise_terms(noise)[0],
                                  _crlb_weights(robot))[0])
