"""The CasADi functions of the nonlinear identification, built once per (mechanism, K, parameters).

One model Function (the exact distance and its joint derivative at one pose)
is vectorised over the K poses with ``map``; everything else is composed from
it symbolically:

``weights``
    the banded whitening of the change covariance
    ``C = sigma_m^2 I + D diag(v) D^T`` (``v_k = sigma_xi^2 |d rho_k / d theta|^2``):
    ``C`` is tridiagonal, its Cholesky factor lower bidiagonal with diagonal
    ``l`` (K-1) and sub-diagonal ``b`` (K-2); whitening is a forward
    substitution.  Memory and time are linear in K; no dense K x K matrix.
``residuals``
    the whitened residuals of the changes and of the Gaussian prior, and their
    Jacobian with respect to the scaled parameters, for given ``(l, b)``.
``gauss_newton``
    a block of ``N_GN`` damped Gauss-Newton iterations inside one Function
    (weights re-evaluated at each iterate, or held at the start), returning
    the iterate, its residuals and Jacobian and the size of the last step;
    :meth:`NllsProblem.run_gauss_newton` repeats blocks until the last step
    is below the tolerance (the planar robot: 2 blocks; the Delta: 3-4);
    :meth:`NllsProblem.batch` is the block mapped over data sets of one design.
``solver``
    Ipopt on ``0.5 c |r(z; l, b)|^2`` with the Gauss-Newton Hessian
    (``hess_lag``), the weights as NLP parameters: the judge of convergence,
    started at the Gauss-Newton point.

Compiled tier
    Every Function above (and Ipopt's objective, gradient and Hessian) has a
    compiled twin (:mod:`zerocal_sym.model.compiled`), used once the problem
    is *hot*: after :data:`~zerocal_sym.model.compiled.HOT_CALLS`
    identifications, or when a batch or a Monte Carlo says so
    (:meth:`NllsProblem.hot`).  Same numbers, 6-8x less time per evaluation.

Parameter vector (``pack``): ``theta (m x K), g, err_fixed, s (K-1), scale,
prior mean, prior whitener (p x p), sigma_m^2, sigma_xi^2``.
"""
from __future__ import annotations

import threading

import numpy as np

from zerocal_sym.identify.whitened import LEVERAGE_TOL
from zerocal_sym.model.compiled import Tier
from zerocal_sym.model.fastcall import FastCall

#: Gauss-Newton iterations inside one call (a block); callers repeat blocks until converged
N_GN = 3
#: at most this many blocks (N_GN * GN_BLOCKS iterations)
GN_BLOCKS = 6
#: Ipopt options (silenced)
IPOPT_OPTIONS = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-10,
    "ipopt.acceptable_tol": 1e-7,
    "ipopt.nlp_scaling_method": "none",
    "ipopt.max_iter": 200,
    "print_time": False,
    # a trial point where the model is undefined (NaN) is Ipopt's to step back from, not the user's to read
    "show_eval_warnings": False,
}


def ipopt_solver(p: int, npar: int, f, grad_f, hess_lag, max_iter=None) -> FastCall:
    """Ipopt (:data:`IPOPT_OPTIONS`; ``max_iter``: its iteration limit, None the default) on the unconstrained NLP
    ``min_x f(x, p)`` (``x`` of size p, parameters of size npar), its gradient ``grad_f`` and Lagrangian Hessian
    ``hess_lag`` given as Functions (or callbacks); as a :class:`FastCall`: ``solver(x0, p, lbx, ubx)``."""
    import casadi as ca

    x, pp = ca.MX.sym("x", p), ca.MX.sym("p", npar)
    oracle = ca.Function("nlls_nlp", [x, pp], [f(x, pp), ca.MX(0, 1)], ["x", "p"], ["f", "g"])
    opts = dict(IPOPT_OPTIONS, grad_f=grad_f, hess_lag=hess_lag, calc_lam_p=False, calc_lam_x=False,
                bound_consistency=False)
    if max_iter is not None:
        opts["ipopt.max_iter"] = int(max_iter)
    return FastCall(ca.nlpsol("nlls", "ipopt", oracle, opts))


#: up to this K the functions are SX, expanded (fastest to evaluate); above, MX graphs with the per-pose
#: model mapped over K (build time and memory linear in K, no K-fold inlining)
EXPAND_MAX_K = 120
#: a per-pose model larger than this (CasADi nodes of the distance and its joint derivative) is never
#: expanded: K inlined copies of a forward kinematics solved by Newton steps (the hexapod's, ~50 000 nodes)
#: and their symbolic Jacobian would take minutes and gigabytes to build
EXPAND_MAX_NODES = 20000

