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

The pieces: :mod:`~zerocal_sym.identify.chi2` (:func:`chi2_sf`,
:func:`chi2_cdf`), :mod:`~zerocal_sym.identify.fitstats` (the linearised,
whitened problem, the chi² test and the per-reading statistics;
:data:`DEFAULT_ALPHA`, :data:`LEVERAGE_TOL`, :data:`RANK_RTOL`),
:mod:`~zerocal_sym.identify.exact_refits` (the exact model, the refits without
readings; :data:`REFINE_TOL`), :mod:`~zerocal_sym.identify.diagnosis` (the
causes, the paragraph, the verdict in the result).  Here: the functions of a
result, the plausibility limits and :data:`ROBUST_EXCLUDE_WEIGHT`; the names of
the pieces are importable from here too.
"""
from __future__ import annotations

import math

import numpy as np

# the pieces of the fit check, kept importable from here (callers, and the names the docstrings use)
from zerocal_sym.identify.chi2 import _gamma_pq, chi2_cdf, chi2_sf  # noqa: F401
from zerocal_sym.identify.diagnosis import (_diagnose, _paragraph, _summary, _variants, apply,  # noqa: F401
                                            finish)
from zerocal_sym.identify.exact_refits import REFINE_TOL, _Exact, _without_each, refits  # noqa: F401
from zerocal_sym.identify.fitstats import (DEFAULT_ALPHA, LEVERAGE_TOL, RANK_RTOL, _fmt_p, _Linear,  # noqa: F401
                                           _noise_dict, statistics)

#: a zero offset beyond this (deg) is not a zero offset but a wrong joint zero / sign / robot file
DEFAULT_MAX_OFFSET_DEG = 10.0
#: the same per file unit of the zero offsets (deg: revolute joints, mm: prismatic ones)
DEFAULT_MAX_OFFSET = {"deg": DEFAULT_MAX_OFFSET_DEG, "mm": 10.0}
#: a MAEMM (norm, mm) beyond this is not an assembly error but a wrong measuring-mechanism geometry
DEFAULT_MAX_MAEMM_MM = 50.0
#: a reading whose robust weight ends below this is an outlier: named, and left out of the fit check
#: (huber: |scale error| > 4 loss scales; soft_l1: > 3.9 loss scales)
ROBUST_EXCLUDE_WEIGHT = 0.25
#: a robust fit may leave out at most this fraction of the K - 1 readings (at least one): beyond, the data
#: are not a good set with a few bad readings but a model that does not fit them, and the fit is rejected
ROBUST_MAX_EXCLUDED_FRACTION = 0.25


def robust_exclusion_limit(n_readings: int) -> int:
    """How many of ``n_readings`` readings a robust fit may leave out (:data:`ROBUST_MAX_EXCLUDED_FRACTION`)."""
    return max(1, int(ROBUST_MAX_EXCLUDED_FRACTION * n_readings))


def _exact_for(robot, meas, result, noise=None) -> tuple:
    """(_Exact, z at the fit check's evaluation point, basis) of a result."""
    from zerocal_sym.model.noise import NoiseModel

    info = result.info
    if noise is None:
        nd = info.get("noise")
        noise = NoiseModel.from_dict(nd) if nd else NoiseModel.paper()
    prior_q = np.asarray(info.get("prior", robot.errors.zeros()), float)
    w = info.get("prior_whitener")
    exact = _Exact(robot, meas.theta_cmd, meas.readings, result.params, prior_q, noise,
                   None if w is None else np.asarray(w, float))
    z = np.asarray(info.get("fit_point", result.estimate), float) * exact.scale
    basis = info.get("fit_basis")
    return exact, z, (None if basis is None else np.asarray(basis, float))


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


def deletion_diagnostics(robot, meas, result, noise=None, threshold: float = 1.0, method: str = "refit") -> dict:
    """How much each reading moves the estimate: the change of every parameter when it is removed.

    ``method="refit"`` (default): the exact model refitted without the
    reading (the change of the correlated changes' covariance marginalised,
    Gauss-Newton from the data's fit reached from the estimate and from the
    prior, the better fit kept; every reading's first step a rank-one update
    of one evaluation, then exact steps per reading:
    :func:`~zerocal_sym.identify.leave_out.without_each`, O(K) per reading).  ``method="one-step"``: the
    mean-shift formula on the whitened model linearised at the estimate,
    ``dz_k = -F^+ J^T a_k delta_k`` (exact for the linearised model; poor when
    a large outlier has dragged the estimate far).

    Parameters
    ----------
    threshold : float
        Flag reading k when its removal moves any zero offset by more than
        ``threshold`` times that offset's standard deviation (``result.std``).

    Returns
    -------
    dict
        ``readings``: per reading ``pose``, ``from_pose``, ``leverage``,
        ``standardised``, ``estimated_error_mm`` (its misfit without it),
        ``change`` (name -> change in user units, deg / mm; None when removing
        it leaves the parameters unidentifiable), ``change_in_std`` (name ->
        |change| / std), ``chi2_without``, ``refit_converged`` (whether the
        refit without it converged; None for ``one-step``: where the rest of
        the readings still do not fit, Gauss-Newton may stop after its
        iterations wherever it is), ``flag``; ``flagged`` (poses, the
        most influential first), ``most_influential`` (pose), ``summary`` (a
        sentence naming them), ``threshold``, ``dof``, ``method``.
    """
    if method not in ("refit", "one-step"):
        raise ValueError(f"method must be 'refit' or 'one-step', got {method!r}")
    exact, z, basis = _exact_for(robot, meas, result, noise)
    lin = exact.linear(z, basis)
    t, lev, delta, dz = lin.per_reading()
    chi2w = np.full(lin.n, np.nan)
    conv = [None] * lin.n
    if method == "refit":
        out = _without_each(exact, z)
        dz = out["z"] - z
        dz[~np.isfinite(out["chi2"]) | (out["dof"] <= 0) & (lin.dof <= 0)] = np.nan
        delta = out["dropped_error_mm"]
        chi2w = out["chi2"]
        conv = [bool(c) for c in out["converged"]]
        # a reading the parameters need (leverage 1): its removal leaves them unidentifiable
        dz[lev > 1 - 1e-9] = np.nan
    errors = robot.errors
    names = result.params
    std = np.array([result.std(n) for n in names])
    offs = [i for i, n in enumerate(names) if n in errors.zero_offsets]
    rows, score = [], []
    for j in range(lin.n):
        k = int(lin.poses[j])
        dp = dz[j] / exact.scale
        ok = bool(np.all(np.isfinite(dp)))
        ratio = np.abs(dp) / std if ok else np.full(len(names), np.inf)
        sel = ratio[offs] if offs else ratio
        score.append(float(np.max(sel)) if sel.size else 0.0)
        rows.append({"pose": k, "from_pose": k - 1, "leverage": float(lev[j]),
                     "standardised": None if not np.isfinite(t[j]) else float(t[j]),
                     "estimated_error_mm": None if not np.isfinite(delta[j]) else float(delta[j]),
                     "chi2_without": None if not np.isfinite(chi2w[j]) else float(chi2w[j]),
                     "refit_converged": conv[j],
                     "change": ({n: errors.to_user_value(n, float(v)) for n, v in zip(names, dp)} if ok else None),
                     "change_in_std": ({n: float(v) for n, v in zip(names, ratio)} if ok else None),
                     "flag": bool(score[-1] > threshold)})
    order = np.argsort(-np.array(score), kind="stable")
    flagged = [rows[j]["pose"] for j in order if rows[j]["flag"]]
    by_pose = {r["pose"]: r for r in rows}

    def one(k):
        r = by_pose[k]
        if r["change_in_std"] is None:
            return f"pose {k} (removing it leaves the parameters unidentifiable)"
        cand = [n for n in r["change_in_std"] if n in errors.zero_offsets] or list(r["change_in_std"])
        worst = max(cand, key=lambda n: r["change_in_std"][n])
        e = r["estimated_error_mm"]
        return (f"pose {k} (moves {worst} by {r['change_in_std'][worst]:.2g} std"
                + (f"; its misfit {e:+.3g} mm" if e is not None else "") + ")")

    if flagged:
        summary = ("removing the reading at " + "; ".join(one(k) for k in flagged) +
                   f" moves a zero offset by more than {threshold:g} standard deviation(s); the most influential "
                   f"is the reading at pose {flagged[0]}")
        if lin.dof <= 1:
            summary += (f" (with {lin.dof} spare degree(s) of freedom every reading is influential: this does not "
                        "single out a bad one)")
    else:
        summary = f"no single reading moves a zero offset by more than {threshold:g} standard deviation(s)"
    return {"readings": rows, "flagged": flagged, "most_influential": int(rows[int(order[0])]["pose"]) if rows else None,
            "summary": summary, "threshold": float(threshold), "dof": int(lin.dof), "method": method}


def plausibility(robot, result, max_offset: float | None = None,
                 max_maemm_mm: float = DEFAULT_MAX_MAEMM_MM, max_offset_deg: float | None = None) -> list:
    """Reasons not to use ``result`` as a calibration (empty list: plausible).

    ``result``: an :class:`~zerocal_sym.identify.result.IdentificationResult`
    or a results file read by :func:`zerocal_sym.io.results.load_result`
    (``load_result(path, allow_failed=True, robot=robot)``, so that a failed
    one is reported here rather than refused there).

    * not a calibration: ``success`` is False (not converged, not
      identifiable, the fit rejected) -- a result accepted despite misfit is
      one;
    * a zero offset beyond ``max_offset`` (in the joints' unit; default 10
      deg for revolute joints: far beyond a homing error; the first-order
      model and TSVD's linearisation fail there, and it usually is a wrong
      joint zero, sign or robot file; 10 mm for prismatic joints: beyond an
      endstop's repeatability, a wrong robot file); ``max_offset_deg``, its
      former name, for revolute joints;
    * a MAEMM (norm of the measuring mechanism's assembly error) beyond
      ``max_maemm_mm`` (default 50 mm, ~7 % of the planar robot's measuring
      length: not an assembly error but a wrong ``c``/``d`` in the robot
      file);
    * a non-finite estimate or standard deviation of an offset; a MAEMM that
      is not finite (a results file without one: unknown, not a reason).
    """
    reasons = []
    if not result.success:
        reasons.append(f"the identification is not a calibration: {result.status}")
    errors = robot.errors
    unit = errors.offset_user_unit
    limit = max_offset if max_offset is not None else max_offset_deg
    limit = DEFAULT_MAX_OFFSET[unit] if limit is None else limit
    off = np.asarray(result.zero_offsets_user, float)
    for n, v in zip(errors.zero_offsets, off):
        if not np.isfinite(v):
            reasons.append(f"zero offset {n} is not a finite number")
        elif abs(v) > limit:
            reasons.append(f"zero offset {n} = {v:+.4g} {unit} is beyond the plausible {limit:g} {unit} "
                           "(a wrong joint zero, sign convention or robot file?)")
    params = getattr(result, "params", None)  # None: a results file (io.results.ResultFile)
    std = np.asarray(result.std_zero_offsets_user, float)
    for n, s in zip(errors.zero_offsets, std):
        if params is not None and n in params and not np.isfinite(s):
            reasons.append(f"the standard deviation of zero offset {n} is not finite (not identifiable)")
    mm = np.asarray(result.maemm_mm, float)
    norm = math.hypot(*mm.tolist()) if mm.size and np.all(np.isfinite(mm)) else None  # (no overflow: 1e308 mm)
    if norm is not None and norm > max_maemm_mm:
        reasons.append(f"MAEMM |rM| = {norm:.4g} mm is beyond the plausible {max_maemm_mm:g} mm "
                       "(the measuring mechanism's c / d in the robot file?)")
    elif mm.size and not np.all(np.isfinite(mm)) and params is not None:
        reasons.append("the MAEMM is not finite")
    return reasons
