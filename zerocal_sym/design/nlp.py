"""Continuous design: the Ipopt NLP over the K poses (:func:`continuous_design`).

The K poses (scaled to ``[-1, 1]^n`` over the design region's bounding box)
are the decision variables of a CasADi/Ipopt NLP built symbolically from the
generated mechanism functions; multi-start from seeded random feasible
designs and from given starts (the boundary scheme).  The region is a box
(variable bounds) or a cylinder (``x^2 + y^2 <= rw^2`` as a nonlinear
constraint, ``z`` by bounds).

Smooth reformulations (NLP): ``D``, ``A`` and ``crlb`` are smooth as they
stand (log det, log trace of the symbolic p x p inverse, p = m + n).  ``E`` and ``cond``
are non-smooth where eigenvalues coalesce, so they use auxiliary variables
and LMI-free eigenvalue constraints: ``max log t`` s.t. ``F_n - t I >= 0``,
and ``min log(t_hi / t_lo) / 2`` s.t. ``M - t_lo I >= 0``, ``t_hi I - M >= 0``
(``F_n``, ``M = G^T G`` normalised by their mean eigenvalue at a reference
design; ``kappa = sqrt(t_hi / t_lo)`` at the optimum).  A matrix
inequality ``X >= 0`` (p x p) is written in one of two exact forms (``psd_form``):

* ``"minors"``: all ``2^p - 1`` principal minors >= 0 (used for ``E`` when
  p <= 4: the planar robot's 15);
* ``"chol"``: ``X = L L^T`` with an auxiliary lower-triangular ``L``
  (``p (p + 1) / 2`` variables, ``diag(L) >= 0``, as many polynomial
  equalities, linear in ``X``; used for ``cond``, where the minors of
  ``M - t_lo I``, with ``kappa^2 ~ 1e4``, are badly scaled and most starts hit
  the iteration limit, and for ``E`` when p > 4: the Delta's 63 minors of
  6 x 6 matrices are slow to build and to solve, see :func:`_psd_form`).

(Only the p *leading* minors would not do: they admit spurious points
where two minors vanish -- Ipopt stopped at ``t = lambda_2 > lambda_min``.)
For these two criteria Ipopt starts with a small barrier parameter
(``mu_init = 1e-6``) so that the auxiliary variables are not pushed away
from a good start.  See docs/design.md for the measurements.
"""
from __future__ import annotations

import itertools
import time

import numpy as np

from zerocal_sym.design.limits import DesignError, _check_k
from zerocal_sym.design.constraints import (Constraints, _feasible_random_subset, _pointwise_ok, check_design,
                                            make_constraints)
from zerocal_sym.design.criteria import (EXTENDED, _check_criterion, _criterion_weights, _fisher_batch,
                                         _noise_terms, _objective, _objective_batch, _terms_batch, _user_value)
from zerocal_sym.design.terms import (Weights, _crlb_weights, _qscale, pose_terms_fn, _user_scale, pose_distances,
                                      pose_terms)

#: formulation of the matrix inequalities per criterion for p <= 4 (measured best, see module docstring)
PSD_FORM = {"E": "minors", "cond": "chol"}


def _psd_form(criterion, p):
    """:data:`PSD_FORM` for p <= 4; ``chol`` beyond (the Delta, p = 6: the 63 minors of ``E`` took 2-3 times
    the build time and 5-10 times the solve time of ``chol``, one of 4 starts hit the iteration limit)."""
    return PSD_FORM.get(criterion, "chol") if p <= 4 else "chol"


# --------------------------------------------------------------------------- continuous (Ipopt)
def _minors(M):
    """All principal minors of a symbolic p x p matrix (2^p - 1): all >= 0 <=> PSD."""
    import casadi as ca

    p = M.shape[0]
    out = []
    for r in range(1, p + 1):
        for idx in itertools.combinations(range(p), r):
            idx = list(idx)
            out.append(ca.det(M[idx, idx]))
    return out


