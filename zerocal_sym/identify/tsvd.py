"""Identification by truncated SVD (paper Eq. 28-29).

The paper's identification model is linear in the increment ``dp`` of the
zero offsets as lengths and the MAEMM, ``(L1 dth1, L2 dth2, drMx, drMy)``
for the paper's robot, ``(L_i dth_i, drM)`` (m + n entries, mm) for any
mechanism (:mod:`zerocal_sym.identify.linear`):

    ds = G dp,   ds_k = s_k - (lambda_{k+1} - lambda_k),   G: (K-1) x (m + n),

solved by the truncated SVD ``dp = sum_{i<=t} (u_i^T ds / sigma_i) v_i``.

Truncation rules (:func:`tsvd_solve`)
-------------------------------------
``threshold`` (**the default**)
    keep ``sigma_i > rtol * sigma_1`` (default ``rtol = 1e-6``).  For the
    paper's 4-parameter model this keeps all four singular values (``sigma_4 /
    sigma_1 ~ 2.1e-3`` for the 6-pose scheme): the weakest direction (the
    common mode of the offsets mixed with ``rMx``) carries the offsets, and
    truncating it loses them (~0.4 deg even without noise, see
    ``docs/reproduction.md``).  In the paper the "truncation" is the reduction
    from the 12-parameter model (Eq. 24-27) to the 4-parameter one (Eq. 28);
    Eq. (29) is then solved at full rank.  It is the default because it is the
    only rule that reproduces the paper's accuracy and recovers the offsets
    exactly without noise.
``gcv``
    generalised cross-validation, ``t = argmin ||r_t||^2 / (m - t)^2``
    (``t < m``).  With ``m - p = 1`` degree of freedom (6 poses) it is fragile.
``discrepancy``
    Morozov's discrepancy principle: the smallest ``t`` with
    ``||r_t|| <= tau * delta``, ``delta^2 = sum(noise_std^2)`` the expected
    squared norm of the noise (``tau = 1``).  Needs the noise level, e.g. from
    a :class:`~zerocal_sym.model.noise.NoiseModel` (:func:`identify_tsvd`
    derives it from the measurement covariance).

An explicit ``t`` overrides the rule.  The filter factors of TSVD are 1 for the
kept singular values and 0 for the others.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.errors import IdentificationError, PoseError
from zerocal_sym.identify.result import IdentificationResult

RULES = ("threshold", "gcv", "discrepancy")
DEFAULT_RULE = "threshold"
DEFAULT_RTOL = 1e-6
#: G with sigma_min / sigma_max below this is treated as rank-deficient (collinear poses).
RANK_RTOL = 1e-9
#: poses whose second principal extent is below this fraction of the first are "on one line".
COLLINEAR_RTOL = 1e-6


@dataclass
class TSVDSolution:
    """A truncated-SVD solution of ``G x = b``.

    Attributes
    ----------
    x : ndarray, shape (p,)
    t : int
        Truncation level (number of singular values kept).
    singular_values : ndarray, shape (min(m, p),)
        All singular values of G, descending.
    filter_factors : ndarray, shape (min(m, p),)
        1 for kept, 0 for discarded singular values.
    rule : str
        ``"threshold"``, ``"gcv"``, ``"discrepancy"`` or ``"fixed"`` (t given).
    U : ndarray, shape (m, r)
    Vt : ndarray, shape (r, p)
    residual_norms : ndarray, shape (r + 1,)
        ``||G x_t - b||`` for ``t = 0 .. r``.
    criterion : ndarray, shape (r + 1,) or None
        GCV function (``gcv``) for each ``t``; None otherwise.
    """

    x: np.ndarray
    t: int
    singular_values: np.ndarray
    filter_factors: np.ndarray
    rule: str
    U: np.ndarray = field(repr=False, default=None)
    Vt: np.ndarray = field(repr=False, default=None)
    residual_norms: np.ndarray = field(repr=False, default=None)
    criterion: np.ndarray | None = field(repr=False, default=None)

    @property
    def condition_number(self) -> float:
        s = self.singular_values
        return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")

    def operator(self) -> np.ndarray:
        """The linear map ``b -> x`` of this truncation, shape (p, m)."""
        t = self.t
        return (self.Vt[:t].T / self.singular_values[:t]) @ self.U[:, :t].T


def tsvd_solve(G, b, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL, noise_std=None, tau=1.0) -> TSVDSolution:
    """Truncated-SVD solution of ``G x = b``.

    Parameters
    ----------
    G : ndarray, shape (m, p)
    b : ndarray, shape (m,)
    t : int, optional
        Truncation level, ``1 <= t <= min(m, p)``; overrides ``rule``.
    rule : {"threshold", "gcv", "discrepancy"}
        Automatic choice of ``t`` (module docstring); default ``threshold``.
    rtol : float
        Relative singular-value threshold of the ``threshold`` rule.
    noise_std : float or ndarray, shape (m,), optional
        Noise std of each element of ``b`` (``discrepancy`` rule; required there).
    tau : float
        Safety factor of the discrepancy principle.

    Returns
    -------
    TSVDSolution
    """
    G = np.asarray(G, float)
    b = np.asarray(b, float)
    if G.ndim != 2 or b.shape != (G.shape[0],):
        raise ValueError(f"G must be (m, p) and b (m,), got {G.shape} and {b.shape}")
    if not (np.isfinite(G).all() and np.isfinite(b).all()):
        raise IdentificationError("G or b contains NaN or inf")
    U, s, Vt = np.linalg.svd(G, full_matrices=False)
    return _solve_svd(U, s, Vt, b, G.shape[0], t, rule, rtol, noise_std, tau)


def _solve_svd(U, s, Vt, b, m, t, rule, rtol, noise_std, tau) -> TSVDSolution:
    """:func:`tsvd_solve` from the thin SVD ``U, s, Vt`` of the checked G (m rows)."""
    r = s.size
    beta = U.T @ b
    # ||r_t||^2 = ||b||^2 - sum_{i<=t} beta_i^2 (exact for the thin SVD plus the orthogonal part)
    tail = np.concatenate([np.cumsum((beta**2)[::-1])[::-1], [0.0]])
    perp = max(float(b @ b) - float(beta @ beta), 0.0)
    res2 = tail + perp
    criterion = None
    positive = int(np.count_nonzero(s > 0))
    if t is not None:
        t = int(t)
        if not 1 <= t <= r:
            raise ValueError(f"truncation t must be in 1..{r}, got {t}")
        used = "fixed"
    elif rule == "threshold":
        t = int(np.count_nonzero(s > rtol * s[0])) if s[0] > 0 else 0
        used = rule
    elif rule == "gcv":
        ts = np.arange(r + 1)
        criterion = np.full(r + 1, np.inf)
        ok = (ts < m) & (ts <= positive)
        criterion[ok] = res2[ok] / (m - ts[ok]) ** 2.0
        criterion[0] = np.inf
        t = int(np.argmin(criterion))
        used = rule
    elif rule == "discrepancy":
        if noise_std is None:
            raise ValueError("the discrepancy principle needs the noise level (noise_std)")
        delta = float(np.sqrt(np.sum(np.broadcast_to(np.asarray(noise_std, float), b.shape) ** 2)))
        ok = np.flatnonzero(np.sqrt(res2[1:positive + 1]) <= tau * delta)
        t = int(ok[0]) + 1 if ok.size else positive
        used = rule
    else:
        raise ValueError(f"unknown truncation rule {rule!r} (known: {', '.join(RULES)})")
    if t < 1:
        raise IdentificationError("G is zero: nothing can be identified")
    f = (np.arange(r) < t).astype(float)
    x = Vt[:t].T @ (beta[:t] / s[:t])
    return TSVDSolution(x=x, t=t, singular_values=s, filter_factors=f, rule=used, U=U, Vt=Vt,
                        residual_norms=np.sqrt(res2), criterion=criterion)


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


def identify_tsvd(robot, meas, prior=None, t=None, rule=DEFAULT_RULE, noise=None, rtol=DEFAULT_RTOL,
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
        ``method = "tsvd"``, params: the zero offsets and the MAEMM.  ``covariance``
        is that of the linear TSVD estimator ``x = A b`` (``A = V_t S_t^-1
        U_t^T``) under the noise model, ``T A C A^T T`` with ``C`` the
        covariance of the measured changes (:func:`zerocal_sym.identify.fisher.
        measurement_covariance`, servo error propagated to first order) and
        ``T`` converting ``L dth`` to ``dth``.  Without a noise model it is
        ``s^2 T A A^T T`` with ``s^2 = ||r||^2 / (K - 1 - t)`` (white noise
        estimated from the linear residuals), or None if ``K - 1 = t``.
        **What TSVD leaves out is added** (``std_kind = "total"``, or
        ``"from residuals"`` without a noise model): the linearisation bias
        ``b = estimate - (exact-model minimum over the kept directions, Gauss-
        Newton from the estimate)`` as ``b b^T``, and for each truncated
        direction ``v_i`` a bias bound ``(|c_i| + 2 sd_i)^2 T v_i v_i^T T``
        (``c_i`` its component in the full-rank exact fit, ``sd_i`` that
        component's std); if these cannot be evaluated the std is labelled
        ``"lower bound"``.  ``info["covariance_noise"]`` is the noise part
        alone, ``info["std_components"]`` the three parts per parameter.
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
    names = errors.resolve("offsets+measuring")
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
        rank = int(np.sum(s > RANK_RTOL * s[0]))
        raise IdentificationError(
            f"identification matrix G has rank {rank} < {p}: the measuring-mechanism vectors of the poses "
            "are degenerate, the offsets and the MAEMM cannot be identified", where=meas.source)
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
    if C is not None:
        cov = C.sandwich(A)  # A C A^T from the bands, O(K p^2)
    elif m > sol.t:
        cov = float(lin_res @ lin_res) / (m - sol.t) * (A @ A.T)
    else:
        cov = None
    full = errors.put(errors.zeros(), names, est)
    pred = np.diff(kin.distance(robot, th, full))
    residuals = np.asarray(meas.readings, float)[1:] - pred
    honest = _honest_uncertainty(robot, meas, names, errors.put(errors.zeros(), names, errors.take(prior, names)),
                                 noise, est, sol, cov)
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
    return res


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


def identify_tsvd_many(robot, rounds, priors=None, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL) -> list:
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
            out[i] = identify_tsvd(robot, rounds[i], priors[i], t=t, rule=rule, rtol=rtol, diagnostics=False)
        except Exception as exc:  # noqa: BLE001 - handed back as that round's outcome
            _raise_if_interrupt(exc)
            out[i] = exc

    errors = robot.errors
    if rule == "discrepancy" and t is None or robot.n < 2:
        for i in range(len(rounds)):
            alone(i)
        return out
    names = errors.resolve("offsets+measuring")
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
        try:
            P = kin.fk(robot, np.concatenate([th + prior[i_off] for _, th, _, prior in items]))
            fin = np.isfinite(P).reshape(len(items), -1).all(axis=1)
            for (i, *_), f in zip(items, fin):
                if not f:
                    alone(i)
            items = [it for it, f in zip(items, fin) if f]
            if not items:
                continue
            N = len(items)
            P = P.reshape(-1, K, P.shape[1])[fin].reshape(N * K, -1)
            mp = [prior[i_meas] for *_, prior in items]
            G, lam = identification_matrix(robot, P, maemm_prior=np.repeat(mp, K, axis=0))
            G = G[(np.arange(N)[:, None] * K + np.arange(K - 1)).ravel()].reshape(N, K - 1, p)
            lam = lam.reshape(N, K)
            B = np.array([rd for _, _, rd, _ in items])[:, 1:] - np.diff(lam, axis=1)
            S = np.linalg.svd(G, compute_uv=False)
            P3 = P.reshape(N, K, -1)
            spread = np.linalg.svd(P3 - P3.mean(axis=1, keepdims=True), compute_uv=False)
            good = ((S[:, -1] > RANK_RTOL * S[:, 0]) & (spread[:, 1] > COLLINEAR_RTOL * spread[:, 0])
                    & np.isfinite(G).reshape(N, -1).all(axis=1) & np.isfinite(B).all(axis=1))
            U, S2, Vt = np.linalg.svd(G[good], full_matrices=False)
        except Exception as exc:  # noqa: BLE001 - e.g. an unreachable pose: each round alone says which
            _raise_if_interrupt(exc)
            for i, *_ in items:
                alone(i)
            continue
        k = 0
        for j, (i, th, rd, prior) in enumerate(items):
            if not good[j]:
                alone(i)
                continue
            try:
                sol = _solve_svd(U[k], S2[k], Vt[k], B[j], K - 1, t, rule, rtol, None, 1.0)
            except Exception as exc:  # noqa: BLE001 - alone, it raises the same
                _raise_if_interrupt(exc)
                alone(i)
                k += 1
                continue
            k += 1
            _, est, status, info = _estimate(errors, names, prior, sol, S[j], T, P3[j], mp[j])
            out[i] = _lean(errors, names, est, status, info)
    return out


def _honest_uncertainty(robot, meas, names, prior_eff, noise, est, sol, cov_noise) -> dict:
    """TSVD's covariance with what it leaves out: linearisation bias and truncated directions' bias bound.

    Returns a dict: ``_covariance`` (total), ``_std_kind``, ``_exact`` (the exact
    whitened model), ``_basis`` (kept directions, scaled), ``_evaluated_at``,
    ``_chi2_at_estimate`` and the JSON-ready ``info`` entries
    ``covariance_noise``, ``linearisation_bias``, ``truncation_bias_bound``,
    ``std_components``, ``std_note``, ``fit_point``, ``fit_basis``, ``prior``, ``noise``.
    """
    from zerocal_sym.identify import fitcheck
    from zerocal_sym.model.noise import NoiseModel

    errors = robot.errors
    nm = NoiseModel() if noise is None else noise
    exact = fitcheck._Exact(robot, meas.theta_cmd, meas.readings, names, prior_eff, nm)
    sc = exact.scale
    p, t = len(names), sol.t
    basis = sol.Vt[:t].T
    z_est = est * sc
    r_est = exact.evaluate(z_est)[0]
    out = {"_exact": exact, "_basis": basis, "_chi2_at_estimate": float(r_est @ r_est),
           "_std_kind": "total" if noise is not None else "from residuals",
           "prior": prior_eff.tolist(), "noise": {"sigma_scale_mm": nm.sigma_scale_mm,
                                                  "sigma_servo_rad": nm.sigma_servo_rad},
           "fit_basis": basis.tolist(),
           "covariance_noise": None if cov_noise is None else np.asarray(cov_noise).tolist()}
    notes = []
    b_lin = np.full(p, np.nan)
    bound = np.zeros(p)
    trunc = np.zeros((p, p))
    z_ref = z_est
    try:
        z_ref = exact.refine(z_est, basis)
        b_lin = est - z_ref / sc
        if t < p:
            z_full = exact.refine(z_ref, None)
            lin = exact.linear(z_full)
            Finv = np.linalg.pinv(lin.J.T @ lin.J)
            if nm.is_zero:  # unit weights: the noise level from the residuals of the full fit
                Finv = Finv * (float(lin.r @ lin.r) / lin.dof if lin.dof > 0 else np.nan)
            for i in range(t, p):
                v = sol.Vt[i]
                c = float(v @ (z_full - z_ref))
                bi = abs(c) + 2.0 * float(np.sqrt(max(v @ Finv @ v, 0.0)))
                u = v / sc
                trunc += bi**2 * np.outer(u, u)
                bound = np.sqrt(bound**2 + (bi * u) ** 2)
    except (FloatingPointError, np.linalg.LinAlgError, ValueError) as exc:
        notes.append(f"the exact-model refinement failed ({exc}): the linearisation and truncation biases are not "
                     "in the std")
    if not (np.all(np.isfinite(b_lin)) and np.all(np.isfinite(trunc))):
        out["_std_kind"] = "lower bound"
        if not notes:
            notes.append("the truncated directions' bias could not be bounded: it is not in the std")
        b_lin = np.where(np.isfinite(b_lin), b_lin, 0.0)
        trunc = np.where(np.isfinite(trunc), trunc, 0.0)
        bound = np.where(np.isfinite(bound), bound, 0.0)
    if cov_noise is None:
        cov = None
        out["_std_kind"] = "lower bound"
        notes.append("no noise model and no spare degree of freedom: the noise part of the std is unknown")
    else:
        cov = np.asarray(cov_noise) + np.outer(b_lin, b_lin) + trunc
    noise_sd = (np.sqrt(np.diag(cov_noise)) if cov_noise is not None else np.full(p, np.nan))
    out["_covariance"] = cov
    out["_evaluated_at"] = ("the exact-model minimum over TSVD's kept directions (Gauss-Newton from its estimate)"
                            if np.any(z_ref != z_est) else "estimate")
    out["fit_point"] = (z_ref / sc).tolist()
    out["linearisation_bias"] = b_lin.tolist()
    out["truncation_bias_bound"] = bound.tolist()
    out["std_components"] = {
        n: {"noise": None if not np.isfinite(noise_sd[k]) else errors.to_user_value(n, float(noise_sd[k])),
            "linearisation_bias": errors.to_user_value(n, float(b_lin[k])),
            "truncation_bias_bound": errors.to_user_value(n, float(bound[k])),
            "unit": errors[n].user_unit}
        for k, n in enumerate(names)}
    out["std_note"] = ("; ".join(notes) if notes else
                       "std = sqrt(noise^2 + linearisation bias^2 + truncation bias bound^2) per parameter "
                       "(covariance: noise + b b^T + bound terms)")
    return out