_CACHE: dict = {}
_LOCK = threading.Lock()


def _banded_whiten(r, l, b):
    """``L^-1 r`` for the lower-bidiagonal ``L`` (diagonal ``l``, sub-diagonal ``b``): forward substitution.

    SX: written out (inlined); MX: one ``mapaccum`` node over the K-1 changes.
    """
    import casadi as ca

    if isinstance(r, ca.SX):
        out = [r[0] / l[0]]
        for k in range(1, r.shape[0]):
            out.append((r[k] - b[k - 1] * out[-1]) / l[k])
        return ca.vertcat(*out)
    y, rk, bk, lk = (ca.SX.sym(n) for n in ("y", "r", "b", "l"))
    step = ca.Function("whiten_step", [y, rk, bk, lk], [(rk - bk * y) / lk])
    n = r.shape[0]
    acc = step.mapaccum("whiten", n)
    return acc(0, r.T, ca.horzcat(0, b.T), l.T).T


def _banded_cholesky(v, sm2):
    """Diagonal and sub-diagonal of chol(sm2 I + D diag(v) D^T), D the (K-1) x K first differences.

    SX: written out; MX: one ``mapaccum`` node for the recurrence
    ``b_k = -v_k / l_{k-1}``, ``l_k = sqrt(c_k - b_k^2)``.
    """
    import casadi as ca

    n = v.shape[0] - 1
    if isinstance(v, ca.SX):
        c = [sm2 + v[k] + v[k + 1] for k in range(n)]
        l, b = [ca.sqrt(c[0])], []
        for k in range(1, n):
            b.append(-v[k] / l[k - 1])
            l.append(ca.sqrt(c[k] - b[-1] ** 2))
        return ca.vertcat(*l), (ca.vertcat(*b) if b else ca.SX(0, 1))
    c = sm2 + v[:-1] + v[1:]
    l0 = ca.sqrt(c[0])
    if n == 1:
        return l0, ca.MX(0, 1)
    lp, ck, vk = (ca.SX.sym(s) for s in ("l", "c", "v"))
    bk = -vk / lp
    step = ca.Function("chol_step", [lp, ck, vk], [ca.sqrt(ck - bk**2), bk])
    lr, br = step.mapaccum("chol", n - 1)(l0, c[1:].T, v[1:-1].T)
    return ca.vertcat(l0, lr.T), br.T


def _fit_terms(n: int, p: int):
    """The fit check's per-reading terms without a dense whitener
    (:meth:`~zerocal_sym.identify.whitened._Linear.per_reading`).

    Inputs: whitened residuals ``r`` (n,), whitened data Jacobian ``J``
    (n, p) of full column rank, the banded Cholesky factor ``l`` (n,), ``b``
    (n-1,) of the change covariance.  With ``a_j = L^-1 e_j`` the whitened
    indicator of reading j, ``F = J^T J``, ``G = L^-T J`` (rows ``J^T a_j``):
    ``aa_j = |a_j|^2`` (the diagonal of ``C^-1``, a backward recurrence),
    ``num_j = a_j^T (r - J F^-1 J^T r)``, ``den_j = aa_j - G_j F^-1 G_j^T``,
    ``Q = F^-1 G^T`` (p, n).  Every operation is O(n p): no n x n matrix.

    Outputs (what the fit check reads): the mean-shift statistic
    ``t_j = num_j / sqrt(den_j)``, the leverage ``1 - den_j / aa_j``, the
    estimated error of the reading ``delta_j = num_j / den_j`` (mm) and the
    move of the fitted coordinates when it is removed, ``Q_j delta_j``
    (p, n); NaN (except the leverage) for a reading that cannot be tested
    (``den_j <= LEVERAGE_TOL aa_j``).
    """
    import casadi as ca

    r, J = ca.SX.sym("r", n), ca.SX.sym("J", n, p)
    l, b = ca.SX.sym("l", n), ca.SX.sym("b", max(n - 1, 0))
    F = ca.mtimes(J.T, J)
    e = r - ca.mtimes(J, ca.solve(F, ca.mtimes(J.T, r)))

    def back(v):  # L^-T v: back substitution with the upper-bidiagonal L^T, row by row from the last
        rows = [None] * n
        rows[n - 1] = v[n - 1, :] / l[n - 1]
        for i in range(n - 2, -1, -1):
            rows[i] = (v[i, :] - b[i] * rows[i + 1]) / l[i]
        return ca.vertcat(*rows)

    num = back(e)
    G = back(J)
    # |L^-1 e_j|^2 = (1 + c_{j+1}^2 S_{j+1}) / l_j^2 with c_k = -b_{k-1} / l_k, S_{n-1} = 1
    S = [None] * n
    S[n - 1] = ca.SX(1)
    for j in range(n - 2, -1, -1):
        S[j] = 1 + (b[j] / l[j + 1]) ** 2 * S[j + 1]
    aa = ca.vertcat(*[S[j] / l[j] ** 2 for j in range(n)])
    Q = ca.solve(F, G.T)
    den = aa - ca.sum1(G.T * Q).T
    # the statistics themselves (whitened._Linear.per_reading): a reading is testable when its mean-shift
    # information is not negligible against its own (leverage < 1); NaN where it is not
    ok = den > LEVERAGE_TOL * aa
    nan = ca.SX(np.nan)
    lev = ca.if_else(aa > 0, 1 - den / aa, 1)
    t = ca.if_else(ok, num / ca.sqrt(ca.if_else(ok, den, 1)), nan)
    delta = ca.if_else(ok, num / ca.if_else(ok, den, 1), nan)
    move = ca.if_else(ca.repmat(ok.T, p, 1), Q * ca.repmat(delta.T, p, 1), nan)
    return ca.Function("fit_terms", [r, J, l, b], [t, lev, delta, move], ["r", "J", "l", "b"],
                       ["t", "leverage", "delta", "move"])


