"""The fit check's second test: the largest standardised residual over the readings, against the noise model.

The chi² sums the K - 1 readings' evidence, so one reading far off among many
hides in it, the more so under a noise model that overstates the noise
(tests/test_fitcheck.py::test_one_gross_reading_among_many_is_rejected).  The
standardised residuals ``t_k`` (the mean-shift statistics of
:meth:`~zerocal_sym.identify.whitened._Linear.per_reading`) are each
``N(0, 1)`` under the noise model; :func:`max_test` tests the largest
``|t|`` over the ``n`` testable readings with Sidak's correction,

    ``p_max = 1 - (1 - 2 Phi(-|t|max))^n``,

and the fit is rejected when ``p_max < alpha`` (beside the chi² test, at the
same ``alpha``).  The ``t_k`` are correlated: through the fit (``I - H``
projects the residuals onto ``K - 1 - rank`` dimensions) and through the
noise (consecutive changes share a pose's servo error).  Sidak's inequality
(``P(all |t_k| <= c) >= prod_k P(|t_k| <= c)`` for centred jointly normal
``t``, any correlation) makes ``p_max`` an upper bound of the exact
p-value: the test's false-rejection rate is at most ``alpha``, below it where
the correlation is strong (with one spare degree of freedom every ``|t_k|``
is the same, and the test never rejects what the chi² accepts).  The exact
distribution of the maximum of correlated normals would need a
``(K - 1)``-dimensional normal probability: not linear in K, so not used.
The two tests together reject a clean round at most ``2 alpha`` of the time
(the union bound); the rate measured: docs/nonlinear.md.

:func:`max_p_value` is the p-value alone; :func:`max_p_values` the same for
many rounds (:func:`~zerocal_sym.identify.batch.identify_batch`); :func:`max_tests` is :func:`max_test` of many
rounds.
"""
from __future__ import annotations

import math

import numpy as np


def max_p_value(t_abs: float, n: int) -> float:
    """Sidak's p-value of the largest ``|t|`` of ``n`` standard normals (module docstring); 1 for ``n = 0``."""
    if n <= 0 or not math.isfinite(t_abs):
        return 1.0 if n <= 0 else 0.0
    q = math.erfc(abs(t_abs) / math.sqrt(2.0))     # P(|N(0, 1)| >= |t|)
    return 1.0 if q >= 1.0 else float(-math.expm1(n * math.log1p(-q)))


def max_p_values(t_abs, n) -> np.ndarray:
    """:func:`max_p_value` of each entry of ``t_abs`` (N,) with ``n`` (N,) or one int readings; NaN where
    ``t_abs`` is NaN."""
    t_abs = np.asarray(t_abs, float)
    n = np.broadcast_to(np.asarray(n), t_abs.shape)
    return np.array([np.nan if t != t else max_p_value(float(t), int(k)) for t, k in zip(t_abs.ravel(), n.ravel())],
                    float).reshape(t_abs.shape)


def max_test(t, poses, delta, alpha: float, checked: bool) -> dict | None:
    """The largest ``|t|`` of the testable readings (finite ``t``) and its test, JSON-ready; None when no
    reading is testable.

    ``t``, ``delta`` (n,): the standardised residuals and estimated errors (mm) of the readings at ``poses``
    (n,); ``checked``: whether the noise model can be tested at all (a zero noise model, no spare degree of
    freedom: not, and never rejected).  Keys: ``pose``, ``from_pose``, ``standardised``,
    ``estimated_error_mm``, ``readings`` (how many were tested), ``p_value`` (Sidak, None when not checked),
    ``alpha``, ``rejected``, ``correction`` (``"sidak"``).
    """
    t = np.asarray(t, float)
    ok = np.isfinite(t)
    if not ok.any():
        return None
    j = int(np.argmax(np.where(ok, np.abs(t), -1.0)))
    n = int(np.count_nonzero(ok))
    p = max_p_value(abs(float(t[j])), n) if checked else None
    d = float(delta[j])
    return {"pose": int(poses[j]), "from_pose": int(poses[j]) - 1, "standardised": float(t[j]),
            "estimated_error_mm": d if math.isfinite(d) else None, "readings": n, "p_value": p,
            "alpha": float(alpha), "rejected": bool(p is not None and p < alpha), "correction": "sidak"}


def max_tests(T, poses, D, alpha: float) -> list:
    """:func:`max_test` (``checked``) of each column of ``T`` and ``D`` (n, N) at the same ``poses`` (n,): the same
    dicts (the largest ``|t|`` of every column found at once)."""
    T, D = np.asarray(T, float), np.asarray(D, float)
    ok = np.isfinite(T)
    at = np.argmax(np.where(ok, np.abs(T), -1.0), axis=0) if T.size else np.zeros(T.shape[1], int)
    counts = np.count_nonzero(ok, axis=0)
    out = []
    for c, (j, n) in enumerate(zip(at.tolist(), counts.tolist())):
        if not n:
            out.append(None)
            continue
        t = float(T[j, c])
        p = max_p_value(abs(t), n)
        d = float(D[j, c])
        out.append({"pose": int(poses[j]), "from_pose": int(poses[j]) - 1, "standardised": t,
                    "estimated_error_mm": d if math.isfinite(d) else None, "readings": n, "p_value": p,
                    "alpha": float(alpha), "rejected": bool(p < alpha), "correction": "sidak"})
    return out
