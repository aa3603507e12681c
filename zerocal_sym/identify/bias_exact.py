"""The omitted errors' worst-case bias on the exact model, by the estimator itself.

:func:`zerocal_sym.identify.bias.tolerance_bias` bounds the bias to first
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
from zerocal_sym.model.noise import VirtualPlant


def nlls_estimator(robot, theta_cmd, names, noise, prior):
    """The weighted exact fit of ``names`` (:func:`~zerocal_sym.identify.batch.identify_batch`, the other errors
    held at ``prior``) as ``readings (N, K) -> estimates (N, p)``."""
    from zerocal_sym.identify.batch import identify_batch

    def estimate(R):
        return identify_batch(robot, theta_cmd, R, list(names), noise=noise, prior=prior).estimate

    return estimate


def tsvd_estimator(robot, theta_cmd, prior=None, t=None, iterations: int = 1):
    """TSVD as an identification ran it (its prior, truncation and iterations) as ``readings -> estimates``."""
    from zerocal_sym.identify.tsvd import identify_tsvd_many

    def estimate(R):
        rounds = [Measurements(theta_cmd, r) for r in R]
        priors = [prior] * len(rounds)
        for _ in range(iterations):
            out = identify_tsvd_many(robot, rounds, priors, t=t)
            priors = [None if isinstance(r, Exception) else r.full_vector() for r in out]
        return np.array([np.full(len(robot.errors.resolve("default")), np.nan) if isinstance(r, Exception)
                         else r.estimate for r in out])

    return estimate


#: up to this many omitted errors every corner of the tolerance box is evaluated; beyond, the first-order worst
#: corners of each offset and every corner one flip away from them
EXHAUSTIVE_MAX = 8


def _candidates(S, rows, t):
    """Corners to evaluate (c, r) and, per row of ``rows``, the indices of its own candidates."""
    r = t.size
    if r <= EXHAUSTIVE_MAX:
        C = np.array(np.meshgrid(*[(-1.0, 1.0)] * r, indexing="ij")).reshape(r, -1).T * t
        return C, [np.arange(len(C))] * len(rows)
    C, own = [], []
    for i in rows:
        start = len(C)
        for sgn in (1.0, -1.0):
            c0 = sgn * np.where(S[i] >= 0, 1.0, -1.0) * t
            C.append(c0)
            for j in range(r):
                c = c0.copy()
                c[j] = -c[j]
                C.append(c)
        own.append(np.arange(start, len(C)))
    return np.array(C), own


def exact_corner_bias(robot, theta_cmd, S, omitted, tolerances, names, err0, estimator) -> dict:
    """The worst bias of each zero offset over corners of the tolerance box, on the exact model.

    Up to :data:`EXHAUSTIVE_MAX` omitted errors every corner; beyond, for each offset its two first-order worst
    corners ``+-sign(S_i) t`` and every corner one flip away from them (``2 (r + 1)`` per offset).

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
    C, own = _candidates(np.asarray(S, float), rows, t)
    truths = [np.array(err0, float, copy=True)]  # the baseline: what the estimator makes of the data without them
    for c in C:
        err = np.array(err0, float, copy=True)
        err[om] = err[om] + c
        truths.append(err)
    th = np.atleast_2d(theta_cmd)
    with np.errstate(all="ignore"):
        R = np.array([VirtualPlant(robot, err).measure(th) for err in truths])
    est = np.asarray(estimator(R), float)
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
    """:func:`~zerocal_sym.identify.bias.tolerance_bias`, each zero offset's worst case checked on the exact model.

    Adds to ``zero_offsets`` ``worst_case_first_order_<unit>`` (the first-order bound) and
    ``worst_case_exact_<unit>`` (:func:`exact_corner_bias`, by ``estimator``), and reports as
    ``worst_case_<unit>`` (and in ``worst_case``) the larger of the two.
    """
    from zerocal_sym.identify.bias import bias_sensitivity, tolerance_bias, tolerance_vector

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
