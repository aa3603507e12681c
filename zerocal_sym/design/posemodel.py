"""The order-free pose model of an approximate design, and its criteria.

An *approximate design* is a probability measure ``xi`` on a finite set of
candidate poses (:mod:`zerocal_sym.design.approx`).  This module holds the
model it is judged by: the per-candidate terms (:class:`PoseModel`), the
information ``M`` of a measure, and each criterion's loss and directional
derivative ``d(x)`` -- what the solver (:mod:`zerocal_sym.design.measure`)
and the certificates use.

The measurement model, and what the certificate is for (decision)
------------------------------------------------------------------
The data are the K-1 *changes* of the scale between consecutive poses, with
covariance ``C = sigma_m^2 I + D V D^T`` (``V = diag(v_k)``, the servo error's
variance of ``rho_k``, ``D`` the first differences): the information
``F = A^T C^-1 A`` of an *ordered* design is not a sum over poses.  We use an
order-free upper bound.  Since ``D D^T`` has eigenvalues below 4,
``sigma_m^2 I >= D (sigma_m^2 / 4) I D^T``, hence

    C >= D Vt D^T,   Vt = diag(v_k + sigma_m^2 / 4),

and, because GLS on the differences equals GLS on the poses with a free
common constant (the differences are its maximal invariant),

    F(ordered design) <= sum_k h_k h_k^T = K M(xi),
    h_k = (aq_k - c) / sqrt(vt_k),  c = the 1/vt-weighted mean of the aq_k,

for *every* order of the K poses (``xi`` their empirical measure, ``M`` the
Schur complement of the intercept in the pose model with regressors
``(1, aq_x) / sqrt(vt_x)``).  So the optimum of the pose model over measures
bounds what any ordered K-pose design on the candidates can reach, and the
certificate is honest for the real (ordered, correlated) problem: the
reported *efficiency lower bound* of a design is its exact criterion (its own
order, the full covariance) against that bound.  The bound is tight when the
scale error is small against the servo error (the paper's noise: the servo
error dominates by a factor ~500 at each change) and the order alternates
between distant poses; with the scale error alone it can be loose (up to the
factor 4 above).  The consecutive-travel constraint and the minimum
separation are relaxed in the bound (it stays an upper bound); the range
travel constraint is handled by windows in ``rho``
(:mod:`zerocal_sym.design.approx`).

Criteria and certificates (``Phi`` at the normalised measure; ``d(x)``
the directional derivative towards the one-point measure at ``x``)
--------------------------------------------------------------------
* ``D``: ``log det M``; ``d(x) = h_x^T M^-1 h_x``, ``sum_x w_x d(x) = p``; for
  any measure ``xi*``: ``(det M*/det M)^(1/p) <= max_x d(x) / p``, so the
  D-efficiency is at least ``p / max_x d``.
* ``A``, ``crlb``, ``position`` (linear criteria ``L(M) = tr(W M^-1)``,
  ``W`` = identity in q-units, the zero offsets' weights, the workspace's
  ``mean J^T J``): ``d(x) = h_x^T M^-1 W M^-1 h_x``, ``sum_x w_x d = L``; by
  convexity and homogeneity ``L(M*) >= L(M)^2 / max_x d``, so the
  efficiency ``L*/L`` is at least ``L / max_x d`` (for the crlb, a standard
  deviation, the ratio to the best is at most ``sqrt(max_x d / L)``).
* ``E``: ``lambda_min(M)``; for any trace-one ``E >= 0``,
  ``lambda_min(M*) <= max_x h_x^T E h_x``; we take the best of
  ``E = M^-s / tr M^-s`` (several s) and the smallest eigenvector's
  projector, so the E-efficiency is at least ``lambda_min(M) / that``.  The
  algorithm maximises the smooth ``-(tr M^-q)^(1/q)`` with q doubled up to
  :data:`E_Q`.
* ``cond`` (not concave) and ``mse`` (not convex: the bias does not shrink
  with the mass) have no certificate here.

``M* <= integral h h^T d xi*`` for any centring ``c`` (the Schur complement is
the minimum over ``c``), which is what each bound uses.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design.criteria import _noise_terms
from zerocal_sym.design.terms import Weights, _qscale, pose_terms

#: largest q of the smooth E-criterion (continuation 2, 4, ..., E_Q)
E_Q = 256


class PoseModel:
    """Per-candidate terms of the order-free pose model (module docstring).

    Attributes
    ----------
    X : ndarray, shape (N, n)
    aq : ndarray, shape (N, p)
        Sensitivities in q-units.
    vt : ndarray, shape (N,)
        ``v + sigma_m^2 / 4``, mm^2.
    rho : ndarray, shape (N,)
    W : ndarray, shape (p, p) or None
        Weight of a linear criterion (None for D and E).

    ``terms``: :func:`~zerocal_sym.design.terms.pose_terms` of ``X`` if already computed (as the feasibility
    check returns them, :func:`~zerocal_sym.design.feasible._pointwise`).
    """

    def __init__(self, robot, X, noise, criterion, weights: Weights | None = None, terms: dict | None = None):
        sm2, sx2 = _noise_terms(noise, robot)
        self.X = np.atleast_2d(np.asarray(X, float))
        t = pose_terms(robot, self.X) if terms is None else terms
        self.aq = t["a"] * _qscale(robot)
        self.vt = sx2 * np.sum(t["dth"] ** 2, axis=1) + sm2 / 4.0
        self.vt = np.maximum(self.vt, 1e-12 * max(float(self.vt.max()), 1e-300))
        self.rho = t["rho"]
        self.criterion = criterion
        wts = weights or Weights(robot)
        p = self.aq.shape[1]
        self.W = {"A": np.eye(p), "crlb": np.diag(wts.crlb), "position": wts.position}.get(criterion)

    def subset(self, idx):
        out = object.__new__(PoseModel)
        out.X, out.aq, out.vt, out.rho = self.X[idx], self.aq[idx], self.vt[idx], self.rho[idx]
        out.criterion, out.W = self.criterion, self.W
        return out

    def extend(self, other):
        out = object.__new__(PoseModel)
        out.X = np.vstack([self.X, other.X])
        out.aq = np.vstack([self.aq, other.aq])
        out.vt = np.concatenate([self.vt, other.vt])
        out.rho = np.concatenate([self.rho, other.rho])
        out.criterion, out.W = self.criterion, self.W
        return out


def _stats(u, aq):
    """Sufficient statistics of ``u = w / vt``: (s0, s1 (p,), S2 (p, p))."""
    return u.sum(), u @ aq, (aq.T * u) @ aq


def _schur(s0, s1, S2):
    """Information ``M`` (p, p) and centre ``c`` (p,) from the statistics."""
    c = s1 / s0
    M = S2 - np.outer(s1, c)
    return (M + M.T) / 2, c


def _crit(criterion, M, W, q=E_Q):
    """``(loss, G, s)``: loss (smaller is better), ``d(x) = h^T G h``, ``s = sum_x w_x d(x)``.

    The gradient of the loss in ``w_x`` is ``-d(x)`` for D and ``-d(x) / s``
    otherwise.  E (the smooth ``log(tr M^-q) / q``) is computed with the
    eigenvalues relative to the smallest (no overflow); ``d / s`` is exact.
    """
    p = M.shape[0]
    ev, U = np.linalg.eigh(M)
    if not ev[0] > 1e-13 * max(ev[-1], 1e-300):
        return math.inf, None, None
    if criterion == "D":
        return -float(np.sum(np.log(ev))), (U / ev) @ U.T, float(p)
    if criterion == "E":
        evq = (ev / ev[0]) ** (-float(q))
        t = float(np.sum(evq))
        return math.log(t) / q - math.log(ev[0]), (U * (evq / ev)) @ U.T, t
    Minv = (U / ev) @ U.T
    phi = float(np.sum(W * Minv))
    return math.log(phi), Minv @ W @ Minv, phi


def _exponent(criterion, q):
    return {"D": 1.0, "E": 1.0 / (q + 1)}.get(criterion, 0.5)


def _sens(G, aq, c, vt):
    Dx = aq - c
    return np.sum((Dx @ G) * Dx, axis=1) / vt


def _evaluate(criterion, W, q, w, aq, vt):
    """Loss, gradient (in w), and the rest at a measure: (loss, grad, d, s, M, c)."""
    M, c = _schur(*_stats(w / vt, aq))
    loss, G, s = _crit(criterion, M, W, q)
    if G is None:
        return math.inf, None, None, None, M, c
    d = _sens(G, aq, c, vt)
    grad = -d if criterion == "D" else -d / s
    return loss, grad, d, s, M, c
