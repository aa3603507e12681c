"""Deletions: the exact fits without each single reading, and how much each reading moves the estimate.

:func:`_without_each` -- the fit without each reading, from the prior and from
the estimate, the lower chi² kept (banded:
:mod:`~zerocal_sym.identify.diagnose.leave_out`; with the revisits' shared
error: :mod:`~zerocal_sym.identify.diagnose.revisit_refits`): the bad reading
of a rejection and the deletion diagnostics.  :func:`deletion_diagnostics`
-- the change of every parameter when one reading is removed, flagging the
readings whose removal moves a zero offset by more than its standard
deviation.  Shapes: K poses (K - 1 readings), p estimated parameters.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.diagnose.leave_out import _Round, without_each
from zerocal_sym.identify.diagnose.revisit_refits import without_each_shared
from zerocal_sym.identify.estimate.exact_model import _Exact, _exact_for


def _without_each(exact: _Exact, z_est=None, select=None) -> dict:
    """Exact refits without each single reading, from the prior and from ``z_est``; the lower chi² per reading
    (:func:`~zerocal_sym.identify.diagnose.leave_out.without_each`; ``select``: the readings refitted exactly).
    With the revisits' shared error: :func:`zerocal_sym.identify.diagnose.revisit_refits.without_each_shared`."""
    if exact.shared:
        return without_each_shared(exact, z_est, select)
    starts = [exact.z_prior] if z_est is None or np.allclose(z_est, exact.z_prior) else [exact.z_prior, z_est]
    rnd = _Round(exact.robot, exact.theta, exact.readings, exact.names, exact.prior_q, exact.noise,
                 exact.w if np.any(exact.w) else None)
    return without_each(rnd, starts, select=select)


def deletion_diagnostics(robot, meas, result, noise=None, threshold: float = 1.0, method: str = "refit") -> dict:
    """How much each reading moves the estimate: the change of every parameter when it is removed.

    ``method="refit"`` (default): the exact model refitted without the
    reading (the change of the correlated changes' covariance marginalised,
    Gauss-Newton from the data's fit reached from the estimate and from the
    prior, the better fit kept; every reading's first step a rank-one update
    of one evaluation, then exact steps per reading:
    :func:`~zerocal_sym.identify.diagnose.leave_out.without_each`, O(K) per reading).  ``method="one-step"``: the
    mean-shift formula on the whitened model linearised at the estimate,
    ``dz_k = -F^+ J^T a_k delta_k`` (exact for the linearised model; poor when
    a large outlier has dragged the estimate far).

    Parameters
    ----------
    threshold : float
        Flag reading k when its removal moves any zero offset by more than
        ``threshold`` times that offset's standard deviation (``result.std``).

    Returns
    -------
    dict
        ``readings``: per reading ``pose``, ``from_pose``, ``leverage``,
        ``standardised``, ``estimated_error_mm`` (its misfit without it),
        ``change`` (name -> change in user units, deg / mm; None when removing
        it leaves the parameters unidentifiable), ``change_in_std`` (name ->
        |change| / std), ``chi2_without``, ``refit_converged`` (whether the
        refit without it converged; None for ``one-step``: where the rest of
        the readings still do not fit, Gauss-Newton may stop after its
        iterations wherever it is), ``flag``; ``flagged`` (poses, the
        most influential first), ``most_influential`` (pose), ``summary`` (a
        sentence naming them), ``threshold``, ``dof``, ``method``.
    """
    if method not in ("refit", "one-step"):
        raise ValueError(f"method must be 'refit' or 'one-step', got {method!r}")
    exact, z, basis = _exact_for(robot, meas, result, noise)
    lin = exact.linear(z, basis)
    t, lev, delta, dz = lin.per_reading()
    chi2w = np.full(lin.n, np.nan)
    conv = [None] * lin.n
    if method == "refit":
        out = _without_each(exact, z)
        dz = out["z"] - z
        dz[~np.isfinite(out["chi2"]) | (out["dof"] <= 0) & (lin.dof <= 0)] = np.nan
        delta = out["dropped_error_mm"]
        chi2w = out["chi2"]
        conv = [bool(c) for c in out["converged"]]
        # a reading the parameters need (leverage 1): its removal leaves them unidentifiable
        dz[lev > 1 - 1e-9] = np.nan
    errors = robot.errors
    names = result.params
    std = np.array([result.std(n) for n in names])
    offs = [i for i, n in enumerate(names) if n in errors.zero_offsets]
    rows, score = [], []
    for j in range(lin.n):
        k = int(lin.poses[j])
        dp = dz[j] / exact.scale
        ok = bool(np.all(np.isfinite(dp)))
        ratio = np.abs(dp) / std if ok else np.full(len(names), np.inf)
        sel = ratio[offs] if offs else ratio
        score.append(float(np.max(sel)) if sel.size else 0.0)
        rows.append({"pose": k, "from_pose": k - 1, "leverage": float(lev[j]),
                     "standardised": None if not np.isfinite(t[j]) else float(t[j]),
                     "estimated_error_mm": None if not np.isfinite(delta[j]) else float(delta[j]),
                     "chi2_without": None if not np.isfinite(chi2w[j]) else float(chi2w[j]),
                     "refit_converged": conv[j],
                     "change": ({n: errors.to_user_value(n, float(v)) for n, v in zip(names, dp)} if ok else None),
                     "change_in_std": ({n: float(v) for n, v in zip(names, ratio)} if ok else None),
                     "flag": bool(score[-1] > threshold)})
    order = np.argsort(-np.array(score), kind="stable")
    flagged = [rows[j]["pose"] for j in order if rows[j]["flag"]]
    by_pose = {r["pose"]: r for r in rows}

    def one(k):
        r = by_pose[k]
        if r["change_in_std"] is None:
            return f"pose {k} (removing it leaves the parameters unidentifiable)"
        cand = [n for n in r["change_in_std"] if n in errors.zero_offsets] or list(r["change_in_std"])
        worst = max(cand, key=lambda n: r["change_in_std"][n])
        e = r["estimated_error_mm"]
        return (f"pose {k} (moves {worst} by {r['change_in_std'][worst]:.2g} std"
                + (f"; its misfit {e:+.3g} mm" if e is not None else "") + ")")

    if flagged:
        summary = ("removing the reading at " + "; ".join(one(k) for k in flagged) +
                   f" moves a zero offset by more than {threshold:g} standard deviation(s); the most influential "
                   f"is the reading at pose {flagged[0]}")
        if lin.dof <= 1:
            summary += (f" (with {lin.dof} spare degree(s) of freedom every reading is influential: this does not "
                        "single out a bad one)")
    else:
        summary = f"no single reading moves a zero offset by more than {threshold:g} standard deviation(s)"
    return {"readings": rows, "flagged": flagged, "most_influential": int(rows[int(order[0])]["pose"]) if rows else None,
            "summary": summary, "threshold": float(threshold), "dof": int(lin.dof), "method": method}
