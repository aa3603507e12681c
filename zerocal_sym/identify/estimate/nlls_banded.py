"""The nonlinear identification of one round with many poses: numpy and the banded whitening, no K-pose graph.

Up to :data:`~zerocal_sym.identify.estimate.nlls_problem.EXPAND_MAX_K` poses a round
is identified with the CasADi functions of
:mod:`~zerocal_sym.identify.estimate.nlls_problem` (expanded SX, compiled once hot).
Above, a CasADi graph over K poses costs time and memory in proportion to K
with a large factor (building its derivatives, the work vectors of the
unrolled Gauss-Newton block); :class:`BandedProblem`
computes the same quantities with the generated kinematics mapped over the
poses (:func:`zerocal_sym.model.kinematics.distance_jacobians`) and the
banded algebra of :mod:`~zerocal_sym.identify.banded`:

``weights``
    the bidiagonal Cholesky factor ``(l, b)`` of the change covariance at ``z``;
``residuals``
    the whitened residuals, prior residuals, Jacobian and predicted changes;
``run_gauss_newton``
    the same damped Gauss-Newton blocks (``N_GN`` iterations, at most
    ``GN_BLOCKS`` blocks, weights re-evaluated or held);
``solver_for``
    Ipopt on the same objective with the same options, its objective,
    gradient and Gauss-Newton Hessian evaluated in numpy (CasADi callbacks):
    Ipopt stays the judge of convergence.

Time and memory are linear in K.  :func:`round_problem` picks the one a
round of K poses is identified with (the Monte Carlo's batches keep
:func:`~zerocal_sym.identify.estimate.nlls_problem.get_problem`).
"""
from __future__ import annotations

import threading
from dataclasses import replace

import numpy as np

from zerocal_sym.identify import banded
from zerocal_sym.identify.estimate import nlls_problem
from zerocal_sym.identify.estimate.nlls_problem import GN_BLOCKS, N_GN, get_problem, ipopt_solver

_CACHE: dict = {}
_LOCK = threading.Lock()


def round_problem(robot, K: int, params="paper"):
    """The problem one round of K poses is identified with: the CasADi functions up to EXPAND_MAX_K poses
    (:func:`~zerocal_sym.identify.estimate.nlls_problem.get_problem`), the banded numpy ones above."""
    if K <= nlls_problem.EXPAND_MAX_K:
        return get_problem(robot, K, params)
    idx = tuple(robot.errors.indices(params))
    key = (robot.mechanism_name, K, idx)
    with _LOCK:
        prob = _CACHE.get(key)
        if prob is None:
            _CACHE.clear()  # one at a time: each holds K-sized arrays of its last evaluation
            prob = _CACHE[key] = BandedProblem(robot, K, idx)
    return prob


