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
"""
from __future__ import annotations

import math

import numpy as np

#: significance level of the fit check (reject when p < alpha)
DEFAULT_ALPHA = 1e-3
#: a zero offset beyond this (deg) is not a zero offset but a wrong joint zero / sign / robot file
DEFAULT_MAX_OFFSET_DEG = 10.0
#: a MAEMM (norm, mm) beyond this is not an assembly error but a wrong measuring-mechanism geometry
DEFAULT_MAX_MAEMM_MM = 50.0
#: a reading whose mean-shift information is below this fraction of its own is not testable (leverage ~1)
LEVERAGE_TOL = 1e-9
#: relative singular-value threshold for the rank of the whitened Jacobian
RANK_RTOL = 1e-9
#: exact-model refinement (TSVD) stops when its step (scaled units, mm) is below this
REFINE_TOL = 1e-9
#: a reading whose robust weight ends below this is an outlier: named, and left out of the fit check
#: (huber: |scale error| > 4 loss scales; soft_l1: > 3.9 loss scales)
ROBUST_EXCLUDE_WEIGHT = 0.25


# ============================================================== chi² distribution (no scipy)
def _gamma_pq(a: float, x: float) -> tuple:
    """Regularised incomplete gamma ``(P(a, x), Q(a, x))`` (series below ``a + 1``, continued fraction above)."""
    if x <= 0.0:
        return 0.0, 1.0
    if math.isinf(x):
        return 1.0, 0.0
    log_pre = -x + a * math.log(x) - math.lgamma(a)
    if x < a + 1.0:
        ap, term = a, 1.0 / a
        total = term
        for _ in range(100000):
            ap += 1.0
            term *= x / ap
            total += term
            if abs(term) < abs(total) * 1e-17:
                break
        p = math.exp(log_pre) * total if log_pre > -745.0 else 0.0
        p = min(max(p, 0.0), 1.0)
        return p, 1.0 - p
    tiny = 1e-300
    b = x + 1.0 - a
    c, d = 1.0 / tiny, 1.0 / b
    h = d
    for i in range(1, 100000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1.0 / d
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-16:
            break
    log_q = log_pre + math.log(h)
    q = math.exp(log_q) if log_q > -745.0 else 0.0
    q = min(max(q, 0.0), 1.0)
    return 1.0 - q, q


def chi2_sf(x, dof) -> float:
    """Survival function ``P(X >= x)`` of the chi² distribution with ``dof`` degrees of freedom.

    ``Q(dof/2, x/2)``, the regularised upper incomplete gamma function
    (series / Lentz continued fraction, :func:`math.lgamma`); accurate to
    ~1e-14 relative, down to ~1e-300 (then 0.0).  ``dof`` may be non-integer.

    Raises
    ------
    ValueError
        ``dof <= 0`` or not finite.
    """
    dof = float(dof)
    if not (dof > 0 and math.isfinite(dof)):
        raise ValueError(f"chi2_sf: dof must be positive, got {dof}")
    x = float(x)
    if math.isnan(x):
        return float("nan")
    return _gamma_pq(0.5 * dof, 0.5 * x)[1]


def chi2_cdf(x, dof) -> float:
    """Distribution function ``P(X <= x)`` (the lower tail, accurate when small)."""
    dof = float(dof)
    if not (dof > 0 and math.isfinite(dof)):
        raise ValueError(f"chi2_cdf: dof must be positive, got {dof}")
    x = float(x)
    if math.isnan(x):
        return float("nan")
    return _gamma_pq(0.5 * dof, 0.5 * x)[0]


# ============================================================== linearised, whitened problem
def band_whitener(l, b) -> np.ndarray:
    """``L^-1`` for the lower-bidiagonal Cholesky factor (diagonal ``l``, sub-diagonal ``b``), dense."""
    l = np.ravel(np.asarray(l, float))
    n = l.size
    L = np.diag(l)
    if n > 1:
        L.ravel()[n::n + 1] = np.ravel(b)[: n - 1]   # the sub-diagonal
    return np.linalg.inv(L)


class _Linear:
    """The whitened problem at the evaluation point of a fit check.

    ``r`` (N,) whitened residuals, data rows first (n of them) then the prior
    rows; ``J`` (N, c) whitened Jacobian w.r.t. the fitted coordinates;
    ``W`` (n, n) the whitener of the data rows, or None with ``band=(l, b)``,
    the banded Cholesky factor it is the inverse of (``W`` is then built
    only if asked for); ``poses`` (n,) the pose index k of each data row;
    ``raw`` (n,) residuals in mm; ``basis`` (p, c) maps the fitted
    coordinates to the scaled parameters ``z`` (``p = z / scale``).
    ``svd``: the caller's thin SVD of ``J`` (its U may carry extra zero rows
    below); ``terms``: the per-reading statistics ``(t, leverage, delta,
    move)`` computed without ``W`` (``nlls_problem._fit_terms``; full column
    rank, no prior rows).
    """

    def __init__(self, r, J, W, poses, raw, basis, scale, names, n_prior_rows=0, point=None, svd=None,
                 band=None, terms=None):
        self.r = np.asarray(r, float)
        self.J = np.atleast_2d(np.asarray(J, float))
        self.poses = np.asarray(poses, int)
        self.raw = np.asarray(raw, float)
        self.basis = np.asarray(basis, float)
        self.scale = np.asarray(scale, float)
        self.names = tuple(names)
        self.n = self.poses.size
        self.n_prior_rows = int(n_prior_rows)
        self.point = point
        self._W, self._band, self._terms = (None if W is None else np.asarray(W, float)), band, terms
        if W is None and band is None:
            raise ValueError("_Linear needs W or band")
        if self._W is not None:
            w_ok = bool(np.isfinite(self._W).all())
        else:
            l, b = (np.ravel(np.asarray(x, float)) for x in band)
            w_ok = bool(np.isfinite(l).all() and np.isfinite(b).all() and np.all(l != 0))
        #: False when the exact model cannot be evaluated there (a pose is not an assembly with these errors)
        self.valid = bool(np.isfinite(self.r).all() and np.isfinite(self.J).all() and w_ok)
        if not self.valid:
            self.r = np.where(np.isfinite(self.r), self.r, 0.0)
            self.J = np.where(np.isfinite(self.J), self.J, 0.0)
            self._W = np.where(np.isfinite(self.W), self.W, 0.0)
            svd, self._terms = None, None
        if svd is None:
            U, s, Vt = np.linalg.svd(self.J, full_matrices=False)
        else:
            U, s, Vt = svd
            U = U[: self.J.shape[0]]
        tol = RANK_RTOL * (s[0] if s.size else 0.0)
        self.rank = int(np.count_nonzero(s > tol)) if s.size else 0
        self.U, self.s, self.Vt = U[:, : self.rank], s[: self.rank], Vt[: self.rank]
        self.dof = self.n + self.n_prior_rows - self.rank
        if self._terms is not None and (self.rank != self.J.shape[1] or self.n_prior_rows
                                        or self.r.size != self.n):
            self._terms = None  # the terms assume full column rank and no prior rows

    @property
    def W(self) -> np.ndarray:
        """The whitener of the data rows (n, n), dense (built on first use from ``band``)."""
        if self._W is None:
            try:
                with np.errstate(all="ignore"):
                    self._W = band_whitener(*self._band)
            except np.linalg.LinAlgError:  # a zero on the diagonal: no whitener (the fit is not valid)
                self._W = np.full((self.n, self.n), np.nan)
        return self._W

    def indicator(self, j) -> np.ndarray:
        """Whitened indicator ``a`` of data row j (N,)."""
        a = np.zeros(self.r.size)
        a[: self.n] = self.W[:, j]
        return a

    def per_reading(self, moves: bool = True):
        """``(t, leverage, delta, dz)`` for every data row: the mean-shift statistic, leverage,
        estimated error of the reading (mm) and the change of ``z`` (n, p) when the reading is removed
        (None with ``moves=False``)."""
        n = self.n
        if self._terms is not None:  # O(n p), from the banded factor (the same quantities, no n x n matrix)
            t, lev, delta, move = self._terms
            t, lev, delta = np.ravel(t), np.ravel(lev), np.ravel(delta)
            dz = (self.basis @ np.reshape(move, (self.J.shape[1], n), order="F")).T if moves else None
            return t, lev, delta, dz
        A = np.zeros((self.r.size, n))
        A[:n] = self.W                             # column j: the whitened indicator a_j
        aa = np.sum(A * A, axis=0)
        UA = self.U.T @ A                          # (rank, n)
        den = aa - np.sum(UA * UA, axis=0)         # a^T (I - H) a
        num = A.T @ self.r - UA.T @ (self.U.T @ self.r)   # a^T (I - H) r
        # F^+ J^T a_j: the move of the coordinates per unit error of reading j
        Q = self.Vt.T @ (UA / self.s[:, None]) if self.rank else None
        with np.errstate(divide="ignore", invalid="ignore"):
            lev = np.where(aa > 0, 1.0 - den / aa, 1.0)
            ok = den > LEVERAGE_TOL * aa
            t = np.where(ok, num / np.sqrt(np.where(ok, den, 1.0)), np.nan)
            delta = np.where(ok, num / np.where(ok, den, 1.0), np.nan)
        # the fit with a free error on reading j moves the coordinates by F^+ J^T a_j delta_j
        dz = (self.basis @ (Q * delta[None, :])).T if self.rank else np.full((n, self.basis.shape[0]), np.nan)
        dz[~ok] = np.nan
        return t, lev, delta, dz


def _noise_dict(noise) -> dict:
    return {"sigma_scale_mm": float(noise.sigma_scale_mm), "sigma_servo_rad": float(noise.sigma_servo_rad)}


def _fmt_p(p) -> str:
    if p is None or not np.isfinite(p):
        return "n/a"
    return "< 1e-300" if p == 0.0 else f"{p:.3g}"


def statistics(lin: _Linear, noise, alpha: float = DEFAULT_ALPHA) -> dict:
    """The chi² test and the per-reading statistics of a linearised, whitened fit (JSON-ready dict).

    Keys: ``checked``, ``reason`` (why not, if not), ``chi2``, ``dof``,
    ``p_value``, ``p_value_lower``, ``alpha``, ``rejected``, ``rms_whitened``,
    ``readings`` (per reading: ``pose``, ``from_pose``, ``residual_mm``,
    ``whitened``, ``leverage``, ``standardised``, ``estimated_error_mm``),
    ``worst`` (the reading with the largest ``|standardised|``, with the chi²
    and p-value without it), ``warnings``, ``noise``, ``model``.
    """
    chi2 = float(lin.r @ lin.r) if lin.valid else float("inf")
    dof = int(lin.dof)
    zero = noise.is_zero
    t, lev, delta, _ = lin.per_reading(moves=False)
    if not lin.valid:
        t[:], delta[:] = np.nan, np.nan
    fit = {"model": "exact", "alpha": float(alpha), "chi2": chi2, "dof": dof, "p_value": None,
           "p_value_lower": None, "checked": False, "reason": None, "rejected": False,
           "rms_whitened": float(math.sqrt(chi2 / dof)) if dof > 0 else None,
           "noise": _noise_dict(noise), "warnings": [], "accepted_despite_misfit": False}
    if zero:
        fit["reason"] = ("the noise model is zero (noise-free weighting by 1 um): there is no noise level to test "
                         "the residuals against, so the fit cannot be checked")
        if dof > 0:  # internally studentised: the noise level estimated from the residuals
            t = t / math.sqrt(chi2 / dof) if chi2 > 0 else t
    elif not lin.valid:
        fit.update(checked=True, p_value=0.0, p_value_lower=1.0, rejected=True,
                   reason="the exact model cannot be evaluated at the estimate (a pose is not an assembly of the "
                          "robot with these errors): the estimate is nonsense")
    elif dof <= 0:
        fit["reason"] = "the fit cannot be checked (no spare degrees of freedom)"
    else:
        pl, p = _gamma_pq(0.5 * dof, 0.5 * chi2)   # lower and upper tails at once (chi2_cdf, chi2_sf)
        fit.update(checked=True, p_value=p, p_value_lower=pl, rejected=bool(p < alpha))
        if pl < alpha:
            fit["warnings"].append(
                f"chi2 = {chi2:.4g} is far below its {dof} degrees of freedom (lower-tail p = {_fmt_p(pl)}): the "
                "noise model overstates the noise, so the standard deviations are too large (conservative)")
    n = lin.n
    tt = np.where(np.isfinite(t), t, np.nan).tolist()
    dd = np.where(np.isfinite(delta), delta, np.nan).tolist()
    fit["readings"] = [{"pose": k, "from_pose": k - 1, "residual_mm": e, "whitened": w, "leverage": v,
                        "standardised": None if ts != ts else ts, "estimated_error_mm": None if ds != ds else ds}
                       for k, e, w, v, ts, ds in zip(lin.poses[:n].tolist(), lin.raw[:n].tolist(), lin.r[:n].tolist(),
                                                     lev[:n].tolist(), tt, dd)]
    fit["worst"] = None
    at = np.where(np.isfinite(t), np.abs(t), -1.0)
    if at.size and at.max() >= 0.0:
        j = int(np.argmax(at))
        w = {"pose": int(lin.poses[j]), "from_pose": int(lin.poses[j]) - 1, "standardised": float(t[j]),
             "estimated_error_mm": float(delta[j]), "chi2_without": None, "p_value_without": None}
        if fit["checked"] and dof >= 2:
            c = max(chi2 - float(t[j]) ** 2, 0.0)
            w.update(chi2_without=c, p_value_without=chi2_sf(c, dof - 1))
        fit["worst"] = w
    fit["_t"] = t  # private: for the diagnosis (removed before returning to the user)
    return fit


# ============================================================== exact-model pieces (CasADi functions of nlls_problem)
class _Exact:
    """The exact whitened model of one identification problem (robot, poses, readings, parameters)."""

    def __init__(self, robot, theta_cmd, readings, names, prior_q, noise, prior_whitener=None):
        from zerocal_sym.identify import fisher
        from zerocal_sym.identify.nlls import noise_terms
        from zerocal_sym.identify.nlls_problem import get_problem

        self.robot = robot
        self.theta = np.atleast_2d(np.asarray(theta_cmd, float))
        self.readings = np.asarray(readings, float)
        self.K = self.theta.shape[0]
        self.names = tuple(names)
        self.p = len(self.names)
        self.prior_q = np.asarray(prior_q, float)
        errors = robot.errors
        self.scale = fisher.parameter_scale(robot, self.names)
        self.mu = errors.take(self.prior_q, self.names)
        self.w = np.zeros((self.p, self.p)) if prior_whitener is None else np.asarray(prior_whitener, float)
        self.noise = noise
        self.prob = get_problem(robot, self.K, self.names)
        self.par = self.prob.pack(self.theta, robot.geometry, self.prior_q, self.readings[1:], self.scale, self.mu,
                                  self.w, *noise_terms(noise))

    @property
    def z_prior(self):
        return self.mu * self.scale

    def evaluate(self, z):
        """``(r, rp, J, pred, l, b)`` at ``z`` (weights at ``z``); copies."""
        last = getattr(self, "_last", None)
        if last is not None and np.array_equal(last[0], z):
            return last[1]
        fast = self.prob.fast
        l, b = (np.array(o, float) for o in fast["weights"](z, self.par))
        r, rp, J, pred = (np.array(o, float) for o in fast["residuals"](z, self.par, l, b))
        return r.ravel(), rp.ravel(), J, pred.ravel(), l.ravel(), b.ravel()

    def prior_rows(self) -> np.ndarray:
        return np.flatnonzero(np.any(self.w != 0, axis=1))

    def linear(self, z, basis=None, point=None) -> _Linear:
        """The whitened problem at ``z``; ``basis`` (p, c) restricts the fitted directions (TSVD)."""
        r, rp, J, pred, l, b = self.evaluate(z)
        K1 = self.K - 1
        rows = self.prior_rows()
        basis = np.eye(self.p) if basis is None else np.asarray(basis, float)
        rr = np.concatenate([r, rp[rows]])
        JJ = np.vstack([J[:K1], J[K1:][rows]]) @ basis
        return _Linear(rr, JJ, band_whitener(l, b), np.arange(1, self.K), self.readings[1:] - pred, basis,
                       self.scale, self.names, len(rows), point)

    def refine(self, z0, basis=None, max_iter: int = 10):
        """Gauss-Newton on the exact model from ``z0`` within ``span(basis)`` (weights re-evaluated)."""
        from zerocal_sym.identify.nlls import GN_STEP_TOL

        z = np.asarray(z0, float).copy()
        if basis is None or (np.shape(basis)[1] == self.p and not np.any(self.w)):
            # the whole space: the nlls problem's Gauss-Newton blocks (one CasADi call per 3 iterations)
            z_gn, step, r, rp, J, pred, l, b = self.prob.run_gauss_newton(z, self.par, True, GN_STEP_TOL)
            if np.all(np.isfinite(z_gn)) and float(step[0]) < GN_STEP_TOL:
                z_gn = np.ravel(z_gn)
                self._last = (z_gn.copy(), (r.ravel(), rp.ravel(), J, pred.ravel(), l.ravel(), b.ravel()))
                return z_gn
        basis = np.eye(self.p) if basis is None else np.asarray(basis, float)
        K1 = self.K - 1
        rows = self.prior_rows()
        for _ in range(max_iter):
            r, rp, J, *_ = self.evaluate(z)
            rr = np.concatenate([r, rp[rows]])
            JJ = np.vstack([J[:K1], J[K1:][rows]]) @ basis
            step = basis @ np.linalg.lstsq(JJ, -rr, rcond=None)[0]
            if not np.all(np.isfinite(step)):
                raise FloatingPointError("exact-model refinement diverged")
            z = z + step
            if np.max(np.abs(step)) < REFINE_TOL:
                break
        return z

    def chi2_fit(self, theta=None, readings=None):
        """chi² and dof of the exact-model least-squares fit (from the prior) to altered data."""
        par = self.par.copy()
        K = self.K
        if theta is not None:
            par[: self.theta.size] = np.asarray(theta, float).ravel()
        if readings is not None:
            par[self.prob.s_slice(len(self.robot.geometry), len(self.robot.errors))] = np.asarray(readings)[1:]
        from zerocal_sym.identify.nlls import GN_STEP_TOL

        out = self.prob.run_gauss_newton(self.z_prior, par, True, GN_STEP_TOL)
        r, rp = np.array(out[2]).ravel(), np.array(out[3]).ravel()
        rows = self.prior_rows()
        chi2 = float(r @ r + rp[rows] @ rp[rows])
        J = np.array(out[4])
        JJ = np.vstack([J[: K - 1], J[K - 1:][rows]])
        sv = np.linalg.svd(JJ, compute_uv=False)
        rank = int(np.sum(sv > RANK_RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
        dof = (K - 1) + len(rows) - rank
        return (chi2 if np.isfinite(chi2) else float("inf")), dof


def refits(robot, theta_cmd, readings, names, prior_q, noise, drops, z0, prior_whitener=None,
           max_iter: int = 20, tol: float = 1e-7) -> dict:
    """Exact-model least-squares fits of one round, each without some readings (vectorised over the fits).

    Fit ``j`` leaves out the changes ``drops[j]`` (0-based: change ``i`` is the
    reading at pose ``i + 1``) by marginalising them out of the covariance of
    the changes (the rows and columns of ``C`` dropped): Gauss-Newton with the
    weights re-evaluated at each iterate, from ``z0[j]`` (scaled units), until
    the step is below ``tol`` (mm) or ``max_iter``.  One call of the generated
    distance Jacobians per iteration for all fits.

    Returns
    -------
    dict
        ``z`` (N, p) scaled estimates, ``chi2`` (N,), ``dof`` (N,),
        ``converged`` (N,) bool, ``residual_mm`` (N, K-1) measured minus
        predicted changes at each fit (the dropped ones too), ``dropped_error_mm``
        (N, K-1): each dropped reading's misfit given the other readings (its
        residual minus what their correlated residuals predict for it; NaN
        where not dropped) -- the estimated error of that reading.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.nlls import noise_terms
    from zerocal_sym.model import kinematics as kin

    errors = robot.errors
    theta = np.atleast_2d(np.asarray(theta_cmd, float))
    K = theta.shape[0]
    s = np.asarray(readings, float)[1:]
    names = tuple(names)
    idx = errors.indices(names)
    p = len(names)
    scale = fisher.parameter_scale(robot, names)
    mu = errors.take(np.asarray(prior_q, float), names)
    w = np.zeros((0, p)) if prior_whitener is None else np.asarray(prior_whitener, float)
    w = w[np.any(w != 0, axis=1)]
    Jp = w / scale
    sm2, sx2 = noise_terms(noise)
    D = fisher.difference_matrix(K)
    N = len(drops)
    Z = np.array(np.broadcast_to(np.asarray(z0, float), (N, p)))
    keeps = [np.setdiff1d(np.arange(K - 1), np.asarray(d, int)) for d in drops]
    done = np.zeros(N, bool)
    bad = np.zeros(N, bool)
    chi2 = np.full(N, np.inf)
    dof = np.array([k.size + w.shape[0] - p for k in keeps])
    res = np.full((N, K - 1), np.nan)
    cond = np.full((N, K - 1), np.nan)
    thN = np.tile(theta, (N, 1))

    def sweep(take_steps):
        E = np.tile(np.asarray(prior_q, float), (N * K, 1))
        E[:, idx] = np.repeat(Z / scale, K, axis=0)
        rho, de, dt = kin.distance_jacobians(robot, thN, E)
        for j in range(N):
            if bad[j] or (take_steps and done[j]):
                continue
            sl = slice(j * K, (j + 1) * K)
            e = s - np.diff(rho[sl])
            A = np.diff(de[sl][:, idx], axis=0) / scale
            v = sx2 * np.sum(dt[sl] ** 2, axis=1)
            C = sm2 * np.eye(K - 1) + (D * v) @ D.T
            kp = keeps[j]
            try:
                L = np.linalg.cholesky(C[np.ix_(kp, kp)])
                rw = np.linalg.solve(L, e[kp])
                Jw = np.linalg.solve(L, -A[kp])
            except np.linalg.LinAlgError:
                bad[j] = True
                continue
            rp = w @ (Z[j] / scale - mu)
            if not (np.all(np.isfinite(rw)) and np.all(np.isfinite(Jw))):
                bad[j] = True
                continue
            chi2[j] = float(rw @ rw + rp @ rp)
            res[j] = e
            drop = np.setdiff1d(np.arange(K - 1), kp)
            if drop.size and not take_steps:  # each dropped reading's misfit given the others (conditional)
                Ck = C[np.ix_(drop, kp)]
                cond[j, drop] = e[drop] - Ck @ np.linalg.solve(C[np.ix_(kp, kp)], e[kp])
            if take_steps:
                step = -np.linalg.lstsq(np.vstack([Jw, Jp]), np.concatenate([rw, rp]), rcond=None)[0]
                Z[j] = Z[j] + step
                done[j] = bool(np.max(np.abs(step)) < tol)

    for _ in range(max_iter):
        sweep(True)
        if np.all(done | bad):
            break
    sweep(False)
    chi2[bad] = np.inf
    return {"z": Z, "chi2": chi2, "dof": dof, "converged": done & ~bad, "residual_mm": res,
            "dropped_error_mm": cond}


