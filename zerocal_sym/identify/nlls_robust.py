"""The robust loss's stage of :func:`~zerocal_sym.identify.nlls.identify_nlls`: which readings are outliers,
and the estimate without them.

It composes the stages: the iteratively reweighted Gauss-Newton of the loss
(:mod:`zerocal_sym.identify.estimate.robust`) from the l2 solution and from
the best exact fit without one reading (the leave-one-out refits of
:mod:`zerocal_sym.identify.diagnose.leave_out`); the candidates are judged by
the fit check's test (:data:`~zerocal_sym.identify.check.statistics.DEFAULT_ALPHA`),
their outliers are the readings weighted below
:data:`~zerocal_sym.identify.check.robust_fit.ROBUST_EXCLUDE_WEIGHT`, and the
estimate is the exact refit without them.  Shapes: K poses, p estimated
parameters.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded
from zerocal_sym.identify.check.robust_fit import ROBUST_EXCLUDE_WEIGHT
from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA
from zerocal_sym.identify.chi2 import chi2_sf
from zerocal_sym.identify.diagnose.leave_out import _Round, refits, without_each
from zerocal_sym.identify.estimate import robust as rb
from zerocal_sym.identify.estimate.nlls_solve import GN_STEP_TOL

#: the exact refits without one reading among which the best deletion start is taken: the readings with the
#: lowest chi² without them in the linearised model
DELETION_CANDIDATES = 8


def lowest(values, k: int) -> np.ndarray:
    """Bool mask of the ``k`` lowest of ``values`` (non-finite last)."""
    v = np.asarray(values, float)
    mask = np.zeros(v.size, bool)
    mask[np.argsort(np.where(np.isfinite(v), v, np.inf), kind="stable")[:k]] = True
    return mask


def robust_stage(prob, par, sol, robot, meas, theta_cmd, names, prior_q, noise, loss, delta, w, z_prior, K):
    """The robust loss from the l2 solution ``sol`` (or from the prior when Ipopt failed: an outlier can
    cause that); updates ``sol`` in place (point, status, weights, residuals, and ``J`` to the information of
    the readings kept or with the final robust weights).  Returns ``(robust, A)``: the robust stage's record
    and ``d pred / d z`` (K-1, p)."""
    fast = prob.fast
    z_start = sol.z if (sol.converged and np.all(np.isfinite(sol.z))) else z_prior
    z, robust, ok = robust_estimate(robot, meas, theta_cmd, names, prior_q, noise, z_start, loss, delta, w, K)
    robust["l2_solver_status"] = sol.ret
    if not ok:
        sol.converged, sol.ret = False, "robust iteration did not converge"
    elif not sol.converged:
        sol.converged, sol.ret = True, f"robust iteration converged; the l2 Ipopt solve: {sol.ret}"
    sol.z = z
    l, b = (np.array(o) for o in fast["weights"](z, par))
    r, rp, J, pred = (np.array(o) for o in fast["residuals"](z, par, l, b))
    J = np.reshape(J, (-1, z.size))
    A = -banded.times_factor(np.ravel(l), np.ravel(b), J[: K - 1])   # d pred / d z = -L J
    excl = np.asarray(robust["excluded_readings"], int) - 1
    if robust["refit_without_outliers"]:  # information of the readings kept
        keep = np.setdiff1d(np.arange(K - 1), excl)
        Jk = np.zeros((K - 1, len(names)))
        Jk[: keep.size] = robust["_C"].take(keep).whiten(-A[keep])
    else:  # information with the final robust weights: the data rows whitened by chol(C_w)
        Jk = robust["_C_w"].whiten(-A)
    sol.l, sol.b, sol.r, sol.rp, sol.pred = l, b, r.ravel(), rp.ravel(), pred.ravel()
    sol.J = np.vstack([Jk, J[K - 1:]])
    return robust, A


def robust_estimate(robot, meas, theta_cmd, names, prior_q, noise, z_l2, loss, delta, w, K):
    """The robust estimate of one round and its outliers (``z_l2``: the l2 solution, scaled).

    Candidates: IRLS from the l2 solution; IRLS from the best exact fit
    without one reading (a large outlier drags the l2 solution far along a
    weak direction); that deletion fit itself, if the loss down-weights the
    reading it left out there (an outlier with high leverage drags IRLS off
    it: Huber's loss bounds a reading's influence, not its leverage).  The
    readings a candidate down-weights below :data:`ROBUST_EXCLUDE_WEIGHT` are its
    outliers, and its estimate is the exact fit without them.  Between
    candidates: one whose fit without its outliers passes the fit check, then
    the fewest outliers, then the lower robust objective.

    Returns ``(z, info, converged)``.
    """
    pw = w if np.any(w) else None
    args = (robot, theta_cmd, meas.readings, names, prior_q, noise)
    cands = [(z_l2, None)]  # (start, the reading a deletion candidate leaves out)
    if K - 2 > len(names):
        # the readings with the lowest chi² without them in the linearised model, refitted exactly
        drop = without_each(_Round(*args, pw), [z_l2], select=lambda c, c0, d: lowest(c, DELETION_CANDIDATES))
        chi2 = np.where(drop["refitted"], drop["chi2"], np.inf)
        if np.any(np.isfinite(chi2)):
            j = int(np.argmin(chi2))
            cands += [(drop["z"][j], None), (drop["z"][j], j)]
    best = None
    for z0, j in cands:
        out = rb.irls(*args, z0, loss, delta, prior_whitener=pw, max_iter=100 if j is None else 0)
        if j is None:
            excl = np.flatnonzero(out["weights"] < ROBUST_EXCLUDE_WEIGHT)
        else:  # the best single deletion itself (an outlier with high leverage drags IRLS off it)
            excl = np.array([j]) if out["weights"][j] < ROBUST_EXCLUDE_WEIGHT else np.zeros(0, int)
            out["converged"] = True
        ref = refits(*args, [excl], out["z"], prior_whitener=pw, max_iter=50 if excl.size else 0,
                              tol=GN_STEP_TOL)
        c, d = float(ref["chi2"][0]), int(ref["dof"][0])
        passes = bool(d > 0 and np.isfinite(c) and chi2_sf(c, d) >= DEFAULT_ALPHA)
        key = (bool(out["converged"]), passes, -excl.size, -out["objective"])
        if best is None or key > best[0]:
            best = (key, out, excl, ref)
    _, out, excl, ref = best
    z, ok = out["z"], out["converged"]
    C, refit = out["C"], False
    err_mm = out["conditional_residual_mm"][excl]
    if ok and excl.size and ref["converged"][0]:  # the outliers named: the estimate is the exact fit without them
        z, refit = ref["z"][0], True
        e, _, C = rb._Model(robot, theta_cmd, meas.readings, names, prior_q, noise, pw).at(z)
        err_mm = rb.conditional_residuals(e, C, np.zeros(K - 1))[0][excl]
    return z, {
        "loss": loss, "scale_sigmas": float(delta), "iterations": int(out["iterations"]),
        "converged": bool(ok), "weights": out["weights"].tolist(), "standardised": out["u"].tolist(),
        "excluded_readings": [int(j) + 1 for j in excl], "excluded_errors_mm": [float(v) for v in err_mm],
        "refit_without_outliers": refit, "_C": C, "_C_w": out["C_w"],
    }, ok