class BandedProblem:
    """The functions of :class:`~zerocal_sym.identify.estimate.nlls_problem.NllsProblem` that one round uses, in numpy.

    The same parameter vector (:meth:`pack`), the same outputs: ``fast``
    holds ``weights(z, par) -> [l, b]``, ``residuals(z, par, l, b) -> [r,
    r_prior, J, pred]`` and ``jfun(z, par, l, b) -> [J_data]``.  Shapes: K
    poses, p parameters, ``z`` (p,) scaled.
    """

    expanded = False
    compiled = False

    def __init__(self, robot, K: int, idx: tuple):
        self.robot = robot
        self.K, self.idx, self.p, self.m = K, tuple(idx), len(idx), robot.m
        self.G, self.q = len(robot.geometry), len(robot.errors)
        p = self.p
        self.npar = self.m * K + self.G + self.q + (K - 1) + 2 * p + p * p + 2
        self.npar_nlp = self.npar + (K - 1) + max(K - 2, 0) + 1
        self.fast = {"weights": self.weights, "residuals": self.residuals, "jfun": self.jfun}
        self._last = None
        self._solvers = {}

    # -- the interface identify_nlls and the fit check use ------------------------------------------------------
    def touch(self) -> None:
        """(The CasADi problems count identifications to turn hot; nothing to compile here.)"""

    def hot(self, wait: bool = False) -> None:
        """(Nothing to compile.)"""

    def pack(self, theta_cmd, geometry, err_fixed, s, scale, mu, w, sm2, sx2):
        """The parameter vector, as :meth:`NllsProblem.pack <zerocal_sym.identify.estimate.nlls_problem.NllsProblem.pack>`."""
        return np.concatenate([np.asarray(theta_cmd, float).ravel(), geometry, err_fixed, s, scale, mu,
                               np.asarray(w, float).ravel(order="F"), [sm2, sx2]])

    def s_slice(self, G: int, q: int) -> slice:
        """Where the K-1 changes sit in the parameter vector."""
        start = self.m * self.K + G + q
        return slice(start, start + self.K - 1)

    def _unpack(self, par):
        K, m, G, q, p = self.K, self.m, self.G, self.q, self.p
        par = np.asarray(par, float).ravel()
        cut = np.cumsum([m * K, G, q, K - 1, p, p, p * p, 1])
        th, g, efix, s, sc, mu, w, sm2, sx2 = np.split(par, cut)
        return (th.reshape(K, m), g, efix, s, sc, mu, w.reshape(p, p, order="F"), float(sm2[0]), float(sx2[0]))

    def _model(self, z, par):
        """``(pred, A, v, s, sc, mu, w, sm2)`` at ``z``: predicted changes (K-1,), ``d pred / d z`` (K-1, p), the
        servo variance of each pose's distance (K,); the last evaluation is kept (weights and residuals at
        one point evaluate the kinematics once)."""
        from zerocal_sym.model import kinematics as kin

        z = np.asarray(z, float).ravel()
        par = np.asarray(par, float).ravel()
        last = self._last
        if last is not None and np.array_equal(last[0], z) and np.array_equal(last[1], par):
            return last[2]
        th, g, efix, s, sc, mu, w, sm2, sx2 = self._unpack(par)
        robot = self.robot if np.array_equal(g, self.robot.geometry) else replace(self.robot, geometry=g)
        err = efix.copy()
        err[list(self.idx)] = z / sc
        with np.errstate(invalid="ignore", over="ignore"):
            rho, de, dt = kin.distance_jacobians(robot, th, err)
        out = (np.diff(rho), np.diff(de[:, list(self.idx)], axis=0) / sc, sx2 * np.sum(dt**2, axis=1),
               s, sc, mu, w, sm2)
        self._last = (z.copy(), par.copy(), out)
        return out

    def weights(self, z, par):
        """``[l, b]``: the bidiagonal Cholesky factor of the change covariance at ``z`` (NaN where it fails)."""
        _, _, v, _, _, _, _, sm2 = self._model(z, par)
        l, b, _ = banded.cholesky(sm2 + v[:-1] + v[1:], -v[1:-1])
        return [l, b]

    def residuals(self, z, par, l, b):
        """``[r, r_prior, J, pred]`` with the weights ``(l, b)``: whitened residuals (K-1,), prior residuals
        (p,), Jacobian (K-1 + p, p) w.r.t. ``z``, predicted changes (K-1,)."""
        pred, A, _, s, sc, mu, w, _ = self._model(z, par)
        l, b = np.ravel(l), np.ravel(b)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            r = banded.forward(l, b, s - pred)
            J = np.vstack([banded.forward(l, b, -A), w / sc])
        return [r, w @ (np.asarray(z, float).ravel() / sc - mu), J, pred]

    def jfun(self, z, par, l, b):
        """``[J_data]``: the whitened Jacobian of the changes (K-1, p)."""
        return [self.residuals(z, par, l, b)[2][: self.K - 1]]

    def run_gauss_newton(self, z0, par, reweight: bool, tol: float):
        """Damped Gauss-Newton from ``z0`` until the last step is below ``tol`` (at most ``GN_BLOCKS`` x
        ``N_GN`` iterations), as :meth:`NllsProblem.run_gauss_newton
        <zerocal_sym.identify.estimate.nlls_problem.NllsProblem.run_gauss_newton>` (which checks after blocks of
        ``N_GN``; here every iteration is checked: one evaluation of the kinematics each): ``z, last_step, r,
        r_prior, J, pred, l, b``."""
        z = np.asarray(z0, float).ravel().copy()
        fixed = None if reweight else self.weights(z, par)
        last = np.inf
        for _ in range(GN_BLOCKS * N_GN):
            l, b = self.weights(z, par) if reweight else fixed
            r, rp, J, _ = self.residuals(z, par, l, b)
            res = np.concatenate([r, rp])
            with np.errstate(invalid="ignore", over="ignore"):
                JtJ = J.T @ J
                ridge = 1e-12 * (np.max(np.diag(JtJ)) + 1e-300)
                try:
                    dz = -np.linalg.solve(JtJ + ridge * np.eye(self.p), J.T @ res)
                except np.linalg.LinAlgError:
                    dz = np.full(self.p, np.nan)
            z = z + dz
            last = float(np.max(np.abs(dz))) if np.all(np.isfinite(dz)) else np.nan
            if not np.all(np.isfinite(z)) or not last >= tol:
                break
        l, b = self.weights(z, par) if reweight else fixed
        r, rp, J, pred = self.residuals(z, par, l, b)
        return [z, np.array([last]), r, rp, J, pred, np.asarray(l), np.asarray(b)]

    def solver_for(self, max_iter):
        """Ipopt on ``0.5 c |r(z; l, b)|^2`` (the NLP parameters ``[par, l, b, c]``) with the Gauss-Newton
        Hessian (:func:`~zerocal_sym.identify.estimate.nlls_problem.ipopt_solver`), its functions numpy callbacks.
        Returns a :class:`~zerocal_sym.model.fastcall.FastCall`: ``solver(x0, p, lbx, ubx)``, ``.stats()``."""
        if max_iter not in self._solvers:
            cbs = _callbacks(self)
            solver = ipopt_solver(self.p, self.npar_nlp, cbs["f"], cbs["grad_f"], cbs["hess"], max_iter)
            solver._callbacks = cbs  # alive as long as the solver
            self._solvers[max_iter] = solver
        return self._solvers[max_iter]

    @property
    def solver(self):
        return self.solver_for(None)

    def objective(self, z, pn, grad: bool = False, hess: float | None = None):
        """``f``, ``(f, grad)`` or the upper triangle of ``hess * c J^T J`` at ``z`` for the NLP parameters ``pn``."""
        K = self.K
        pn = np.asarray(pn, float).ravel()
        par, l, b = pn[: self.npar], pn[self.npar: self.npar + K - 1], pn[self.npar + K - 1: -1]
        c = float(pn[-1])
        r, rp, J, _ = self.residuals(z, par, l, b)
        if hess is not None:
            return np.triu(hess * c * (J.T @ J))
        res = np.concatenate([r, rp])
        f = 0.5 * c * float(res @ res)
        return (f, c * (J.T @ res)) if grad else f


