"""TSVD on one round (paper Eq. 28-29): the model linearised at the prior, the truncated SVD, its std.

The paper's identification model is linear in the increment ``dp`` of the
zero offsets as lengths and the MAEMM (:mod:`zerocal_sym.identify.linear`),
``ds = G dp``, solved by the truncated SVD
(:mod:`~zerocal_sym.identify.estimate.truncated_svd`).  :func:`tsvd_round`
checks the round, linearises at the prior, solves and gives the estimate
with its covariance, honest per parameter
(:mod:`~zerocal_sym.identify.estimate.tsvd_uncertainty`); the fit check and
the rest of :func:`~zerocal_sym.identify.tsvd.identify_tsvd` come after it.
Shapes: K poses, m joints, p = m + n identified parameters.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import IdentificationError, PoseError
from zerocal_sym.identify.estimate.truncated_svd import DEFAULT_RTOL, DEFAULT_RULE, tsvd_solve
from zerocal_sym.identify.estimate.tsvd_uncertainty import _honest_uncertainty
from zerocal_sym.identify.result import IdentificationResult

#: G with sigma_min / sigma_max below this is treated as rank-deficient (collinear poses).
RANK_RTOL = 1e-9
#: poses whose second principal extent is below this fraction of the first are "on one line".
COLLINEAR_RTOL = 1e-6


def _validate(meas, robot, p):
    th = np.asarray(meas.theta_cmd, float)
    rd = np.asarray(meas.readings, float)
    K = th.shape[0]
    if th.ndim != 2 or th.shape[1] != robot.m or rd.shape != (K,):
        raise IdentificationError(f"measurements must be theta_cmd (K, {robot.m}) and readings (K,) for the "
                                  f"{robot.m}-joint robot {robot.name!r}, got {th.shape} and {rd.shape}",
                                  where=meas.source)
    if K < p + 1:
        raise IdentificationError(f"too few poses: K = {K} < {p + 1} ({p} parameters are identified from K - 1 "
                                  "measured changes)", where=meas.source)
    for name, arr in (("commanded joint angles", th), ("reading", rd)):
        if np.isfinite(arr).all():
            continue
        k = int(np.flatnonzero(~np.all(np.isfinite(arr.reshape(K, -1)), axis=1))[0])
        raise IdentificationError(f"{name} of pose {k} is not a finite number", where=meas.where(k))
    return th, rd


def tsvd_round(robot, meas, prior=None, t=None, rule=DEFAULT_RULE, noise=None, rtol=DEFAULT_RTOL,
               diagnostics: bool = True):
    """TSVD's estimate of one round, with its covariance: :func:`~zerocal_sym.identify.tsvd.identify_tsvd`
    before the fit check (its parameters and result there).

    Returns
    -------
    (IdentificationResult, dict or None)
        The result (``success`` True, no ``info["fit"]``) and the honest uncertainty's private parts
        (:func:`~zerocal_sym.identify.estimate.tsvd_uncertainty._honest_uncertainty`: the exact model, the kept
        directions, the fit check's point), None without ``diagnostics`` (the estimate alone).
    """
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.identify.fisher import change_covariance
    from zerocal_sym.identify.linear import identification_matrix

    errors = robot.errors
    names = errors.resolve("default")
    offs, maemm = errors.zero_offsets, errors.measuring
    p = len(names)
    th, readings = _validate(meas, robot, p)
    prior = errors.zeros() if prior is None else np.asarray(prior, float)
    if prior.shape != (len(errors),) or not np.isfinite(prior).all():
        raise ValueError(f"prior must be a finite vector of the {len(errors)} source errors")
    P = kin.fk(robot, th + errors.take(prior, offs))
    if not np.isfinite(P).all():
        k = int(np.flatnonzero(~np.all(np.isfinite(P), axis=1))[0])
        raise PoseError("commanded joint angles are not an assembly of the robot", where=meas.where(k))
    maemm_prior = errors.take(prior, maemm)
    G, lam = identification_matrix(robot, P, maemm_prior=maemm_prior)
    b = readings[1:] - np.diff(lam)
    s = np.linalg.svd(G, compute_uv=False)
    if s[-1] <= RANK_RTOL * s[0]:
        from zerocal_sym.identify.identifiability import null_space_phrase

        rank = int(np.sum(s > RANK_RTOL * s[0]))
        why = null_space_phrase(robot, th, names, err0=prior)
        raise IdentificationError(
            f"identification matrix G has rank {rank} < {p}: the offsets and the MAEMM cannot be identified from "
            f"these poses ({why or 'the measuring-mechanism vectors of the poses are degenerate'}); measure other "
            "poses", where=meas.source)
    spread = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    if spread[1] <= COLLINEAR_RTOL * spread[0]:
        raise IdentificationError(
            f"the {P.shape[0]} poses lie on one straight line: G is nearly rank-deficient (condition number "
            f"{s[0] / s[-1]:.3g}); use poses that span the workspace (e.g. the {robot.workspace.scheme_name} "
            "scheme's two boundaries)", where=meas.source)
    C = None
    if noise is not None and (diagnostics or (rule == "discrepancy" and t is None)):
        C = change_covariance(robot, th, noise, err0=prior)  # tridiagonal, as bands: O(K)
    noise_std = None if C is None else C.std()
    if rule == "discrepancy" and t is None and noise_std is None:
        raise ValueError("rule='discrepancy' needs a noise model")
    sol = tsvd_solve(G, b, t=t, rule=rule, rtol=rtol, noise_std=noise_std)
    # G's columns: offsets as lengths (lever * dtheta), then the MAEMM (mm)
    T = np.diag(1.0 / robot.error_scale(names))
    inc, est, status, info = _estimate(errors, names, prior, sol, s, T, P, maemm_prior)
    if not diagnostics:  # the estimate alone (the Monte Carlo): no covariance, residuals, honest std, fit check
        return _lean(errors, names, est, status, info), None
    lin_res = b - G @ sol.x
    A = T @ sol.operator()
    m = G.shape[0]
    base = errors.put(errors.zeros(), offs + maemm, errors.take(prior, offs + maemm))  # what TSVD's model holds
    if C is not None:  # the servo error through the exact model at the estimate
        cov = change_covariance(robot, th, noise, err0=errors.put(base, names, est)).sandwich(A)  # A C A^T, O(K p^2)
    elif m > sol.t:
        cov = float(lin_res @ lin_res) / (m - sol.t) * (A @ A.T)
    else:
        cov = None
    full = errors.put(errors.zeros(), names, est)
    pred = np.diff(kin.distance(robot, th, full))
    residuals = np.asarray(meas.readings, float)[1:] - pred
    honest = _honest_uncertainty(robot, meas, names, errors.put(errors.zeros(), names, errors.take(prior, names)),
                                 noise, est, sol, cov, A=A, base=base)
    items = list(info.items())  # the keys in their documented order: linear_residuals after kappa
    info = dict(items[:5] + [("linear_residuals", lin_res)] + items[5:])
    info.update({k: v for k, v in honest.items() if not k.startswith("_")})
    res = IdentificationResult(method="tsvd", params=names, estimate=est, covariance=honest["_covariance"],
                               success=True, status=status, residuals=residuals, info=info, errors=errors,
                               std_kind=honest["_std_kind"])
    return res, honest


def _estimate(errors, names, prior, sol, s, T, P, maemm_prior):
    """``(inc, est, status, info)`` of a TSVD solution (``T``: ``L dth`` to ``dth``; ``s``: G's singular values)."""
    inc = T @ sol.x
    est = errors.take(prior, names) + inc
    status = f"ok: TSVD t = {sol.t} of {s.size} ({sol.rule})"
    if sol.t < s.size:
        status += "; truncated directions are not identified (biased estimate)"
    info = {
        "singular_values": sol.singular_values,
        "truncation": sol.t,
        "filter_factors": sol.filter_factors,
        "rule": sol.rule,
        "kappa": float(s[0] / s[-1]),
        "increment": inc,
        "nominal_poses": P,
        "right_singular_vectors": sol.Vt,
        "maemm_prior": maemm_prior,
    }
    return inc, est, status, info


def _lean(errors, names, est, status, info):
    """The result without diagnostics (``identify_tsvd(..., diagnostics=False)``)."""
    info["diagnostics"] = False
    return IdentificationResult(method="tsvd", params=names, estimate=est, covariance=None, success=True,
                                status=status + "; fit not checked (diagnostics off)", info=info,
                                errors=errors, std_kind="lower bound")
