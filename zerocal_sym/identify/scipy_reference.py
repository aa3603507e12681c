"""The outside reference of the comparison: ``scipy.optimize.least_squares`` on the problem Ipopt solves."""
from __future__ import annotations

import time

import numpy as np

from zerocal_sym.errors import ZerocalError


def least_squares_or_error():
    """scipy's ``least_squares``, or a one-line error saying how to get scipy."""
    try:
        from scipy.optimize import least_squares
    except ImportError:  # pragma: no cover - scipy is a test extra
        raise ZerocalError("the scipy reference needs scipy (a test/benchmark extra: pip install "
                           "'zerocal_sym[test]'), or leave 'scipy' out of --methods") from None
    return least_squares


def scipy_identify(robot, meas, params="paper", noise=None, prior=None, callbacks: str = "fast"):
    """``scipy.optimize.least_squares`` on the problem Ipopt solves (reference).

    The whitened, scaled residuals of :func:`zerocal_sym.identify.nlls.residual_problem`
    (weights at ``prior``), Levenberg-Marquardt from ``prior``.  ``callbacks``
    (passed to ``residual_problem``): ``"fast"`` (default) evaluates the CasADi
    residuals and Jacobian through zero-copy buffers, ``"plain"`` through the
    ordinary ``Function`` call (numpy <-> DM conversions, ~0.1-0.2 ms per call,
    most of the solver time at K = 6); the values, hence the estimate, are the
    same bit for bit, only ``time_s`` differs.

    Returns
    -------
    estimate : ndarray, shape (p,)
        rad / mm.
    info : dict
        ``success``, ``nfev``, ``cost``, ``time_s`` (the solver call only).
    """
    from zerocal_sym.identify.nlls import residual_problem

    least_squares = least_squares_or_error()
    fun, jac, scale = residual_problem(robot, meas, params, noise, prior, callbacks=callbacks)
    p0 = robot.errors.zeros() if prior is None else np.asarray(prior, float)
    z0 = robot.errors.take(p0, robot.errors.resolve(params)) * scale
    t = time.perf_counter()
    sol = least_squares(fun, z0, jac=jac, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    dt = time.perf_counter() - t
    return sol.x / scale, {"success": bool(sol.success), "nfev": int(sol.nfev), "cost": float(sol.cost),
                           "time_s": dt}
