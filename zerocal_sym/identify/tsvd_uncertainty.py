"""TSVD's covariance with what it leaves out: the linearisation bias and the truncated directions' bias bound.

:func:`_honest_uncertainty` adds to the noise covariance of the linear TSVD
estimator ``b b^T``, ``b`` its linearisation bias (the estimate minus the
exact-model minimum over the kept directions), and for each truncated
direction ``v_i`` a bias bound ``(|c_i| + 2 sd_i)^2 T v_i v_i^T T``; what
:func:`~zerocal_sym.identify.tsvd.identify_tsvd` reports as ``std_kind``
``"total"`` (its docstring).  The exact model it refines on
(:class:`~zerocal_sym.identify.exact_refits._Exact`) is the one the fit check
then evaluates.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.exact_refits import _Exact
from zerocal_sym.identify.fitstats import _noise_dict


def _honest_uncertainty(robot, meas, names, prior_eff, noise, est, sol, cov_noise) -> dict:
    """TSVD's covariance with what it leaves out: linearisation bias and truncated directions' bias bound.

    Returns a dict: ``_covariance`` (total), ``_std_kind``, ``_exact`` (the exact
    whitened model), ``_basis`` (kept directions, scaled), ``_evaluated_at``,
    ``_chi2_at_estimate`` and the JSON-ready ``info`` entries
    ``covariance_noise``, ``linearisation_bias``, ``truncation_bias_bound``,
    ``std_components``, ``std_note``, ``fit_point``, ``fit_basis``, ``prior``, ``noise``.
    """
    from zerocal_sym.model.noise import NoiseModel

    errors = robot.errors
    nm = NoiseModel() if noise is None else noise
    exact = _Exact(robot, meas.theta_cmd, meas.readings, names, prior_eff, nm)
    sc = exact.scale
    p, t = len(names), sol.t
    basis = sol.Vt[:t].T
    z_est = est * sc
    r_est = exact.evaluate(z_est)[0]
    out = {"_exact": exact, "_basis": basis, "_chi2_at_estimate": float(r_est @ r_est),
           "_std_kind": "total" if noise is not None else "from residuals",
           "prior": prior_eff.tolist(), "noise": _noise_dict(nm),
           "fit_basis": basis.tolist(),
           "covariance_noise": None if cov_noise is None else np.asarray(cov_noise).tolist()}
    notes = []
    b_lin = np.full(p, np.nan)
    bound = np.zeros(p)
    trunc = np.zeros((p, p))
    z_ref = z_est
    try:
        z_ref = exact.refine(z_est, basis)
        b_lin = est - z_ref / sc
        if t < p:
            z_full = exact.refine(z_ref, None)
            lin = exact.linear(z_full)
            Finv = np.linalg.pinv(lin.J.T @ lin.J)
            if nm.is_zero:  # unit weights: the noise level from the residuals of the full fit
                Finv = Finv * (float(lin.r @ lin.r) / lin.dof if lin.dof > 0 else np.nan)
            for i in range(t, p):
                v = sol.Vt[i]
                c = float(v @ (z_full - z_ref))
                bi = abs(c) + 2.0 * float(np.sqrt(max(v @ Finv @ v, 0.0)))
                u = v / sc
                trunc += bi**2 * np.outer(u, u)
                bound = np.sqrt(bound**2 + (bi * u) ** 2)
    except (FloatingPointError, np.linalg.LinAlgError, ValueError) as exc:
        notes.append(f"the exact-model refinement failed ({exc}): the linearisation and truncation biases are not "
                     "in the std")
    if not (np.all(np.isfinite(b_lin)) and np.all(np.isfinite(trunc))):
        out["_std_kind"] = "lower bound"
        if not notes:
            notes.append("the truncated directions' bias could not be bounded: it is not in the std")
        b_lin = np.where(np.isfinite(b_lin), b_lin, 0.0)
        trunc = np.where(np.isfinite(trunc), trunc, 0.0)
        bound = np.where(np.isfinite(bound), bound, 0.0)
    if cov_noise is None:
        cov = None
        out["_std_kind"] = "lower bound"
        notes.append("no noise model and no spare degree of freedom: the noise part of the std is unknown")
    else:
        cov = np.asarray(cov_noise) + np.outer(b_lin, b_lin) + trunc
    noise_sd = (np.sqrt(np.diag(cov_noise)) if cov_noise is not None else np.full(p, np.nan))
    out["_covariance"] = cov
    out["_evaluated_at"] = ("the exact-model minimum over TSVD's kept directions (Gauss-Newton from its estimate)"
                            if np.any(z_ref != z_est) else "estimate")
    out["fit_point"] = (z_ref / sc).tolist()
    out["linearisation_bias"] = b_lin.tolist()
    out["truncation_bias_bound"] = bound.tolist()
    out["std_components"] = {
        n: {"noise": None if not np.isfinite(noise_sd[k]) else errors.to_user_value(n, float(noise_sd[k])),
            "linearisation_bias": errors.to_user_value(n, float(b_lin[k])),
            "truncation_bias_bound": errors.to_user_value(n, float(bound[k])),
            "unit": errors[n].user_unit}
        for k, n in enumerate(names)}
    out["std_note"] = ("; ".join(notes) if notes else
                       "std = sqrt(noise^2 + linearisation bias^2 + truncation bias bound^2) per parameter "
                       "(covariance: noise + b b^T + bound terms)")
    return out
