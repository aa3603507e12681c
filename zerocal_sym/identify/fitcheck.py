"""Can this calibration be trusted?  Fit check, outlier diagnostics, plausibility.

Every identification (:func:`~zerocal_sym.identify.nlls.identify_nlls`,
:func:`~zerocal_sym.identify.tsvd.identify_tsvd`) ends with :func:`fit_check`'s
core: the residuals of the **exact** model at the estimate, whitened by the
noise model's covariance of the changes, are tested against it.

chi² test
    ``chi2 = |r_w|^2`` (+ the whitened prior residuals of a MAP fit) on
    ``dof = (K - 1) + (prior rows) - rank`` degrees of freedom: ``rank`` is the
    number of identified parameters (of identified combinations when the
    problem is rank-deficient; TSVD: its truncation level ``t``, so the
    truncated directions' misfit stays in the chi²).  ``p = P(chi2_dof >= chi2)``
    by :func:`chi2_sf` (regularised incomplete gamma, no scipy).  The fit is
    **rejected** when ``p < alpha`` (default :data:`DEFAULT_ALPHA` = 0.001):
    the result gets ``success = False`` and a status starting with
    ``"rejected"``.  ``accept_misfit=True`` keeps the calibration (status
    ``"accepted despite misfit ..."``, recorded in ``info["fit"]``).  A chi² far
    *below* its dof (lower tail ``< alpha``) is a warning, not a rejection (the
    noise model overstates the noise: the standard deviations are too large).
    It cannot be checked -- and is never rejected -- with no spare degree of
    freedom (``dof = 0``) or a zero noise model (noise-free weighting by 1 um
    has no noise level to test against).

Largest standardised residual
    The second test (:mod:`~zerocal_sym.identify.check.max_reading`): the
    largest ``|t_k|`` (below) over the testable readings, its p-value by
    Sidak's correction for their number (an upper bound, whatever their
    correlation); the fit is also **rejected** when it is below ``alpha`` --
    one reading far off among many, which the chi² dilutes.  The status then
    names that reading (its cause: the exact refit without it).  Together the
    two tests refuse a clean round at most ``2 alpha`` of the time.

Per reading
    For reading ``k`` (the change from pose ``k-1`` to pose ``k``) the
    standardised residual is the mean-shift outlier statistic
    ``t_k = a_k^T r_w / sqrt(a_k^T (I - H) a_k)``, ``a_k = W e_k`` the whitened
    indicator of reading ``k`` and ``H`` the hat matrix of the whitened
    Jacobian; ``t_k^2`` is the drop of chi² when reading ``k`` alone is given a
    free error ``delta_k = a_k^T r_w / a_k^T (I - H) a_k`` (mm; the estimated
    error of that reading), and ``t_k ~ N(0, 1)`` under the noise model.  With
    a diagonal covariance (scale error only) it is ``r_k / sqrt(1 - h_kk)``;
    with the servo error the changes are correlated and ``t_k`` is its exact
    generalisation.  The leverage reported is ``1 - a^T (I - H) a / a^T a``
    (``h_kk`` for a diagonal covariance).

Causes (when rejected; each refit is the exact model from the prior, a few ms)
    * a bad reading at pose ``k``: with ``dof >= 2``, removing reading ``k``
      (``chi2 - t_k^2`` on ``dof - 1``) makes the fit acceptable; with one spare
      degree of freedom every reading explains the misfit equally and none can
      be named;
    * readings cumulative (the head not reset): refit on their differences;
    * sign-flipped readings: refit on their negatives;
    * poses out of order: refit with the poses reversed, or two consecutive
      poses swapped;
    * otherwise: a wrong robot file (systematic misfit) or a noise model that
      understates the noise by about ``sqrt(chi2 / dof)``.
    A cause is *detected* when its refit passes the test (``p >= alpha``).

:func:`deletion_diagnostics` -- the change of every parameter when one
reading is removed (the one-step mean-shift formula, exact for the linearised
model), flagging readings whose removal moves a zero offset by more than its
standard deviation.  :func:`plausibility` -- reasons to refuse a result
(offsets beyond :data:`DEFAULT_MAX_OFFSET_DEG`, MAEMM beyond
:data:`DEFAULT_MAX_MAEMM_MM`, not converged).

The stages: the chi² test and the per-reading statistics
(:mod:`~zerocal_sym.identify.check.statistics`, on the whitened problem of
:mod:`~zerocal_sym.identify.whitened`), the plausibility limits
(:mod:`~zerocal_sym.identify.check.plausibility`), a robust fit's outliers
(:mod:`~zerocal_sym.identify.check.robust_fit`); the causes and the verdict in
the result (:mod:`~zerocal_sym.identify.diagnose.causes`,
:mod:`~zerocal_sym.identify.diagnose.verdict`), the deletion diagnostics and
the refits without readings (:mod:`~zerocal_sym.identify.diagnose.deletions`,
:mod:`~zerocal_sym.identify.diagnose.leave_out`), on the exact model of
:mod:`~zerocal_sym.identify.estimate.exact_model`.  Here they are composed:
:func:`fit_check` (a result's fit check, recomputed) and :func:`check_result`
(the fit check as the identifications call it); the public names of the
stages are importable from here too.
"""
from __future__ import annotations