def _without_each(exact: "_Exact", z_est=None) -> dict:
    """Exact refits without each single reading, from the prior and from ``z_est``; the lower chi² per reading."""
    K1 = exact.K - 1
    starts = [exact.z_prior] if z_est is None or np.allclose(z_est, exact.z_prior) else [exact.z_prior, z_est]
    drops = [[j] for _ in starts for j in range(K1)]
    z0 = np.vstack([np.tile(z, (K1, 1)) for z in starts])
    out = refits(exact.robot, exact.theta, exact.readings, exact.names, exact.prior_q, exact.noise, drops, z0,
                 prior_whitener=exact.w if np.any(exact.w) else None)
    c = out["chi2"].reshape(len(starts), K1)
    pick = np.argmin(np.where(np.isfinite(c), c, np.inf), axis=0)
    rows = pick * K1 + np.arange(K1)
    return {key: out[key][rows] for key in ("z", "chi2", "dof", "converged", "residual_mm", "dropped_error_mm")}


# ============================================================== causes
def _variants(K: int, theta, readings):
    """(key, description, theta, readings) of the cheap alternative readings of the data."""
    R = np.asarray(readings, float)
    yield ("sign", "the readings have the wrong sign (scale mounted or read reversed)", None, -R)
    yield ("cumulative", "the readings are cumulative (the head was not reset after each reading)", None,
           np.concatenate([[0.0], np.diff(R)]))
    yield ("reversed", "the poses were visited in the reverse order of the file", theta[::-1].copy(), None)
    if K <= 40:
        for j in range(K - 1):
            th = theta.copy()
            th[[j, j + 1]] = th[[j + 1, j]]
            yield (f"swap{j}", f"poses {j} and {j + 1} were visited in the other order", th, None)


