"""The likely causes of a rejected fit, and the paragraph that says them.

:func:`_diagnose` looks for them (the user's bounds or prior against the
data, readings of the wrong sign or cumulative, poses out of order, one bad
reading -- each an exact-model refit) and :func:`_paragraph` writes
``fit["diagnosis"]``; :func:`_diagnose_max` does both for a fit that only the
largest standardised residual rejects (the chi² passes: the reading it names);
:mod:`~zerocal_sym.identify.diagnose.verdict` adds them to the statistics of :func:`~zerocal_sym.identify.check.statistics.statistics`.
The causes and when each is detected: :mod:`zerocal_sym.identify.fitcheck`.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.identify.chi2 import _fmt_p, chi2_sf
from zerocal_sym.identify.diagnose.deletions import _without_each
from zerocal_sym.identify.estimate.exact_model import _Exact


def _variants(K: int, theta, readings):
    """(key, description, theta, readings) of the cheap alternative readings of the data."""
    R = np.asarray(readings, float)
    yield ("sign", "the readings have the wrong sign (scale mounted or read reversed)", None, -R)
    yield ("cumulative", "the readings are cumulative (the head was not reset after each reading)", None,
           np.concatenate([[0.0], np.diff(R)]))
    yield ("reversed", "the poses were visited in the reverse order of the file", theta[::-1].copy(), None)
    if K <= 40:
        for j in range(K - 1):
            th = theta.copy()
            th[[j, j + 1]] = th[[j + 1, j]]
            yield (f"swap{j}", f"poses {j} and {j + 1} were visited in the other order", th, None)


#: the readings refitted exactly when looking for one bad reading: those that would pass the check if the
#: refit lowered chi² SCREEN_FACTOR times as much as the model linearised at the start says, and the
#: SCREEN_KEEP with the lowest linearised chi² without them
SCREEN_FACTOR = 2.0
SCREEN_KEEP = 8


def could_pass(chi2_lin, chi2_start, dof: int, alpha: float) -> np.ndarray:
    """Which readings to refit exactly (bool (n,)).

    ``chi2_start`` (n,): chi² without each reading at the start; ``chi2_lin``
    (n,): after its first Gauss-Newton step in the linearised model.  A
    reading is refitted when ``chi2_start - SCREEN_FACTOR (chi2_start -
    chi2_lin)`` passes the check at ``alpha`` on ``dof`` (the exact model's
    nonlinearity would have to more than double the drop to make another pass),
    or when it is among the :data:`SCREEN_KEEP` lowest ``chi2_lin``.
    """
    c, c0 = np.asarray(chi2_lin, float), np.asarray(chi2_start, float)
    bound = c0 - SCREEN_FACTOR * (c0 - c)
    keep = np.zeros(c.size, bool)
    if dof > 0:
        cand = np.flatnonzero(np.isfinite(bound))
        cand = cand[bound[cand] < chi2_isf_upper(alpha, dof)]
        keep[cand] = [chi2_sf(max(bound[j], 0.0), dof) >= alpha for j in cand]
    keep[np.argsort(np.where(np.isfinite(c), c, np.inf), kind="stable")[:SCREEN_KEEP]] = True
    return keep


def chi2_isf_upper(alpha: float, dof: int) -> float:
    """An upper bound of the chi² at upper tail ``alpha`` on ``dof``: ``x = dof + 2 sqrt(dof t) + 2 t``,
    ``t = ln(1/alpha)``, has ``sf(x) <= alpha`` (Laurent and Massart 2000); only the readings below it need
    the exact tail."""
    t = math.log(1.0 / alpha) if alpha > 0 else math.inf
    return dof + 2.0 * math.sqrt(dof * t) + 2.0 * t


def _diagnose(exact: _Exact | None, fit: dict, alpha: float, z_est=None) -> tuple:
    """(causes, paragraph) of a rejected fit."""
    chi2, dof = fit["chi2"], fit["dof"]
    causes = []
    active = fit.get("active_bounds") or []
    if exact is not None and (active or np.any(exact.w)):
        # the user's constraints (an active bound, a Gaussian prior) against the data: the free fit
        what = ([f"the bound on {', '.join(active)} (active at the estimate)"] if active else []) + \
               (["the Gaussian prior"] if np.any(exact.w) else [])
        try:
            free = _Exact(exact.robot, exact.theta, exact.readings, exact.names, exact.prior_q, exact.noise)
            c, d = free.chi2_fit()
            p = chi2_sf(c, d) if d > 0 else float("nan")
        except Exception:  # noqa: BLE001
            c, d, p = float("nan"), 0, float("nan")
        if np.isfinite(p) and p >= alpha:
            causes.append({"cause": "constraints", "detected": True,
                           "text": " and ".join(what) + " contradict(s) the data",
                           "evidence": f"without them chi2 = {c:.4g} on {d} dof ({_fmt_p(p)})"})
        return causes, _paragraph(fit, causes, alpha, exact)
    if exact is not None:
        best = None
        for key, text, th, rd in _variants(exact.K, exact.theta, exact.readings):
            try:
                c, d = exact.chi2_fit(th, rd)
            except Exception:  # noqa: BLE001 - an alternative that cannot be evaluated explains nothing
                continue
            if d <= 0 or not np.isfinite(c):
                continue
            p = chi2_sf(c, d)
            if p >= alpha and c < chi2 and (best is None or p > best[3]):
                best = (key, text, c, p, d)
        if best is not None:
            key, text, c, p, d = best
            causes.append({"cause": "out of order" if key.startswith("swap") or key == "reversed" else key,
                           "detected": True, "text": text,
                           "evidence": f"refitted so, chi2 = {c:.4g} on {d} dof ({_fmt_p(p)})"})
    # one bad reading: exact refits, each without one reading (from the prior: an outlier may have dragged
    # the estimate far along a weak direction, where the linearisation at the estimate says little), of the
    # readings whose removal could pass (the screen: the linearised refit of every reading, O(K))
    if exact is not None and dof >= 2 and not causes:
        K1 = exact.K - 1
        try:
            out = _without_each(exact, z_est, select=lambda c, c0, d: could_pass(c, c0, d, alpha))
        except Exception:  # noqa: BLE001 - then no reading is named
            out = None
        if out is not None:
            pk = np.full(K1, np.nan)
            for j in np.flatnonzero(out["refitted"]):  # (the others cannot pass: could_pass)
                c, d = out["chi2"][j], out["dof"][j]
                pk[j] = chi2_sf(c, d) if d > 0 and np.isfinite(c) else np.nan
            ok = [j for j in range(K1) if np.isfinite(pk[j]) and pk[j] >= alpha and out["chi2"][j] < chi2]
            if ok:
                j = max(ok, key=lambda j: pk[j])
                k = j + 1
                e = float(out["dropped_error_mm"][j])
                c, d = float(out["chi2"][j]), int(out["dof"][j])
                text = (f"the reading at pose {k} (the change from pose {k - 1} to pose {k}) is off by about "
                        f"{e:+.3g} mm")
                ev = f"without it chi2 = {c:.4g} on {d} dof ({_fmt_p(pk[j])})"
                others = [i + 1 for i in ok if i != j]
                if others:
                    ev += f"; without the reading at pose {', '.join(map(str, others))} instead it would fit too"
                causes.append({"cause": "bad reading", "detected": True, "pose": int(k), "from_pose": int(k - 1),
                               "estimated_error_mm": e, "text": text, "evidence": ev,
                               "also_possible": [int(o) for o in others]})
    return causes, _paragraph(fit, causes, alpha, exact)


def _paragraph(fit: dict, causes: list, alpha: float, exact) -> str:
    chi2, dof = fit["chi2"], fit["dof"]
    detected = [c for c in causes if c["detected"]]
    ratio = chi2 / dof if dof > 0 else float("inf")
    head = (f"The noise model rejects this fit: chi2 = {chi2:.4g} on {dof} degrees of freedom "
            f"({_fmt_p(fit['p_value'])}, below {alpha:g}); the residuals are about {math.sqrt(ratio):.3g} times "
            "the noise the noise model states.")
    if not math.isfinite(chi2):  # no residuals to test: the model is not finite at the estimate
        head = ("The fit is rejected: the exact model cannot be evaluated at the estimate (a pose is not an "
                "assembly of the robot with those errors), so the data do not fit this robot anywhere near it.")
    if detected:
        c = detected[0]
        body = f" Likely cause (detected): {c['text']}: {c['evidence']}."
        if c["cause"] == "bad reading":
            body += (" (A robot-file error that shows mostly in this change looks the same in one round: "
                     f"re-measure pose {c['pose']} to tell.)")
        others = "Otherwise check the robot file, the noise model and the readings."
        return head + body + " " + others
    parts = []
    if dof == 1:
        parts.append("a bad reading (with one spare degree of freedom every reading explains the misfit equally, "
                     "so none can be named; more poses would tell)")
    elif dof >= 2:
        w = fit.get("worst") or {}
        if w:
            parts.append(f"more than one bad reading (the largest standardised residual, {w['standardised']:+.3g} "
                         f"at pose {w['pose']}, does not explain the misfit alone)")
    parts.append("a wrong robot file (a geometry that is not this robot's leaves a systematic misfit)")
    if math.isfinite(ratio):
        parts.append(f"a noise model that understates the noise (by about {math.sqrt(ratio):.3g} x in standard "
                     "deviation; scale error {:.3g} um, servo error {:.3g} deg per joint as given)".format(
                         fit["noise"]["sigma_scale_mm"] * 1e3, math.degrees(fit["noise"]["sigma_servo_rad"])))
    else:
        parts.append("readings that are not this round's (shuffled or edited rows, another robot's data)")
    if fit.get("active_bounds") or (exact is not None and np.any(exact.w)):
        parts.insert(0, "the bounds or the prior given (they hold the estimate where the data do not agree; the "
                        "fit without them does not pass either)")
        checked = ""
    else:
        checked = ("Checked and not found: poses visited in reverse or two consecutive poses swapped, cumulative "
                   "readings (head not reset), sign-flipped readings." if exact is not None else "")
    return head + " Likely causes: " + "; ".join(parts) + ". " + checked


def _diagnose_max(exact: _Exact | None, fit: dict, alpha: float, z_est=None) -> tuple:
    """(causes, paragraph) of a fit rejected by the largest standardised residual alone (the chi² passes).

    The cause is that reading, named as :func:`_diagnose` names a bad reading: its estimated error and the chi²
    without it from the exact refit without it (from the prior and from ``z_est``), or, without ``exact`` or
    where that refit fails, from the model linearised at the estimate (``estimated_error_mm``, ``chi2 - t^2``).
    """
    mr = fit["max_reading"]
    k, j = mr["pose"], mr["pose"] - 1
    e, c, d = mr["estimated_error_mm"], max(fit["chi2"] - mr["standardised"] ** 2, 0.0), fit["dof"] - 1
    if exact is not None and j < exact.K - 1:
        try:
            out = _without_each(exact, z_est, select=lambda c_, c0, d_: np.arange(c_.size) == j)
            if np.isfinite(out["chi2"][j]) and np.isfinite(out["dropped_error_mm"][j]):
                e, c, d = float(out["dropped_error_mm"][j]), float(out["chi2"][j]), int(out["dof"][j])
        except Exception:  # noqa: BLE001 - then the linearised values
            pass
    text = f"the reading at pose {k} (the change from pose {k - 1} to pose {k})" + (
        f" is off by about {e:+.3g} mm" if e is not None else " is off")
    ev = (f"its standardised residual {mr['standardised']:+.3g} is the largest of {mr['readings']} "
          f"({_fmt_p(mr['p_value'])} for the largest of {mr['readings']} under the noise model, below {alpha:g})")
    if d > 0:
        ev += f"; without it chi2 = {c:.4g} on {d} dof ({_fmt_p(chi2_sf(c, d))})"
    causes = [{"cause": "bad reading", "detected": True, "pose": int(k), "from_pose": int(k - 1),
               "estimated_error_mm": e, "text": text, "evidence": ev, "also_possible": [], "test": "max_reading"}]
    head = (f"The noise model rejects this fit: one reading is further off than the noise model allows among "
            f"{mr['readings']} readings (the largest standardised residual, {mr['standardised']:+.3g} at pose {k}: "
            f"{_fmt_p(mr['p_value'])}, below {alpha:g}), though chi2 = {fit['chi2']:.4g} on {fit['dof']} degrees of "
            f"freedom passes ({_fmt_p(fit['p_value'])}).")
    body = (f" Likely cause (detected): {text}: {ev}. (A robot-file error that shows mostly in this change looks the "
            f"same in one round: re-measure pose {k} to tell.) Otherwise check the robot file, the noise model and "
            "the readings.")
    return causes, head + body