#: a mechanism whose per-pose terms have more expression nodes than this (the hexapod's, its forward kinematics
#: by Newton steps inside the distance model: 58588; the planar robot's 294, the Deltas' 829 and 1600) gets the
#: large form of the NLP (:func:`nlp_form`)
LARGE_TERMS_NODES = 20000


def nlp_form(robot) -> str:
    """``"exact"`` (exact Hessian of the Lagrangian) or ``"large"`` for a mechanism whose per-pose terms exceed
    :data:`LARGE_TERMS_NODES` nodes: a limited-memory (L-BFGS) Hessian.  For the hexapod at K = 16, from the
    16-corner fraction, the exact Hessian took 229 s to build and 62 s to solve, L-BFGS 58 s and 10 s, and
    reached a lower CRLB (0.03693 against 0.03756 mm): ``python benchmarks/bench_design_hexapod.py --parts
    form`` (docs/design.md)."""
    return "large" if pose_terms_fn(robot).n_nodes() > LARGE_TERMS_NODES else "exact"


class _NLP:
    """The symbolic design NLP for one (robot, K, criterion, constraints, noise)."""

    def __init__(self, robot, K, criterion, cons: Constraints, noise, fscale, mscale, max_iter=500,
                 psd_form=None, ipopt_options=None, tolerances=None, form=None):
        import casadi as ca

        form = form or nlp_form(robot)
        self.form = form
        X = ca.SX
        self.robot, self.K, self.criterion, self.cons = robot, K, criterion, cons
        self._need_B, self.wts = False, None
        sm2, sx2 = _noise_terms(noise, robot)
        qs = _qscale(robot)
        wc = _crlb_weights(robot)
        wts = Weights(robot, tolerances) if criterion in ("position",) + EXTENDED else None
        self.wts = wts
        dim, p = robot.n, len(qs)  # pose coordinates, parameters
        psd_form = psd_form or _psd_form(criterion, p)
        self.n = dim
        region = cons.region
        c, h = region.center, region.half
        z = X.sym("z", dim, K)
        P = ca.repmat(ca.DM(c), 1, K) + ca.repmat(ca.DM(h), 1, K) * z
        f = pose_terms_fn(robot).map(K)
        theta, ratio, s, rho, a, dth, ao = f(P, robot.geometry)
        aq = ca.repmat(ca.DM(qs), 1, K) * a
        v = sx2 * ca.sum1(dth ** 2)
        g, lbg, ubg = [], [], []

        def add(expr, lo, hi):
            expr = ca.vec(expr)
            g.append(expr)
            lbg.append(np.broadcast_to(lo, expr.shape[0]).astype(float))
            ubg.append(np.broadcast_to(hi, expr.shape[0]).astype(float))

        add(ratio, -1 + 1e-9, 1 - 1e-9)
        clip = getattr(region, "clip", None)
        cyl = region if region.kind == "cylinder" else (clip if getattr(clip, "kind", "") == "cylinder" else None)
        if cyl is not None:  # x^2 + y^2 <= rw^2 (the box bounds give z and the bounding square)
            add((P[0, :] ** 2 + P[1, :] ** 2) / cyl.rw ** 2, -np.inf, 1.0)
        cells = region.nlp_cells() if hasattr(region, "nlp_cells") else None
        self.cells, self.p_sym = cells, None
        if cells:  # a polygon: each pose in a convex cell (its start's), half-planes a x + b y <= c as parameters
            hmax = max(len(c_) for c_ in cells)
            par = X.sym("cells", 3 * hmax, K)
            for j in range(hmax):
                add(par[3 * j, :] * P[0, :] + par[3 * j + 1, :] * P[1, :] - par[3 * j + 2, :], -np.inf, 0.0)
            self.p_sym, self.hmax = ca.vec(par), hmax
        if cons.mode_signs is not None:  # the reachable set: signed margin (the home pose's modes)
            add(s * ca.repmat(ca.DM(np.asarray(cons.mode_signs)), 1, K), cons.singularity_margin + 1e-7, np.inf)
        elif cons.singularity_margin > 0:
            add(s ** 2, (cons.singularity_margin + 1e-7) ** 2, np.inf)
        if cons.joint_limits is not None:
            jl = cons.joint_limits_internal()
            for i in range(robot.m):
                add(theta[i, :], jl[i, 0] + 1e-9, jl[i, 1] - 1e-9)
        aux = []  # (name, symbol column, lb, ub, init(nums) -> values)
        l0 = cons.travel_mm
        if cons.travel_mode == "range":
            r = X.sym("r", 2)  # rho window, scaled by 1/l0
            aux.append(("rho window", r, -np.inf, np.inf,
                        lambda n: np.array([n["rho"].min(), n["rho"].max()]) / l0))
            add(rho / l0 - r[0], 0, np.inf)
            add(r[1] - rho / l0, 0, np.inf)
            add(r[1] - r[0], -np.inf, 1 - 1e-9)
        else:
            add((rho[1:] - rho[:-1]) / l0, -1 + 1e-9, 1 - 1e-9)
        if cons.min_separation_mm > 0:  # in file units (a degree of an orientation counts as a mm)
            us = ca.DM(_user_scale(robot))
            Pu = P * ca.repmat(us, 1, K)
            d2 = ca.vertcat(*[ca.sumsqr(Pu[:, i] - Pu[:, j]) / 1e4 for i in range(K) for j in range(i + 1, K)])
            add(d2, (cons.min_separation_mm + 1e-6) ** 2 / 1e4, np.inf)

        def psd(name, X, X0):
            """X (symbolic p x p) >= 0: principal minors, or X = L L^T with L lower-triangular (auxiliary)."""
            if psd_form == "minors":
                add(ca.vertcat(*_minors(X)), 0, np.inf)
                return
            tri = [(i, j) for i in range(p) for j in range(i + 1)]
            lv = X.sym(name, len(tri))
            Lm = X.zeros(p, p)
            for k, (i, j) in enumerate(tri):
                Lm[i, j] = lv[k]
            R = X - Lm @ Lm.T
            add(ca.vertcat(*[R[i, j] for i, j in tri]), 0, 0)
            lb = np.array([0.0 if i == j else -np.inf for i, j in tri])

            def init(n):
                Xn = X0(n)
                Lc = np.linalg.cholesky(Xn + 1e-12 * max(np.trace(Xn), 1e-12) * np.eye(p))
                return np.array([Lc[i, j] for i, j in tri])

            aux.append((name, lv, lb, np.inf, init))

        # differences and Fisher information (LDL^T of the tridiagonal covariance)
        b = [aq[:, i + 1] - aq[:, i] for i in range(K - 1)]
        if criterion == "cond":
            M = sum((bi @ bi.T for bi in b), X.zeros(p, p)) / mscale
            tl = X.sym("tlo")
            th_ = X.sym("thi")
            aux.append(("tlo", tl, 1e-12, np.inf, lambda n: max(0.5 * n["wM"][0], 1e-12)))
            aux.append(("thi", th_, 1e-12, np.inf, lambda n: 1.5 * n["wM"][-1]))
            psd("Llo", M - tl * X.eye(p), lambda n: n["M"] - 0.5 * n["wM"][0] * np.eye(p))
            psd("Lhi", th_ * X.eye(p) - M, lambda n: 1.5 * n["wM"][-1] * np.eye(p) - n["M"])
            obj = 0.5 * (ca.log(th_) - ca.log(tl))
        else:
            d = [sm2 + v[i] + v[i + 1] for i in range(K - 1)]
            e = [-v[i + 1] for i in range(K - 2)]
            Dp, w = d[0], b[0]
            F = w @ w.T / Dp
            if criterion in EXTENDED:  # cross information with the omitted errors (scaled by t / sqrt(3))
                aoq = ca.repmat(ca.DM(wts.tol), 1, K) * ao
                bo = [aoq[:, i + 1] - aoq[:, i] for i in range(K - 1)]
                wo = bo[0]
                Hx = w @ wo.T / Dp
            for i in range(1, K - 1):
                m = e[i - 1] / Dp
                Dp = d[i] - m * e[i - 1]
                w = b[i] - m * w
                F = F + w @ w.T / Dp
                if criterion in EXTENDED:
                    wo = bo[i] - m * wo
                    Hx = Hx + w @ wo.T / Dp
            Fn = F / fscale
            if criterion == "D":
                obj = -ca.log(ca.det(Fn))
            elif criterion == "E":
                tt = X.sym("t")
                aux.append(("t", tt, 1e-12, np.inf, lambda n: max(0.5 * n["wF"][0], 1e-12)))
                psd("L", Fn - tt * X.eye(p), lambda n: n["Fn"] - 0.5 * n["wF"][0] * np.eye(p))
                obj = -ca.log(tt)
            else:
                Finv = ca.inv(Fn)
                if criterion == "A":
                    obj = ca.log(ca.trace(Finv))
                elif criterion == "position":
                    Wp = wts.position
                    obj = ca.log(sum(float(Wp[i, j]) * Finv[j, i] for i in range(p) for j in range(p)
                                     if Wp[i, j] != 0))
                elif criterion in EXTENDED:  # variance + squared bias; Finv = fscale F^-1, bias = F^-1 H
                    Bm = Finv @ (Hx / fscale)
                    if wts.bias_model == "worst":  # (sum_k |B_jk|)^2 by an epigraph: -u <= B <= u, smooth
                        rows = [j for j in range(p) if wc[j] != 0]
                        r_ = Bm.shape[1]
                        ub = X.sym("ub", len(rows), r_)
                        Bsel = ca.vertcat(*[Bm[j, :] for j in rows])
                        add(ca.vec(ub - Bsel), 0, np.inf)
                        add(ca.vec(ub + Bsel), 0, np.inf)
                        aux.append(("bias bound", ca.vec(ub), 0.0, np.inf,
                                    lambda n, rows=rows: (np.abs(n["B"][rows]) * (1 + 1e-6)
                                                          + 1e-12).ravel(order="F")))
                        self._need_B = True
                        b2 = [0] * p
                        for i_, j in enumerate(rows):
                            b2[j] = ca.sum2(ub[i_, :]) ** 2
                    else:
                        b2 = [ca.sumsqr(Bm[j, :]) for j in range(p)]
                    obj = ca.log(sum(float(wc[j]) * (Finv[j, j] + fscale * b2[j])
                                     for j in range(p) if wc[j] != 0))
                else:
                    obj = ca.log(sum(float(wc[j]) * Finv[j, j] for j in range(p) if wc[j] != 0))
        self.aux = aux
        x = ca.vertcat(ca.vec(z), *[a_[1] for a_ in aux])
        self.lbx = np.concatenate([-np.ones(dim * K)] + [np.broadcast_to(a_[2], a_[1].shape[0]) for a_ in aux])
        self.ubx = np.concatenate([np.ones(dim * K)] + [np.broadcast_to(a_[3], a_[1].shape[0]) for a_ in aux])
        self.lbg = np.concatenate(lbg)
        self.ubg = np.concatenate(ubg)
        self.fscale, self.mscale = fscale, mscale
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": max_iter,
                "ipopt.tol": 1e-10, "ipopt.acceptable_tol": 1e-7, "ipopt.constr_viol_tol": 1e-9,
                "ipopt.bound_relax_factor": 0.0, "error_on_fail": False, "show_eval_warnings": False}
        if criterion in ("cond", "E"):
            opts["ipopt.mu_init"] = 1e-6
        if form == "large":
            opts["ipopt.hessian_approximation"] = "limited-memory"
        opts.update(ipopt_options or {})
        prob = {"x": x, "f": obj, "g": ca.vertcat(*g)}
        if self.p_sym is not None:
            prob["p"] = self.p_sym
        self.solver = ca.nlpsol("design", "ipopt", prob, opts)
        #: objective and constraints as a Function of x (for checks)
        self.fg = ca.Function("design_fg", [x] + ([self.p_sym] if self.p_sym is not None else []),
                              [obj, ca.vertcat(*g)])
        self.sm2, self.sx2, self.qs, self.wc = sm2, sx2, qs, wc

    def x0(self, P0):
        """Initial point from a design (auxiliary variables from its numeric values)."""
        cons = self.cons
        z0 = np.clip((np.asarray(P0) - cons.region.center) / cons.region.half, -1, 1)
        t = pose_terms(self.robot, P0)
        aq = t["a"] * self.qs
        G = np.diff(aq, axis=0)
        v = self.sx2 * np.sum(t["dth"] ** 2, axis=1)
        nums = {"rho": t["rho"], "M": G.T @ G / self.mscale,
                "Fn": _fisher_batch(aq[None], v[None], self.sm2)[0] / self.fscale}
        nums["wM"] = np.linalg.eigvalsh(nums["M"])
        nums["wF"] = np.linalg.eigvalsh(nums["Fn"])
        if self._need_B:  # the bias per tolerance of the start (q-units), for the epigraph bounds
            ext = self.wts.extend(aq, t["ao"])
            Fe = _fisher_batch(ext[None], v[None], self.sm2)[0]
            p_ = aq.shape[1]
            try:
                nums["B"] = np.linalg.solve(Fe[:p_, :p_], Fe[:p_, p_:])
            except np.linalg.LinAlgError:
                nums["B"] = np.ones((p_, ext.shape[1] - p_))
        aux = [np.atleast_1d(a_[4](nums)) for a_ in self.aux]
        return np.concatenate([z0.ravel()] + aux)  # z is (n, K) column-major == P0 (K, n) row-major

    def params(self, P0):
        """The NLP's parameters for a start (each pose's polygon cell), or None."""
        if self.p_sym is None:
            return None
        k = self.cons.region.clip.cell_of(P0)
        out = np.zeros((self.K, self.hmax, 3))
        out[:, :, 2] = 1.0  # padding rows: 0 <= 1
        for i, ci in enumerate(k):
            H = self.cells[ci]
            out[i, :len(H)] = H
        return out.reshape(self.K, -1).ravel()  # column-major (3 hmax, K) == row-major (K, 3 hmax)

    def solve(self, P0):
        """Run Ipopt from ``P0`` (K, n); returns (P, status, iterations), P of shape (K, n)."""
        kw = {}
        if self.p_sym is not None:
            kw["p"] = self.params(P0)
        sol = self.solver(x0=self.x0(P0), lbx=self.lbx, ubx=self.ubx, lbg=self.lbg, ubg=self.ubg, **kw)
        st = self.solver.stats()
        x = sol["x"].full().ravel()
        z = np.clip(x[:self.n * self.K].reshape(self.K, self.n), -1, 1)
        P = self.cons.region.center + self.cons.region.half * z
        return P, st.get("return_status", "?"), int(st.get("iter_count", -1))


