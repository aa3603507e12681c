"""Nonlinear (maximum-likelihood / MAP) identification with CasADi and Ipopt.

The model is the exact distance-change model of the generated mechanism (no
linearisation)::

    s_k = rho(theta_cmd_{k+1}; e) - rho(theta_cmd_k; e) + noise,   k = 1..K-1

with ``e`` the q source errors of the mechanism (rad, mm), of which the parameters selected by
``params`` are estimated and the others held at ``prior`` (default zero).

Weighting (errors-in-variables, marginalised to first order)
    The servo error ``xi`` on the joints is not a latent variable here: it is
    propagated through the kinematics into the covariance of the changes,
    ``C = Cov(s) = sigma_m^2 I + D diag(sigma_xi^2 |d rho/d theta|^2) D^T``
    (:func:`zerocal_sym.identify.fisher.measurement_covariance`; consecutive changes
    are correlated because they share a pose).  The residuals are whitened by
    the inverse Cholesky factor of ``C``, re-evaluated at every Gauss-Newton
    iterate (``reweight=1``: the answer is the weights' fixed point; 0 holds
    them at the start), so the cost is
    ``0.5 |L^-1 (s - s(p))|^2`` (+ prior terms): a Gaussian negative
    log-likelihood whose Gauss-Newton Hessian is the Fisher information used
    by :mod:`zerocal_sym.identify.fisher`.

Scaling
    The optimisation variable is ``z = c * p`` with ``c = L_i`` (mm/rad) for
    the zero offsets (the arc ``L_i dtheta_i``, the paper's ``dq``) and 1 for
    lengths (:func:`zerocal_sym.identify.fisher.parameter_scale`), so every variable
    is in mm; the whitened residuals are in units of their standard deviation.

Hessian
    Ipopt gets the Gauss-Newton Hessian ``J^T J + diag(w^2)`` of the
    least-squares cost through nlpsol's ``hess_lag`` option (as in CasADi's
    ``sysid.py`` example); ``J`` is the CasADi Jacobian of the whitened
    residuals.

Priors and bounds
    Optional Gaussian prior per parameter (``prior`` mean, ``prior_std``, in
    rad / mm): the estimate is then the MAP.  Optional bounds in the same
    units.  The NLP is built once per (mechanism, K, parameter set) and cached:
    data, weights, geometry, fixed errors and priors are NLP parameters.

The stages composed here: the estimate (:mod:`zerocal_sym.identify.estimate`:
the inputs, the CasADi problem, Gauss-Newton and Ipopt's verdict, the fit
with the revisits' shared error), a robust loss's outliers
(:mod:`~zerocal_sym.identify.nlls_robust`), the fit check and its diagnosis
(:mod:`~zerocal_sym.identify.fitcheck`), the limits of a robust fit
(:mod:`~zerocal_sym.identify.check.robust_fit`).
"""
from __future__ import annotations

import time

import numpy as np

from zerocal_sym.identify import banded, fisher
from zerocal_sym.identify.check.robust_fit import (kept_outlier, limit_outliers, robust_linear,
                                                   unchecked_after_removal)
from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA
from zerocal_sym.identify.estimate import robust as rb
from zerocal_sym.identify.estimate.nlls_banded import round_problem
from zerocal_sym.identify.estimate.nlls_inputs import (_as_vector, check_measurements, initial, prior_whitener,
                                                      scaled_bounds)
from zerocal_sym.identify.estimate.nlls_problem import get_problem
from zerocal_sym.identify.estimate.nlls_shared import revisit_stage, revisits_entry
from zerocal_sym.identify.estimate.nlls_solve import information, noise_terms, solve, status_line
from zerocal_sym.identify.fitcheck import check_result
from zerocal_sym.identify.nlls_robust import robust_stage
from zerocal_sym.identify.result import IdentificationResult, _noise_dict
from zerocal_sym.identify.whitened import _Linear
from zerocal_sym.model.noise import NoiseModel

#: losses of identify_nlls (robust ones: zerocal_sym.identify.estimate.robust)
LOSSES = ("l2", "huber", "soft_l1")


