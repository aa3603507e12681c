"""TSVD's standard deviations, honest per parameter: the noise, the linearisation bias, the truncated directions.

TSVD's estimate is linear in the data: ``x = x0 + A s`` with ``A`` (p x (K-1))
its truncated, unweighted operator at the linearisation point ``x0`` (the
prior, or the previous step of an iterated TSVD; ``A`` includes ``T``, lengths
to offsets).  So its error is exactly

    x - x_true = beta(x_true) + A n,      beta(t) = x0 + A (s0(t) - s0(x0)) - t,

``n`` the noise of the measured changes, ``s0`` the exact model's changes and
``beta`` the **linearisation bias** (second order in ``t - x0``; zero at a
converged iterated TSVD).  :func:`tsvd_std_parts` (many rounds at once) gives
per round:

* the noise ``Sigma = A C A^T``, ``C`` the covariance of the changes (scale
  error; servo error through the exact model at the estimate);
* the bias ``b = x - t*`` at ``t*``, the source errors whose noise-free data
  TSVD maps onto this estimate (``A r(t*) = 0``, ``r`` the measured minus the
  exact-model changes; Newton's method from the estimate, each step halved
  until it lowers ``|A r|``): it estimates ``beta(x_true)`` with the error
  ``D (t* - x_true)``, ``D = A J - I`` (``J`` the exact Jacobian), so its std
  ``sd_b`` follows from ``Sigma`` to first order;
* the plug-in ``beta(x) = -A r(x)`` (one more TSVD step with the same
  operator), and ``nl``: how far it is from its first-order prediction
  ``b + D b`` (the bias's curvature between the estimate and ``t*``).

:func:`combine` then decides per parameter.  The std is **honest**
(``"total"``), ``std^2 = sigma^2 + b^2``, where the bias is small and known
well enough for the std itself to be known: ``t*`` found, no parameter's bias
beyond :data:`B_MAX` noise std (else the one-step linearisation is poor and
the first-order picture of every bias with it), ``sd_b^2 + 2 sd_b |b| <=``
:data:`STD_TOL` ``sigma^2``, no truncation bound, and ``+-2`` std covering an
error of mean ``b`` with at most :data:`MAX_COVERAGE` (else the bias
dominates).  Otherwise the std is an **upper bound** (``"bound"``):

    std^2 = sigma^2 + (max(|b|, |beta(x)|) + 2 sd_b + 2 nl + tb)^2

(``tb`` the truncated directions' bias bound; without ``t*`` the plug-in's
``2 |beta(x)| + 2 sd``).  Never a std that leaves the bias out.  Why not
honest everywhere: a bias estimate moves with the noise, and most where the
error is largest, so a std that adds an uncertain bias covers more than it
says; where the bias is not small the std is a bound, and an iterated TSVD
(no linearisation bias) has an honest std.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.identify.estimate.exact_model import _Exact
from zerocal_sym.identify.result import _noise_dict

#: honest: the bias known well enough that std^2 is known to this fraction of the noise variance
#: (``sd_b^2 + 2 sd_b |b| <= STD_TOL sigma^2``)
STD_TOL = 0.05
#: honest: no parameter of the round has a bias (estimated either way) beyond this many noise std: beyond, the
#: one-step linearisation is poor and the first-order picture of every bias with it
B_MAX = 3.0
#: honest: +-2 std covers an error of the estimated bias with at most this probability (else the bias dominates)
MAX_COVERAGE = 0.97
#: Newton's method for t*: at most this many steps, stopping when |A r| is below BIAS_TOL noise std
BIAS_ITERATIONS = 20
BIAS_TOL = 1e-6
#: the two kinds of a TSVD parameter's std (``info["std_kinds"]``)
STD_KINDS = ("total", "bound")


def _normal_cdf(x):
    x = np.asarray(x, float)
    return 0.5 * np.vectorize(math.erfc, otypes=[float])(-x / math.sqrt(2.0))


def coverage(bias, std, sigma):
    """``P(|N(bias, sigma^2)| <= 2 std)``: how often +-2 std covers an error of that mean and noise."""
    sigma = np.where(sigma > 0, sigma, np.finfo(float).tiny)
    return _normal_cdf((2 * std - bias) / sigma) - _normal_cdf((-2 * std - bias) / sigma)


def tsvd_std_parts(robot, theta, readings, names, estimate, base, A, noise=None, cov_noise=None) -> dict:
    """The noise covariance and the linearisation bias of N TSVD estimates at once (module docstring).

    Parameters
    ----------
    theta : ndarray, shape (N, K, m)
        Commanded joints of each round, rad.
    readings : ndarray, shape (N, K - 1)
        Measured changes, mm.
    names : tuple of str
        The p identified parameters.
    estimate : ndarray, shape (N, p)
        TSVD's estimates (internal units).
    base : ndarray, shape (N, q)
        The source errors the model holds (the prior's zero offsets and measuring errors; the estimate replaces
        ``names``).
    A : ndarray, shape (N, p, K - 1)
        Each round's TSVD operator, changes (mm) to parameters (internal units).
    noise : NoiseModel, optional
        The noise of the changes (needed unless ``cov_noise`` is given).
    cov_noise : ndarray, shape (N, p, p), optional
        The noise covariance, when it is known otherwise (from the residuals).

    Returns
    -------
    dict
        ``cov_noise`` (N, p, p); (N, p): ``bias`` (``b``, NaN where ``t*`` was not found), ``bias_std``,
        ``bias_plugin`` (``beta(x)``), ``bias_plugin_std``, ``nonlinearity``; ``residuals``
        (N, K - 1) (measured minus exact-model changes at the estimate).
    """
    from zerocal_sym.model import kinematics as kin

    errors = robot.errors
    theta = np.asarray(theta, float)
    readings = np.asarray(readings, float)
    N, K, m = theta.shape
    p = len(names)
    idx = [errors.index(n) for n in names]
    full = np.array(base, float, copy=True)
    full[:, idx] = estimate
    with np.errstate(all="ignore"):
        rho, de, dt = kin.distance_jacobians(robot, theta.reshape(N * K, m), np.repeat(full, K, axis=0))
    rho, de, dt = rho.reshape(N, K), de.reshape(N, K, -1), dt.reshape(N, K, m)
    r = readings - np.diff(rho, axis=1)
    plugin = -np.einsum("npk,nk->np", A, r)
    D = np.einsum("npk,nkj->npj", A, np.diff(de[:, :, idx], axis=1)) - np.eye(p)
    if cov_noise is None and getattr(noise, "has_shared", False):  # a shared revisit error: each round's own C
        from zerocal_sym.identify.fisher import change_covariance

        cov_noise = np.array([change_covariance(robot, theta[n], noise, err0=full[n]).sandwich(A[n])
                              for n in range(N)])
    if cov_noise is None:
        var_rho = noise.sigma_joint ** 2 * np.sum(dt ** 2, axis=2)  # (N, K): the servo error at each pose
        AD = -np.diff(A, axis=2, prepend=0.0, append=0.0)  # A @ Dm (N, p, K), Dm the (K-1) x K difference matrix
        cov_noise = (noise.sigma_scale_mm ** 2 * np.einsum("npk,nqk->npq", A, A)
                     + np.einsum("npk,nk,nqk->npq", AD, var_rho, AD))
    cov_noise = np.asarray(cov_noise, float)
    sig = np.sqrt(np.maximum(np.einsum("nii->ni", cov_noise), 0.0))
    unit = np.where(sig > 0, sig, 1.0)
    with np.errstate(all="ignore"):  # (A J)^+: Newton's step for A r(t) = 0 (within the kept directions if truncated)
        AJ = D + np.eye(p)
        M = np.linalg.pinv(np.where(np.isfinite(AJ), AJ, 0.0), rcond=1e-10)
    z, ok = _solve_t_star(robot, theta, readings, full, idx, A, M, estimate, plugin, unit)
    bias = np.where(ok[:, None], np.asarray(estimate) - z, np.nan)
    MD = np.einsum("npq,nqj->npj", D, M)  # b - beta(x_true) = D M A n to first order
    bias_std = np.sqrt(np.maximum(np.einsum("npi,nij,npj->np", MD, cov_noise, MD), 0.0))
    plugin_std = np.sqrt(np.maximum(np.einsum("npi,nij,npj->np", D, cov_noise, D), 0.0))
    nl = np.abs(plugin - bias - np.einsum("npq,nq->np", D, bias))
    return {"cov_noise": cov_noise, "bias": bias, "bias_std": bias_std, "bias_plugin": plugin, "bias_plugin_std": plugin_std, "nonlinearity": nl, "residuals": r}


def _solve_t_star(robot, theta, readings, full, idx, A, M, estimate, plugin, unit):
    """``t*`` with ``A r(t*) = 0`` per round (Newton with the Jacobian at the estimate, steps halved until they
    lower ``|A r|`` in noise std); ``(t* (N, p), found (N,))``."""
    from zerocal_sym.model import kinematics as kin

    N, K, m = theta.shape

    def step_at(z, rows):
        f = full[rows].copy()
        f[:, idx] = z
        with np.errstate(all="ignore"):
            s0 = kin.distance(robot, theta[rows].reshape(-1, m), np.repeat(f, K, axis=0)).reshape(-1, K)
            g = np.einsum("npq,nqk,nk->np", M[rows], A[rows], readings[rows] - np.diff(s0, axis=1))
        return g, np.sqrt(np.sum((g / unit[rows]) ** 2, axis=1))

    z = np.array(estimate, float, copy=True)
    with np.errstate(all="ignore"):
        g = -np.einsum("npq,nq->np", M, plugin)
        gn = np.sqrt(np.sum((g / unit) ** 2, axis=1))
    gn = np.where(np.isfinite(gn), gn, np.inf)
    stuck = ~np.isfinite(gn)
    for _ in range(BIAS_ITERATIONS):
        act = np.flatnonzero((gn > BIAS_TOL) & ~stuck)
        if act.size == 0:
            break
        lam = np.ones(act.size)
        todo = np.arange(act.size)
        for _h in range(10):
            rows = act[todo]
            zt = z[rows] + lam[todo, None] * g[rows]
            gt, nt = step_at(zt, rows)
            better = np.isfinite(nt) & (nt < gn[rows])
            z[rows[better]], g[rows[better]], gn[rows[better]] = zt[better], gt[better], nt[better]
            todo = todo[~better]
            if todo.size == 0:
                break
            lam[todo] /= 2
        stuck[act[todo]] = True  # no step lowers it: t* not found
    return z, (gn <= BIAS_TOL) & ~stuck


def combine(parts, trunc=None, trunc_bound=None):
    """The covariance of N TSVD estimates, each parameter's kind and std (module docstring).

    Parameters
    ----------
    parts : dict
        :func:`tsvd_std_parts`'s.
    trunc : ndarray, shape (N, p, p), optional
        The truncated directions' bias bound terms ``sum_i bound_i^2 u_i u_i^T``.
    trunc_bound : ndarray, shape (N, p), optional
        Per parameter the truncated directions' bias bound.

    Returns
    -------
    cov : ndarray, shape (N, p, p)
        ``Sigma + b b^T + trunc``, rows and columns scaled to the std on its diagonal (correlations kept).
    kinds : ndarray of str, shape (N, p)
        ``"total"`` or ``"bound"``.
    """
    cov_noise = parts["cov_noise"]
    sig = np.sqrt(np.maximum(np.einsum("nii->ni", cov_noise), 0.0))
    b, sb, nl = parts["bias"], parts["bias_std"], parts["nonlinearity"]
    plug, sp = parts["bias_plugin"], parts["bias_plugin_std"]
    tb = np.zeros_like(sig) if trunc_bound is None else np.asarray(trunc_bound, float)
    found = np.isfinite(b)
    bb = np.where(found, b, 0.0)
    std = np.sqrt(sig ** 2 + bb ** 2)
    with np.errstate(invalid="ignore"):
        small = np.all(found & (np.abs(bb) <= B_MAX * sig) & (np.abs(plug) <= B_MAX * sig), axis=1, keepdims=True)
        honest = (small & (sb ** 2 + 2 * sb * np.abs(bb) <= STD_TOL * sig ** 2) & (tb <= 0.0)
                  & (coverage(np.abs(bb), std, sig) <= MAX_COVERAGE))
        far = np.where(found, np.maximum(np.abs(bb), np.abs(plug)) + 2 * sb + 2 * np.where(found, nl, 0.0),
                       2 * np.abs(plug) + 2 * sp) + tb
    std = np.where(honest, std, np.sqrt(sig ** 2 + far ** 2))
    cov = cov_noise + np.einsum("ni,nj->nij", bb, bb)
    if trunc is not None:
        cov = cov + trunc
    d = np.sqrt(np.maximum(np.einsum("nii->ni", cov), np.finfo(float).tiny))
    f = np.where(np.isfinite(std), std / d, np.nan)
    cov = cov * f[:, :, None] * f[:, None, :]
    return cov, np.where(honest, STD_KINDS[0], STD_KINDS[1])


def _honest_uncertainty(robot, meas, names, prior_eff, noise, est, sol, cov_noise, A=None, base=None) -> dict:
    """TSVD's covariance, honest per parameter: noise, linearisation bias and truncated directions' bias bound.

    ``A`` (p, K-1): the TSVD operator (changes to parameters, internal units); ``base`` (q,): the source errors
    TSVD's model holds (its prior's zero offsets and measuring errors; default ``prior_eff``).  Returns a dict:
    ``_covariance`` (total), ``_std_kind``, ``_exact`` (the exact whitened model), ``_basis`` (kept directions,
    scaled), ``_evaluated_at``, ``_chi2_at_estimate`` and the JSON-ready ``info`` entries ``covariance_noise``,
    ``linearisation_bias``, ``truncation_bias_bound``, ``std_kinds``, ``std_components``, ``std_note``,
    ``fit_point``, ``fit_basis``, ``prior``, ``noise``.
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
    bound = np.zeros(p)
    trunc = np.zeros((p, p))
    z_ref = z_est
    parts = None
    try:
        z_ref = exact.refine(z_est, basis)  # the fit check's point: the exact-model minimum over the kept directions
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
        notes.append(f"the exact-model refinement failed ({exc}): the truncated directions' bias is not in the std")
    if cov_noise is not None and A is not None:
        parts = tsvd_std_parts(robot, np.asarray(meas.theta_cmd, float)[None], np.asarray(meas.readings, float)[None, 1:],
                               names, est[None], np.asarray(prior_eff if base is None else base, float)[None],
                               np.asarray(A, float)[None], cov_noise=np.asarray(cov_noise, float)[None])
    if notes or not np.all(np.isfinite(trunc)):
        out["_std_kind"] = "lower bound"
        notes = notes or ["the truncated directions' bias could not be bounded: it is not in the std"]
        trunc, bound = np.zeros((p, p)), np.zeros(p)
    kinds = np.full(p, STD_KINDS[1] if parts is not None else "lower bound", dtype=object)
    if cov_noise is None:
        cov = None
        out["_std_kind"] = "lower bound"
        notes.append("no noise model and no spare degree of freedom: the noise part of the std is unknown")
    elif parts is None:
        cov = np.asarray(cov_noise, float) + trunc
        out["_std_kind"] = "lower bound"
        notes.append("the linearisation bias was not evaluated: it is not in the std")
    else:
        c3, k3 = combine(parts, trunc[None], bound[None])
        cov, kinds = c3[0], k3[0]
        if out["_std_kind"] == "total" and np.any(kinds == STD_KINDS[1]):
            out["_std_kind"] = "bound"
    nan = np.full(p, np.nan)
    b, b_sd = (parts["bias"][0], parts["bias_std"][0]) if parts is not None else (nan, nan)
    plug = parts["bias_plugin"][0] if parts is not None else nan
    noise_sd = (np.sqrt(np.diag(cov_noise)) if cov_noise is not None else nan)
    out["_covariance"] = cov
    out["_evaluated_at"] = ("the exact-model minimum over TSVD's kept directions (Gauss-Newton from its estimate)"
                            if np.any(z_ref != z_est) else "estimate")
    out["fit_point"] = (z_ref / sc).tolist()
    out["linearisation_bias"] = b.tolist()
    out["truncation_bias_bound"] = bound.tolist()
    out["std_kinds"] = {n: str(kinds[k]) for k, n in enumerate(names)}

    def user(n, v):
        return None if not np.isfinite(v) else errors.to_user_value(n, float(v))

    out["std_components"] = {
        n: {"noise": user(n, noise_sd[k]), "linearisation_bias": user(n, b[k]),
            "linearisation_bias_std": user(n, b_sd[k]), "linearisation_bias_at_estimate": user(n, plug[k]),
            "truncation_bias_bound": errors.to_user_value(n, float(bound[k])), "kind": str(kinds[k]),
            "unit": errors[n].user_unit}
        for k, n in enumerate(names)}
    out["std_note"] = ("; ".join(notes) if notes else
                       "kind \"total\": std^2 = noise^2 + bias^2, honest where the linearisation bias is small "
                       "and well determined; kind \"bound\": an upper bound, "
                       "std^2 = noise^2 + (|bias| + 2 bias_std + 2 nonlinearity + truncation bound)^2 "
                       "(zerocal_sym/identify/estimate/tsvd_uncertainty.py)")
    return out


