"""The omitted errors' worst-case bias on the exact model, by the estimator itself.

:func:`zerocal_sym.identify.budget.bias.tolerance_bias` bounds the bias to first
order: ``sum_j |S_ij| t_j``, reached at the corner ``sign(S_i) t`` of the
tolerance box.  Beyond first order the bias at that corner differs (the
model is not linear in the omitted errors, nor in the offsets the data show).
:func:`exact_corner_bias` evaluates it: for each zero offset ``i`` the two
corners ``+-sign(S_i) t`` (the first-order worst for a positive and a
negative bias), noise-free readings of the exact virtual plant with the
identified parameters at their estimate and the omitted errors at the corner,
identified by the method's own estimator (:func:`nlls_estimator`: the
weighted exact fit; :func:`tsvd_estimator`: TSVD as it was run), the bias the
estimate minus the truth.  The worst case reported is the larger of the
first-order bound and these exact biases.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant


#: Gauss-Newton of the weighted exact fit (:func:`nlls_estimator`): at most this many steps, until a step is below
#: this (scaled units, mm: five orders below the last digit a bias is reported with)
GN_ITERATIONS = 40
GN_TOL = 1e-8


def _anderson(x, f, x_prev, f_prev):
    """The next points of Gauss-Newton iterations ``x -> x + f`` (rows: data sets), each accelerated by
    Anderson mixing of depth one (the secant through the last two steps) where the steps contract, else the
    plain step.  The fixed points are Gauss-Newton's (where ``f = 0``): only the path to them is shorter.  A
    corner's fit leaves a residual, so Gauss-Newton converges only linearly there (on the rotary Delta at
    K = 10^4 it used every step it was allowed); the secant makes it superlinear.

    Shapes: ``x``, ``f``, ``x_prev``, ``f_prev`` (N, p); ``f_prev`` NaN where there is no previous step."""
    g = x + f
    df = f - f_prev
    den = np.sum(df * df, axis=1)
    n_f, n_prev = np.linalg.norm(f, axis=1), np.linalg.norm(f_prev, axis=1)
    with np.errstate(all="ignore"):
        gamma = np.sum(f * df, axis=1) / den
        mixed = g - gamma[:, None] * (df + (x - x_prev))  # g - gamma (g - g_prev)
    use = np.isfinite(gamma) & (den > 0) & (n_f < n_prev) & (np.abs(gamma) <= 10.0) & np.all(np.isfinite(mixed),
                                                                                              axis=1)
    return np.where(use[:, None], mixed, g)


def nlls_estimator(robot, theta_cmd, names, noise, prior):
    """The weighted exact fit of ``names`` (the other errors held at ``prior``) as ``readings (N, K) -> estimates
    (N, p)``: Gauss-Newton from ``prior`` on the exact model, all data sets at once, whitened by the covariance of
    the changes at ``prior`` (the weights of :func:`~zerocal_sym.identify.nlls.identify_nlls` at its estimate;
    a corner of the tolerance box moves them at second order).  NaN where it does not converge."""
    from zerocal_sym.identify import fisher
    from zerocal_sym.model import kinematics as kin

    errors = robot.errors
    th = np.atleast_2d(theta_cmd)
    K = th.shape[0]
    idx = [errors.index(n) for n in names]
    prior = np.asarray(prior, float)
    noise = NoiseModel.coerce(noise, robot=robot)
    C = None if noise.is_zero else fisher.change_covariance(robot, th, noise, prior)
    scale = fisher.parameter_scale(robot, names)

    def white(a):  # (K-1, ...) whitened by C
        return a if C is None else C.whiten(a)

    def estimate(R, start=None):
        R = np.asarray(R, float)
        N = R.shape[0]
        z = np.tile(prior[idx], (N, 1))
        if start is not None:  # a warm start (e.g. the first-order prediction), where finite
            start = np.asarray(start, float)
            z = np.where(np.isfinite(start), start, z)
        done = np.zeros(N, bool)
        x_prev, f_prev = np.zeros((N, len(idx))), np.full((N, len(idx)), np.nan)
        for _ in range(GN_ITERATIONS):
            live = np.flatnonzero(~done)  # only the data sets still iterating
            full = np.tile(prior, (live.size, 1))
            full[:, idx] = z[live]
            with np.errstate(all="ignore"):
                rho, de, _ = kin.distance_jacobians(robot, np.tile(th, (live.size, 1)), np.repeat(full, K, axis=0))
            r = R[live, 1:] - np.diff(rho.reshape(live.size, K), axis=1)
            J = np.diff(de.reshape(live.size, K, -1)[:, :, idx], axis=1) / scale
            f = np.full((live.size, len(idx)), np.nan)
            for a, n in enumerate(live):
                if np.all(np.isfinite(J[a])) and np.all(np.isfinite(r[a])):
                    f[a] = np.linalg.lstsq(white(J[a]), white(r[a]), rcond=None)[0]
            x = z[live] * scale
            nxt = _anderson(x, f, x_prev[live], f_prev[live])
            x_prev[live], f_prev[live] = x, f
            bad = ~np.all(np.isfinite(f), axis=1)
            conv = ~bad & (np.max(np.abs(np.where(bad[:, None], 0.0, f)), axis=1) < GN_TOL)
            z[live] = np.where(conv[:, None], x + f, nxt) / scale  # converged: the Gauss-Newton step's end
            z[live[bad]] = np.nan
            done[live] = bad | conv
            if done.all():
                break
        z[~done] = np.nan
        return z

    estimate.takes_start = True
    return estimate


def tsvd_estimator(robot, theta_cmd, prior=None, t=None, iterations: int = 1):
    """TSVD as an identification ran it (its prior, truncation and iterations) as ``readings -> estimates``."""
    from zerocal_sym.identify.estimate.tsvd_many import tsvd_many

    def estimate(R):
        rounds = [Measurements(theta_cmd, r) for r in R]
        priors = [prior] * len(rounds)
        for _ in range(iterations):
            out = tsvd_many(robot, rounds, priors, t=t)
            priors = [None if isinstance(r, Exception) else r.full_vector() for r in out]
        return np.array([np.full(len(robot.errors.resolve("default")), np.nan) if isinstance(r, Exception)
                         else r.estimate for r in out])

    return estimate


#: up to this many omitted errors every corner of the tolerance box is evaluated (if the poses allow, below);
#: beyond, the two first-order worst corners of each offset
EXHAUSTIVE_MAX = 8
#: every corner only while (corners + 1) x K stays below this many poses
EXHAUSTIVE_POSES = 50_000
#: the estimator sees at most this many poses at once (data sets per call: this over K)
CHUNK_POSES = 100_000


def _candidates(S, rows, t, K):
    """Corners to evaluate (c, r) and, per row of ``rows``, the indices of its own candidates."""
    r = t.size
    if r <= EXHAUSTIVE_MAX and (2 ** r + 1) * K <= EXHAUSTIVE_POSES:
        C = np.array(np.meshgrid(*[(-1.0, 1.0)] * r, indexing="ij")).reshape(r, -1).T * t
        return C, [np.arange(len(C))] * len(rows)
    C, own = [], []
    for i in rows:
        own.append(np.arange(len(C), len(C) + 2))
        C += [sgn * np.where(S[i] >= 0, 1.0, -1.0) * t for sgn in (1.0, -1.0)]
    return np.array(C), own


def exact_corner_bias(robot, theta_cmd, S, omitted, tolerances, names, err0, estimator) -> dict:
    """The worst bias of each zero offset over corners of the tolerance box, on the exact model.

    Up to :data:`EXHAUSTIVE_MAX` omitted errors (and :data:`EXHAUSTIVE_POSES` poses over all corners) every
    corner; beyond, for each offset its two first-order worst corners ``+-sign(S_i) t``.

    Parameters
    ----------
    S : ndarray, shape (p, r)
        First-order sensitivity of the estimate to the omitted errors (rows ``names``).
    omitted : sequence of str
        The r omitted errors (columns of ``S``).
    tolerances : ndarray, shape (r,)
        Their tolerances (internal units).
    names : sequence of str
        The identified parameters.
    err0 : ndarray, shape (q,)
        The truth around which the corners are taken: the identified parameters at their estimate, the
        omitted errors at the values the fit holds.
    estimator : callable
        ``readings (N, K) -> estimates (N, p)``.

    Returns
    -------
    dict
        Per zero offset (internal units): ``worst`` (the largest magnitude of the estimate at a corner minus the
        estimate of the same data without the omitted errors; NaN where the estimator failed), ``corner``
        (r,) where it is, ``first_order`` (the exact bias at the first-order worst corners, the larger).
    """
    errors = robot.errors
    off = [n for n in errors.zero_offsets if n in names]
    rows = [list(names).index(n) for n in off]
    om = [errors.index(n) for n in omitted]
    t = np.asarray(tolerances, float)
    th = np.atleast_2d(theta_cmd)
    C, own = _candidates(np.asarray(S, float), rows, t, th.shape[0])
    truths = [np.array(err0, float, copy=True)]  # the baseline: what the estimator makes of the data without them
    for c in C:
        err = np.array(err0, float, copy=True)
        err[om] = err[om] + c
        truths.append(err)
    with np.errstate(all="ignore"):
        R = np.array([VirtualPlant(robot, err).measure(th) for err in truths])
    step = max(1, CHUNK_POSES // th.shape[0])
    if getattr(estimator, "takes_start", False):  # each corner from its first-order prediction
        base = np.asarray(err0, float)[[errors.index(n) for n in names]]
        starts = np.vstack([base] + [base + np.asarray(S, float) @ c for c in C])
        est = np.concatenate([np.asarray(estimator(R[i:i + step], starts[i:i + step]), float)
                              for i in range(0, len(R), step)])
    else:
        est = np.concatenate([np.asarray(estimator(R[i:i + step]), float) for i in range(0, len(R), step)])
    out = {}
    for n, i, idx in zip(off, rows, own):
        b = est[1 + idx, i] - est[0, i]
        lin = np.array([np.argmin(np.abs(C[idx] - s * np.where(S[i] >= 0, 1.0, -1.0) * t).sum(axis=1))
                        for s in (1.0, -1.0)])
        ok = np.all(np.isfinite(b))
        out[n] = {"worst": float(np.max(np.abs(b))) if ok else float("nan"),
                  "corner": C[idx][int(np.argmax(np.abs(b)))] if ok else None,
                  "first_order": float(np.max(np.abs(b[lin]))) if ok else float("nan")}
    return out


def tolerance_bias_exact(robot, theta_cmd, tolerances, params, noise, err0, estimator, operator=None,
                         estimator_name="weighted least squares") -> dict:
    """:func:`~zerocal_sym.identify.budget.bias.tolerance_bias`, each zero offset's worst case checked on the exact model.

    Adds to ``zero_offsets`` ``worst_case_first_order_<unit>`` (the first-order bound) and
    ``worst_case_exact_<unit>`` (:func:`exact_corner_bias`, by ``estimator``), and reports as
    ``worst_case_<unit>`` (and in ``worst_case``) the larger of the two.
    """
    from zerocal_sym.identify.budget.bias import bias_sensitivity, tolerance_bias, tolerance_vector

    errors = robot.errors
    names = errors.resolve(params)
    rep = tolerance_bias(robot, theta_cmd, tolerances, names, noise, err0, operator=operator,
                         estimator=estimator_name)
    S, om = bias_sensitivity(robot, theta_cmd, names, noise, err0, operator=operator)
    t = tolerance_vector(robot, tolerances, om)
    zo = rep["zero_offsets"]
    unit = zo["unit"]
    first = list(zo[f"worst_case_{unit}"])
    if np.any(t > 0):
        ex = exact_corner_bias(robot, theta_cmd, S, om, t, names, err0, estimator)
        exact = [errors.to_user_value(n, ex[n]["worst"]) for n in zo["names"]]
    else:
        exact = [0.0] * len(first)
    worst = [max(a, b) if np.isfinite(b) else a for a, b in zip(first, exact)]
    zo[f"worst_case_first_order_{unit}"] = first
    zo[f"worst_case_exact_{unit}"] = [None if not np.isfinite(v) else v for v in exact]
    zo[f"worst_case_{unit}"] = worst
    for n, w in zip(zo["names"], worst):
        rep["worst_case"][list(names).index(n)] = w
    rep["model"] += ("; each zero offset's worst case is the larger of that bound and the exact bias at its two "
                     "first-order worst corners (noise-free data of the exact model, identified by the estimator "
                     "itself, linearised at the estimate)")
    return rep