def identify_nlls(robot, meas, params="paper", noise: NoiseModel | None = None, prior=None,
                  bounds=None, prior_std=None, warm_start=None, reweight: int = 1,
                  max_iter: int | None = None, prior_cov=None, loss: str = "l2", loss_scale: float | None = None,
                  fit_alpha: float = DEFAULT_ALPHA, accept_misfit: bool = False) -> IdentificationResult:
    """Maximum-likelihood (or MAP) identification with Ipopt on the exact model.

    Parameters
    ----------
    robot : Robot
    meas : Measurements
        ``theta_cmd`` (K, m) rad and ``readings`` (K,) mm, all finite
        (else :class:`~zerocal_sym.errors.IdentificationError` naming the
        poses).  ``readings[0]`` (the reference pose, 0 by definition) is
        not used: only the K - 1 changes ``readings[1:]`` enter.
    params : str or sequence of str
        Parameters to estimate, by name (see :meth:`SourceErrors.resolve`):
        ``"paper"`` (= ``offsets+measuring``: the zero offsets and the MAEMM),
        ``"all"``, ``"offsets+measuring+L1,L2"``, ...
    noise : NoiseModel or str, optional
        Weights and covariance (default: the paper's noise model), or the
        name of one as the CLI's ``--noise`` takes (``paper``,
        ``scale-only``, ``servo-only``, ``none``:
        :meth:`NoiseModel.named <zerocal_sym.model.noise.NoiseModel.named>`;
        anything else: TypeError).  A zero model weights every change
        equally (1 um) and estimates the covariance from the residuals.
    prior : ndarray, shape (q,), optional
        Current belief about the total source errors (rad, mm): the values
        of the parameters not estimated, the mean of the Gaussian prior of
        those estimated (with ``prior_std``) and the initial guess when
        ``warm_start`` is None.  Default zero.
    bounds : dict name -> (lo, hi) or ndarray, shape (p, 2), optional
        rad / mm.
    prior_std : ndarray, shape (p,) or dict name -> std, optional
        Gaussian prior std (rad / mm); ``inf`` for none.
    prior_cov : ndarray, shape (p, p), optional
        Full Gaussian prior covariance instead of ``prior_std``.
    warm_start : None, "tsvd" or ndarray, shape (p,)
        Where Gauss-Newton starts: the prior (None, the default), the
        truncated-SVD estimate, or given values.
    reweight : int
        1 (default): the weights (the covariance of the changes depends
        weakly on the estimate) are re-evaluated at every Gauss-Newton iterate,
        so the answer is their fixed point; 0: held at the start point.
    max_iter : int, optional
        Ipopt iteration limit (default 200).
    loss : {"l2", "huber", "soft_l1"}
        ``l2`` (default): the Gaussian likelihood, solved as below.  A robust
        loss starts from the l2 solution and runs iteratively reweighted
        Gauss-Newton on the exact model (:mod:`zerocal_sym.identify.estimate.robust`:
        each reading judged by its conditional residual given the others, so
        the servo error's correlation does not spread a bad reading).
        Readings whose weight ends below
        :data:`~zerocal_sym.identify.check.robust_fit.ROBUST_EXCLUDE_WEIGHT` are
        outliers: named in the status, the estimate refitted without them
        (its covariance that of the readings kept), left out of the fit
        check.  Otherwise the covariance is the inverse of the information
        with the final weights.  Not with ``bounds``.
    loss_scale : float, optional
        Where the robust loss turns from quadratic to linear, in standard
        deviations of a reading's conditional residual (default 1.345 for
        huber, 1.0 for soft_l1).
    fit_alpha : float
        The fit check's level (:mod:`zerocal_sym.identify.fitcheck`): a fit
        with ``p < fit_alpha`` is rejected (``success`` False, status
        ``"rejected: ..."``).  Default 0.001.
    accept_misfit : bool
        Keep a fit the check rejects as a calibration (status "accepted
        despite misfit ...").

    Solution: ``N_GN`` damped Gauss-Newton iterations inside one CasADi
    call (:mod:`zerocal_sym.identify.estimate.nlls_problem`), then Ipopt's verdict on
    that point, whose status decides ``success`` (Ipopt is the judge): a
    converged point without bounds that passes Ipopt's own termination test
    at a start (:func:`~zerocal_sym.identify.estimate.nlls_solve.ipopt_accepts`, on
    the Jacobian and residuals already computed) gets what Ipopt returns
    there (``Solve_Succeeded``, 0 iterations); otherwise Ipopt solves from it
    (0-1 iterations from a converged point).  If Gauss-Newton did not
    converge (or left the bounds) Ipopt starts at the start point and, with
    ``reweight``, solves once more with the weights at its solution.

    Returns
    -------
    IdentificationResult
        ``method = "nlls"``; ``success`` False whenever Ipopt did not
        converge (``status`` says why) and when the fit check rejects the fit;
        ``info``: ``solver_status``, ``iterations``, ``cost``, ``chi2``,
        ``dof``, ``time_s``, ``weighting``, ``warm_start``, ``confirmation``
        (``"first-order test"`` or ``"ipopt"``), ``rank``,
        ``singular_values`` (of the scaled whitened Jacobian),
        ``nonidentifiable``, ``fit`` (the fit check), ``robust`` (with a
        robust loss).  ``std_kind``: ``"total"`` (the Cramér-Rao bound at the
        estimate: the exact model has no linearisation bias) or ``"from
        residuals"`` (zero noise model).
    """
    t0 = time.perf_counter()
    noise = NoiseModel.coerce(noise, robot=robot)
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")
    delta = None
    if loss != "l2":
        delta = rb.DEFAULT_SCALE[loss] if loss_scale is None else float(loss_scale)
        if not delta > 0:
            raise ValueError(f"loss_scale must be positive, got {loss_scale!r}")
        if bounds is not None:
            raise ValueError("a robust loss does not take bounds")
        if noise.has_shared:
            raise ValueError("a robust loss does not take a shared revisit error (the noise model's "
                             "sigma_revisit_mm, [noise] revisit_std_mm): use loss 'l2'")
    errors = robot.errors
    names = errors.resolve(params)
    theta_cmd, readings = check_measurements(robot, meas)
    K = theta_cmd.shape[0]
    s = readings[1:]
    prior_q = errors.zeros() if prior is None else _as_vector(prior, len(errors), "prior")
    scale = fisher.parameter_scale(robot, names)
    w = prior_whitener(names, prior_std, prior_cov)
    prob = round_problem(robot, K, names)
    prob.touch()
    mu = errors.take(prior_q, names)
    has_prior = bool(w.any())
    lbx, ubx = scaled_bounds(bounds, list(names), scale)
    x0, start = initial(robot, meas, names, prior_q, warm_start, mu)
    z0 = x0 * scale if bounds is None else np.clip(x0 * scale, lbx, ubx)  # (clipping to +-inf: no-op)
    par = prob.pack(theta_cmd, robot.geometry, prior_q, s, scale, mu, w, *noise_terms(noise))
    sol = solve(prob, z0, par, reweight, bounds is not None, lbx, ubx, max_iter, K)
    sol.cov = sol.A = None
    if noise.has_shared and not noise.is_zero:  # the full covariance (not tridiagonal): on from the banded fit
        revisit_stage(prob, par, sol, robot, theta_cmd, names, prior_q, noise, scale, K,
                      *((lbx, ubx) if bounds is not None else ()))
    robust = A = None
    robust_failed = None
    if loss != "l2":
        try:
            robust, A = robust_stage(prob, par, sol, robot, meas, theta_cmd, names, prior_q, noise, loss, delta, w,
                                      mu * scale, K)
        except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
            # the robust refit's linear algebra failed on these data (the model not finite at its estimate, a
            # covariance that is no covariance there): not a calibration, and the status says so
            robust_failed = str(exc)
            sol.converged = False
    r, rp, J, pred, l, b = sol.r, sol.rp, sol.J, sol.pred, sol.l, sol.b
    Jd = J[: K - 1]  # data part of the Jacobian (whitened, per scaled unit)
    svd, sv, rank, cov, nonid, offsets_ok = information(J, Jd, r, K, has_prior, noise, scale, names, errors)
    success = sol.converged and offsets_ok and svd is not None  # (None: the model is not finite at sol.z)
    info = {
        "solver_status": sol.ret,
        "iterations": sol.iterations,
        "cost": 0.5 * float(r @ r + rp @ rp),
        "chi2": float(r @ r),
        "dof": (K - 1) - len(names),
        "time_s": None,
        "weighting": ("unit (1 um), covariance from residuals" if noise.is_zero else
                      "errors-in-variables: whitened by the banded chol(Cov(s)), servo error propagated"
                      + ("; the revisits' shared error by the full covariance (Gauss-Newton from the banded "
                         "fit)" if sol.cov is not None else "")),
        "noise": _noise_dict(noise),
        "warm_start": start,
        "gauss_newton": {"converged": sol.gn_ok, "last_step_mm": sol.step},
        "confirmation": sol.confirmation,
        "initial": x0.tolist(),
        "rank": rank,
        "singular_values": sv.tolist(),
        "nonidentifiable": nonid,
        "scale_mm_per_unit": scale.tolist(),
        "prior": prior_q.tolist(),
        "loss": loss,
    }
    if has_prior:
        info["prior_whitener"] = w.tolist()
    res = IdentificationResult(method="nlls", params=names, estimate=sol.z / scale,
                               covariance=cov, success=bool(success),
                               status=(status_line(sol, offsets_ok, rank, names, robust, loss)
                                       + (f"; the {loss} refit failed: {robust_failed}" if robust_failed else "")),
                               residuals=np.asarray(s - pred), info=info, errors=errors,
                               std_kind="from residuals" if noise.is_zero else "total")
    # the fit check: whitened exact-model residuals at the estimate against the noise model
    rows = np.flatnonzero(np.any(w != 0, axis=1))
    if robust is None:
        terms = None
        if not rows.size and rank == len(names) and "fit_terms" in prob.fast and sol.cov is None:
            terms = [o.copy() for o in prob.fast["fit_terms"](r, Jd, l, b)]  # the per-reading terms, O(K p)
        lin = _Linear(np.concatenate([r, rp[rows]]) if rows.size else r,
                      np.vstack([Jd, J[K - 1:][rows]]) if rows.size else Jd,
                      (l, b) if sol.cov is None else sol.cov, np.arange(1, K), s - pred, np.eye(len(names)),
                      scale, names, len(rows),
                      svd=None if rows.size else svd,  # no prior rows: J's SVD is Jd's
                      terms=terms)
        at = "estimate"
    else:
        lin = robust_linear(robust, s - pred, A, J[K - 1:][rows], rp[rows], scale, names, K)
        at = ("estimate, without the readings the robust loss down-weighted (at pose "
              f"{', '.join(map(str, robust['excluded_readings']))})" if robust["excluded_readings"] else "estimate")
        info["robust"] = {k: v for k, v in robust.items() if not k.startswith("_")}
    z = sol.z
    tol_b = 1e-7 * (1.0 + np.abs(z))
    active = [] if bounds is None else [n for n, zz, lo, hi, tb in zip(names, z, lbx, ubx, tol_b)
                                        if zz <= lo + tb or zz >= hi - tb]
    check_result(robot, meas, res, lin, noise, names, prior_q, fit_alpha, accept_misfit,
                 prior_whitener=w if has_prior else None, evaluated_at=at, active_bounds=active)
    if robust is not None:
        kept_outlier(res, robust, loss)
        limit_outliers(res, robust, loss, K, accept_misfit)
        unchecked_after_removal(res, robust, loss, K, accept_misfit)
    revisits_entry(res, robot, theta_cmd, s - pred, sol, A, K, noise, names, prior_q, scale)
    info["time_s"] = time.perf_counter() - t0
    return res