def _diagnose(exact: _Exact | None, fit: dict, alpha: float, z_est=None) -> tuple:
    """(causes, paragraph) of a rejected fit."""
    chi2, dof = fit["chi2"], fit["dof"]
    causes = []
    active = fit.get("active_bounds") or []
    if exact is not None and (active or np.any(exact.w)):
        # the user's constraints (an active bound, a Gaussian prior) against the data: the free fit
        what = ([f"the bound on {', '.join(active)} (active at the estimate)"] if active else []) + \
               (["the Gaussian prior"] if np.any(exact.w) else [])
        try:
            free = _Exact(exact.robot, exact.theta, exact.readings, exact.names, exact.prior_q, exact.noise)
            c, d = free.chi2_fit()
            p = chi2_sf(c, d) if d > 0 else float("nan")
        except Exception:  # noqa: BLE001
            c, d, p = float("nan"), 0, float("nan")
        if np.isfinite(p) and p >= alpha:
            causes.append({"cause": "constraints", "detected": True,
                           "text": " and ".join(what) + " contradict(s) the data",
                           "evidence": f"without them chi2 = {c:.4g} on {d} dof (p = {_fmt_p(p)})"})
        return causes, _paragraph(fit, causes, alpha, exact)
    if exact is not None:
        best = None
        for key, text, th, rd in _variants(exact.K, exact.theta, exact.readings):
            try:
                c, d = exact.chi2_fit(th, rd)
            except Exception:  # noqa: BLE001 - an alternative that cannot be evaluated explains nothing
                continue
            if d <= 0 or not np.isfinite(c):
                continue
            p = chi2_sf(c, d)
            if p >= alpha and c < chi2 and (best is None or p > best[3]):
                best = (key, text, c, p, d)
        if best is not None:
            key, text, c, p, d = best
            causes.append({"cause": "out of order" if key.startswith("swap") or key == "reversed" else key,
                           "detected": True, "text": text,
                           "evidence": f"refitted so, chi2 = {c:.4g} on {d} dof (p = {_fmt_p(p)})"})
    # one bad reading: exact refits, each without one reading (from the prior: an outlier may have dragged
    # the estimate far along a weak direction, where the linearisation at the estimate says little)
    if exact is not None and dof >= 2 and not causes:
        K1 = exact.K - 1
        try:
            out = _without_each(exact, z_est)
        except Exception:  # noqa: BLE001 - then no reading is named
            out = None
        if out is not None:
            pk = np.array([chi2_sf(c, d) if d > 0 and np.isfinite(c) else np.nan
                           for c, d in zip(out["chi2"], out["dof"])])
            ok = [j for j in range(K1) if np.isfinite(pk[j]) and pk[j] >= alpha and out["chi2"][j] < chi2]
            if ok:
                j = max(ok, key=lambda j: pk[j])
                k = j + 1
                e = float(out["dropped_error_mm"][j, j])
                c, d = float(out["chi2"][j]), int(out["dof"][j])
                text = (f"the reading at pose {k} (the change from pose {k - 1} to pose {k}) is off by about "
                        f"{e:+.3g} mm")
                ev = f"without it chi2 = {c:.4g} on {d} dof (p = {_fmt_p(pk[j])})"
                others = [i + 1 for i in ok if i != j]
                if others:
                    ev += f"; without the reading at pose {', '.join(map(str, others))} instead it would fit too"
                causes.append({"cause": "bad reading", "detected": True, "pose": int(k), "from_pose": int(k - 1),
                               "estimated_error_mm": e, "text": text, "evidence": ev,
                               "also_possible": [int(o) for o in others]})
    return causes, _paragraph(fit, causes, alpha, exact)


