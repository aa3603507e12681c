"""Approximate (continuous) designs with an optimality certificate (issue 13).

An *approximate design* is a probability measure ``xi`` on a finite set of
candidate poses: weight ``w_x`` on pose ``x``.  K poses realise ``K w_x``
visits of ``x``.  The optimal measure is a convex problem; the
equivalence theorem gives, at any measure, a bound on how far it is from the
optimum -- a certificate.

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
travel constraint is handled by windows in ``rho`` (below).

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

Algorithm: multiplicative updates ``w_x <- w_x (d(x) / sum w d)^lambda``
(``lambda`` = 1 for D, 1/2 for the linear criteria, 1/(q+1) for E) with a
vertex-exchange step after each (weight moved from the worst support point
to the best candidate, exact line search on the criterion, which is
unimodal along it) until the efficiency bound is within ``tol`` of 1; then
the support is refined (local grids around it, finer each round, added to
the candidates).  The certificate is over the final candidate set (the
coarse grid plus the refinements), not over the continuum.

Travel range (``max rho - min rho <= l0``): the candidates' ``rho`` is
covered by windows ``[r, r + l0]`` every ``delta`` = l0 / 8; the design is the
best over these windows, and the bound is the largest over the enlarged
windows ``[r, r + l0 + delta]``, each of which contains every l0-window
starting in ``[r, r + delta]`` -- so the bound covers every window.

Realisation of K poses (:func:`realize`): efficient rounding (Pukelsheim &
Rieder 1992) of the support's weights to counts; replicates of a support
point on a lattice around it (hexagonal in 2-D, face-centred cubic in 3-D,
spacing the minimum separation) inside the feasible set and the travel
window; the visiting order cycles through the support points (stride
scheduling, never the same point twice in a row, several cycle orders tried
and the best kept by the exact criterion).
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.design.constraints import (Constraints, DesignError, _check_k, _pointwise_ok, check_design,
                                            make_constraints)
from zerocal_sym.design.criteria import (_check_criterion, _criterion_terms, _criterion_weights, _noise_terms,
                                         _objective_batch, _user_value)
from zerocal_sym.design.terms import Weights, _qscale, design_params, pose_terms

#: criteria with an approximate design and a certificate
APPROX_CRITERIA = ("D", "A", "E", "crlb", "position")
#: largest q of the smooth E-criterion (continuation 2, 4, ..., E_Q)
E_Q = 256
#: default target efficiency gap of the measure (efficiency lower bound >= 1 - TOL)
TOL = 1e-4
#: default number of coarse candidate poses
N_CANDIDATES = 1500
#: active-set sizes of :func:`solve_measure`: support points kept, violators added per round
MAX_ACTIVE, MAX_ADD = 60, 20
#: windows per scale range l0 (delta = l0 / WINDOW_STEPS)
WINDOW_STEPS = 8


# --------------------------------------------------------------------------- the pose model
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
    """

    def __init__(self, robot, X, noise, criterion, weights: Weights | None = None):
        sm2, sx2 = _noise_terms(noise)
        self.X = np.atleast_2d(np.asarray(X, float))
        t = pose_terms(robot, self.X)
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


def _regressors(aq, vt):
    """``g_x = (1, aq_x) / sqrt(vt_x)``, shape (N, p + 1): the pose model with its free constant."""
    return np.column_stack([np.ones(len(vt)), aq]) / np.sqrt(vt)[:, None]


def _fgh(criterion, R, W, q, w, escale=None):
    """Convex form of the criterion on regressors ``R`` (S, p + 1): value, gradient and Hessian in ``w``.

    In terms of ``N = sum_x w_x g_x g_x^T`` (the pose model with its free
    constant; ``M^-1 = (N^-1)_pp``): D ``-log det N + log N_00``, linear
    ``tr(W~ N^-1)`` (``W~`` = ``W`` padded), E ``tr(P^q)`` with
    ``P = (N^-1)_pp / escale``.  Hessians: ``A o A - g0^2 g0^2T / N_00^2``,
    ``2 A o B`` and, for E, ``q (2 A o (U P^(q-1) U^T) + Z diag(Gamma) Z^T)``
    (``A = R N^-1 R^T``, ``B = R N^-1 W~ N^-1 R^T``, ``U`` the rows
    ``(N^-1 g_x)_p``, ``Gamma`` the divided differences of ``pi^(q-1)``).
    """
    N = (R.T * w) @ R
    try:
        L = np.linalg.cholesky(N)
    except np.linalg.LinAlgError:
        return math.inf, None, None
    Li = np.linalg.inv(L)
    Ninv = Li.T @ Li
    Y = R @ Ninv
    A = Y @ R.T
    if criterion == "D":
        g0 = R[:, 0] ** 2
        N00 = N[0, 0]
        f = -2 * float(np.sum(np.log(np.diag(L)))) + math.log(N00)
        return f, -np.diag(A) + g0 / N00, A * A - np.outer(g0, g0) / N00 ** 2
    if criterion != "E":
        Yp = Y[:, 1:]
        Bm = Yp @ W @ Yp.T
        return float(np.sum(W * Ninv[1:, 1:])), -np.diag(Bm), 2 * A * Bm
    P = Ninv[1:, 1:] / escale
    pi, V = np.linalg.eigh(P)
    pi = np.maximum(pi, 0)
    Ua = (Y[:, 1:] / math.sqrt(escale)) @ V  # rows a_x = V^T u_x
    Pq1 = (Ua * pi ** (q - 1)) @ Ua.T
    f = float(np.sum(pi ** q))
    ks = np.arange(q - 1)
    Gam = np.einsum("ki,kj->ij", pi[None, :] ** ks[:, None], pi[None, :] ** (q - 2 - ks)[:, None])
    Z = np.einsum("xi,xj->xij", Ua, Ua).reshape(len(w), -1)
    H = q * (2 * A * Pq1 + (Z * Gam.ravel()) @ Z.T)
    return f, -q * np.diag(Pq1), H


