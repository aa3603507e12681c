"""Rounds of several calibration loops identified at once: the mapped Gauss-Newton, each round as ``identify_nlls``.

:func:`identify_rounds` takes one measurement round per loop (each its own commanded joints, after its own
compensation, and its own prior: the loop's current totals, for a sequential MAP the previous round's
covariance) and runs the Gauss-Newton blocks of all of them in one mapped call per block
(:meth:`~zerocal_sym.identify.estimate.nlls_problem.NllsProblem.run_batch`: every column evaluated as the single
Function evaluates it).  A round whose Gauss-Newton converged and passes Ipopt's own first-order test
(:func:`~zerocal_sym.identify.estimate.nlls_solve.ipopt_accepts`, as ``identify_nlls`` confirms it) gets the
estimate, covariance and verdict ``identify_nlls`` would give, from the same functions on the same arrays
(:func:`~zerocal_sym.identify.estimate.nlls_solve.information`, the fit check's chi² test
:func:`~zerocal_sym.identify.check.statistics.chi2_test` and its largest standardised residual
:func:`~zerocal_sym.identify.check.max_reading.max_test`): the same numbers, bit for bit.  Every other round goes
through :func:`~zerocal_sym.identify.nlls.identify_nlls` itself.  What acts on each round alone is done for all
of them at once where that gives the same bits: the SVDs stacked (each matrix factored on its own), the compiled
per-reading terms ``fit_terms`` mapped over the rounds, their largest-residual tests together
(:func:`~zerocal_sym.identify.check.max_reading.max_tests`).

What a loop reads of a round (``lean`` results): ``success``, ``status``, the estimate and covariance,
``info["fit"]["rejected"]`` (and ``max_reading``); the fit check's per-reading statistics and the diagnosis of a
rejected fit are not kept (``info["lean"]`` is True): ``zerocal compare`` does not report them.  Shapes: K poses, m
joints, q source errors, p estimated parameters.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from zerocal_sym.errors import IdentificationError, ZerocalError
from zerocal_sym.identify import fisher
from zerocal_sym.identify.check.max_reading import max_test, max_tests
from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA, chi2_test
from zerocal_sym.identify.estimate.nlls_inputs import prior_whitener
from zerocal_sym.identify.estimate.nlls_problem import EXPAND_MAX_K, GN_BLOCKS, batch_size, get_problem
from zerocal_sym.identify.estimate.nlls_solve import (GN_STEP_TOL, information, ipopt_accepts, noise_terms,
                                                     status_line)
from zerocal_sym.identify.result import IdentificationResult
from zerocal_sym.identify.whitened import RANK_RTOL, _Linear
from zerocal_sym.model.fastcall import mapped


def _blocks(prob, z, P):
    """Gauss-Newton blocks over the columns of ``z`` (p, n) and ``P`` (npar, n), each data set until its last step
    is below the tolerance, as :meth:`NllsProblem.run_gauss_newton` does one.  Returns per data set the outputs
    of its last block: ``z`` (p,), ``step``, ``r`` (K-1,), ``rp`` (p,), ``J`` (K-1 + p, p), ``pred`` (K-1,), ``l``
    (K-1,), ``b`` (K-2,)."""
    p, n = z.shape
    where = [None] * n  # per data set: (its last block's outputs, its column there)
    todo = np.arange(n)
    zc = z.copy()
    for _ in range(GN_BLOCKS):
        outs = prob.run_batch(zc[:, todo], P[:, todo])
        zk, sk = outs[0], outs[1]
        for j, i in enumerate(todo.tolist()):
            where[i] = (outs, j)
        zc[:, todo] = zk
        more = np.isfinite(zk).all(axis=0) & ~(sk[0] < GN_STEP_TOL)
        todo = todo[more]
        if not todo.size:
            break
    last = []
    for outs, j in where:
        zk, sk, rk, rpk, Jk, pk, lk, bk = outs
        last.append((np.array(zk[:, j]), float(sk[0, j]), np.array(rk[:, j]), np.array(rpk[:, j]),
                     np.array(Jk[:, j * p:(j + 1) * p], order="F"), np.array(pk[:, j]), np.array(lk[:, j]),
                     np.array(bk[:, j])))
    return last


def _validity_and_rank(R, Jd, L, B, S) -> tuple:
    """What :class:`_Linear` finds of N rounds without prior rows, from their Jacobians' singular values: whether
    each is valid (its residuals ``R`` (N, K-1), data Jacobian ``Jd`` (N, K-1, p), ``L`` (N, K-1) and ``B``
    (N, K-2) finite, ``L`` nowhere zero) and its rank (singular values ``S`` (N, p) above ``RANK_RTOL`` times the
    largest; 0 where not valid: ``_Linear`` zeroes what is not finite and takes its own SVD, and the verdict is
    "rejected" either way).  Returns ``valid`` (N,) bool and ``rank`` (N,) int."""
    n = len(R)
    valid = (np.isfinite(R).all(axis=1) & np.isfinite(Jd).reshape(n, -1).all(axis=1) & np.isfinite(L).all(axis=1)
             & np.isfinite(B).all(axis=1) & np.all(L != 0, axis=1))
    rank = np.count_nonzero(S > RANK_RTOL * S[:, :1], axis=1) if S.shape[1] else np.zeros(n, int)
    return valid, np.where(valid, rank, 0)


class _Verdict:
    """What :func:`~zerocal_sym.identify.check.statistics.chi2_test` reads of a :class:`_Linear` without prior rows:
    ``r``, ``valid``, ``dof`` (the same definitions), from :func:`_validity_and_rank` of the round (``known``:
    ``(valid, rank)`` already computed for many rounds at once; else from the SVD ``svd`` of its Jacobian)."""

    def __init__(self, r, Jd, l, b, svd, known=None):
        if known is None:
            S = np.atleast_2d(svd[1]) if svd is not None else np.zeros((1, 0))
            valid, rank = _validity_and_rank(r[None], Jd[None], l[None], b[None], S)
            known = bool(valid[0]), int(rank[0])
        self.r = r
        self.valid, rank = known
        self.dof = r.size - rank


def _max_reading(prob, lin, sol, svd, rank, K, names, scale, alpha, checked):
    """The fit check's largest standardised residual and its test, from the per-reading terms ``identify_nlls``
    computes for the same point (the compiled ``fit_terms`` without prior rows at full rank, else
    :meth:`_Linear.per_reading`): None when not checked."""
    if not checked or not lin.valid:
        return None
    if isinstance(lin, _Linear):  # prior rows
        t, _, delta, _ = lin.per_reading(moves=False)
    elif rank == len(names) and "fit_terms" in prob.fast:
        t, _, delta, _ = (np.ravel(np.array(o, float)) for o in prob.fast["fit_terms"](sol.r, sol.J[: K - 1], sol.l,
                                                                                       sol.b))
    else:
        t, _, delta, _ = _Linear(sol.r, sol.J[: K - 1], (sol.l, sol.b), np.arange(1, K), np.zeros(K - 1),
                                 np.eye(len(names)), scale, names, 0, svd=svd).per_reading(moves=False)
    return max_test(t, np.arange(1, K), delta, alpha, checked)


def _lean_start(robot, names, scale, noise, w, sol, K, alpha, svd=None, sv=None, verdict=None) -> SimpleNamespace:
    """The first part of the result ``identify_nlls`` gives for a confirmed point ``sol``: the information, the
    status and the chi² test (:func:`_lean` ends it).  ``svd``, ``sv``: the SVDs :func:`information` takes, already
    computed; ``verdict``: ``(valid, rank)`` of :class:`_Verdict`, already computed."""
    r, rp, J, l, b = sol.r, sol.rp, sol.J, sol.l, sol.b
    has_prior = bool(w.any())
    Jd = J[: K - 1]
    svd, sv, rank, cov, nonid, offsets_ok = information(J, Jd, r, K, has_prior, noise, scale, names, robot.errors,
                                                        svd, sv)
    rows = np.flatnonzero(np.any(w != 0, axis=1)) if has_prior else ()
    if len(rows):  # the fit check's whitened problem with the prior rows (its own SVD)
        lin = _Linear(np.concatenate([r, rp[rows]]), np.vstack([Jd, J[K - 1:][rows]]), (l, b), np.arange(1, K),
                      np.zeros(K - 1), np.eye(len(names)), scale, names, len(rows))
    else:  # the same quantities from J's SVD (as _Linear takes it: the data rows are all of J's information)
        lin = _Verdict(r, Jd, l, b, svd, verdict)
    chi2, dof, checked, rejected, p, _ = chi2_test(lin, noise, alpha)
    return SimpleNamespace(sol=sol, svd=svd, rank=rank, cov=cov, nonid=nonid, lin=lin, chi2=chi2, dof=dof,
                           checked=checked, rejected=rejected, p=p,
                           success=sol.converged and offsets_ok and svd is not None,
                           status=status_line(sol, offsets_ok, rank, names, None, "l2"))


def _lean(robot, names, scale, noise, prior_q, st, mr, alpha) -> IdentificationResult:
    """The result ``identify_nlls`` gives for a confirmed point: its estimate, covariance and verdict (the fit
    check's two tests; the per-reading statistics and a rejection's diagnosis left out), from :func:`_lean_start`'s
    ``st`` and the largest standardised residual's test ``mr`` (:func:`_max_reading`)."""
    sol, success, status = st.sol, st.success, st.status
    chi2, dof, rejected, p = st.chi2, st.dof, st.rejected, st.p
    if rejected and success:
        success = False
        status = "rejected: the noise model rejects the fit" + (f" (chi2 {chi2:.4g} on {dof} dof, p = {p:.3g})"
                                                               if np.isfinite(chi2) else "")
    elif mr is not None and mr["rejected"] and success:
        success = False
        status = (f"rejected: the noise model rejects the fit (one reading: standardised residual "
                  f"{mr['standardised']:+.3g} at pose {mr['pose']}, the largest of {mr['readings']}, "
                  f"p = {mr['p_value']:.3g})")
    info = {"solver_status": sol.ret, "iterations": sol.iterations, "chi2": float(sol.r @ sol.r), "rank": st.rank,
            "confirmation": sol.confirmation, "prior": prior_q.tolist(), "nonidentifiable": st.nonid,
            "noise": {"sigma_scale_mm": noise.sigma_scale_mm, "sigma_servo_rad": noise.sigma_servo_rad},
            "fit": {"checked": st.checked, "rejected": bool(rejected or (mr is not None and mr["rejected"])),
                    "chi2_rejected": rejected, "chi2": chi2, "dof": dof, "p_value": p, "alpha": alpha,
                    "max_reading": mr},
            "lean": True}
    return IdentificationResult(method="nlls", params=names, estimate=sol.z / scale, covariance=st.cov,
                                success=bool(success), status=status, info=info, errors=robot.errors,
                                std_kind="from residuals" if noise.is_zero else "total")