def make_nlls_identifier(params="paper", noise: NoiseModel | None = None, sequential: bool = False, **kwargs):
    """An ``identify(robot, meas, prior)`` callable for the calibration loop.

    Parameters
    ----------
    params, noise, **kwargs
        Passed to :func:`identify_nlls`.
    sequential : bool
        Carry the information of earlier rounds: when ``prior`` is this
        identifier's own previous estimate (as the calibration loop passes
        it), that estimate's covariance is used as a Gaussian prior
        (``prior_cov``), so round j's estimate is the MAP given all j rounds
        (Gaussian approximation of the previous posterior).  Make a new
        identifier per loop.

    Returns
    -------
    callable
        ``identify(robot, meas, prior) -> IdentificationResult``.
    """
    state = {"last": None}

    def identify(robot, meas, prior=None):
        kw = dict(kwargs)
        cov = sequential_prior_cov(robot, params, state["last"], prior) if sequential else None
        if cov is not None:
            kw["prior_cov"] = cov
        res = identify_nlls(robot, meas, params=params, noise=noise, prior=prior, **kw)
        state["last"] = res
        return res

    identify.__name__ = f"nlls[{params}]" + ("-sequential" if sequential else "")
    return identify


def sequential_prior_cov(robot, params, last, prior):
    """The Gaussian prior a sequential MAP takes from the previous result ``last`` of its loop: its covariance,
    when ``prior`` is that result's own estimate (as the calibration loop passes it) and it is a finite
    calibration; else None."""
    if last is None or prior is None or not last.success:
        return None
    full = last.full_vector()
    idx = robot.errors.indices(params)
    if np.allclose(np.asarray(prior, float)[idx], full[idx], rtol=0, atol=1e-15) \
            and last.covariance is not None and np.all(np.isfinite(last.covariance)):
        return last.covariance
    return None


