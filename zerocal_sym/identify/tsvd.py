"""Identification by truncated SVD (paper Eq. 28-29).

The paper's identification model is linear in the increment ``dp`` of the
zero offsets as lengths and the MAEMM, ``(L1 dth1, L2 dth2, drMx, drMy)``
for the paper's robot, ``(L_i dth_i, drM)`` (m + n entries, mm) for any
mechanism (:mod:`zerocal_sym.identify.linear`):

    ds = G dp,   ds_k = s_k - (lambda_{k+1} - lambda_k),   G: (K-1) x (m + n),

solved by the truncated SVD ``dp = sum_{i<=t} (u_i^T ds / sigma_i) v_i``.

The truncated SVD itself and its truncation rules (``threshold``, the
default; ``gcv``; ``discrepancy``) are in
:mod:`~zerocal_sym.identify.truncated_svd` (:func:`tsvd_solve`); the
covariance with what TSVD leaves out (the linearisation bias, the truncated
directions' bias bound) in :mod:`~zerocal_sym.identify.tsvd_uncertainty`.
Here: :func:`identify_tsvd`, and :func:`identify_tsvd_many` (many rounds at
once, the estimate only).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import IdentificationError, PoseError
from zerocal_sym.identify.result import IdentificationResult
# RULES and TSVDSolution: kept importable from here
from zerocal_sym.identify.truncated_svd import (DEFAULT_RTOL, DEFAULT_RULE, RULES, TSVDSolution,  # noqa: F401
                                                _solve_svd, tsvd_solve)
from zerocal_sym.identify.tsvd_uncertainty import _honest_uncertainty

#: G with sigma_min / sigma_max below this is treated as rank-deficient (collinear poses).
RANK_RTOL = 1e-9
#: poses whose second principal extent is below this fraction of the first are "on one line".
COLLINEAR_RTOL = 1e-6


def _validate(meas, robot, p):
    th = np.asarray(meas.theta_cmd, float)
    rd = np.asarray(meas.readings, float)
    K = th.shape[0]
    if th.ndim != 2 or th.shape[1] != robot.m or rd.shape != (K,):
        raise IdentificationError(f"measurements must be theta_cmd (K, {robot.m}) and readings (K,) for the "
                                  f"{robot.m}-joint robot {robot.name!r}, got {th.shape} and {rd.shape}",
                                  where=meas.source)
    if K < p + 1:
        raise IdentificationError(f"too few poses: K = {K} < {p + 1} ({p} parameters are identified from K - 1 "
                                  "measured changes)", where=meas.source)
    for name, arr in (("commanded joint angles", th), ("reading", rd)):
        if np.isfinite(arr).all():
            continue
        k = int(np.flatnonzero(~np.all(np.isfinite(arr.reshape(K, -1)), axis=1))[0])
        raise IdentificationError(f"{name} of pose {k} is not a finite number", where=meas.where(k))
    return th, rd


#: an iterated TSVD stops when its increment is below this (rad, mm)
ITERATE_TOL = 1e-10


def identify_tsvd(robot, meas, prior=None, t=None, rule=DEFAULT_RULE, noise=None, rtol=DEFAULT_RTOL,
                  fit_alpha: float | None = None, accept_misfit: bool = False, diagnostics: bool = True,
                  iterations: int = 1):
    """Identify zero offsets and MAEMM from one round of measurements by TSVD (see :func:`_identify_tsvd`).

    ``iterations`` > 1: the TSVD iterated -- relinearised at its estimate (the estimate as the next prior) until
    the largest increment is below :data:`ITERATE_TOL` or ``iterations`` steps were taken; the result is the
    last step's, with ``info["tsvd_iterations"]`` and ``info["tsvd_converged"]``.  One step (the default) is
    the paper's: its linearisation at zero errors leaves a bias the iteration removes.
    """
    kw = dict(t=t, rule=rule, noise=noise, rtol=rtol, fit_alpha=fit_alpha, accept_misfit=accept_misfit,
              diagnostics=diagnostics)
    if iterations < 1:
        raise ValueError(f"iterations must be >= 1, got {iterations}")
    errors = robot.errors
    res = _identify_tsvd(robot, meas, prior, **kw)
    if iterations == 1:
        return res
    for j in range(2, iterations + 1):
        step = res.info["increment"]
        if not np.all(np.isfinite(step)) or np.max(np.abs(step)) < ITERATE_TOL:
            break
        base = errors.zeros() if prior is None else np.asarray(prior, float)
        res = _identify_tsvd(robot, meas, errors.put(base, res.params, res.estimate), **kw)
    else:
        j = iterations + 1
    res.info["tsvd_iterations"] = j - 1
    res.info["tsvd_converged"] = bool(np.max(np.abs(res.info["increment"])) < ITERATE_TOL)
    return res


def _identify_tsvd(robot, meas, prior=None, t=None, rule=DEFAULT_RULE, noise=None, rtol=DEFAULT_RTOL,
                   fit_alpha: float | None = None, accept_misfit: bool = False, diagnostics: bool = True):
    """Identify zero offsets and MAEMM from one round of measurements by TSVD.

    The model is linearised at the prior: the nominal poses are
    ``P_k = FK(theta_cmd_k + prior offsets)`` (the poses the controller meant
    to reach) and the nominal measuring-mechanism vector is corrected with the
    prior MAEMM, ``lambda_k = P_k - c - d - rM_prior`` (Eq. 30).  The TSVD
    solution is the increment; the estimate is prior + increment.

    Parameters
    ----------
    robot : Robot
    meas : Measurements
        ``theta_cmd`` (K, m) rad (compensation already applied), ``readings`` (K,) mm.
    prior : ndarray, shape (q,), optional
        Current total source-error estimates (rad, mm; only the offsets and the
        MAEMM are used).  Default zero (the paper's first identification).
    t : int, optional
        Fixed truncation level (1..m+n).
    rule : str
        Truncation rule (see :func:`tsvd_solve`); default ``threshold``.
    noise : NoiseModel, optional
        Noise of the measurements: gives the covariance of the estimate and
        the noise level of the discrepancy principle.
    rtol : float
        Threshold of the ``threshold`` rule.
    fit_alpha : float, optional
        Level of the fit check (:mod:`zerocal_sym.identify.fitcheck`, default
        0.001): a fit with ``p < fit_alpha`` is rejected (``success`` False,
        status ``"rejected: ..."``).  Without a noise model the fit cannot be
        checked.
    accept_misfit : bool
        Keep a rejected fit as a calibration (status "accepted despite misfit").
    diagnostics : bool
        Default True: everything below.  False: the estimate only (the same
        numbers, bit for bit) -- no covariance, residuals, honest std or fit
        check (``covariance`` None, ``std_kind`` ``"lower bound"``, ``info``
        only ``singular_values``, ``truncation``, ``filter_factors``,
        ``rule``, ``kappa``, ``increment``, ``nominal_poses``,
        ``right_singular_vectors``, ``maemm_prior`` and ``diagnostics``
        False; status ends in "fit not checked").  For callers that use
        the estimate alone, such as the Monte Carlo
        (:mod:`zerocal_sym.identify.montecarlo`): its TSVD runs without a
        noise model, where the fit check cannot reject anyway (zero noise:
        nothing to test against), so ``success`` is the same as with
        diagnostics; about 3x faster (many rounds at once:
        :func:`identify_tsvd_many`).  With a noise model the fit check
        could reject the fit, and without diagnostics it does not.

    Returns
    -------
    IdentificationResult
        ``method = "tsvd"``, params: the zero offsets and the MAEMM.  ``covariance``:
        the noise of the linear TSVD estimator ``x = A b`` (``A = T V_t S_t^-1 U_t^T``,
        ``T`` converting ``L dth`` to ``dth``), ``A C A^T`` with ``C`` the covariance
        of the changes at the estimate (without a noise model ``s^2 A A^T``,
        ``s^2 = ||r||^2 / (K - 1 - t)``, or None if ``K - 1 = t``), and **what TSVD
        leaves out**, per parameter (:mod:`~zerocal_sym.identify.tsvd_uncertainty`):
        its linearisation bias ``b`` (``x - t*``, ``t*`` the truth its noise-free
        data maps onto the estimate) and, for each truncated direction, a bias
        bound; ``info["std_kinds"]`` says per
        parameter whether its std is honest (``"total"``: ``noise^2 + b^2``,
        the bias small and well determined) or an upper bound (``"bound"``);
        ``std_kind`` is ``"total"`` when all are, else ``"bound"`` (``"from
        residuals"`` without a noise model, ``"lower bound"`` if a part cannot
        be evaluated, with ``info["std_note"]``).  ``info["covariance_noise"]``
        is the noise part alone, ``info["std_components"]`` the parts per
        parameter.
        ``residuals`` are the measured minus the exact-model changes at the
        estimate.  ``info``: ``singular_values``, ``truncation``,
        ``filter_factors``, ``rule``, ``kappa``, ``linear_residuals``,
        ``increment``, ``nominal_poses``, ``linearisation_bias``, ``fit`` (the
        fit check, at the exact-model minimum over the kept directions:
        a test of the data, not of TSVD's linearisation).

    Raises
    ------
    IdentificationError
        K < m + n + 1, a non-finite reading or angle (naming the pose), G of rank < m + n
        (collinear measuring-mechanism vectors), poses on one straight line
        (G nearly rank-deficient, condition number ~1e4-1e5).
    PoseError
        A commanded pose that is not an assembly of the robot.
    """
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.identify.fisher import change_covariance
    from zerocal_sym.identify.linear import identification_matrix

    errors = robot.errors
    names = errors.resolve("default")
    offs, maemm = errors.zero_offsets, errors.measuring
    p = len(names)
    th, readings = _validate(meas, robot, p)
    prior = errors.zeros() if prior is None else np.asarray(prior, float)
    if prior.shape != (len(errors),) or not np.isfinite(prior).all():
        raise ValueError(f"prior must be a finite vector of the {len(errors)} source errors")
    P = kin.fk(robot, th + errors.take(prior, offs))
    if not np.isfinite(P).all():
        k = int(np.flatnonzero(~np.all(np.isfinite(P), axis=1))[0])
        raise PoseError("commanded joint angles are not an assembly of the robot", where=meas.where(k))
    maemm_prior = errors.take(prior, maemm)
    G, lam = identification_matrix(robot, P, maemm_prior=maemm_prior)
    b = readings[1:] - np.diff(lam)
    s = np.linalg.svd(G, compute_uv=False)
    if s[-1] <= RANK_RTOL * s[0]:
        from zerocal_sym.identify.identifiability import null_space_phrase

        rank = int(np.sum(s > RANK_RTOL * s[0]))
        why = null_space_phrase(robot, th, names, err0=prior)
        raise IdentificationError(
            f"identification matrix G has rank {rank} < {p}: the offsets and the MAEMM cannot be identified from "
            f"these poses ({why or 'the measuring-mechanism vectors of the poses are degenerate'}); measure other "
            "poses", where=meas.source)
    spread = np.linalg.svd(P - P.mean(axis=0), compute_uv=False)
    if spread[1] <= COLLINEAR_RTOL * spread[0]:
        raise IdentificationError(
            f"the {P.shape[0]} poses lie on one straight line: G is nearly rank-deficient (condition number "
            f"{s[0] / s[-1]:.3g}); use poses that span the workspace (e.g. the {robot.workspace.scheme_name} "
            "scheme's two boundaries)", where=meas.source)
    C = None
    if noise is not None and (diagnostics or (rule == "discrepancy" and t is None)):
        C = change_covariance(robot, th, noise, err0=prior)  # tridiagonal, as bands: O(K)
    noise_std = None if C is None else C.std()
    if rule == "discrepancy" and t is None and noise_std is None:
        raise ValueError("rule='discrepancy' needs a noise model")
    sol = tsvd_solve(G, b, t=t, rule=rule, rtol=rtol, noise_std=noise_std)
    # G's columns: offsets as lengths (lever * dtheta), then the MAEMM (mm)
    T = np.diag(1.0 / robot.error_scale(names))
    inc, est, status, info = _estimate(errors, names, prior, sol, s, T, P, maemm_prior)
    if not diagnostics:  # the estimate alone (the Monte Carlo): no covariance, residuals, honest std, fit check
        return _lean(errors, names, est, status, info)
    lin_res = b - G @ sol.x
    A = T @ sol.operator()
    m = G.shape[0]
    base = errors.put(errors.zeros(), offs + maemm, errors.take(prior, offs + maemm))  # what TSVD's model holds
    if C is not None:  # the servo error through the exact model at the estimate
        cov = change_covariance(robot, th, noise, err0=errors.put(base, names, est)).sandwich(A)  # A C A^T, O(K p^2)
    elif m > sol.t:
        cov = float(lin_res @ lin_res) / (m - sol.t) * (A @ A.T)
    else:
        cov = None
    full = errors.put(errors.zeros(), names, est)
    pred = np.diff(kin.distance(robot, th, full))
    residuals = np.asarray(meas.readings, float)[1:] - pred
    honest = _honest_uncertainty(robot, meas, names, errors.put(errors.zeros(), names, errors.take(prior, names)),
                                 noise, est, sol, cov, A=A, base=base)
    items = list(info.items())  # the keys in their documented order: linear_residuals after kappa
    info = dict(items[:5] + [("linear_residuals", lin_res)] + items[5:])
    info.update({k: v for k, v in honest.items() if not k.startswith("_")})
    res = IdentificationResult(method="tsvd", params=names, estimate=est, covariance=honest["_covariance"],
                               success=True, status=status, residuals=residuals, info=info, errors=errors,
                               std_kind=honest["_std_kind"])
    from zerocal_sym.identify import fitcheck

    exact = honest["_exact"]
    lin = exact.linear(np.asarray(info["fit_point"]) * exact.scale, honest["_basis"])
    fitcheck.check_result(robot, meas, res, lin, exact.noise, names, exact.prior_q,
                          fitcheck.DEFAULT_ALPHA if fit_alpha is None else fit_alpha, accept_misfit,
                          evaluated_at=honest["_evaluated_at"])
    res.info["fit"]["chi2_at_estimate"] = honest["_chi2_at_estimate"]
    _revisits(res, robot, th, exact, np.asarray(info["fit_point"]) * exact.scale)
    return res


def _revisits(res, robot, th, exact, z):
    """``info["revisits"]`` when the round revisits a pose (:func:`zerocal_sym.identify.revisits.revisit_report`,
    at the fit check's point)."""
    from zerocal_sym.identify.revisits import has_revisits, revisit_report

    if not has_revisits(robot, th):
        return
    try:
        e, A = exact.raw(z)
        rep = revisit_report(robot, th, e, A, exact.noise, exact.robot.errors.put(exact.prior_q, exact.names,
                                                                                   z / exact.scale))
    except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
        rep = {"reason": f"not estimated: {exc}"}
    if rep is not None:
        res.info["revisits"] = rep


def _estimate(errors, names, prior, sol, s, T, P, maemm_prior):
    """``(inc, est, status, info)`` of a TSVD solution (``T``: ``L dth`` to ``dth``; ``s``: G's singular values)."""
    inc = T @ sol.x
    est = errors.take(prior, names) + inc
    status = f"ok: TSVD t = {sol.t} of {s.size} ({sol.rule})"
    if sol.t < s.size:
        status += "; truncated directions are not identified (biased estimate)"
    info = {
        "singular_values": sol.singular_values,
        "truncation": sol.t,
        "filter_factors": sol.filter_factors,
        "rule": sol.rule,
        "kappa": float(s[0] / s[-1]),
        "increment": inc,
        "nominal_poses": P,
        "right_singular_vectors": sol.Vt,
        "maemm_prior": maemm_prior,
    }
    return inc, est, status, info


def _raise_if_interrupt(exc):
    """Re-raise Ctrl-C that C code turned into an error (CasADi's ``RuntimeError("KeyboardInterrupt")``, an
    error made of one): a batch must not swallow it (see ``zerocal_sym.cli._interrupt``)."""
    e, seen = exc, set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt) or (isinstance(e, RuntimeError) and str(e).strip() == "KeyboardInterrupt"):
            raise exc
        seen.add(id(e))
        e = e.__cause__ or e.__context__


def _lean(errors, names, est, status, info):
    """The result without diagnostics (``identify_tsvd(..., diagnostics=False)``)."""
    info["diagnostics"] = False
    return IdentificationResult(method="tsvd", params=names, estimate=est, covariance=None, success=True,
                                status=status + "; fit not checked (diagnostics off)", info=info,
                                errors=errors, std_kind="lower bound")


def identify_tsvd_many(robot, rounds, priors=None, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL, noise=None) -> list:
    """``identify_tsvd(robot, meas, prior, t=t, rule=rule, rtol=rtol, diagnostics=False)`` of many rounds at once.

    The kinematics, identification matrices and SVDs of all rounds (with
    the same number of poses) are evaluated in one batch; every batched
    operation acts on each round alone, so the results are those of one call
    per round bit for bit, at a fraction of the cost for short rounds (the
    Monte Carlo's loops run in lockstep through this:
    :func:`zerocal_sym.identify.loop.calibration_loops`).  A round the batch
    cannot take (a check fails, an unreachable pose) is identified alone.

    Parameters
    ----------
    rounds : sequence of Measurements
    priors : sequence of ndarray (q,) or None, optional
        One per round (default: all zero).
    t, rule, rtol
        As :func:`identify_tsvd` (no noise model: not the ``discrepancy`` rule).
    noise : NoiseModel, optional
        With it each result carries its std as :func:`identify_tsvd` computes it (``covariance``,
        ``std_kind``, ``info["std_kinds"]``, ``info["linearisation_bias"]``, ...;
        :func:`~zerocal_sym.identify.tsvd_uncertainty.attach_std_many`), still without the fit check; a
        truncated round (``t < p``) is identified alone, with diagnostics and ``fit_alpha=0``.

    Returns
    -------
    list
        Per round its :class:`IdentificationResult`, or the exception
        :func:`identify_tsvd` raised for it.
    """
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.model import kinematics as kin

    rounds = list(rounds)
    priors = [None] * len(rounds) if priors is None else list(priors)
    if len(priors) != len(rounds):
        raise ValueError(f"{len(rounds)} rounds but {len(priors)} priors")
    out = [None] * len(rounds)

    def alone(i):
        try:
            out[i] = identify_tsvd(robot, rounds[i], priors[i], t=t, rule=rule, rtol=rtol, noise=noise,
                                   diagnostics=noise is not None, fit_alpha=0.0)
        except Exception as exc:  # noqa: BLE001 - handed back as that round's outcome
            _raise_if_interrupt(exc)
            out[i] = exc

    errors = robot.errors
    if rule == "discrepancy" and t is None or robot.n < 2:
        for i in range(len(rounds)):
            alone(i)
        return out
    names = errors.resolve("default")
    p = len(names)
    i_off = [errors.index(n) for n in errors.zero_offsets]
    i_meas = [errors.index(n) for n in errors.measuring]
    T = np.diag(1.0 / robot.error_scale(names))
    groups = {}  # K -> [(i, theta_cmd, readings, prior)]
    for i, (meas, prior) in enumerate(zip(rounds, priors)):
        try:
            th, rd = _validate(meas, robot, p)
            prior = errors.zeros() if prior is None else np.asarray(prior, float)
            ok = prior.shape == (len(errors),) and np.isfinite(prior).all()
        except Exception as exc:  # noqa: BLE001 - alone, it raises the same
            _raise_if_interrupt(exc)
            ok = False
        if ok:
            groups.setdefault(th.shape[0], []).append((i, th, rd, prior))
        else:
            alone(i)
    for K, items in groups.items():
        keys = {}  # the kinematics, G and its SVD once per distinct (poses, prior): rounds of one design share them
        u = np.array([keys.setdefault((th.tobytes(), prior.tobytes()), len(keys)) for _, th, _, prior in items])
        first = [items[j] for j in np.unique(u, return_index=True)[1]]
        try:
            P = kin.fk(robot, np.concatenate([th + prior[i_off] for _, th, _, prior in first]))
            fin = np.isfinite(P).reshape(len(first), -1).all(axis=1)  # a round with an unreachable pose: alone
            sel = np.flatnonzero(fin)
            Nu = sel.size
            P3 = P.reshape(len(first), K, -1)[sel]
            mp = [first[j][3][i_meas] for j in sel]
            G, lam = identification_matrix(robot, P3.reshape(Nu * K, -1), maemm_prior=np.repeat(mp, K, axis=0))
            G = G[(np.arange(Nu)[:, None] * K + np.arange(K - 1)).ravel()].reshape(Nu, K - 1, p)
            lam = lam.reshape(Nu, K)
            S = np.linalg.svd(G, compute_uv=False)
            spread = np.linalg.svd(P3 - P3.mean(axis=1, keepdims=True), compute_uv=False)
            good = ((S[:, -1] > RANK_RTOL * S[:, 0]) & (spread[:, 1] > COLLINEAR_RTOL * spread[:, 0])
                    & np.isfinite(G).reshape(Nu, -1).all(axis=1))
            U, S2, Vt = np.linalg.svd(G[good], full_matrices=False) if good.any() else (None,) * 3
            at = np.cumsum(good) - 1  # position of a good G among the SVDs
            u = np.where(fin, np.cumsum(fin) - 1, -1)[u]  # each round's row among the finite distinct ones
        except Exception as exc:  # noqa: BLE001 - e.g. an unreachable pose: each round alone says which
            _raise_if_interrupt(exc)
            for i, *_ in items:
                alone(i)
            continue
        pending = []  # rounds whose std is computed together (a noise model given)
        for (i, th, rd, prior), j in zip(items, u):
            b = rd[1:] - np.diff(lam[j]) if j >= 0 else None
            if j < 0 or not (good[j] and np.isfinite(b).all()):
                alone(i)
                continue
            k = at[j]
            try:
                sol = _solve_svd(U[k], S2[k], Vt[k], b, K - 1, t, rule, rtol, None, 1.0)
            except Exception as exc:  # noqa: BLE001 - alone, it raises the same
                _raise_if_interrupt(exc)
                alone(i)
                continue
            if noise is not None and sol.t < p:  # the truncated directions' bound needs the exact fits: alone
                alone(i)
                continue
            _, est, status, info = _estimate(errors, names, prior, sol, S[j], T, P3[j], mp[j])
            out[i] = _lean(errors, names, est, status, info)
            if noise is not None:
                pending.append((out[i], th, rd, T @ sol.operator(), prior))
        if pending:
            from zerocal_sym.identify.tsvd_uncertainty import attach_std_many

            attach_std_many(robot, pending, noise)
    return out
