"""The bias-aware design measure (criterion ``mse``): variance and the omitted errors' bias, no certificate.

:func:`mse_measure` starts from the crlb measure
(:func:`zerocal_sym.design.approx.approximate_design`) and lowers the
expected mean squared error of the zero offsets at K poses on the same
candidates; the criterion is not convex, so there is no certificate.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design.approx import ApproxDesign, _clusters
from zerocal_sym.design.constraints import Constraints
from zerocal_sym.design.criteria import _noise_terms
from zerocal_sym.design.terms import Weights, _qscale, pose_terms


def _mse_terms(robot, X, noise, tolerances):
    """Regressors of the pose model with the omitted errors: (G_theta (N, 1 + p), G_o (N, r), W~ (1 + p,))."""
    sm2, sx2 = _noise_terms(noise, robot)
    t = pose_terms(robot, X)
    wts = Weights(robot, tolerances)
    vt = sx2 * np.sum(t["dth"] ** 2, axis=1) + sm2 / 4.0
    sq = np.sqrt(vt)[:, None]
    Gt = np.column_stack([np.ones(len(vt)), t["a"] * _qscale(robot)]) / sq
    Go = (t["ao"] * wts.tol) / sq
    return Gt, Go, np.concatenate([[0.0], wts.crlb]), wts.bias_model


def _mse_value_grad(w, Gt, Go, wd, K, model="rms"):
    """Mean squared offset error (rad^2) of the pose model at mass K, and its gradient in ``w``.

    ``MSE = tr(W T) / K + tr(W B B^T)`` with ``T = N_tt^-1`` and the bias
    ``B = T N_to`` (per RMS tolerance); ``d/dw_x = -u^T W u / K + 2 u^T W B e``
    (``u = T g_t``, ``e = g_o - B^T g_t``).  ``model="worst"``: the bias term
    is ``sum_j W_j (sum_k |B_jk|)^2`` (per tolerance).
    """
    Ntt = (Gt.T * w) @ Gt
    Nto = (Gt.T * w) @ Go
    try:
        T = np.linalg.inv(Ntt)
    except np.linalg.LinAlgError:
        return math.inf, None
    B = T @ Nto
    U = Gt @ T
    E = Go - Gt @ B
    if model == "worst":
        sB = np.sum(np.abs(B), axis=1)
        val = float(np.sum(wd * np.diag(T))) / K + float(np.sum(wd * sB ** 2))
        grad = -np.sum(U * U * wd, axis=1) / K + 2 * np.sum((U * (wd * sB)) @ np.sign(B) * E, axis=1)
        return val, grad
    val = float(np.sum(wd * np.diag(T))) / K + float(np.sum(wd[:, None] * B ** 2))
    grad = -np.sum(U * U * wd, axis=1) / K + 2 * np.sum((U * wd) @ B * E, axis=1)
    return val, grad


def mse_measure(robot, ad: ApproxDesign, K: int, cons: Constraints | None = None, noise=None, tolerances=None,
                max_iter: int = 2000):
    """A measure that lowers the expected mean squared error at K poses (variance and bias), from a crlb measure.

    Local descent on the simplex (exponentiated gradient with backtracking)
    over the candidates of ``ad``; the bias does not shrink with K, so the
    optimum depends on K.  No certificate (the criterion is not convex).
    Returns an :class:`ApproxDesign` with ``criterion = "mse"``; its ``loss``
    is the log of the mean squared error (rad^2) at mass 1 scaled to K
    (``value(K)`` gives the RMS in degrees at that K only).
    """
    from zerocal_sym.model.noise import NoiseModel

    noise = NoiseModel.coerce(noise, robot=robot)
    X = ad.X
    Gt, Go, wd, model = _mse_terms(robot, X, noise, tolerances)
    w = np.maximum(ad.w, 0) + 1e-6 / len(ad.w)
    w /= w.sum()
    f, g = _mse_value_grad(w, Gt, Go, wd, K, model)
    eta = 1.0
    for _ in range(max_iter):
        gn = (g - w @ g) / max(abs(f), 1e-300)
        while True:
            wn = w * np.exp(-eta * np.clip(gn, -50, 50))
            wn /= wn.sum()
            fn, gg = _mse_value_grad(wn, Gt, Go, wd, K, model)
            if gg is not None and fn <= f - 1e-4 * eta * float(w @ (gn * (g - w @ g))):
                break
            eta *= 0.5
            if eta < 1e-12:
                break
        if eta < 1e-12 or f - fn < 1e-12 * f:
            if gg is not None and fn < f:
                w, f, g = wn, fn, gg
            break
        w, f, g = wn, fn, gg
        eta = min(eta * 2, 1e3)
    h = ad.info.get("grid_mm", 1.0)
    h = (h if np.ndim(h) == 0 else np.asarray(h, float)) / 3 ** ad.info.get("refine_rounds", 0)
    reps, ws = _clusters(X, w, 1.5 * h)
    out = ApproxDesign(criterion="mse", X=X, w=w, support=reps, support_w=ws, eff_lb=math.nan,
                       loss=math.log(f * K), bound_loss=math.nan, window=ad.window, n_candidates=ad.n_candidates,
                       iterations=ad.iterations, windows=ad.windows, p=ad.p, time_s=ad.time_s,
                       info=dict(ad.info, start="crlb measure", K=K), unit=ad.unit)
    return out
