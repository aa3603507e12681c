"""Identification by truncated SVD (paper Eq. 28-29): the estimate, its fit check, the result.

The paper's identification model is linear in the increment ``dp`` of the
zero offsets as lengths and the MAEMM, ``(L1 dth1, L2 dth2, drMx, drMy)``
for the paper's robot, ``(L_i dth_i, drM)`` (m + n entries, mm) for any
mechanism (:mod:`zerocal_sym.identify.linear`):

    ds = G dp,   ds_k = s_k - (lambda_{k+1} - lambda_k),   G: (K-1) x (m + n),

solved by the truncated SVD ``dp = sum_{i<=t} (u_i^T ds / sigma_i) v_i``.

The estimate (:mod:`~zerocal_sym.identify.estimate.tsvd_round`: one round;
:mod:`~zerocal_sym.identify.estimate.tsvd_many`: many at once), the truncated
SVD itself and its truncation rules (``threshold``, the default; ``gcv``;
``discrepancy``: :mod:`~zerocal_sym.identify.estimate.truncated_svd`) and the
covariance with what TSVD leaves out (the linearisation bias, the truncated
directions' bias bound: :mod:`~zerocal_sym.identify.estimate.tsvd_uncertainty`)
are the estimate stage's.  Here the stages composed: :func:`identify_tsvd`
(the estimate, the fit check and its diagnosis, the revisits), and
:func:`identify_tsvd_many` (many rounds at once, the estimate only).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA
from zerocal_sym.identify.estimate.truncated_svd import DEFAULT_RTOL, DEFAULT_RULE
from zerocal_sym.identify.estimate.tsvd_many import tsvd_many
from zerocal_sym.identify.estimate.tsvd_round import tsvd_round
from zerocal_sym.identify.fitcheck import check_result

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
        Truncation rule (see :func:`~zerocal_sym.identify.estimate.truncated_svd.tsvd_solve`); default
        ``threshold``.
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
        leaves out**, per parameter (:mod:`~zerocal_sym.identify.estimate.tsvd_uncertainty`):
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
    res, honest = tsvd_round(robot, meas, prior, t=t, rule=rule, noise=noise, rtol=rtol, diagnostics=diagnostics)
    if honest is None:  # without diagnostics: the estimate alone
        return res
    th = np.asarray(meas.theta_cmd, float)
    info, names = res.info, res.params
    exact = honest["_exact"]
    lin = exact.linear(np.asarray(info["fit_point"]) * exact.scale, honest["_basis"])
    check_result(robot, meas, res, lin, exact.noise, names, exact.prior_q,
                 DEFAULT_ALPHA if fit_alpha is None else fit_alpha, accept_misfit,
                 evaluated_at=honest["_evaluated_at"])
    res.info["fit"]["chi2_at_estimate"] = honest["_chi2_at_estimate"]
    _revisits(res, robot, th, exact, np.asarray(info["fit_point"]) * exact.scale)
    return res


def _revisits(res, robot, th, exact, z):
    """``info["revisits"]`` when the round revisits a pose
    (:func:`zerocal_sym.identify.estimate.revisits.revisit_report`, at the fit check's point)."""
    from zerocal_sym.identify.estimate.revisits import has_revisits, revisit_report

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


def identify_tsvd_many(robot, rounds, priors=None, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL, noise=None) -> list:
    """``identify_tsvd(robot, meas, prior, t=t, rule=rule, rtol=rtol, diagnostics=False)`` of many rounds at once
    (:func:`~zerocal_sym.identify.estimate.tsvd_many.tsvd_many`: the results of one call per round, bit for bit).

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
        :func:`~zerocal_sym.identify.estimate.tsvd_uncertainty.attach_std_many`), still without the fit check; a
        truncated round (``t < p``) is identified alone, with diagnostics and ``fit_alpha=0``.

    Returns
    -------
    list
        Per round its :class:`IdentificationResult`, or the exception
        :func:`identify_tsvd` raised for it.
    """
    def alone(meas, prior):
        return identify_tsvd(robot, meas, prior, t=t, rule=rule, rtol=rtol, noise=noise,
                             diagnostics=noise is not None, fit_alpha=0.0)

    return tsvd_many(robot, rounds, priors, t=t, rule=rule, rtol=rtol, noise=noise, alone=alone)