def _restricted(criterion, W, q, R, w0, tol=1e-13, max_iter=200):
    """The optimal measure on a few regressors (projected Newton on the simplex) from ``w0``.

    Active-set Newton: on the free weights the KKT system of the Newton step
    with ``sum(dw) = 0``; a step that would make a weight negative stops at
    zero and frees it; a zero weight whose gradient is below the multiplier
    is freed again.  Returns the weights, shape (S,).
    """
    S = len(w0)
    w = np.maximum(np.asarray(w0, float), 0)
    w /= w.sum()
    escale = None
    if criterion == "E":
        N = (R.T * w) @ R
        escale = float(np.linalg.eigvalsh(np.linalg.inv(N)[1:, 1:])[-1])
    free = w > 0
    f, g, H = _fgh(criterion, R, W, q, w, escale)
    if g is None:
        return w
    for _ in range(max_iter):
        F = np.flatnonzero(free)
        n = len(F)
        Hf = H[np.ix_(F, F)]
        reg = 1e-12 * max(float(np.trace(Hf)) / n, 1e-300)
        KKT = np.zeros((n + 1, n + 1))
        KKT[:n, :n] = Hf + reg * np.eye(n)
        KKT[:n, n] = KKT[n, :n] = 1.0
        sol = np.linalg.lstsq(KKT, np.concatenate([-g[F], [0.0]]), rcond=None)[0]
        dw, nu = sol[:n], sol[n]
        lam = -nu  # multiplier: g_i = lam on the support at the optimum
        # free a zero weight that wants to grow
        zero = np.flatnonzero(~free)
        if len(zero):
            viol = zero[g[zero] < lam - 1e-10 * abs(lam)]
            if len(viol) and np.max(np.abs(dw)) < 1e-9:
                free[viol[np.argmin(g[viol])]] = True
                continue
        slope = float(g[F] @ dw)
        if not slope < -tol * max(abs(f), 1e-300):
            if len(zero) and np.any(g[zero] < lam - 1e-10 * abs(lam)):
                free[zero[np.argmin(g[zero])]] = True
                continue
            break
        neg = dw < 0
        tmax = float(np.min(-w[F][neg] / dw[neg])) if np.any(neg) else math.inf
        t = min(1.0, tmax)
        while True:
            wn = w.copy()
            wn[F] = np.maximum(w[F] + t * dw, 0)
            if t == tmax:
                wn[F[neg][np.argmin(-w[F][neg] / dw[neg])]] = 0.0
            wn /= wn.sum()
            fn, gn, Hn = _fgh(criterion, R, W, q, wn, escale)
            if gn is not None and fn <= f + 1e-4 * t * slope:
                break
            t *= 0.5
            if t < 1e-14:
                return w
        w, f, g, H = wn, fn, gn, Hn
        free = w > 0
    return w


