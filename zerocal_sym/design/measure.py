"""The optimal design measure on a set of candidate poses, and its certificate.

The criteria, their directional derivatives ``d(x)`` and the efficiency
bounds are those of the order-free pose model
(:mod:`zerocal_sym.design.posemodel`).

Algorithm (:func:`solve_measure`): multiplicative updates
``w_x <- w_x (d(x) / sum w d)^lambda`` (``lambda`` = 1 for D, 1/2 for the
linear criteria, 1/(q+1) for E) find the rough support; then an active-set
loop optimises the measure restricted to the support and the worst
violators of the equivalence theorem (projected Newton on the simplex,
:func:`_restricted`, on the criterion's convex form :func:`_fgh`) until the
efficiency bound is within ``tol`` of 1 over all candidates.  E is reached
by continuation in q up to :data:`~zerocal_sym.design.posemodel.E_Q`, and its
certificate is :func:`e_certificate`.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.posemodel import E_Q, PoseModel, _evaluate, _exponent, _schur, _sens, _stats

#: default target efficiency gap of the measure (efficiency lower bound >= 1 - TOL)
TOL = 1e-4
#: active-set sizes of :func:`solve_measure`: support points kept, violators added per round
MAX_ACTIVE, MAX_ADD = 60, 20
#: log of the largest float: a value above it is +inf (:func:`_value`)
_LOG_MAX = math.log(np.finfo(float).max)


def _regressors(aq, vt):
    """``g_x = (1, aq_x) / sqrt(vt_x)``, shape (N, p + 1): the pose model with its free constant."""
    return np.column_stack([np.ones(len(vt)), aq]) / np.sqrt(vt)[:, None]


def _value(criterion, R, W, q, w, escale=None):
    """The convex form's value at ``w`` (:func:`_fgh`) and the factors its derivatives reuse.

    Returns ``(f, st)``, ``st`` None (and ``f`` inf) when ``N`` is not positive definite, or for E
    when the value overflows (``pi`` far above 1: a trial point far from the start, which the
    backtracking rejects; computed, ``pi ** q`` would overflow with a RuntimeWarning).  The
    backtracking of :func:`_restricted` needs the value alone.  Keep the arithmetic as it is,
    operation for operation (and that of :func:`_grad_hess`): near the optimum the solver's
    accept/reject decisions compare values that differ by round-off, so an equivalent but
    reordered formula changes the support and weights of the measures it returns.
    """
    N = (R.T * w) @ R
    try:
        L = np.linalg.cholesky(N)
    except np.linalg.LinAlgError:
        return math.inf, None
    if criterion == "D":
        return -2 * float(np.sum(np.log(np.diag(L)))) + math.log(N[0, 0]), (N, L, None, None)
    Li = np.linalg.inv(L)
    Ninv = Li.T @ Li
    if criterion != "E":
        return float(np.sum(W * Ninv[1:, 1:])), (N, L, Ninv, None)
    pi, V = np.linalg.eigh(Ninv[1:, 1:] / escale)
    pi = np.maximum(pi, 0)
    if pi[-1] > 1 and q * math.log(pi[-1]) > _LOG_MAX - math.log(len(pi)):  # sum(pi ** q) > the largest float
        return math.inf, None
    return float(np.sum(pi ** q)), (N, L, Ninv, (pi, V))


def _grad_hess(criterion, R, W, q, st, escale=None, G00=None):
    """Gradient and Hessian of the convex form (:func:`_fgh`) from the factors of :func:`_value`.

    ``G00``: ``outer(g0, g0)`` (D; computed if not given).
    """
    N, L, Ninv, eig = st
    if Ninv is None:
        Li = np.linalg.inv(L)
        Ninv = Li.T @ Li
    Y = R @ Ninv
    A = Y @ R.T
    if criterion == "D":
        g0 = R[:, 0] ** 2
        N00 = N[0, 0]
        H = A * A
        H -= (np.outer(g0, g0) if G00 is None else G00) / N00 ** 2
        return -np.diag(A) + g0 / N00, H
    if criterion != "E":
        Yp = Y[:, 1:]
        Bm = Yp @ W @ Yp.T
        H = 2 * A
        H *= Bm
        return -np.diag(Bm), H
    pi, V = eig
    Ua = (Y[:, 1:] / math.sqrt(escale)) @ V  # rows a_x = V^T u_x
    Pq1 = (Ua * pi ** (q - 1)) @ Ua.T
    ks = np.arange(q - 1)
    Gam = np.einsum("ki,kj->ij", pi[None, :] ** ks[:, None], pi[None, :] ** (q - 2 - ks)[:, None])
    Z = (Ua[:, :, None] * Ua[:, None, :]).reshape(len(Ua), -1)
    H = 2 * A
    H *= Pq1
    H += (Z * Gam.ravel()) @ Z.T
    H *= q
    return -q * np.diag(Pq1), H


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
    f, st = _value(criterion, R, W, q, w, escale)
    if st is None:
        return math.inf, None, None
    return (f, *_grad_hess(criterion, R, W, q, st, escale))


def _restricted(criterion, W, q, R, w0, tol=1e-13, max_iter=200):
    """The optimal measure on a few regressors (projected Newton on the simplex) from ``w0``.

    Active-set Newton: on the free weights the KKT system of the Newton step
    with ``sum(dw) = 0``; a step that would make a weight negative stops at
    zero and frees it; a zero weight whose gradient is below the multiplier
    is freed again.  Returns the weights, shape (S,).

    The backtracking evaluates the value alone (:func:`_value`); the gradient
    and Hessian are computed at the accepted point only, from its factors.  A
    step that leaves the weights unchanged (bit for bit) and the free set as
    it was would be repeated until ``max_iter``: it ends the loop.
    """
    w = np.maximum(np.asarray(w0, float), 0)
    w /= w.sum()
    escale = None
    if criterion == "E":
        N = (R.T * w) @ R
        escale = float(np.linalg.eigvalsh(np.linalg.inv(N)[1:, 1:])[-1])
    G00 = np.outer(R[:, 0] ** 2, R[:, 0] ** 2) if criterion == "D" else None
    free = w > 0
    f, st = _value(criterion, R, W, q, w, escale)
    if st is None:
        return w
    g, H = _grad_hess(criterion, R, W, q, st, escale, G00)
    for _ in range(max_iter):
        F = np.flatnonzero(free)
        n = len(F)
        Hf = H.take(F, 0).take(F, 1)
        reg = 1e-12 * max(float(np.trace(Hf)) / n, 1e-300)
        KKT = np.zeros((n + 1, n + 1))
        KKT[:n, :n] = Hf + reg * np.eye(n)
        KKT[:n, n] = KKT[n, :n] = 1.0
        rhs = np.zeros(n + 1)
        gF = g[F]
        rhs[:n] = -gF
        sol = np.linalg.lstsq(KKT, rhs, rcond=None)[0]
        dw, nu = sol[:n], sol[n]
        lam = -nu  # multiplier: g_i = lam on the support at the optimum
        # free a zero weight that wants to grow
        zero = np.flatnonzero(~free)
        if len(zero):
            viol = zero[g[zero] < lam - 1e-10 * abs(lam)]
            if len(viol) and np.max(np.abs(dw)) < 1e-9:
                free[viol[np.argmin(g[viol])]] = True
                continue
        slope = float(gF @ dw)
        if not slope < -tol * max(abs(f), 1e-300):
            if len(zero) and np.any(g[zero] < lam - 1e-10 * abs(lam)):
                free[zero[np.argmin(g[zero])]] = True
                continue
            break
        wF = w[F]
        neg = dw < 0
        if np.any(neg):
            ratio = -wF[neg] / dw[neg]
            k = int(np.argmin(ratio))
            tmax, hit = float(ratio[k]), F[neg][k]
        else:
            tmax = math.inf
        t = min(1.0, tmax)
        while True:
            wn = w.copy()
            wn[F] = np.maximum(wF + t * dw, 0)
            if t == tmax:
                wn[hit] = 0.0
            wn /= wn.sum()
            fn, st = _value(criterion, R, W, q, wn, escale)
            if st is not None and fn <= f + 1e-4 * t * slope:
                break
            t *= 0.5
            if t < 1e-14:
                return w
        if np.array_equal(wn, w):
            # a null step (the value's decrease is below round-off): w, f, g and H are what they were
            # (the same arithmetic on the same weights); with the same free set, every further pass
            # would repeat this one until max_iter, and the result is w
            if np.array_equal(w > 0, free):
                return w
        else:
            w, f = wn, fn
            g, H = _grad_hess(criterion, R, W, q, st, escale, G00)
        free = w > 0
    return w


def solve_measure(model: PoseModel, criterion, w0=None, tol=TOL, max_rounds=60, q=E_Q, certify=True):
    """Optimal measure on the candidates of ``model`` for a concave criterion.

    A few multiplicative steps from ``w0`` find the rough support; then an
    active-set loop: the measure restricted to the support and the candidates
    with the largest ``d(x)`` is optimised (projected Newton on the simplex,
    :func:`_restricted`), and the
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

    def evaluate(qq, first):
        out = _evaluate(criterion, W, qq, w, aq, vt)
        if out[1] is None:  # a singular information matrix: no criterion value, no derivative
            if first:
                raise DesignError("the candidate poses cannot identify the parameters (singular information)")
            raise DesignError(f"the {criterion} measure on these candidate poses became singular: they barely "
                              f"identify the parameters, condition {_condition(aq, vt):.2g} at equal weights; "
                              "widen the region")
        return out

    for qq in qs:
        lam = _exponent(criterion, qq)
        for it in range(30):  # multiplicative steps: the rough support
            loss, grad, d, s, M, c = evaluate(qq, first=it == 0 and qq == qs[0])
            w = w * np.maximum(d / s, 0) ** lam
            w /= w.sum()
        for _ in range(max_rounds):
            loss, grad, d, s, M, c = evaluate(qq, first=False)
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
    loss, grad, d, s, M, c = evaluate(qs[-1], first=False)
    out = {"w": w, "M": M, "c": c, "d": d, "loss": loss, "s": s, "iterations": rounds, "q": qs[-1]}
    if criterion == "E":  # the E-certificate (a small optimisation) only when asked; else the smooth one's
        out["eff_lb"], out["E_bound"] = e_certificate(model, M, c) if certify else (float(s / d.max()), None)
    else:
        out["eff_lb"] = float(s / d.max())
    return out


def _condition(aq, vt):
    """Condition number of the information of the equal-weight measure on the candidates ``aq`` (N, p)."""
    M, _ = _schur(*_stats(np.full(len(vt), 1.0 / len(vt)) / vt, aq))
    ev = np.linalg.eigvalsh(M)
    return float(ev[-1] / ev[0]) if ev[0] > 0 else math.inf


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
        Lz = np.zeros((k, k))  # its lower triangle rewritten by each zmat (the rest stays 0)

        def zmat(x):
            Lz[tri] = x
            Z = Lz @ Lz.T
            return Z / Z.trace()

        def fmax(x, beta):
            vals = np.einsum("xi,ij,xj->x", Hs, zmat(x), Hs)
            m = vals.max()
            return m + np.log(np.exp(beta * (vals - m) / m).sum()) * m / beta

        x = np.eye(k)[tri]
        for beta in (20.0, 200.0, 2000.0):
            x = minimize(fmax, x, args=(beta,), method="Nelder-Mead",
                         options={"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000}).x
        Ez = U[:, :k] @ zmat(x) @ U[:, :k].T
        best = min(best, float(_sens(Ez, model.aq, c, model.vt).max()))
    return float(ev[0] / best), best