def _fit_terms_many(prob, R, J, L, B) -> tuple:
    """``fit_terms`` of n columns at once, each as the single Function evaluates it (one mapped Function per
    :func:`~zerocal_sym.identify.estimate.nlls_problem.batch_size`, the columns padded with copies of the first):
    ``R`` (K-1, n), ``J`` (K-1, p n: ``[J_1 | J_2 | ...]``), ``L`` (K-1, n), ``B`` (K-2, n).  Returns ``t`` and
    ``delta``, (K-1, n) each."""
    f = prob.functions["fit_terms"]
    n, p = R.shape[1], J.shape[1] // max(1, R.shape[1])
    N = batch_size(n)
    if N > n:
        R, L, B = (np.concatenate([a, np.repeat(a[:, :1], N - n, axis=1)], axis=1) for a in (R, L, B))
        J = np.concatenate([J, np.tile(J[:, :p], (1, N - n))], axis=1)
    t, _, delta, _ = mapped(f, N, (True,) * f.n_in())(R, J, L, B)
    return np.reshape(t, (-1, N), order="F")[:, :n].copy(), np.reshape(delta, (-1, N), order="F")[:, :n].copy()


def _finish(robot, names, scale, noise, priors, K, alpha, prob, done, svds, svs) -> dict:
    """The results of the confirmed rounds ``done`` (index, last block), with the SVDs already stacked: per round
    :func:`_lean_start`; the largest standardised residuals of those the compiled ``fit_terms`` serves in one
    mapped call (:func:`max_tests`), the others as :func:`_max_reading`; then :func:`_lean`."""
    p = len(names)
    a = c = 0
    sts = []
    for (i, (z, step, r, rp, J, pred, l, b)), w, f, s in done:
        svd = sv = verdict = None
        if f:
            svd, verdict = (svds[0][a], svds[1][a], svds[2][a]), svds[3][a]
            a += 1
        if s:
            sv = svs[c]
            c += 1
        sol = SimpleNamespace(z=z, ret="Solve_Succeeded", converged=True, iterations=0, gn_ok=True, step=step,
                              l=l, b=b, r=r, rp=rp, J=J, pred=pred, confirmation="first-order test")
        sts.append(_lean_start(robot, names, scale, noise, w, sol, K, alpha, svd, sv, verdict))
    mrs = [None] * len(sts)
    many = ([k for k, st in enumerate(sts) if st.checked and st.lin.valid and isinstance(st.lin, _Verdict)
             and st.rank == p] if "fit_terms" in prob.fast else [])
    if many:
        sols = [sts[k].sol for k in many]
        T, D = _fit_terms_many(prob, np.column_stack([x.r for x in sols]),
                               np.hstack([x.J[: K - 1] for x in sols]), np.column_stack([x.l for x in sols]),
                               np.column_stack([x.b for x in sols]).reshape(K - 2, len(sols)))
        for k, mr in zip(many, max_tests(T, np.arange(1, K), D, alpha)):
            mrs[k] = mr
    fast = set(many)
    out = {}
    for k, (((i, _), _, _, _), st) in enumerate(zip(done, sts)):
        if k not in fast:
            mrs[k] = _max_reading(prob, st.lin, st.sol, st.svd, st.rank, K, names, scale, alpha, st.checked)
        out[i] = _lean(robot, names, scale, noise, np.asarray(priors[i], float), st, mrs[k], alpha)
    return out