def solve_measure(model: PoseModel, criterion, w0=None, tol=TOL, max_rounds=60, q=E_Q, certify=True):
    """Optimal measure on the candidates of ``model`` for a concave criterion.

    A few multiplicative steps from ``w0`` find the rough support; then an
    active-set loop: the measure restricted to the support and the candidates
    with the largest ``d(x)`` is optimised (SLSQP on the simplex), and the
    worst violators of the equivalence theorem are added, until the
    efficiency bound is within ``tol`` of 1 over *all* candidates.

    Parameters
    ----------
    w0 : ndarray, shape (N,), optional
        Start (default uniform).
    tol : float
        Stop when the efficiency lower bound is at least ``1 - tol``.

    Returns
    -------
    dict
        ``w`` (N,), ``M`` (p, p), ``c`` (p,), ``d`` (N,), ``loss``,
        ``s`` (``sum w d``), ``eff_lb`` (lower bound on the efficiency:
        D ``p / max d``, linear criteria ``L / max d``, E from
        :func:`e_certificate`), ``iterations`` (restricted solves), ``q`` (E only).
    """
    N = len(model.vt)
    if N == 0:
        raise DesignError("no candidate poses")
    aq, vt, W = model.aq, model.vt, model.W
    w = np.full(N, 1.0 / N) if w0 is None else np.maximum(np.asarray(w0, float), 0)
    w = w / w.sum()
    qs = [q] if criterion != "E" else [qq for qq in (4, 16, 64) if qq < q] + [q]
    rounds = 0
    for qq in qs:
        lam = _exponent(criterion, qq)
        for _ in range(30):  # multiplicative steps: the rough support
            loss, grad, d, s, M, c = _evaluate(criterion, W, qq, w, aq, vt)
            if grad is None:
                raise DesignError("the candidate poses cannot identify the parameters (singular information)")
            w = w * np.maximum(d / s, 0) ** lam
            w /= w.sum()
        for _ in range(max_rounds):
            loss, grad, d, s, M, c = _evaluate(criterion, W, qq, w, aq, vt)
            eff = s / d.max()
            if eff >= 1 - tol:
                break
            rounds += 1
            sup = np.argsort(-w)[:MAX_ACTIVE]
            sup = sup[w[sup] > 1e-6 * w[sup[0]]]
            top = np.argsort(-d)[:MAX_ADD]
            act = np.union1d(sup, top[d[top] > s])
            wa = w[act] + 1e-3 / len(act)
            w = np.zeros(N)
            w[act] = _restricted(criterion, W, qq, _regressors(aq[act], vt[act]), wa / wa.sum())
    loss, grad, d, s, M, c = _evaluate(criterion, W, qs[-1], w, aq, vt)
    out = {"w": w, "M": M, "c": c, "d": d, "loss": loss, "s": s, "iterations": rounds, "q": qs[-1]}
    if criterion == "E":  # the E-certificate (a small optimisation) only when asked; else the smooth one's
        out["eff_lb"], out["E_bound"] = e_certificate(model, M, c) if certify else (float(s / d.max()), None)
    else:
        out["eff_lb"] = float(s / d.max())
    return out