class NllsProblem:
    """The cached functions for (mechanism, K, parameter indices)."""

    def __init__(self, mechanism, K: int, idx: tuple):
        import casadi as ca

        f = mechanism["distance"]
        m, G, q = f.size1_in(0), f.size1_in(1), f.size1_in(2)
        self.K, self.idx, self.p, self.m = K, idx, len(idx), m
        p = self.p
        th1, g1, e1 = ca.SX.sym("th", m), ca.SX.sym("g", G), ca.SX.sym("e", q)
        rho1 = f(th1, g1, e1)
        pose = ca.Function("pose", [th1, g1, e1], [rho1, ca.sumsqr(ca.jacobian(rho1, th1))])
        pose_k = pose.map(K)
        X = ca.SX if K <= EXPAND_MAX_K and pose.n_nodes() <= EXPAND_MAX_NODES else ca.MX
        self.expanded = X is ca.SX

        z = X.sym("z", p)
        th = X.sym("theta", m, K)
        g = X.sym("g", G)
        efix = X.sym("err_fixed", q)
        s = X.sym("s", K - 1)
        sc = X.sym("scale", p)          # p = z / sc
        mu = X.sym("prior_mean", p)
        w = X.sym("prior_W", p, p)      # prior whitener (physical units), 0 = no prior
        sm2 = X.sym("sigma_m2")
        sx2 = X.sym("sigma_xi2")
        par = ca.vertcat(ca.vec(th), g, efix, s, sc, mu, ca.vec(w), sm2, sx2)
        self.npar = par.numel()
        E = np.zeros((q, p))
        E[list(idx), range(p)] = 1.0
        keep = np.ones(q)
        keep[list(idx)] = 0.0
        pz = z / sc
        err = ca.DM(keep) * efix + ca.mtimes(ca.DM(E), pz)
        rho, dth2 = pose_k(th, g, err)
        pred = (rho[0, 1:] - rho[0, :-1]).T
        l, b = _banded_cholesky(sx2 * dth2.T, sm2)
        self.weights = ca.Function("weights", [z, par], [l, b], ["z", "p"], ["l", "b"])

        L = X.sym("l", K - 1)
        B = X.sym("b", max(K - 2, 0))
        r = _banded_whiten(s - pred, L, B)
        rp = ca.mtimes(w, pz - mu)
        res = ca.vertcat(r, rp)
        J = ca.jacobian(res, z)
        self.residuals = ca.Function("residuals", [z, par, L, B], [r, rp, J, pred],
                                     ["z", "p", "l", "b"], ["r", "r_prior", "J", "pred"])
        self.rfun = ca.Function("r", [z, par, L, B], [r])
        self.jfun = ca.Function("J", [z, par, L, B], [ca.jacobian(r, z)])

        # one damped Gauss-Newton step; weights at z (reweight) or given
        JtJ = ca.mtimes(J.T, J)
        ridge = 1e-12 * (ca.mmax(ca.diag(JtJ)) + 1e-300)
        A, rhs = JtJ + ridge * X.eye(p), ca.mtimes(J.T, res)
        dz = -(ca.solve(A, rhs) if self.expanded else ca.solve(A, rhs, "qr"))
        step_fixed = ca.Function("gn_step_fixed", [z, par, L, B], [z + dz, ca.norm_inf(dz)])
        lz, bz = self.weights(z, par)
        zn, dn = step_fixed(z, par, lz, bz)
        step_rew = ca.Function("gn_step", [z, par], [zn, dn])

        def unroll(reweight):
            # reweight: weights at every iterate; else held at the given (l, b) (the start's)
            z0, pp = ca.MX.sym("z0", p), ca.MX.sym("p", self.npar)
            lx, bx = ca.MX.sym("l", K - 1), ca.MX.sym("b", max(K - 2, 0))
            zk, dk = z0, ca.MX(np.inf)
            for _ in range(N_GN):
                zk, dk = step_rew(zk, pp) if reweight else step_fixed(zk, pp, lx, bx)
            lk, bk = self.weights(zk, pp) if reweight else (lx, bx)
            rk, rpk, Jk, predk = self.residuals(zk, pp, lk, bk)
            ins, names = ([z0, pp], ["z0", "p"]) if reweight else ([z0, pp, lx, bx], ["z0", "p", "l0", "b0"])
            fn = ca.Function("gauss_newton" if reweight else "gauss_newton_fixed", ins,
                             [zk, dk, rk, rpk, Jk, predk, lk, bk],
                             names, ["z", "last_step", "r", "r_prior", "J", "pred", "l", "b"])
            return fn.expand() if self.expanded else fn

        self.gauss_newton = unroll(True)
        self.gauss_newton_fixed = unroll(False)

        fit_terms = _fit_terms(K - 1, p) if self.expanded else None

        c = X.sym("obj_scale")
        pn = ca.vertcat(par, L, B, c)
        f_obj = 0.5 * c * ca.dot(res, res)
        sigma = X.sym("lam_f")
        H = ca.triu(sigma * c * JtJ)
        nlp_f = ca.Function("nlp_f", [z, pn], [f_obj], ["x", "p"], ["f"])
        nlp_grad_f = ca.Function("nlp_grad_f", [z, pn], [f_obj, ca.gradient(f_obj, z)], ["x", "p"], ["f", "grad"])
        nlp_hess_l = ca.Function("nlp_hess_l", [z, pn, sigma, X.sym("lam_g", 0)], [H],
                                 ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])
        self.npar_nlp = pn.numel()
        funcs = {"gauss_newton": self.gauss_newton, "gauss_newton_fixed": self.gauss_newton_fixed,
                 "weights": self.weights, "residuals": self.residuals, "rfun": self.rfun, "jfun": self.jfun,
                 "nlp_f": nlp_f, "nlp_grad_f": nlp_grad_f, "nlp_hess_l": nlp_hess_l}
        if fit_terms is not None:
            funcs["fit_terms"] = fit_terms
        if self.expanded:
            funcs = {k: (f.expand() if k.startswith("nlp") else f) for k, f in funcs.items()}
        # Ipopt's interface builds a gradient of the objective at init: the compiled objective carries its adjoint
        funcs["adj1_nlp_f"] = funcs["nlp_f"].reverse(1)
        self.tier = Tier(funcs, f"nlls-{mechanism.name}-K{K}-" + "_".join(map(str, idx)))
        self._version = None
        self._batch = {}

    # -- the current tier (interpreted, or compiled once hot) -------------------------------------------------
    def _sync(self):
        if self._version != self.tier.version:
            fs = self.tier.get()
            self._fast = {name: FastCall(fs[name])
                          for name in ("gauss_newton", "gauss_newton_fixed", "weights", "residuals", "jfun",
                                       "rfun", "fit_terms") if name in fs}
            self._solvers, self._batch = {}, {}
            self._version = self.tier.version
        return self.tier.get()

    @property
    def fast(self) -> dict:
        """Zero-copy callers (:class:`FastCall`) of the Functions identify_nlls calls every time."""
        self._sync()
        return self._fast

    @property
    def functions(self) -> dict:
        """The current Functions by name (interpreted, or their compiled twins)."""
        return self._sync()

    @property
    def compiled(self) -> bool:
        return self.tier.compiled

    def hot(self, wait: bool = False) -> None:
        """This problem will be solved many times: compile it (:meth:`zerocal_sym.model.compiled.Tier.hot`)."""
        self.tier.hot(wait)

    def touch(self) -> None:
        """One more identification (the tier turns hot after HOT_CALLS)."""
        self.tier.touch()

    def solver_for(self, max_iter):
        """The Ipopt solver with this iteration limit (None: the default), built once per tier.

        Returns a :class:`FastCall`: ``solver(x0, p, lbx, ubx)`` -> ``[x, f, ...]``;
        ``solver.stats()`` the Ipopt statistics of the last call.  The NLP is
        the objective Function wrapped (its gradient and Gauss-Newton Hessian
        given as ``grad_f`` and ``hess_lag``), so the compiled twins serve
        Ipopt too (:func:`ipopt_solver`).
        """
        fs = self._sync()
        if max_iter not in self._solvers:
            self._solvers[max_iter] = ipopt_solver(self.p, self.npar_nlp, fs["nlp_f"], fs["nlp_grad_f"],
                                                   fs["nlp_hess_l"], max_iter)
        return self._solvers[max_iter]

    @property
    def solver(self):
        return self.solver_for(None)

    def run_gauss_newton(self, z0, par, reweight: bool, tol: float):
        """Blocks of Gauss-Newton from ``z0`` until the last step is below ``tol`` (at most ``GN_BLOCKS``).

        Without ``reweight`` the weights stay those at ``z0`` through every block.

        Returns the outputs of the last block as arrays (copies):
        ``z, last_step, r, r_prior, J, pred, l, b``.
        """
        fast = self.fast["gauss_newton" if reweight else "gauss_newton_fixed"]
        z = np.asarray(z0, float)
        fixed = () if reweight else tuple(np.array(o) for o in self.fast["weights"](z, par))
        for _ in range(GN_BLOCKS):
            out = fast(z, par, *fixed)  # views of the call's buffers: z is copied in by the next call
            z = out[0]
            if not np.isfinite(z).all() or out[1][0] < tol:
                break
        return [np.array(o) for o in out]

    def batch(self, N: int) -> FastCall:
        """``gauss_newton`` mapped over ``batch_size(N)`` data sets (columns of z0 and of the parameter vector),
        zero-copy: one Function per power of two, not one per N (:meth:`run_batch` pads the columns)."""
        fs = self._sync()
        N = batch_size(N)
        if N not in self._batch:
            self._batch[N] = FastCall(fs["gauss_newton"].map(N))
        return self._batch[N]

    def run_batch(self, z0, P) -> list:
        """One block of Gauss-Newton over the n columns of ``z0`` (p, n) and ``P`` (npar, n), each column as
        ``gauss_newton`` alone (the mapped Function evaluates every column the same way, whatever their
        number); the columns are padded to :func:`batch_size` with copies of the first.

        Returns copies of the outputs for the n columns: ``z`` (p, n), ``last_step`` (1, n), ``r`` (K-1, n),
        ``r_prior`` (p, n), ``J`` (K-1 + p, p n: ``[J_1 | J_2 | ...]``), ``pred`` (K-1, n), ``l`` (K-1, n),
        ``b`` (K-2, n).
        """
        n = z0.shape[1]
        N = batch_size(n)
        if N > n:
            z0 = np.concatenate([z0, np.repeat(z0[:, :1], N - n, axis=1)], axis=1)
            P = np.concatenate([P, np.repeat(P[:, :1], N - n, axis=1)], axis=1)
        out = self.batch(N)(z0, P)
        width = [self.p if k == 4 else 1 for k in range(len(out))]
        return [np.array(np.reshape(o, (-1, N * w), order="F")[:, : n * w], order="F") for o, w in zip(out, width)]

    def pack(self, theta_cmd, geometry, err_fixed, s, scale, mu, w, sm2, sx2):
        """The parameter vector, shape (npar,).

        ``theta_cmd`` shape (K, m), ``s`` (K-1,), ``w`` (prior whitener) shape (p, p).
        """
        return np.concatenate([np.asarray(theta_cmd, float).ravel(), geometry, err_fixed, s, scale, mu,
                               np.asarray(w, float).ravel(order="F"), [sm2, sx2]])

    def s_slice(self, G: int, q: int) -> slice:
        """Where the K-1 changes sit in the parameter vector."""
        start = self.m * self.K + G + q
        return slice(start, start + self.K - 1)


def batch_size(n: int) -> int:
    """The size of the mapped Function that serves n data sets: the next power of two (1, 2, 4, ...)."""
    return 1 << max(0, int(n) - 1).bit_length()


def get_problem(robot, K: int, params="paper") -> NllsProblem:
    """The cached problem for ``K`` poses and the parameter set (built on first use)."""
    idx = tuple(robot.errors.indices(params))
    key = (robot.mechanism_name, K, idx)
    with _LOCK:
        prob = _CACHE.get(key)
        if prob is None:
            prob = _CACHE[key] = NllsProblem(robot.mechanism, K, idx)
    return prob