def _paragraph(fit: dict, causes: list, alpha: float, exact) -> str:
    chi2, dof = fit["chi2"], fit["dof"]
    detected = [c for c in causes if c["detected"]]
    ratio = chi2 / dof if dof > 0 else float("inf")
    head = (f"The noise model rejects this fit: chi2 = {chi2:.4g} on {dof} degrees of freedom "
            f"(p = {_fmt_p(fit['p_value'])} < {alpha:g}); the residuals are about {math.sqrt(ratio):.3g} times "
            "the noise the noise model states.")
    if detected:
        c = detected[0]
        body = f" Likely cause (detected): {c['text']}: {c['evidence']}."
        if c["cause"] == "bad reading":
            body += (" (A robot-file error that shows mostly in this change looks the same in one round: "
                     f"re-measure pose {c['pose']} to tell.)")
        others = "Otherwise check the robot file, the noise model and the readings."
        return head + body + " " + others
    parts = []
    if dof == 1:
        parts.append("a bad reading (with one spare degree of freedom every reading explains the misfit equally, "
                     "so none can be named; more poses would tell)")
    elif dof >= 2:
        w = fit.get("worst") or {}
        if w:
            parts.append(f"more than one bad reading (the largest standardised residual, {w['standardised']:+.3g} "
                         f"at pose {w['pose']}, does not explain the misfit alone)")
    parts.append("a wrong robot file (a geometry that is not this robot's leaves a systematic misfit)")
    parts.append(f"a noise model that understates the noise (by about {math.sqrt(ratio):.3g} x in standard "
                 "deviation; scale error {:.3g} um, servo error {:.3g} deg per joint as given)".format(
                     fit["noise"]["sigma_scale_mm"] * 1e3, math.degrees(fit["noise"]["sigma_servo_rad"])))
    if fit.get("active_bounds") or (exact is not None and np.any(exact.w)):
        parts.insert(0, "the bounds or the prior given (they hold the estimate where the data do not agree; the "
                        "fit without them does not pass either)")
        checked = ""
    else:
        checked = ("Checked and not found: poses visited in reverse or two consecutive poses swapped, cumulative "
                   "readings (head not reset), sign-flipped readings." if exact is not None else "")
    return head + " Likely causes: " + "; ".join(parts) + ". " + checked


