"""The stages of :func:`~zerocal_sym.identify.nlls.identify_nlls` after its inputs are checked.

:func:`solve` (Gauss-Newton inside one CasADi call, then Ipopt's verdict:
its own termination test at a converged Gauss-Newton point, or its solve),
:func:`information` (rank, covariance and null space from one SVD of the
whitened, scaled Jacobian), :func:`status_line` and :func:`noise_terms` (the
noise model's terms of the whitening).  Shapes: K poses, p
estimated parameters.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from zerocal_sym.identify.whitened import RANK_RTOL

#: weighting of noise-free data (``NoiseModel()``): residuals in units of 1 um
UNIT_SIGMA_MM = 1e-3
#: Ipopt return statuses that count as converged (anything else: success False)
CONVERGED_STATUSES = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
#: Gauss-Newton is converged when its last step is below this (scaled units, mm)
GN_STEP_TOL = 1e-8
#: how a converged Gauss-Newton point is confirmed: ``"test"`` -- Ipopt's own termination test at its starting
#: point (:func:`ipopt_accepts`), evaluated on the Jacobian and residuals Gauss-Newton returned, Ipopt solving
#: whenever it does not pass; ``"ipopt"`` -- Ipopt solves every time (the tests compare the two)
CONFIRM = "test"
#: the test passes when Ipopt's optimality error at the point is below this fraction of Ipopt's tolerance: the
#: gradient here (numpy, from J and r) and Ipopt's (CasADi's reverse mode) differ by round-off, far below it
CONFIRM_MARGIN = 0.5


def noise_terms(noise):
    """``(sigma_m^2, sigma_xi^2)`` of the whitening; a zero model weights every change by 1 um."""
    if noise.is_zero:
        return UNIT_SIGMA_MM**2, 0.0
    return float(noise.sigma_scale_mm) ** 2, float(noise.sigma_servo_rad) ** 2


def ipopt_accepts(J, r, rp, K) -> bool:
    """Would Ipopt, started at this point, stop there at once (``Solve_Succeeded`` after 0 iterations)?

    Ipopt's NLP here (:mod:`~zerocal_sym.identify.estimate.nlls_problem`) is unconstrained, without bounds, unscaled
    (``nlp_scaling_method none``), with the objective ``0.5 c |[r; rp]|^2``, ``c = 1 / |J_data|_F^2``.  At its
    starting point, before any iteration, Ipopt checks convergence first (before its iteration limit): with
    no constraints, bounds or multipliers its optimality error is the largest entry of the gradient
    ``c J^T [r; rp]`` (the dual infeasibility, its scaling factor 1), and it stops with ``Solve_Succeeded``,
    the point unchanged, when that is at most ``ipopt.tol``.  This is that test, with the margin
    :data:`CONFIRM_MARGIN`; ``J`` (K-1 + p, p), ``r`` (K-1,), ``rp`` (p,).
    """
    from zerocal_sym.identify.estimate.nlls_problem import IPOPT_OPTIONS

    Jd = J[: K - 1]
    c = 1.0 / max(1e-300, float(np.vdot(Jd, Jd)))
    g = c * (J.T @ np.concatenate([r, rp]))
    err = float(np.max(np.abs(g))) if g.size else 0.0
    return bool(np.isfinite(err) and err <= CONFIRM_MARGIN * IPOPT_OPTIONS["ipopt.tol"])


def solve(prob, z0, par, reweight, bounded, lbx, ubx, max_iter, K) -> SimpleNamespace:
    """Gauss-Newton in one CasADi call, then Ipopt's verdict on its point: Ipopt's status decides.

    A converged Gauss-Newton point without bounds is first put to Ipopt's own
    termination test at a starting point (:func:`ipopt_accepts`, on the
    Jacobian and residuals already computed): when it passes, the result is
    what Ipopt returns there (``Solve_Succeeded``, 0 iterations, the point
    unchanged) without calling it; otherwise (or with bounds, which Ipopt
    moves a start away from, or :data:`CONFIRM` ``"ipopt"``) Ipopt solves from
    that point.  If Gauss-Newton did not converge (or left the bounds) Ipopt
    starts at ``z0`` and, with ``reweight``, solves once more with the weights
    at its solution.  Returns ``z`` (p,), ``ret`` (Ipopt's status),
    ``converged``, ``iterations`` (Ipopt's), ``gn_ok``, ``step``
    (Gauss-Newton's last, mm), ``confirmation`` (``"first-order test"`` or
    ``"ipopt"``) and, at the final point, the weights ``l`` (K-1,), ``b``
    (K-2,), the whitened residuals ``r`` (K-1,) and prior residuals ``rp``,
    the Jacobian ``J`` (K-1 + p, p) and the predicted changes ``pred`` (K-1,).
    """
    fast = prob.fast
    z_gn, step, r, rp, J, pred, l, b = prob.run_gauss_newton(z0, par, bool(reweight), GN_STEP_TOL)
    step = float(step[0])
    gn_ok = bool(np.isfinite(z_gn).all() and step < GN_STEP_TOL
                 and (not bounded or (np.all(z_gn >= lbx) and np.all(z_gn <= ubx))))
    if gn_ok and not bounded and CONFIRM == "test":
        r, rp, pred = r.ravel(), rp.ravel(), pred.ravel()
        J = np.reshape(J, (-1, z_gn.size))
        if ipopt_accepts(J, r, rp, K):
            return SimpleNamespace(z=z_gn, ret="Solve_Succeeded", converged=True, iterations=0, gn_ok=True,
                                   step=step, l=l, b=b, r=r, rp=rp, J=J, pred=pred, confirmation="first-order test")
    solver = prob.solver_for(max_iter)
    if gn_ok:  # Ipopt confirms the Gauss-Newton point (weights at that point)
        z, passes = z_gn, 1
    else:      # Ipopt from the start; with reweight once more with the weights at its solution
        z, passes = z0, 1 + bool(reweight)
        l, b = (np.array(o) for o in fast["weights"](z0, par))
    total_iter, stats = 0, {}
    for k in range(passes):
        if k:
            l, b = (np.array(o) for o in fast["weights"](z, par))
        Jz = J[: K - 1] if (gn_ok and not k) else fast["jfun"](z, par, l, b)[0]
        c = 1.0 / max(1e-300, float(np.vdot(Jz, Jz)))  # GN Hessian of norm ~1 (Frobenius: no SVD)
        zn = solver(z, np.concatenate([par, l, b, [c]]), lbx, ubx)[0].copy()
        stats = solver.stats()
        total_iter += int(stats.get("iter_count", 0))
        moved = bool((zn != z).any())
        z = zn
        if str(stats.get("return_status")) not in CONVERGED_STATUSES:
            break
    ret = str(stats.get("return_status", "unknown"))
    if not gn_ok or moved:  # residuals and Jacobian at the final point (else Gauss-Newton's are current)
        l, b = (np.array(o) for o in fast["weights"](z if reweight else z0, par))
        r, rp, J, pred = (np.array(o) for o in fast["residuals"](z, par, l, b))
    return SimpleNamespace(z=z, ret=ret, converged=ret in CONVERGED_STATUSES and bool(np.isfinite(z).all()),
                           iterations=total_iter, gn_ok=gn_ok, step=step, l=l, b=b, r=r.ravel(), rp=rp.ravel(),
                           J=np.reshape(J, (-1, z.size)), pred=pred.ravel(),  # (a column when p = 1)
                           confirmation="ipopt")


def information(J, Jd, r, K, has_prior, noise, scale, names, errors, svd=None, sv=None):
    """Rank, covariance and null space from one SVD of ``J`` (K-1 + p, p): ``F = J^T J = V diag(sJ^2) V^T``.

    Returns ``svd`` (J's), ``sv`` (singular values of the data part ``Jd``),
    ``rank``, ``cov`` (p, p; physical units, ``inf``/NaN on non-identifiable
    parameters), ``nonid`` (the null-space directions by name) and whether
    every zero offset estimated is identifiable.  A ``J`` that is not finite
    (the exact model cannot be evaluated at the point: a pose is not an
    assembly of the robot with those errors) carries no information: rank 0,
    no SVD (None), the variances infinite.  ``svd`` (J's, ``full_matrices=False``) and ``sv`` (with a prior:
    ``Jd``'s singular values) when already computed (a batch's stacked SVDs: the same numbers).
    """
    if not np.all(np.isfinite(J)):  # (LAPACK would fail on it, and print to stdout)
        p = J.shape[1]
        cov = np.full((p, p), np.nan)
        np.fill_diagonal(cov, np.inf)
        return None, np.zeros(0), 0, cov, [], not any(n in names for n in errors.zero_offsets)
    UJ, sJ, Vt = np.linalg.svd(J, full_matrices=False) if svd is None else svd
    sF = sJ**2
    if sv is None or not has_prior:
        sv = (np.linalg.svd(Jd, compute_uv=False) if has_prior else sJ[:min(Jd.shape)]) if Jd.size else np.zeros(0)
    tol = RANK_RTOL * (sF[0] if sF.size else 0.0)
    rank = int(np.count_nonzero(sF > tol))
    null = Vt[rank:]
    if noise.is_zero:
        dof = (K - 1) - rank
        s2 = float(r @ r) * UNIT_SIGMA_MM**2 / dof if dof > 0 else np.nan
    else:
        s2 = 1.0
    Finv = (Vt[:rank].T / sF[:rank]) @ Vt[:rank]
    cov = s2 * Finv / np.outer(scale, scale)
    nonid, offsets_ok = [], True
    if null.size:  # rank deficient
        for v in null:
            v = v / scale  # direction in physical units
            v = v / np.max(np.abs(v))
            nonid.append({n: float(c) for n, c in zip(names, v) if abs(c) > 1e-6})
        for k in range(len(names)):  # non-identifiable parameters get infinite variance
            if np.max(np.abs(null[:, k])) > 1e-6:
                cov[k, :] = np.nan
                cov[:, k] = np.nan
                cov[k, k] = np.inf
        offsets_ok = all(not np.max(np.abs(null[:, names.index(n)])) > 1e-6
                         for n in errors.zero_offsets if n in names)
    return (UJ, sJ, Vt), sv, rank, cov, nonid, offsets_ok


def status_line(sol, offsets_ok, rank, names, robust, loss) -> str:
    """The result's status line: Ipopt's verdict, identifiability, the robust loss's outliers."""
    ret = sol.ret
    if not (np.all(np.isfinite(sol.J)) and np.all(np.isfinite(sol.r))):
        status = (f"the exact model cannot be evaluated where the solver stopped ({ret}): a pose is not an "
                  "assembly of the robot with those errors")
    elif not sol.converged:
        status = f"Ipopt did not converge: {ret}"
    elif not offsets_ok:
        status = (f"converged ({ret}) but the zero offsets are not identifiable from these poses "
                  f"with parameters {', '.join(names)} (rank {rank} of {len(names)})")
    elif rank < len(names):
        status = (f"converged ({ret}); rank {rank} of {len(names)}: some geometric combinations are "
                  "not identifiable (see info['nonidentifiable'])")
    else:
        status = f"converged ({ret})"
    if robust is not None and robust["excluded_readings"]:
        status += (f"; {loss} loss: reading(s) at pose {', '.join(map(str, robust['excluded_readings']))} "
                   "down-weighted as outliers (estimated error " +
                   ", ".join(f"{e:+.3g} mm" for e in robust["excluded_errors_mm"]) + ")" +
                   ("; estimate refitted without them" if robust["refit_without_outliers"] else ""))
    return status