def attach_std_many(robot, pending, noise) -> None:
    """Give lean TSVD results (``identify_tsvd_many(..., noise=noise)``) their std, all rounds at once.

    ``pending``: ``(result, theta_cmd (K, m), readings (K,), A (p, K-1), prior (q,))`` per round, one K.  Sets
    each result's ``covariance``, ``std_kind``, ``residuals`` and ``info`` ``covariance_noise``,
    ``linearisation_bias``, ``std_kinds`` as :func:`_honest_uncertainty` computes them for an untruncated TSVD.
    """
    errors = robot.errors
    names = pending[0][0].params
    held = errors.zero_offsets + errors.measuring
    base = np.array([errors.put(errors.zeros(), held, errors.take(prior, held)) for *_, prior in pending])
    parts = tsvd_std_parts(robot, np.array([th for _, th, *_ in pending]),
                           np.array([rd[1:] for _, _, rd, *_ in pending]), names,
                           np.array([res.estimate for res, *_ in pending]), base,
                           np.array([A for *_, A, _ in pending]), noise=noise)
    cov, kinds = combine(parts)
    for n, (res, *_) in enumerate(pending):
        res.covariance = cov[n]
        res.std_kind = "bound" if np.any(kinds[n] == STD_KINDS[1]) else "total"
        res.residuals = parts["residuals"][n]
        res.info.update({"covariance_noise": parts["cov_noise"][n], "linearisation_bias": parts["bias"][n],
                         "std_kinds": dict(zip(names, kinds[n].tolist()))})