def _random_start(robot, K, cons, rng, tries=50):
    """A random design of K feasible, separated poses (None if none found)."""
    for _ in range(tries):
        pts = cons.region.sample(rng, 40 * K)
        pts = pts[_pointwise_ok(robot, pts, cons)]
        if len(pts) < K:
            continue
        rho = pose_terms(robot, pts)["rho"]
        close = None
        if cons.min_separation_mm > 0:
            close = pose_distances(robot, pts) < cons.min_separation_mm
            np.fill_diagonal(close, False)
        idx = _feasible_random_subset(rng, rho, K, cons, tries=20, close=close)
        if idx is None:
            continue
        P = pts[idx]
        if not check_design(robot, P, cons):
            return P
    return None


def _scales(robot, P, noise):
    """Normalisations of F_q and G^T G (mean eigenvalue at a reference design)."""
    sm2, sx2 = _noise_terms(noise, robot)
    t = pose_terms(robot, P)
    aq = t["a"] * _qscale(robot)
    v = sx2 * np.sum(t["dth"] ** 2, axis=1)
    F = _fisher_batch(aq[None], v[None], sm2)[0]
    G = np.diff(aq, axis=0)
    p = aq.shape[1]
    return max(np.trace(F) / p, 1e-300), max(np.trace(G.T @ G) / p, 1e-300)