def identify_rounds(robot, rounds, priors, params, noise, prior_covs=None, alpha: float = DEFAULT_ALPHA) -> list:
    """Identify one round per loop at once, each as ``identify_nlls(robot, round, params, noise, prior=prior,
    prior_cov=prior_cov)`` (the defaults otherwise) would.

    Parameters
    ----------
    rounds : list of Measurements
        ``theta_cmd`` (K, m) and ``readings`` (K,) each; the same K.
    priors : list of ndarray, shape (q,)
        The source errors each round is identified from (its loop's totals).
    params : tuple of str
        The parameters estimated (resolved names).
    noise : NoiseModel
    prior_covs : list of ndarray (p, p) or None, optional
        A Gaussian prior per round (a sequential MAP), None where there is none.

    Returns
    -------
    list
        Per round its :class:`IdentificationResult` (lean when confirmed in the batch, see the module), or the
        :class:`IdentificationError` / :class:`ZerocalError` ``identify_nlls`` raised for it.
    """
    from zerocal_sym.identify.nlls import identify_nlls

    n = len(rounds)
    prior_covs = [None] * n if prior_covs is None else list(prior_covs)
    out = [None] * n

    def single(i):
        try:
            out[i] = identify_nlls(robot, rounds[i], params, noise=noise, prior=priors[i], prior_cov=prior_covs[i],
                                   fit_alpha=alpha)
        except (IdentificationError, ZerocalError) as exc:
            out[i] = exc

    K = np.shape(rounds[0].theta_cmd)[0] if n else 0
    ok = [i for i in range(n) if np.shape(rounds[i].theta_cmd)[0] == K
          and np.isfinite(rounds[i].theta_cmd).all() and np.isfinite(rounds[i].readings).all()]
    if K > EXPAND_MAX_K or K - 1 < 1:  # identify_nlls' numpy problem above EXPAND_MAX_K poses: no mapped twin
        ok = []
    batch = set(ok)
    for i in range(n):
        if i not in batch:
            single(i)
    if not ok:
        return out
    errors = robot.errors
    names = tuple(params)
    scale = fisher.parameter_scale(robot, names)
    prob = get_problem(robot, K, names)
    prob.hot()
    sm2, sx2 = noise_terms(noise)
    geometry = robot.geometry
    ws, mus, cols = {}, {}, []
    for i in ok:
        prior_q = np.asarray(priors[i], float)
        ws[i] = prior_whitener(names, None, prior_covs[i])
        mus[i] = errors.take(prior_q, names)
        meas = rounds[i]
        cols.append(prob.pack(meas.theta_cmd, geometry, prior_q, np.asarray(meas.readings, float)[1:], scale,
                              mus[i], ws[i], sm2, sx2))
    P = np.array(cols).T
    Z0 = np.array([mus[i] * scale for i in ok]).T
    last = _blocks(prob, Z0, P)
    done = []  # the confirmed rounds: (i, their last block)
    for j, i in enumerate(ok):
        z, step, r, rp, J, pred, l, b = last[j]
        if not (np.isfinite(z).all() and step < GN_STEP_TOL and ipopt_accepts(J, r, rp, K)):
            single(i)  # Ipopt decides, as in identify_nlls
            continue
        done.append((i, last[j]))
    if not done:
        return out
    # the SVDs information takes, stacked (each matrix on its own: the same numbers), and _Verdict's validity and
    # rank from them; a J that is not finite is left to information (none passes ipopt_accepts)
    fin = [bool(np.isfinite(blk[4]).all()) for _, blk in done]
    Js = np.array([blk[4] for (_, blk), f in zip(done, fin) if f])
    svds = None
    if len(Js):
        svds = list(np.linalg.svd(Js, full_matrices=False))
        R, L, B = (np.array([blk[k] for (_, blk), f in zip(done, fin) if f]) for k in (2, 6, 7))
        valid, rank = _validity_and_rank(R, Js[:, : K - 1], L, B, svds[1])
        svds.append(list(zip(valid.tolist(), rank.tolist())))
    seq = [f and bool(ws[i].any()) and K - 1 > 0 for (i, _), f in zip(done, fin)]
    svs = np.linalg.svd(Js[np.array(seq)[np.array(fin)]][:, : K - 1], compute_uv=False) if any(seq) else None
    for i, res in _finish(robot, names, scale, noise, priors, K, alpha, prob,
                          [(d, ws[d[0]], f, s) for d, f, s in zip(done, fin, seq)], svds, svs).items():
        out[i] = res
    return out


class LoopRounds:
    """``identify_many`` of :func:`~zerocal_sym.identify.loop.calibration_loops` (``pass_loops=True``) for Ipopt
    loops: each round as ``make_nlls_identifier(params, noise, sequential)``'s identifier of its loop would
    identify it (the sequential MAP's prior from that loop's previous result), all of them at once
    (:func:`identify_rounds`)."""

    def __init__(self, names, noise, sequential: bool):
        self.names, self.noise, self.sequential = names, noise, sequential
        self.last = {}

    def __call__(self, robot, rounds, priors, loops):
        from zerocal_sym.identify.nlls import sequential_prior_cov

        covs = [sequential_prior_cov(robot, self.names, self.last.get(i), pr) if self.sequential else None
                for i, pr in zip(loops, priors)]
        out = identify_rounds(robot, rounds, priors, self.names, self.noise, covs)
        for i, res in zip(loops, out):
            self.last[i] = None if isinstance(res, BaseException) else res
        return out