def _summary(fit: dict) -> str:
    s = f"chi2 {fit['chi2']:.4g} on {fit['dof']} dof, p = {_fmt_p(fit['p_value'])} < {fit['alpha']:g}"
    det = [c for c in fit.get("causes", []) if c.get("detected")]
    if det:
        s += f"; likely: {det[0]['text']}"
    return s


def finish(fit: dict, exact: _Exact | None, diagnose: bool = True, z_est=None) -> dict:
    """Add the causes and the paragraph to a rejected fit; drop the private arrays."""
    fit["causes"], fit["diagnosis"] = [], None
    if fit["rejected"]:
        if diagnose:
            fit["causes"], fit["diagnosis"] = _diagnose(exact, fit, fit["alpha"], z_est)
        else:
            fit["diagnosis"] = _diagnose(None, fit, fit["alpha"])[1]
    elif fit["checked"]:
        fit["diagnosis"] = (f"The fit agrees with the noise model: chi2 = {fit['chi2']:.4g} on {fit['dof']} dof "
                            f"(p = {_fmt_p(fit['p_value'])}).")
    else:
        fit["diagnosis"] = fit["reason"]
    fit.pop("_t", None)
    return fit


def apply(result, fit: dict, accept_misfit: bool = False):
    """Record ``fit`` in ``result.info["fit"]`` and, if rejected, change ``status`` / ``success``.

    Only a result that was a calibration (``success``) can be rejected; a
    failed identification keeps its own status.  Returns ``result``.
    """
    result.info["fit"] = fit
    det = [c for c in fit.get("causes", []) if c.get("detected")]
    if not result.success and det:  # a failed identification: say what the data look like
        result.status += f"; the data look wrong: {det[0]['text']} ({det[0]['evidence']})"
    if fit["rejected"] and result.success:
        if accept_misfit:
            fit["accepted_despite_misfit"] = True
            result.status = f"accepted despite misfit ({_summary(fit)}); {result.status}"
        else:
            result.success = False
            result.status = f"rejected: the noise model rejects the fit ({_summary(fit)})"
    return result