def e_certificate(model: PoseModel, M, c):
    """Lower bound on the E-efficiency: ``lambda_min(M) / min_E max_x h_x^T E h_x`` over a few trace-one ``E``.

    Returns
    -------
    eff_lb : float
    bound : float
        Upper bound on ``lambda_min`` of any measure on the candidates.
    """
    ev, U = np.linalg.eigh(M)
    best = math.inf
    trials = [np.outer(U[:, 0], U[:, 0])]
    for s in (1, 2, 4, 8, 16, 33, 65, 129, 257):
        e = (ev / ev[0]) ** (-float(s))
        trials.append((U * (e / e.sum())) @ U.T)
    for E in trials:
        best = min(best, float(_sens(E, model.aq, c, model.vt).max()))
    # E = V Z V^T on the eigenvectors of the smallest eigenvalues, Z >= 0 with trace 1 chosen to
    # minimise max_x h_x^T E h_x (a small convex problem; any such E gives a valid bound)
    k = int(min(len(ev), max(2, np.sum(ev <= 1.5 * ev[0]))))
    if k > 1:
        from scipy.optimize import minimize

        Hs = ((model.aq - c) / np.sqrt(model.vt)[:, None]) @ U[:, :k]  # (N, k)
        top = np.argsort(-np.sum(Hs ** 2, axis=1))[:400]
        Hs = Hs[top]
        tri = np.tril_indices(k)

        def zmat(x):
            Lz = np.zeros((k, k))
            Lz[tri] = x
            Z = Lz @ Lz.T
            return Z / np.trace(Z)

        def fmax(x, beta):
            vals = np.einsum("xi,ij,xj->x", Hs, zmat(x), Hs)
            m = vals.max()
            return m + np.log(np.sum(np.exp(beta * (vals - m) / m))) * m / beta

        x = np.eye(k)[tri]
        for beta in (20.0, 200.0, 2000.0):
            x = minimize(fmax, x, args=(beta,), method="Nelder-Mead",
                         options={"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000}).x
        Ez = U[:, :k] @ zmat(x) @ U[:, :k].T
        best = min(best, float(_sens(Ez, model.aq, c, model.vt).max()))
    return float(ev[0] / best), best


# --------------------------------------------------------------------------- candidates
def candidate_poses(robot, cons: Constraints, n_target: int = N_CANDIDATES) -> tuple:
    """Feasible candidate poses over the region, about ``n_target`` of them.

    Returns
    -------
    X : ndarray, shape (N, n)
    h : float
        Grid spacing, mm (the refinement's starting scale).
    """
    reg = cons.region
    X, h = reg.design_grid(n_target) if hasattr(reg, "design_grid") else _box_grid(reg, n_target)
    ok = _pointwise_ok(robot, X, cons)
    X = X[ok]
    if len(X) == 0:
        raise DesignError("no feasible candidate pose in the region: relax the singularity margin or joint "
                          "limits, or enlarge the region")
    return X, h


def _box_grid(reg, n_target):
    """A grid of about ``n_target`` points over the region's bounding box, kept inside the region."""
    lo, hi = np.asarray(reg.lo, float), np.asarray(reg.hi, float)
    vol = float(np.prod(hi - lo))
    n = len(lo)
    h = (vol / n_target) ** (1.0 / n)
    axes = [np.linspace(lo[i], hi[i], max(2, int(round((hi[i] - lo[i]) / h)) + 1)) for i in range(n)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, n)
    X = X[reg.contains(X, 1e-9)]
    if getattr(reg, "kind", "") == "cylinder":  # the rims themselves
        k = max(8, int(round(2 * np.pi * reg.rw / h)))
        t = 2 * np.pi * np.arange(k) / k
        rims = [np.column_stack([reg.rw * np.cos(t), reg.rw * np.sin(t), np.full(k, z)]) for z in axes[2]]
        X = np.vstack([X] + rims)
    return X, h


def _local_grid(x, h, n, steps=3):
    """Points ``x + h * (i, j[, k])`` for integer offsets in ``[-steps, steps]``, shape (M, n)."""
    r = np.arange(-steps, steps + 1)
    off = np.stack(np.meshgrid(*([r] * n), indexing="ij"), axis=-1).reshape(-1, n) * h
    return x + off


# --------------------------------------------------------------------------- windows
def _windows(rho, cons: Constraints):
    """Travel windows: list of (lo, hi) ranges of rho the design may use, and the enlarged ones for the bound."""
    if cons.travel_mode != "range" or np.ptp(rho) <= cons.travel_mm:
        r = (float(rho.min()) - 1e-9, float(rho.max()) + 1e-9)
        return [r], [r]
    l0 = cons.travel_mm
    delta = l0 / WINDOW_STEPS
    starts = np.arange(rho.min(), rho.max() - l0 + delta, delta)
    exact = [(float(s), float(s + l0)) for s in starts]
    enlarged = [(float(s), float(s + l0 + delta)) for s in starts]
    return exact, enlarged


@dataclass
class ApproxDesign:
    """An optimal design measure and its certificate.

    Attributes
    ----------
    criterion : str
    X : ndarray, shape (N, n)
        The candidates of the chosen window (coarse grid and refinements).
    w : ndarray, shape (N,)
        The measure (sums to 1).
    support : ndarray, shape (s, n)
        Support points (clusters of the measure's weight).
    support_w : ndarray, shape (s,)
    eff_lb : float
        Efficiency lower bound of the measure against the best measure on the
        candidates of *every* window (the certificate).
    loss : float
        Criterion of the measure (internal, mass 1).
    bound_loss : float
        The certified bound on the best loss of any measure (mass 1): no
        ordered design of K poses on the candidates does better than this at
        mass K.
    window : tuple
        The rho range used.
    """

    criterion: str
    X: np.ndarray
    w: np.ndarray
    support: np.ndarray
    support_w: np.ndarray
    eff_lb: float
    loss: float
    bound_loss: float
    window: tuple
    n_candidates: int
    iterations: int
    windows: int
    p: int
    time_s: float
    info: dict = field(default_factory=dict)

    def sensitivity(self, robot, noise=None):
        """``d(x) / s`` of the measure at new poses: a function of ``X`` (M, n) -> (M,) (1 on the support)."""
        from zerocal_sym.model.noise import NoiseModel

        noise = noise or NoiseModel.paper()
        crit = "crlb" if self.criterion == "mse" else self.criterion  # mse: the variance part's sensitivity
        wts = Weights(robot)
        m0 = PoseModel(robot, self.X, noise, crit, wts)
        M, c = _schur(*_stats(self.w / m0.vt, m0.aq))
        _, G, s = _crit(crit, M, m0.W, self.info.get("q", E_Q))

        def score(Y):
            m = PoseModel(robot, Y, noise, crit, wts)
            return _sens(G, m.aq, c, m.vt) / s

        return score

    def value(self, K):
        """The measure's criterion for K poses in user units (the order-free pose model)."""
        return _mass_value(self.criterion, self.loss, K, self.p)

    def bound(self, K):
        """Best value any ordered K-pose design on the candidates can reach (user units)."""
        return _mass_value(self.criterion, self.bound_loss, K, self.p)

    def efficiency(self, value, K):
        """Lower bound on the efficiency of a design with user value ``value`` at K poses (1 = optimal)."""
        return _efficiency(self.criterion, value, self.bound(K), self.p)

    def to_dict(self, K=None):
        d = {"criterion": self.criterion, "efficiency_lower_bound": self.eff_lb,
             "support": self.support.tolist(), "support_weights": self.support_w.tolist(),
             "n_candidates": self.n_candidates, "iterations": self.iterations, "windows": self.windows,
             "rho_window_mm": list(self.window), "time_s": self.time_s,
             "model": "order-free pose model, servo variance + sigma_m^2/4 per pose: an upper bound on the "
                      "information of every ordered design"}
        if K is not None:
            d["K"] = K
            d["measure_value"] = self.value(K)
            d["bound"] = self.bound(K)
        d.update(self.info)
        return d


def _mass_value(criterion, loss, K, p):
    """User value at mass K from the internal loss at mass 1."""
    if not math.isfinite(loss):
        return _user_value(criterion, math.inf)
    if criterion == "D":
        return -loss + p * math.log(K)
    if criterion == "E":  # loss = -log lambda_min after e_certificate conversion
        return math.exp(-loss) * K
    return _user_value(criterion, loss - math.log(K))


def _efficiency(criterion, value, bound, p):
    """Efficiency lower bound of a user value against the bound (1 = as good as the bound)."""
    if value is None or bound is None or not math.isfinite(bound):
        return None
    if criterion == "D":
        return math.exp((value - bound) / p) if math.isfinite(value) else 0.0
    if criterion == "E":
        return value / bound
    if criterion in ("crlb", "position"):
        return (bound / value) ** 2 if value > 0 else None
    return bound / value if value > 0 else None


def _loss_bound(criterion, sol):
    """Certified bound on the best loss (mass 1) from a solved measure."""
    if criterion == "D":
        return sol["loss"] - model_p(sol) * math.log(1.0 / sol["eff_lb"])
    if criterion == "E":
        return -math.log(sol["E_bound"])
    return sol["loss"] + math.log(sol["eff_lb"])


def model_p(sol):
    return sol["M"].shape[0]


def _e_loss(sol):
    """E: the reported loss is -log lambda_min (the algorithm's is the smooth one)."""
    return -math.log(float(np.linalg.eigvalsh(sol["M"])[0]))


def _clusters(X, w, radius, min_frac=1e-4):
    """Support clusters: weights above ``min_frac`` of the largest, merged within ``radius`` into the heaviest."""
    order = np.argsort(-w)
    keep = order[w[order] >= min_frac * w[order[0]]]
    reps, ws = [], []
    for k in keep:
        if reps:
            dist = np.linalg.norm(np.array(reps) - X[k], axis=1)
            j = int(np.argmin(dist))
            if dist[j] <= radius:
                ws[j] += w[k]
                continue
        reps.append(X[k])
        ws.append(w[k])
    ws = np.array(ws)
    return np.array(reps), ws / ws.sum()


def approximate_design(robot, criterion="crlb", cons: Constraints | None = None, noise=None,
                       n_candidates: int = N_CANDIDATES, tol: float = TOL, refine: int = 2,
                       tolerances=None) -> ApproxDesign:
    """The optimal design measure over feasible candidate poses, with its certificate.

    Parameters
    ----------
    criterion : {"D", "A", "E", "crlb", "position"}
    cons : Constraints, optional
    noise : NoiseModel, optional
    n_candidates : int
        Size of the coarse candidate grid.
    tol : float
        Target efficiency gap of the measure.
    refine : int
        Rounds of local refinement of the support (grid spacing / 3 each).

    Returns
    -------
    ApproxDesign
    """
    from zerocal_sym.model.noise import NoiseModel

    t0 = time.perf_counter()
    _check_criterion(criterion)
    if criterion not in APPROX_CRITERIA:
        raise DesignError(f"criterion {criterion!r} has no approximate design (known: {', '.join(APPROX_CRITERIA)}; "
                          "cond is not concave, mse not convex)")
    noise = noise or NoiseModel.paper()
    cons = cons or make_constraints(robot)
    wts = _criterion_weights(robot, criterion, tolerances) if criterion == "position" else Weights(robot, tolerances)
    X, h = candidate_poses(robot, cons, n_candidates)
    model = PoseModel(robot, X, noise, criterion, wts)
    p = model.aq.shape[1]
    exact, enlarged = _windows(model.rho, cons)
    iters = 0

    def solve_in(mod, win, w0=None, tol_=tol, certify=True):
        idx = np.flatnonzero((mod.rho >= win[0]) & (mod.rho <= win[1]))
        if len(idx) < p + 1:
            return idx, None
        sub = mod.subset(idx)
        try:
            sol = solve_measure(sub, criterion, None if w0 is None else w0[idx], tol_, certify=certify)
        except DesignError:
            return idx, None
        return idx, sol

    def user_loss(sol):
        return _e_loss(sol) if criterion == "E" else sol["loss"]

    # the best exact window (coarse)
    best = None
    for win in exact:
        idx, sol = solve_in(model, win, tol_=max(tol, 1e-2) if len(exact) > 1 else tol, certify=False)
        if sol is None:
            continue
        iters += sol["iterations"]
        if best is None or user_loss(sol) < user_loss(best[2]):
            best = (win, idx, sol)
    if best is None:
        raise DesignError("no travel window of the candidate poses can identify the parameters")
    win, idx, sol = best
    # refine the support of the chosen window
    for r in range(refine):
        hr = h / 3 ** (r + 1)
        sub = model.subset(idx)
        reps, _ = _clusters(sub.X, sol["w"], 1.5 * h)
        new = np.vstack([_local_grid(x, hr, robot.n) for x in reps])
        new = new[_pointwise_ok(robot, new, cons)]
        if len(new):
            nm = PoseModel(robot, new, noise, criterion, wts)
            keep = (nm.rho >= win[0]) & (nm.rho <= win[1])
            nm = nm.subset(np.flatnonzero(keep))
            model = model.extend(nm)
        w0 = np.zeros(len(model.X))
        w0[idx] = sol["w"]
        idx = np.flatnonzero((model.rho >= win[0]) & (model.rho <= win[1]))
        w0 = w0[idx]
        w0 = 0.9 * w0 / w0.sum() + 0.1 / len(w0)
        sol = solve_measure(model.subset(idx), criterion, w0, tol, certify=r == refine - 1)
        iters += sol["iterations"]
    if criterion == "E" and sol.get("E_bound") is None:
        sol["eff_lb"], sol["E_bound"] = e_certificate(model.subset(idx), sol["M"], sol["c"])
    # the bound over every window (enlarged windows cover all l0-windows)
    if len(enlarged) == 1:
        bound_loss = _loss_bound(criterion, sol)
    else:
        bound_loss = math.inf
        for ew in enlarged:
            _, bsol = solve_in(model, ew)
            if bsol is None:
                continue
            iters += bsol["iterations"]
            bound_loss = min(bound_loss, _loss_bound(criterion, bsol))
        bound_loss = min(bound_loss, _loss_bound(criterion, sol))
    sub = model.subset(idx)
    reps, ws = _clusters(sub.X, sol["w"], 1.5 * h / 3 ** refine)
    loss = user_loss(sol)
    eff = _efficiency(criterion, _mass_value(criterion, loss, 1, p), _mass_value(criterion, bound_loss, 1, p), p)
    return ApproxDesign(criterion=criterion, X=sub.X, w=sol["w"], support=reps, support_w=ws, eff_lb=float(eff),
                        loss=loss, bound_loss=bound_loss, window=win, n_candidates=len(model.X), iterations=iters,
                        windows=len(exact), p=p, time_s=time.perf_counter() - t0,
                        info={"grid_mm": h, "refine_rounds": refine, "q": sol["q"]})


# --------------------------------------------------------------------------- K poses from a measure
def efficient_rounding(w, K):
    """Counts summing to K from weights (Pukelsheim & Rieder 1992), shape (s,).

    ``n_i = ceil((K - s/2) w_i)``, then the count with the smallest ``n_i / w_i``
    is raised (or the largest ``(n_i - 1) / w_i`` lowered) until the sum is K.
    """
    w = np.asarray(w, float)
    s = len(w)
    n = np.maximum(np.ceil((K - s / 2) * w), 0).astype(int)
    while n.sum() < K:
        n[int(np.argmin(n / w))] += 1
    while n.sum() > K:
        r = np.where(n > 0, (n - 1) / w, -np.inf)
        n[int(np.argmax(r))] -= 1
    return n


def _lattice(n, spacing, count):
    """Lattice offsets sorted by length, at least ``count`` of them, nearest neighbours ``spacing`` apart.

    Hexagonal in 2-D, face-centred cubic in 3-D, cubic otherwise.  Shape (M, n).
    """
    R = 2
    while (2 * R + 1) ** n < 3 * count + 10:
        R += 1
    r = np.arange(-R, R + 1)
    ijk = np.stack(np.meshgrid(*([r] * n), indexing="ij"), axis=-1).reshape(-1, n).astype(float)
    if n == 2:
        B = np.array([[1.0, 0.0], [0.5, math.sqrt(3) / 2]])
    elif n == 3:
        B = np.array([[0.0, 1.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 0.0]]) / math.sqrt(2)
    else:
        B = np.eye(n)
    off = ijk @ B * spacing
    order = np.argsort(np.linalg.norm(off, axis=1), kind="stable")
    return off[order]


def place_replicates(robot, cons: Constraints, reps, counts, window=None, score=None):
    """``counts[i]`` poses around each support point ``reps[i]``: the point itself and lattice neighbours.

    Lattice spacing: the minimum separation (at least 0.01 mm); each pose
    feasible (:func:`zerocal_sym.design.constraints._pointwise_ok`), with
    ``rho`` inside ``window`` and at least the spacing from every pose
    already placed.  Among the feasible lattice points near a support point
    those with the largest ``score`` are taken (``score(Y)`` -> shape (M,):
    the sensitivity ``d(x)`` of the optimal measure, i.e. the points that
    lose the least information); default the nearest.

    Returns
    -------
    P : ndarray, shape (K, n)
    label : ndarray of int, shape (K,)
        The support point of each pose.

    Raises
    ------
    DesignError
        If a support point has too few feasible neighbours.
    """
    n = robot.n
    sp = max(cons.min_separation_mm, 0.01) * (1 + 1e-6)
    P, lab = [np.empty((0, n))], [np.empty(0, int)]
    placed = np.empty((0, n))
    for i, (x, c) in enumerate(zip(np.atleast_2d(reps), counts)):
        if c <= 0:
            continue
        m = 3 * c + 10
        while True:
            Y = x + _lattice(n, sp, m)[:m]
            ok = _pointwise_ok(robot, Y, cons)
            if window is not None and np.any(ok):
                rho = pose_terms(robot, Y[ok])["rho"]
                okk = (rho >= window[0] - 1e-9) & (rho <= window[1] + 1e-9)
                ok[np.flatnonzero(ok)] = okk
            if len(placed) and np.any(ok):
                dist = np.min(np.linalg.norm(Y[ok][:, None, :] - placed[None], axis=2), axis=1)
                ok[np.flatnonzero(ok)] = dist >= sp * (1 - 1e-9)
            good = Y[ok]
            if len(good) >= c:
                if score is not None and len(good) > c:
                    pool = good[:max(3 * c, c + 6)]
                    sc = score(pool)
                    sc[0] = np.inf if np.allclose(pool[0], x) else sc[0]  # the support point itself first
                    good = pool[np.argsort(-sc, kind="stable")[:c]]
                else:
                    good = good[:c]
                break
            if m > 64 * c + 2000:
                raise DesignError(f"cannot place {c} poses {sp:g} mm apart around the support point "
                                  f"{np.round(x, 3).tolist()} mm within the constraints")
            m *= 4
        P.append(good)
        lab.append(np.full(c, i))
        placed = np.vstack([placed, good])
    return np.vstack(P), np.concatenate(lab)


def _interleave(counts, priority, rho=None, label_rho=None, l0=None):
    """Visiting sequence of support points: stride scheduling, never the same point twice in a row if avoidable.

    ``priority`` breaks ties (earlier first).  With ``l0`` (consecutive travel)
    a step is taken only to points whose ``rho`` is within ``l0`` of the
    previous one (``label_rho`` per support point).  Returns shape (K,) of
    support-point indices, or None if the travel rule blocks.
    """
    counts = np.asarray(counts, int)
    K = int(counts.sum())
    rank = np.empty(len(counts), int)
    rank[np.asarray(priority)] = np.arange(len(counts))
    cur = np.zeros(len(counts))
    left = counts.copy()
    seq = np.empty(K, int)
    prev = -1
    for k in range(K):
        cur[left > 0] += counts[left > 0]
        cand = np.flatnonzero(left > 0)
        if l0 is not None and prev >= 0:
            cand = cand[np.abs(label_rho[cand] - label_rho[prev]) <= l0]
            if len(cand) == 0:
                return None
        if len(cand) > 1 and prev in cand:
            cand = cand[cand != prev]
        score = cur[cand] - 1e-9 * rank[cand]
        j = int(cand[np.argmax(score)])
        cur[j] -= K
        left[j] -= 1
        seq[k] = j
        prev = j
    return seq


def realize(robot, ad: ApproxDesign, K: int, cons: Constraints | None = None, noise=None, tolerances=None,
            criterion=None, n_orders: int = 60, seed: int = 0):
    """K ordered poses from an approximate design: efficient rounding, replicates, visiting order.

    Parameters
    ----------
    ad : ApproxDesign
    K : int
    criterion : str, optional
        Criterion of the order search (default the measure's).
    n_orders : int
        Cycle orders of the support points tried (all of them for up to 5 points).

    Returns
    -------
    P : ndarray, shape (K, n)
        Poses in visiting order.
    info : dict
        ``counts`` per support point, ``objective`` (exact, internal),
        ``orders_tried``.
    """
    from zerocal_sym.model.noise import NoiseModel

    noise = noise or NoiseModel.paper()
    cons = cons or make_constraints(robot)
    criterion = criterion or ad.criterion
    reps, ws = ad.support, ad.support_w
    if len(reps) > K:  # every support point gets a pose (small weights can carry the identifiability)
        keep = np.argsort(-ws)[:K]
        reps, ws = reps[keep], ws[keep] / ws[keep].sum()
    counts = efficient_rounding(ws, K)
    window = ad.window if cons.travel_mode == "range" else None
    P, lab = place_replicates(robot, cons, reps, counts, window, ad.sensitivity(robot, noise))
    sm2, sx2 = _noise_terms(noise)
    wt = _criterion_weights(robot, criterion, tolerances)
    t = pose_terms(robot, P)
    aq, v = _criterion_terms(robot, criterion, t, _qscale(robot), sx2, wt)
    rho = t["rho"]
    s = len(counts)
    label_rho = np.array([rho[lab == i].mean() if np.any(lab == i) else 0.0 for i in range(s)])
    l0 = cons.travel_mm if cons.travel_mode == "consecutive" else None
    rng = np.random.default_rng(seed)
    if s <= 5:
        prios = [np.array(pr) for pr in itertools.permutations(range(s))]
    else:
        prios = [np.argsort(-ws), np.arange(s)] + [rng.permutation(s) for _ in range(n_orders)]
    best = None
    members = [list(np.flatnonzero(lab == i)) for i in range(s)]
    for pr in prios:
        seq = _interleave(counts, pr, rho, label_rho, l0)
        if seq is None:
            continue
        nxt = [0] * s
        idx = np.empty(K, int)
        for k, j in enumerate(seq):
            idx[k] = members[j][nxt[j]]
            nxt[j] += 1
        if l0 is not None and np.any(np.abs(np.diff(rho[idx])) > l0):
            continue
        o = float(_objective_batch(criterion, aq[idx][None], v[idx][None], sm2, wt)[0])
        if best is None or o < best[0]:
            best = (o, idx)
    if best is None:
        raise DesignError(f"no visiting order of the {K} poses keeps every change of rho within "
                          f"l0 = {cons.travel_mm:g} mm")
    o, idx = best
    return P[idx], {"counts": counts.tolist(), "support": reps.tolist(), "objective": o,
                    "orders_tried": len(prios)}


# --------------------------------------------------------------------------- bias-aware measure (no certificate)
def _mse_terms(robot, X, noise, tolerances):
    """Regressors of the pose model with the omitted errors: (G_theta (N, 1 + p), G_o (N, r), W~ (1 + p,))."""
    sm2, sx2 = _noise_terms(noise)
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

    noise = noise or NoiseModel.paper()
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
    h = ad.info.get("grid_mm", 1.0) / 3 ** ad.info.get("refine_rounds", 0)
    reps, ws = _clusters(X, w, 1.5 * h)
    out = ApproxDesign(criterion="mse", X=X, w=w, support=reps, support_w=ws, eff_lb=math.nan,
                       loss=math.log(f * K), bound_loss=math.nan, window=ad.window, n_candidates=ad.n_candidates,
                       iterations=ad.iterations, windows=ad.windows, p=ad.p, time_s=ad.time_s,
                       info=dict(ad.info, start="crlb measure", K=K))
    return out


# --------------------------------------------------------------------------- fewest poses for a target CRLB
def fewest_poses(robot, target_deg: float, cons: Constraints | None = None, noise=None, k_max: int | None = None,
                 ad: ApproxDesign | None = None):
    """The fewest poses K whose design reaches an RMS zero-offset CRLB of ``target_deg``, with the bound.

    The crlb measure (:func:`approximate_design`) gives a certified lower
    bound: no ordered design of fewer than ``K_lower_bound`` poses on the
    candidates can reach the target (its CRLB is at least
    ``sqrt(bound / K)``).  Designs realised from the measure
    (:func:`realize`) are evaluated exactly from there upwards (the CRLB
    falls as ``1/sqrt(K)``: a step to the predicted K, then bisection), and
    the smallest K whose design meets the target is returned with its poses.

    Returns
    -------
    dict
        ``K``, ``K_lower_bound``, ``target_crlb_deg``, ``crlb_rms_deg`` (of
        the returned design), ``poses`` (K, n), ``evaluated`` {K: crlb},
        ``approximate`` (the measure's summary), ``time_s``.

    Raises
    ------
    DesignError
        A target that needs more than ``k_max`` poses.
    """
    from zerocal_sym.design.constraints import MAX_K, min_k
    from zerocal_sym.design.criteria import criterion_values
    from zerocal_sym.model.noise import NoiseModel

    t0 = time.perf_counter()
    try:
        target = float(target_deg)
    except (TypeError, ValueError):
        raise DesignError(f"the target CRLB must be a number of degrees, got {target_deg!r}") from None
    if not (math.isfinite(target) and target > 0):
        raise DesignError(f"the target CRLB must be positive and finite, got {target_deg!r} deg")
    noise = noise or NoiseModel.paper()
    cons = cons or make_constraints(robot)
    k_max = MAX_K if k_max is None else int(k_max)
    ad = ad or approximate_design(robot, "crlb", cons, noise)
    tr = math.radians(target) ** 2
    k_lb = max(min_k(robot), int(math.ceil(math.exp(ad.bound_loss) / tr * (1 - 1e-12))))
    if k_lb > k_max:
        raise DesignError(f"a CRLB of {target:g} deg needs at least {k_lb} poses (certified), more than "
                          f"the {k_max} allowed")
    evaluated = {}
    designs = {}

    def crlb_at(K, n_orders=10):
        P, _ = realize(robot, ad, K, cons, noise, n_orders=n_orders)
        v = criterion_values(robot, P, noise)["crlb"]
        evaluated[K] = v
        designs[K] = P
        return v

    K = k_lb
    v = crlb_at(K)
    lo = None
    while v > target:
        lo = K
        K = min(k_max, max(K + 1, int(math.ceil(K * (v / target) ** 2))))
        if K == lo:
            raise DesignError(f"no design of up to {k_max} poses reaches a CRLB of {target:g} deg "
                              f"(at {k_max}: {v:.4g} deg)")
        v = crlb_at(K)
    hi = K
    lo = k_lb - 1 if lo is None else lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if crlb_at(mid) <= target:
            hi = mid
        else:
            lo = mid
    # the final design with the full order search
    v = crlb_at(hi, n_orders=60)
    if v > target:  # the fuller order search never makes it worse than the short one; keep the short one
        v = min(x for k, x in evaluated.items() if k == hi)
    return {"K": int(hi), "K_lower_bound": int(k_lb), "target_crlb_deg": target, "crlb_rms_deg": float(v),
            "poses": designs[hi], "evaluated": {int(k): float(x) for k, x in sorted(evaluated.items())},
            "approximate": ad.to_dict(hi), "time_s": time.perf_counter() - t0}