import numpy as np

# the public names of the fit check's stages, importable from here (callers, and the names the docstrings use)
from zerocal_sym.identify.check.plausibility import (DEFAULT_MAX_MAEMM_MM, DEFAULT_MAX_OFFSET,  # noqa: F401
                                                     DEFAULT_MAX_OFFSET_DEG, plausibility)
from zerocal_sym.identify.check.robust_fit import ROBUST_EXCLUDE_WEIGHT, robust_exclusion_limit  # noqa: F401
from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA, statistics
from zerocal_sym.identify.chi2 import chi2_cdf, chi2_sf  # noqa: F401
from zerocal_sym.identify.diagnose.deletions import deletion_diagnostics  # noqa: F401
from zerocal_sym.identify.diagnose.verdict import apply, finish
from zerocal_sym.identify.estimate.exact_model import _Exact, _exact_for
from zerocal_sym.identify.whitened import _Linear


def fit_check(robot, meas, result, noise=None, alpha: float = DEFAULT_ALPHA, diagnose: bool = True) -> dict:
    """The fit check of an identification, recomputed from the exact model.

    Parameters
    ----------
    robot, meas
        As identified.
    result : IdentificationResult
        Evaluated at its estimate (TSVD: at the exact-model minimum over its
        kept directions, ``info["fit_point"]``); the parameters not
        identified at ``info["prior"]``.
    noise : NoiseModel, optional
        Default: the result's (``info["noise"]``), else the paper's.
    alpha : float
        Reject when ``p < alpha``.
    diagnose : bool
        Look for the causes of a rejection (refits, a few ms).

    Returns
    -------
    dict
        See :func:`statistics`, plus ``causes`` (list of dicts with
        ``cause``, ``detected``, ``text``, ``evidence``) and ``diagnosis`` (a
        paragraph).  Nothing in ``result`` is changed (:func:`apply` does).
    """
    exact, z, basis = _exact_for(robot, meas, result, noise)
    lin = exact.linear(z, basis)
    fit = statistics(lin, exact.noise, alpha)
    return finish(fit, exact, diagnose, z)


def check_result(robot, meas, result, lin: _Linear, noise, names, prior_q, alpha: float = DEFAULT_ALPHA,
                 accept_misfit: bool = False, prior_whitener=None, evaluated_at: str = "estimate",
                 active_bounds=()):
    """The fit check as the identifications call it: statistics of ``lin``, causes, :func:`apply`."""
    fit = statistics(lin, noise, alpha)
    fit["evaluated_at"] = evaluated_at
    fit["active_bounds"] = list(active_bounds)
    exact = None
    if fit["rejected"]:
        try:
            exact = _Exact(robot, meas.theta_cmd, meas.readings, names, prior_q, noise, prior_whitener)
        except Exception:  # noqa: BLE001 - no refits then; the paragraph says what it could not check
            exact = None
    z_est = np.asarray(result.info.get("fit_point", result.estimate), float) * lin.scale
    return apply(result, finish(fit, exact, z_est=z_est), accept_misfit)
