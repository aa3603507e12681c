"""What a round's revisits say about the shared error of a pose: its REML estimate and interval.

A round that visits some poses more than once can estimate the standard
deviation ``sigma_r`` of a pose's systematic error of the measured length
shared by its revisits (:class:`~zerocal_sym.model.noise.NoiseModel`
``sigma_revisit_mm``): the independent errors (scale, servo) differ from
visit to visit of a pose, the shared one does not, so the readings between
revisited poses scatter more than the independent noise explains exactly
when ``sigma_r > 0``.

Method (decision): restricted maximum likelihood (REML) of the one variance
component ``sigma_r^2`` with the independent terms held at the noise
model's values, on the model linearised at the estimate: residuals ``e``
(K-1,) of the changes, their Jacobian ``X`` (K-1, r) (r: the identified
combinations), ``C(s) = T(s) + B(s) B(s)^T``
(:mod:`zerocal_sym.identify.covariance`)::

    l(s) = -1/2 [ log det C + log det(X^T C^-1 X) + e^T P e ],   P = C^-1 - C^-1 X (X^T C^-1 X)^-1 X^T C^-1

(REML, not ML: the r parameters fitted from the same data do not bias the
estimate low).  ``e^T P e`` does not depend on where the residuals are taken
on the linear model.  The estimate maximises ``l`` over ``s >= 0`` (a grid,
then Brent); its uncertainty is the profile interval ``{s: 2 (l_max - l(s))
<= 3.84}`` (95 %, by the likelihood-ratio test, honest at the boundary where
a standard error from the curvature is not), and the test of ``sigma_r = 0``
uses the boundary mixture ``p = 0.5 P(chi2_1 >= 2 (l_max - l(0)))``.  The
information on ``sigma_r`` comes from how the G revisited poses' mean
readings scatter beyond the independent noise, with the r parameters
fitted: a handful of revisited poses (a design's support points) leave few
degrees of freedom, and the interval is wide (it says so).

Each evaluation of ``l`` is O(G r^2) after an O(K P) start when the round has at most
:data:`MAX_POSES_LOW_RANK` distinct poses P (every pose's error in the low-rank part: the bands are the
same for every ``s``), O(K (r + G)) otherwise; about a hundred are made.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.identify.chi2 import chi2_sf
from zerocal_sym.identify.covariance import ChangeCovariance

#: 2 (l_max - l) at the edge of the 95 % profile interval (chi2 with 1 dof)
CHI2_95 = 3.841458820694124
#: grid points of the first search (geometric, below the largest value tried)
GRID = 24


#: a round of at most this many distinct poses puts every pose's shared error in the low-rank part: the bands
#: are then the same for every sigma_r, factored once, and each evaluation of the likelihood is O(G p^2)
MAX_POSES_LOW_RANK = 200


def _gram_loglik(logdet, M):
    """``l`` from ``log det C`` and the Gram matrix ``M = [X e]^T C^-1 [X e]`` ((r+1) x (r+1))."""
    try:
        Lx = np.linalg.cholesky(M[:-1, :-1])
    except np.linalg.LinAlgError:
        return -math.inf
    u = np.linalg.solve(Lx, M[:-1, -1])
    return -0.5 * (logdet + 2.0 * float(np.sum(np.log(np.diag(Lx)))) + float(M[-1, -1] - u @ u))


def _likelihood(sm2, v, labels, X, e):
    """``s -> l(s)`` (module docstring), ``-inf`` where C is not positive definite."""
    Y = np.column_stack([X, e])
    P = int(labels.max()) + 1
    if P <= MAX_POSES_LOW_RANK:  # every pose's error in the low-rank part: the bands do not depend on s
        C0 = ChangeCovariance.from_variances(math.sqrt(sm2), v)
        l, b = C0.cholesky()
        W1 = C0.whiten(np.diff(np.eye(P)[labels], axis=0))      # L^-1 D Z, per unit sigma_r
        lam1, V = np.linalg.eigh(W1.T @ W1)
        keep = lam1 > 1e-14 * max(float(lam1.max(initial=0.0)), 1e-300)
        lam1 = lam1[keep]
        Q = (W1 @ V[:, keep]) / np.sqrt(lam1)
        Yw = C0.whiten(Y)
        G0, Qy = Yw.T @ Yw, Q.T @ Yw
        ld0 = 2.0 * float(np.sum(np.log(l)))

        def f(s):
            lam = s * s * lam1
            M = G0 + Qy.T @ ((1.0 / (1.0 + lam) - 1.0)[:, None] * Qy)
            return _gram_loglik(ld0 + float(np.sum(np.log1p(lam))), M)
        return f

    def f(s):
        C = ChangeCovariance.from_variances(math.sqrt(sm2), v, labels, s)
        try:
            Yw = C.whiten(Y)
            logdet = C.logdet()
        except np.linalg.LinAlgError:
            return -math.inf
        return _gram_loglik(logdet, Yw.T @ Yw)
    return f


def reml_revisit_std(e, X, sm2, v, labels) -> dict:
    """The REML estimate of ``sigma_r`` (mm) and its 95 % profile interval (module docstring).

    Parameters
    ----------
    e : ndarray, shape (K-1,)
        Residuals of the changes, mm.
    X : ndarray, shape (K-1, p)
        Their Jacobian w.r.t. the estimated parameters (any scaling; its
        column space is what counts).
    sm2 : float
        Scale variance per change, mm^2.
    v : ndarray, shape (K,)
        Independent variance of each visit's length (servo), mm^2.
    labels : ndarray of int, shape (K,)
        The pose of each visit.

    Returns
    -------
    dict
        ``estimate_mm``, ``ci95_mm`` ([lo, hi]; hi None when the likelihood
        does not fall by the interval's amount within 1000 times the
        residuals' scale), ``p_value_zero`` (the test of ``sigma_r = 0``),
        ``method``.
    """
    e = np.asarray(e, float)
    X = np.atleast_2d(np.asarray(X, float))
    U, sv, _ = np.linalg.svd(X, full_matrices=False)
    X = U[:, : int(np.sum(sv > 1e-10 * (sv[0] if sv.size else 0.0)))]  # the identified combinations
    f = _likelihood(sm2, v, np.asarray(labels, int), X, e)
    scale = math.sqrt(max(float(np.mean(e * e)), sm2, 1e-30))
    grid = np.concatenate([[0.0], scale * np.geomspace(1e-4, 10.0, GRID)])
    vals = np.array([f(s) for s in grid])
    i = int(np.argmax(vals))
    s_hat, l_max = float(grid[i]), float(vals[i])
    if 0 < i < grid.size - 1:  # refine between the neighbours
        from scipy.optimize import minimize_scalar

        opt = minimize_scalar(lambda s: -f(s), bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                              options={"xatol": 1e-6 * grid[i]})
        if -opt.fun > l_max:
            s_hat, l_max = float(opt.x), float(-opt.fun)
    target = l_max - 0.5 * CHI2_95
    lo = 0.0 if vals[0] >= target else _edge(f, target, 0.0, s_hat)
    hi, top = None, grid[-1]
    for _ in range(3):
        if f(top) < target:
            hi = _edge(f, target, s_hat, top)
            break
        top *= 10.0
    lr = max(2.0 * (l_max - float(vals[0])), 0.0)
    return {"estimate_mm": s_hat, "ci95_mm": [lo, hi], "p_value_zero": 0.5 * chi2_sf(lr, 1) if lr > 0 else 1.0,
            "method": "REML (independent terms held at the noise model; model linearised at the estimate)"}


def _edge(f, target, a, b):
    """The point between ``a`` and ``b`` where ``f`` crosses ``target`` (f(a), f(b) on either side)."""
    from scipy.optimize import brentq

    return float(brentq(lambda s: f(s) - target, a, b, xtol=1e-6 * max(b, 1e-12)))


def has_revisits(robot, theta_cmd) -> bool:
    """Whether the round visits a pose more than once: two rows of the commanded joints (file unit) within
    :data:`~zerocal_sym.model.revisits.REVISIT_TOL` of each other, as :func:`~zerocal_sym.identify.fisher.pose_labels`
    groups them (O(K log K))."""
    from zerocal_sym.model import units
    from zerocal_sym.model.revisits import REVISIT_TOL, first_duplicate

    return first_duplicate(units.joints_to_user(robot, np.atleast_2d(theta_cmd)), REVISIT_TOL) is not None


def revisit_report(robot, theta_cmd, e, A, noise, err0=None) -> dict | None:
    """The round's revisits and the REML estimate of their shared error (None: no pose is revisited).

    ``theta_cmd`` (K, m) rad, ``e`` (K-1,) residuals of the changes at the
    estimate (mm), ``A`` (K-1, p) their Jacobian there, ``noise`` the model
    (its independent terms are held; its ``sigma_revisit_mm`` is reported as
    ``assumed_mm``), ``err0`` (q,) the estimate (the servo variance is
    evaluated there).

    Returns
    -------
    dict or None
        ``revisited_poses`` (G), ``visits`` (of them), ``poses`` (distinct),
        ``assumed_mm``, and :func:`reml_revisit_std`'s entries, or
        ``reason`` when no estimate can be made (a zero noise model).
    """
    from zerocal_sym.identify.fisher import pose_labels
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.revisits import shared_design

    lab = pose_labels(robot, theta_cmd)
    _, groups = shared_design(lab)
    if not groups:
        return None
    out = {"revisited_poses": len(groups), "visits": int(sum(len(g) for g in groups)),
           "poses": int(lab.max()) + 1, "assumed_mm": float(noise.sigma_revisit_mm)}
    if noise.is_zero:
        out["reason"] = "the noise model is zero: no independent noise to compare the revisits' scatter with"
        return out
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(A))):
        out["reason"] = "the exact model is not finite at the estimate"
        return out
    _, _, dt = kin.distance_jacobians(robot, np.atleast_2d(theta_cmd), err0)
    v = noise.sigma_joint**2 * np.sum(dt**2, axis=1)
    out.update(reml_revisit_std(e, A, float(noise.sigma_scale_mm) ** 2, v, lab))
    lo, hi = out["ci95_mm"]
    out["assumed_in_ci95"] = bool(lo <= out["assumed_mm"] and (hi is None or out["assumed_mm"] <= hi))
    return out


def describe(rep: dict) -> str:
    """One line for the text output."""
    if "revisited_poses" not in rep:
        return f"revisits: their shared error {rep.get('reason')}"
    head = (f"revisits: {rep['revisited_poses']} of {rep['poses']} poses visited more than once "
            f"({rep['visits']} visits)")
    if "estimate_mm" not in rep:
        return f"{head}; shared error not estimated ({rep.get('reason')})"
    lo, hi = rep["ci95_mm"]
    ci = f"{lo * 1e3:.3g}-{hi * 1e3:.3g} um" if hi is not None else f">= {lo * 1e3:.3g} um"
    line = (f"{head}; their shared error (REML) {rep['estimate_mm'] * 1e3:.3g} um, 95 % interval {ci}, "
            f"p = {rep['p_value_zero']:.3g} for none; the noise model assumes {rep['assumed_mm'] * 1e3:.3g} um")
    if not rep["assumed_in_ci95"]:
        line += (" (outside the interval: set [noise] revisit_std_mm in the robot file to what the revisits "
                 "show)")
    return line