def residual_problem(robot, meas, params="paper", noise: NoiseModel | None = None, prior=None,
                     callbacks: str = "plain"):
    """The same whitened, scaled least-squares problem as numpy callables.

    For outside solvers (``scipy.optimize.least_squares``) on exactly the
    problem Ipopt solves with ``warm_start=None, reweight=0`` (weights at
    ``prior``, no bounds, no Gaussian prior); with the shared revisit error
    whitened by the full covariance at ``prior`` (the problem
    :func:`identify_nlls` goes on to).

    ``callbacks``: ``"plain"`` calls the CasADi Functions the ordinary way
    (numpy converted in and out); ``"fast"`` through zero-copy buffers
    (:class:`~zerocal_sym.model.fastcall.FastCall`; the returned
    arrays are copies).

    Returns
    -------
    fun : callable z -> ndarray, shape (K-1,)
        Whitened residuals.
    jac : callable z -> ndarray, shape (K-1, p)
    scale : ndarray, shape (p,)
        ``p = z / scale`` (physical units); start at ``prior[params] * scale``.
    """
    noise = NoiseModel.coerce(noise, robot=robot)
    errors = robot.errors
    names = errors.resolve(params)
    theta_cmd = np.atleast_2d(np.asarray(meas.theta_cmd, float))
    prior_q = errors.zeros() if prior is None else _as_vector(prior, len(errors), "prior")
    scale = fisher.parameter_scale(robot, names)
    prob = get_problem(robot, theta_cmd.shape[0], names)
    par = prob.pack(theta_cmd, robot.geometry, prior_q, np.asarray(meas.readings, float)[1:], scale,
                    errors.take(prior_q, names), np.zeros((len(names), len(names))), *noise_terms(noise))
    fast = prob.fast
    l, b = (np.array(o) for o in fast["weights"](errors.take(prior_q, names) * scale, par))
    if callbacks not in ("plain", "fast"):
        raise ValueError(f"callbacks must be 'plain' or 'fast', got {callbacks!r}")
    if callbacks == "fast":
        rfun, jfun = fast["rfun"], fast["jfun"]  # (one buffer per thread, outputs copied)
        fun, jac = (lambda z: rfun(z, par, l, b)[0].copy()), (lambda z: jfun(z, par, l, b)[0].copy())
    else:
        rfun, jfun = prob.functions["rfun"], prob.functions["jfun"]
        fun, jac = (lambda z: rfun(z, par, l, b).full().ravel()), (lambda z: jfun(z, par, l, b).full())
    if noise.has_shared and not noise.is_zero:  # the full covariance at the prior: W L0 (L0 r = the residuals)
        C = fisher.change_covariance(robot, theta_cmd, noise, prior_q)
        return ((lambda z: C.whiten(banded.times_factor(l, b, fun(z)))),
                (lambda z: C.whiten(banded.times_factor(l, b, np.reshape(jac(z), (theta_cmd.shape[0] - 1, -1))))),
                scale)
    return fun, jac, scale
