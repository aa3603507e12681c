"""The verdict of a fit check in the result: the causes added to a rejected fit, the result's status.

:func:`finish` adds the causes and the paragraph
(:mod:`~zerocal_sym.identify.diagnose.causes`; a fit rejected by the largest
standardised residual alone: the reading it names) to the statistics of
:func:`~zerocal_sym.identify.check.statistics.statistics`; :func:`apply`
records the fit in a result and, when it is rejected, changes its
``success`` and ``status``.
"""
from __future__ import annotations

import math

from zerocal_sym.identify.chi2 import _fmt_p
from zerocal_sym.identify.diagnose.causes import _diagnose, _diagnose_max
from zerocal_sym.identify.estimate.exact_model import _Exact


def _max_only(fit: dict) -> bool:
    """Whether only the largest standardised residual rejects the fit (the chi² passes)."""
    return bool(fit["rejected"] and not fit.get("chi2_rejected", True)
                and (fit.get("max_reading") or {}).get("rejected"))


def _summary(fit: dict) -> str:
    if _max_only(fit):
        mr = fit["max_reading"]
        s = (f"one reading: standardised residual {mr['standardised']:+.3g} at pose {mr['pose']}, the largest of "
             f"{mr['readings']}, {_fmt_p(mr['p_value'])}, below {fit['alpha']:g}, though chi2 {fit['chi2']:.4g} on "
             f"{fit['dof']} dof, {_fmt_p(fit['p_value'])}, passes")
    else:
        s = f"chi2 {fit['chi2']:.4g} on {fit['dof']} dof, {_fmt_p(fit['p_value'])}, below {fit['alpha']:g}"
    det = [c for c in fit.get("causes", []) if c.get("detected")]
    if det:
        s += f"; likely: {det[0]['text']}"
    return s


def finish(fit: dict, exact: _Exact | None, diagnose: bool = True, z_est=None) -> dict:
    """Add the causes and the paragraph to a rejected fit; drop the private arrays."""
    fit["causes"], fit["diagnosis"] = [], None
    if _max_only(fit):  # the reading it names (its exact refit only when diagnosing)
        fit["causes"], fit["diagnosis"] = _diagnose_max(exact if diagnose else None, fit, fit["alpha"], z_est)
    elif fit["rejected"]:
        if diagnose:
            fit["causes"], fit["diagnosis"] = _diagnose(exact, fit, fit["alpha"], z_est)
        else:
            fit["diagnosis"] = _diagnose(None, fit, fit["alpha"])[1]
    elif fit["checked"]:
        fit["diagnosis"] = (f"The fit agrees with the noise model: chi2 = {fit['chi2']:.4g} on {fit['dof']} dof "
                            f"({_fmt_p(fit['p_value'])}).")
    else:
        fit["diagnosis"] = fit["reason"]
    fit.pop("_t", None)
    return fit


def apply(result, fit: dict, accept_misfit: bool = False):
    """Record ``fit`` in ``result.info["fit"]`` and, if rejected, change ``status`` / ``success``.

    Only a result that was a calibration (``success``) can be rejected; a
    failed identification keeps its own status.  Returns ``result``.
    """
    result.info["fit"] = fit
    det = [c for c in fit.get("causes", []) if c.get("detected")]
    if not result.success and det:  # a failed identification: say what the data look like
        result.status += f"; the data look wrong: {det[0]['text']} ({det[0]['evidence']})"
    if fit["rejected"] and result.success:
        if accept_misfit and math.isfinite(fit["chi2"]):  # (not when the model cannot be evaluated at all)
            fit["accepted_despite_misfit"] = True
            result.status = f"accepted despite misfit ({_summary(fit)}); {result.status}"
        else:
            result.success = False
            result.status = (f"rejected: the noise model rejects the fit ({_summary(fit)})"
                             if math.isfinite(fit["chi2"]) else
                             "rejected: the exact model cannot be evaluated at the estimate (a pose is not an "
                             "assembly of the robot with those errors" + (f"; likely: {det[0]['text']})" if det
                                                                         else ")"))
    return result
