"""The weighted fit with the revisits' shared error: Gauss-Newton with the full covariance of the changes.

The CasADi problem of :mod:`zerocal_sym.identify.estimate.nlls_problem` whitens by
the bands of the covariance (scale and servo errors: tridiagonal).  A pose's
systematic error shared by its revisits (``sigma_revisit_mm > 0``) adds
``sigma_r^2`` to each pose visited once and a low-rank part per revisited
pose (:mod:`zerocal_sym.identify.covariance`): not tridiagonal.  So the fit
goes on from the banded (Ipopt) solution by Gauss-Newton on the exact model
with the full covariance (weights re-evaluated at every iterate, as the
banded fit does), in numpy: each step O(K (p + G)).  What it returns is the
whitened problem at its end: residuals, Jacobian (prior rows kept) and the
covariance, for the information and the fit check.

:func:`revisit_stage` -- the stage; :func:`pred_jacobian` -- ``d pred / d z``
from the banded problem's whitened Jacobian; :func:`revisits_entry` -- a
result's ``info["revisits"]`` (:mod:`zerocal_sym.identify.estimate.revisits`).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import banded

#: Gauss-Newton iterations of the stage at most (from the banded fit: a few)
MAX_ITER = 30


def pred_jacobian(l, b, J, K):
    """``d pred / d z`` (K-1, p) from the banded problem's whitened Jacobian ``J`` (its data rows: ``-L^-1 A``)."""
    return -banded.times_factor(np.ravel(l), np.ravel(b), np.reshape(J, (-1, np.shape(J)[-1]))[: K - 1])


def revisit_stage(prob, par, sol, robot, theta_cmd, names, prior_q, noise, scale, K, lbx=None, ubx=None):
    """Gauss-Newton with the full covariance from ``sol`` (the banded fit); updates ``sol`` in place.

    ``sol.z``, ``r`` (K-1,) and ``J`` (K-1 + p, p) become the full-covariance fit's (whitened by
    :meth:`ChangeCovariance.whiten`), ``pred`` its changes; ``sol.cov`` the covariance at the end, ``sol.A``
    ``d pred / d z`` there.  ``sol.converged`` is False when the stage does not converge in
    :data:`MAX_ITER` steps (``sol.ret`` says so).
    """
    from zerocal_sym.identify.fisher import change_covariance
    from zerocal_sym.identify.estimate.nlls_solve import GN_STEP_TOL

    errors = robot.errors
    fast = prob.fast
    s = np.asarray(par[prob.s_slice(len(robot.geometry), len(errors))], float)
    z = np.asarray(sol.z, float).copy()
    ok = False
    for it in range(MAX_ITER + 1):
        l, b = (np.ravel(np.array(o)) for o in fast["weights"](z, par))
        _, rp, J0, pred = (np.array(o) for o in fast["residuals"](z, par, l, b))
        J0 = np.reshape(J0, (-1, z.size))
        A = pred_jacobian(l, b, J0, K)
        pred = pred.ravel()
        C = change_covariance(robot, theta_cmd, noise, errors.put(prior_q, names, z / scale))
        rw, Jw = C.whiten(s - pred), C.whiten(-A)
        Jp, rp = J0[K - 1:], rp.ravel()
        if not (np.all(np.isfinite(rw)) and np.all(np.isfinite(Jw))):
            break
        if ok or it == MAX_ITER:
            break
        step = np.linalg.lstsq(np.vstack([Jw, Jp]), -np.concatenate([rw, rp]), rcond=None)[0]
        zn = z + step
        if lbx is not None:
            zn = np.clip(zn, lbx, ubx)
        ok = bool(np.max(np.abs(zn - z)) < GN_STEP_TOL)
        z = zn
    sol.z, sol.r, sol.rp, sol.pred = z, rw, rp, pred
    sol.J = np.vstack([Jw, Jp])
    sol.cov, sol.A = C, A
    if not ok:
        sol.converged = False
        sol.ret = (f"{sol.ret}; the fit with the revisits' shared error (Gauss-Newton, full covariance) did not "
                   f"converge in {MAX_ITER} steps")
    return sol


def revisits_entry(res, robot, theta_cmd, e, sol, A, K, noise, names, prior_q, scale):
    """``info["revisits"]``: the round's revisits and the REML estimate of their shared error (when it has
    any; :func:`zerocal_sym.identify.estimate.revisits.revisit_report`)."""
    from zerocal_sym.identify.estimate.revisits import has_revisits, revisit_report

    if not has_revisits(robot, theta_cmd):
        return
    if A is None:
        A = sol.A if sol.A is not None else pred_jacobian(sol.l, sol.b, sol.J, K)
    try:
        rep = revisit_report(robot, theta_cmd, e, A, noise, robot.errors.put(prior_q, names, sol.z / scale))
    except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
        rep = {"reason": f"not estimated: {exc}"}
    if rep is not None:
        res.info["revisits"] = rep
