"""The arguments of :func:`~zerocal_sym.identify.nlls.identify_nlls`, checked and put in its units.

Each function says what is wrong and where (the argument, the pose, the
file) and returns arrays in the shapes of the glossary (K poses, m joints,
p estimated parameters): the measurements, the Gaussian prior's whitener,
the bounds in scaled units and the start.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import IdentificationError
from zerocal_sym.identify import fisher


def _as_vector(x, n, what):
    a = np.asarray(x, float).ravel()
    if a.shape != (n,):
        raise ValueError(f"{what}: expected {n} values, got {a.size}")
    return a


def index_list(idx, limit: int = 10) -> str:
    """``1, 4, 7`` (at most ``limit`` of them, then how many in all): poses or rows in an error message."""
    idx = [int(i) for i in idx]
    more = f", ... ({len(idx)} in all)" if len(idx) > limit else ""
    return ", ".join(map(str, idx[:limit])) + more


def check_measurements(robot, meas):
    """``theta_cmd`` (K, m) and ``readings`` (K,) of ``meas`` as float arrays.

    Raises
    ------
    IdentificationError
        Fewer than 2 poses, shapes that do not fit the robot or each other,
        NaN or inf (naming the poses, and the file's line when ``meas`` came
        from a file).
    """
    if not (hasattr(meas, "theta_cmd") and hasattr(meas, "readings")):
        raise TypeError(f"meas must be a Measurements(theta_cmd, readings) (zerocal_sym.model.measurements), got "
                        f"{type(meas).__name__}")
    theta_cmd = np.atleast_2d(np.asarray(meas.theta_cmd, float))
    K = theta_cmd.shape[0]
    src = getattr(meas, "source", None)
    src = None if src == "<memory>" else src  # (errors name a file, not an object in memory)
    if K < 2:
        raise IdentificationError(f"need at least 2 poses, got {K}")
    if theta_cmd.ndim != 2 or theta_cmd.shape[1] != robot.m:
        raise IdentificationError(f"theta_cmd must have shape (K, m) = (K, {robot.m}), the {robot.m} commanded "
                                  f"joint angles of robot {robot.name!r} at each pose, got {theta_cmd.shape}",
                                  where=src)
    readings = np.asarray(meas.readings, float)
    if readings.shape != (K,):
        raise IdentificationError(f"readings must have shape (K,) = ({K},) for the {K} poses of theta_cmd, got "
                                  f"{readings.shape}", where=src)
    for what, a in (("theta_cmd (commanded joint angles)", theta_cmd), ("readings", readings)):
        bad = np.flatnonzero(~np.all(np.isfinite(a.reshape(K, -1)), axis=1))
        if bad.size:
            raise IdentificationError(f"{what} must be finite: NaN or inf at pose(s) {index_list(bad)}",
                                      where=meas.where(int(bad[0])) if getattr(meas, "lines", None) else src)
    return theta_cmd, readings


def prior_whitener(names, prior_std=None, prior_cov=None) -> np.ndarray:
    """The Gaussian prior's whitener ``W`` (p, p): the prior term of the cost is ``|W (p - mu)|^2 / 2``.

    ``prior_cov`` (p, p) gives ``W`` with ``W^T W = prior_cov^-1``;
    ``prior_std`` (p,) or a dict name -> std gives ``diag(1 / std)`` (``inf``:
    no prior on that parameter); neither: zeros (no prior).
    """
    p = len(names)
    if prior_cov is not None:
        if prior_std is not None:
            raise ValueError("give prior_std or prior_cov, not both")
        pc = np.asarray(prior_cov, float)
        if pc.shape != (p, p):
            raise ValueError(f"prior_cov: expected shape ({p}, {p}), got {pc.shape}")
        try:
            return fisher.whitener(pc)
        except np.linalg.LinAlgError:
            raise ValueError("prior_cov must be symmetric positive definite") from None
    if prior_std is None:
        return np.zeros((p, p))
    if isinstance(prior_std, dict):
        std = np.full(p, np.inf)
        for k, v in prior_std.items():
            std[names.index(k)] = v
    else:
        std = _as_vector(prior_std, p, "prior_std")
    if np.any(std <= 0):
        raise ValueError("prior_std must be positive (inf for no prior)")
    return np.diag(1.0 / std)


def scaled_bounds(bounds, names, scale):
    """Lower and upper bounds (p,) each, in scaled units (``z = scale * p``); +-inf where none.

    ``bounds``: None, a dict name -> (lo, hi) or an array (p, 2), rad / mm.
    """
    n = len(names)
    lo, hi = np.full(n, -np.inf), np.full(n, np.inf)
    if bounds is None:
        return lo, hi
    if isinstance(bounds, dict):
        for k, (a, b) in bounds.items():
            if k not in names:
                raise ValueError(f"bounds given for {k!r}, which is not estimated ({', '.join(names)})")
            lo[names.index(k)], hi[names.index(k)] = a, b
    else:
        b = np.asarray(bounds, float)
        if b.shape != (n, 2):
            raise ValueError(f"bounds: expected shape ({n}, 2), got {b.shape}")
        lo, hi = b[:, 0].copy(), b[:, 1].copy()
    if np.any(lo > hi):
        raise ValueError("bounds: lower bound above upper bound")
    return lo * scale, hi * scale


def initial(robot, meas, names, prior_q, warm_start, prior_values):
    """Initial guess (physical units, shape (p,)) and a note on where it came from.

    ``prior_values``: ``prior_q`` at ``names`` (the start without a warm start).
    """
    x0 = np.array(prior_values, float)
    if warm_start is None:
        return x0, "prior"
    if isinstance(warm_start, str):
        if warm_start != "tsvd":
            raise ValueError(f"warm_start must be 'tsvd', None or an array, got {warm_start!r}")
        from zerocal_sym.identify.estimate.tsvd_round import tsvd_round

        try:
            ts = tsvd_round(robot, meas, prior=prior_q, diagnostics=False)[0]  # the estimate alone
        except Exception as exc:  # noqa: BLE001 - a failed warm start is not fatal
            return x0, f"prior (tsvd failed: {exc})"
        for k, n in enumerate(names):
            if n in ts.params and np.isfinite(ts.value(n)):
                x0[k] = ts.value(n)
        return x0, "tsvd"
    return _as_vector(warm_start, len(names), "warm_start"), "given"