def _callbacks(prob: BandedProblem) -> dict:
    """The CasADi callbacks of :meth:`BandedProblem.solver_for`: ``f``, ``grad_f``, ``hess`` (and ``f``'s adjoint,
    which Ipopt's interface builds at initialisation)."""
    import casadi as ca

    p, npn = prob.p, prob.npar_nlp
    dense = ca.Sparsity.dense

    class _Fn(ca.Callback):
        def __init__(self, name, ins, outs, fn, reverse=None):
            ca.Callback.__init__(self)
            self._ins, self._outs, self._fn, self._rev = ins, outs, fn, reverse
            self.construct(name, {})

        def get_n_in(self):
            return len(self._ins)

        def get_n_out(self):
            return len(self._outs)

        def get_sparsity_in(self, i):
            return self._ins[i]

        def get_sparsity_out(self, i):
            return self._outs[i]

        def has_reverse(self, nadj):
            return self._rev is not None and nadj == 1

        def get_reverse(self, nadj, name, inames, onames, opts):
            return self._rev

        def eval(self, arg):
            return self._fn([np.array(a, float) for a in arg])

    def f(a):
        return [prob.objective(a[0], a[1])]

    def grad_f(a):
        f_, g = prob.objective(a[0], a[1], grad=True)
        return [f_, g]

    def adj(a):  # (x, p, f, adj_f) -> (adj_x, adj_p)
        _, g = prob.objective(a[0], a[1], grad=True)
        return [float(a[3].ravel()[0]) * g, np.zeros(npn)]

    def hess(a):  # (x, p, lam_f, lam_g) -> triu(lam_f c J^T J)
        H = prob.objective(a[0], a[1], hess=float(a[2].ravel()[0]))
        return [ca.DM(ca.Sparsity.upper(p), _triu_values(H))]

    x, pn, one = dense(p, 1), dense(npn, 1), dense(1, 1)
    rev = _Fn("nlls_f_adj", [x, pn, one, one], [x, pn], adj)
    return {"f": _Fn("nlls_f", [x, pn], [one], f, rev), "grad_f": _Fn("nlls_grad_f", [x, pn], [one, x], grad_f),
            "hess": _Fn("nlls_hess", [x, pn, one, ca.Sparsity(0, 1)], [ca.Sparsity.upper(p)], hess), "_rev": rev}


def _triu_values(H) -> np.ndarray:
    """The upper triangle of ``H`` in CasADi's column-major order of ``Sparsity.upper``."""
    p = H.shape[0]
    return np.array([H[i, j] for j in range(p) for i in range(j + 1)])