def continuous_design(robot, K, criterion="crlb", cons: Constraints | None = None, noise=None, seed=0,
                      n_starts: int = 8, starts=None, max_iter: int = 500, tolerances=None, step=None):
    """Multi-start Ipopt over the K poses.

    Parameters
    ----------
    robot : Robot
    K : int
    criterion : {"cond", "D", "A", "E", "crlb"}
    cons : Constraints, optional
    noise : NoiseModel, optional
        Default: the robot's (``Robot.noise``: scale and joint errors).
    seed : int
        Seed of the random starts.
    n_starts : int
        Number of random starts.
    starts : list of (label, ndarray shape (K, n)), optional
        Extra starts (e.g. the boundary scheme, an exchange design).
    tolerances : dict, optional
        Tolerances of the omitted errors (``mse``).
    step : callable, optional
        ``step()`` after each Ipopt start (progress).

    Returns
    -------
    dict
        ``poses`` (K, n) of the best feasible local optimum, ``objective``,
        ``value`` (user units), ``runs`` (label, value, status, iterations,
        feasible, time per start), ``time_s``, ``build_s``.
    """
    t0 = time.perf_counter()
    cons = cons or make_constraints(robot)
    _check_k(K, robot)
    _check_criterion(criterion)
    rng = np.random.default_rng(seed)
    all_starts = list(starts or [])
    for i in range(n_starts):
        P0 = _random_start(robot, K, cons, rng)
        if P0 is not None:
            all_starts.append((f"random {i}", P0))
    if not all_starts:
        raise DesignError("could not find a feasible random start: the constraints leave (almost) no room")
    ref = next((P for _, P in all_starts if np.isfinite(_objective_batch(
        "D", *_terms_batch(robot, P, noise), _noise_terms(noise, robot)[0], _crlb_weights(robot))[0])),
               all_starts[0][1])
    fscale, mscale = _scales(robot, ref, noise)
    nlp = _NLP(robot, K, criterion, cons, noise, fscale, mscale, max_iter, tolerances=tolerances)
    build_s = time.perf_counter() - t0
    best, runs = None, []
    for label, P0 in all_starts:
        ts = time.perf_counter()
        P, status, iters = nlp.solve(P0)
        viol = check_design(robot, P, cons)
        o = _objective(robot, criterion, P, noise, tolerances)
        runs.append({"start": label, "value": _user_value(criterion, o, robot.errors.offset_unit), "status": status,
                     "iterations": iters,
                     "feasible": not viol, "time_s": time.perf_counter() - ts})
        if step is not None:
            step()
        if not viol and np.isfinite(o) and (best is None or o < best[1]):
            best = (P, o)
    if best is None:
        raise DesignError("no Ipopt start ended at a feasible design; statuses: "
                          + ", ".join(sorted({r["status"] for r in runs})))
    return {"poses": best[0], "objective": best[1], "value": _user_value(criterion, best[1], robot.errors.offset_unit),
            "runs": runs,
            "time_s": time.perf_counter() - t0, "build_s": build_s, "nlp": nlp}