# ============================================================== public, from a result
def _exact_for(robot, meas, result, noise=None) -> tuple:
    """(_Exact, z at the fit check's evaluation point, basis) of a result."""
    from zerocal_sym.model.noise import NoiseModel

    info = result.info
    if noise is None:
        nd = info.get("noise")
        noise = NoiseModel(nd["sigma_scale_mm"], nd["sigma_servo_rad"]) if nd else NoiseModel.paper()
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
    Gauss-Newton from the estimate and from the prior, the better fit kept;
    one vectorised pass for all readings).  ``method="one-step"``: the
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
        |change| / std), ``chi2_without``, ``flag``; ``flagged`` (poses, the
        most influential first), ``most_influential`` (pose), ``summary`` (a
        sentence naming them), ``threshold``, ``dof``, ``method``.
    """
    if method not in ("refit", "one-step"):
        raise ValueError(f"method must be 'refit' or 'one-step', got {method!r}")
    exact, z, basis = _exact_for(robot, meas, result, noise)
    lin = exact.linear(z, basis)
    t, lev, delta, dz = lin.per_reading()
    chi2w = np.full(lin.n, np.nan)
    if method == "refit":
        out = _without_each(exact, z)
        dz = out["z"] - z
        dz[~np.isfinite(out["chi2"]) | (out["dof"] <= 0) & (lin.dof <= 0)] = np.nan
        delta = np.array([out["dropped_error_mm"][j, j] for j in range(lin.n)])
        chi2w = out["chi2"]
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


def plausibility(robot, result, max_offset_deg: float = DEFAULT_MAX_OFFSET_DEG,
                 max_maemm_mm: float = DEFAULT_MAX_MAEMM_MM) -> list:
    """Reasons not to use ``result`` as a calibration (empty list: plausible).

    ``result``: an :class:`~zerocal_sym.identify.result.IdentificationResult`
    or a results file read by :func:`zerocal_sym.io.results.load_result`
    (``load_result(path, allow_failed=True, robot=robot)``, so that a failed
    one is reported here rather than refused there).

    * not a calibration: ``success`` is False (not converged, not
      identifiable, the fit rejected) -- a result accepted despite misfit is
      one;
    * a zero offset beyond ``max_offset_deg`` (default 10 deg: far beyond a
      homing error; the first-order model and TSVD's linearisation fail
      there, and it usually is a wrong joint zero, sign or robot file);
    * a MAEMM (norm of the measuring mechanism's assembly error) beyond
      ``max_maemm_mm`` (default 50 mm, ~7 % of the planar robot's measuring
      length: not an assembly error but a wrong ``c``/``d`` in the robot
      file);
    * a non-finite estimate or standard deviation of an offset.
    """
    reasons = []
    if not result.success:
        reasons.append(f"the identification is not a calibration: {result.status}")
    errors = robot.errors
    off = np.asarray(result.zero_offsets_deg, float)
    for n, v in zip(errors.zero_offsets, off):
        if not np.isfinite(v):
            reasons.append(f"zero offset {n} is not a finite number")
        elif abs(v) > max_offset_deg:
            reasons.append(f"zero offset {n} = {v:+.4g} deg is beyond the plausible {max_offset_deg:g} deg "
                           "(a wrong joint zero, sign convention or robot file?)")
    params = getattr(result, "params", None)  # None: a results file (io.results.ResultFile)
    std = np.asarray(result.std_zero_offsets_deg, float)
    for n, s in zip(errors.zero_offsets, std):
        if params is not None and n in params and not np.isfinite(s):
            reasons.append(f"the standard deviation of zero offset {n} is not finite (not identifiable)")
    mm = np.asarray(result.maemm_mm, float)
    if mm.size and np.all(np.isfinite(mm)) and float(np.linalg.norm(mm)) > max_maemm_mm:
        reasons.append(f"MAEMM |rM| = {np.linalg.norm(mm):.4g} mm is beyond the plausible {max_maemm_mm:g} mm "
                       "(the measuring mechanism's c / d in the robot file?)")
    elif mm.size and not np.all(np.isfinite(mm)):
        reasons.append("the MAEMM is not finite")
    return reasons
