"""The fit check's tests: the chi² of the whitened exact-model residuals against the noise model, the largest
standardised residual against it, and the statistics of every reading.

:func:`chi2_test` is the chi² test alone; :func:`statistics` both tests (the
second: :func:`~zerocal_sym.identify.check.max_reading.max_test`) and the
per-reading statistics (:meth:`~zerocal_sym.identify.whitened._Linear.per_reading`)
as the JSON-ready dict a result carries in ``info["fit"]``.  The tests, the
statistics and their definitions: :mod:`zerocal_sym.identify.fitcheck`.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.identify.check.max_reading import max_test
from zerocal_sym.identify.chi2 import _fmt_p, _gamma_pq, chi2_sf
from zerocal_sym.identify.result import _noise_dict
from zerocal_sym.identify.whitened import _Linear

#: significance level of each of the fit check's two tests (reject when either p < alpha)
DEFAULT_ALPHA = 1e-3


def chi2_test(lin: _Linear, noise, alpha: float = DEFAULT_ALPHA) -> tuple:
    """The chi² test alone: ``(chi2, dof, checked, rejected, p_value, p_value_lower)`` (:func:`statistics`' verdict;
    the p-values None where not checked: a zero noise model, no spare degree of freedom)."""
    chi2 = float(lin.r @ lin.r) if lin.valid else float("inf")
    dof = int(lin.dof)
    if noise.is_zero or (lin.valid and dof <= 0):
        return chi2, dof, False, False, None, None
    if not lin.valid:
        return chi2, dof, True, True, 0.0, 1.0
    pl, p = _gamma_pq(0.5 * dof, 0.5 * chi2)   # lower and upper tails at once (chi2_cdf, chi2_sf)
    return chi2, dof, True, bool(p < alpha), p, pl


def statistics(lin: _Linear, noise, alpha: float = DEFAULT_ALPHA) -> dict:
    """The two tests and the per-reading statistics of a linearised, whitened fit (JSON-ready dict).

    Keys: ``checked``, ``reason`` (why not, if not), ``chi2``, ``dof``,
    ``p_value``, ``p_value_lower`` (the chi² test's), ``alpha``, ``rejected``
    (by either test), ``chi2_rejected``, ``max_reading`` (the largest
    ``|standardised|`` and its test: :func:`~zerocal_sym.identify.check.max_reading.max_test`), ``rms_whitened``,
    ``readings`` (per reading: ``pose``, ``from_pose``, ``residual_mm``,
    ``whitened``, ``leverage``, ``standardised``, ``estimated_error_mm``),
    ``worst`` (the reading with the largest ``|standardised|``, with the chi²
    and p-value without it), ``warnings``, ``noise``, ``model``.
    """
    chi2, dof, checked, rejected, p, pl = chi2_test(lin, noise, alpha)
    zero = noise.is_zero
    t, lev, delta, _ = lin.per_reading(moves=False)
    if not lin.valid:
        t[:], delta[:] = np.nan, np.nan
    fit = {"model": "exact", "alpha": float(alpha), "chi2": chi2, "dof": dof, "p_value": p,
           "p_value_lower": pl, "checked": checked, "reason": None, "rejected": rejected,
           "rms_whitened": float(math.sqrt(chi2 / dof)) if dof > 0 else None,
           "noise": _noise_dict(noise), "warnings": [], "accepted_despite_misfit": False}
    if zero:
        fit["reason"] = ("the noise model is zero (noise-free weighting by 1 um): there is no noise level to test "
                         "the residuals against, so the fit cannot be checked")
        if dof > 0:  # internally studentised: the noise level estimated from the residuals
            t = t / math.sqrt(chi2 / dof) if chi2 > 0 else t
    elif not lin.valid:
        fit["reason"] = ("the exact model cannot be evaluated at the estimate (a pose is not an assembly of the "
                         "robot with these errors): the estimate is nonsense")
    elif dof <= 0:
        fit["reason"] = "the fit cannot be checked (no spare degrees of freedom)"
    elif pl < alpha:
        fit["warnings"].append(
            f"chi2 = {chi2:.4g} is far below its {dof} degrees of freedom (lower-tail {_fmt_p(pl)}): the "
            "noise model overstates the noise, so the standard deviations are too large (conservative)")
    n = lin.n
    tt = np.where(np.isfinite(t), t, np.nan).tolist()
    dd = np.where(np.isfinite(delta), delta, np.nan).tolist()
    fit["readings"] = [{"pose": k, "from_pose": k - 1, "residual_mm": e, "whitened": w, "leverage": v,
                        "standardised": None if ts != ts else ts, "estimated_error_mm": None if ds != ds else ds}
                       for k, e, w, v, ts, ds in zip(lin.poses[:n].tolist(), lin.raw[:n].tolist(), lin.r[:n].tolist(),
                                                     lev[:n].tolist(), tt, dd)]
    fit["worst"] = None
    at = np.where(np.isfinite(t), np.abs(t), -1.0)
    if at.size and at.max() >= 0.0:
        j = int(np.argmax(at))
        w = {"pose": int(lin.poses[j]), "from_pose": int(lin.poses[j]) - 1, "standardised": float(t[j]),
             "estimated_error_mm": float(delta[j]), "chi2_without": None, "p_value_without": None}
        if fit["checked"] and dof >= 2:
            c = max(chi2 - float(t[j]) ** 2, 0.0)
            w.update(chi2_without=c, p_value_without=chi2_sf(c, dof - 1))
        fit["worst"] = w
    fit["max_reading"] = max_test(t, lin.poses[:n], delta, alpha, checked)
    fit["chi2_rejected"] = rejected
    if fit["max_reading"] is not None and fit["max_reading"]["rejected"]:
        fit["rejected"] = True
    fit["_t"] = t  # private: for the diagnosis (removed before returning to the user)
    return fit
