"""Batched identification: N data sets of one design in one CasADi call.

For Monte Carlo studies and design verification: the K commanded poses are
the same for every data set, only the readings differ.  The Gauss-Newton
iterations of :mod:`zerocal_sym.identify.estimate.nlls_problem` are mapped over the N
data sets (``Function.map``) and evaluated in one zero-copy call; each data
set is *confirmed* when its last Gauss-Newton step is below
:data:`~zerocal_sym.identify.estimate.nlls_solve.GN_STEP_TOL` (the same criterion as the
single path uses before Ipopt confirms).  A data set that is not confirmed
goes through :func:`zerocal_sym.identify.nlls.identify_nlls` (Ipopt the judge).
The estimates of confirmed data sets equal the single path's to the
Gauss-Newton tolerance (a test).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import IdentificationError
from zerocal_sym.identify import fisher
from zerocal_sym.identify.check.max_reading import max_p_values
from zerocal_sym.identify.estimate.nlls_inputs import index_list
from zerocal_sym.identify.estimate.nlls_problem import GN_BLOCKS, get_problem
from zerocal_sym.identify.estimate.nlls_solve import GN_STEP_TOL, noise_terms
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.whitened import standardised_many
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel

#: a batch of at least this many data sets makes the problem hot (compiled, :mod:`zerocal_sym.model.compiled`)
HOT_BATCH = 50
#: data sets per mapped call (memory and the size of the mapped Function stay bounded)
CHUNK = 1000


@dataclass
class BatchResult:
    """N identifications of one design.

    Attributes
    ----------
    params : tuple of str
    estimate : ndarray, shape (N, p)
        rad / mm; NaN where the identification failed.
    std : ndarray, shape (N, p)
        Standard deviations from the Fisher information at each estimate.
    success : ndarray of bool, shape (N,)
    confirmed : ndarray of bool, shape (N,)
        Confirmed in the batch (False: handed to the single path).
    chi2 : ndarray, shape (N,)
        Sum of squared whitened residuals.
    dof : int
        Degrees of freedom of ``chi2`` (K - 1 - p).
    p_value : ndarray, shape (N,)
        The fit check's p-value ``P(chi2_dof >= chi2)``
        (:func:`zerocal_sym.identify.chi2.chi2_sf`; NaN where not
        available).  The batch does not reject: ``success`` means converged;
        compare ``p_value`` with a level (the single path's default 0.001).
    p_value_max : ndarray, shape (N,)
        The fit check's second p-value: of the largest ``|standardised
        residual|`` over the K - 1 readings
        (:func:`zerocal_sym.identify.check.max_reading.max_p_value`; NaN where
        not available).  The single path rejects when either p-value is below
        its level: :meth:`rejected`.
    """

    params: tuple
    estimate: np.ndarray
    std: np.ndarray
    success: np.ndarray
    confirmed: np.ndarray
    chi2: np.ndarray
    dof: int = 0
    p_value: np.ndarray | None = None
    p_value_max: np.ndarray | None = None

    def rejected(self, alpha: float) -> np.ndarray:
        """Where the single path's fit check would reject at ``alpha`` (bool (N,)): either p-value below it."""
        return (self.p_value < alpha) | (self.p_value_max < alpha)

    def values(self, names) -> np.ndarray:
        """Columns of the estimate by name, shape (N, len(names))."""
        return self.estimate[:, [self.params.index(n) for n in names]]


def _gauss_newton_blocks(prob, z, P):
    """Blocks of Gauss-Newton over the columns of (z, P), each data set until its last step is small.

    Returns ``z`` (n, p), ``step`` (n,), whitened residuals ``r`` (n, K-1), data Jacobians ``J`` (n, K-1, p),
    the bidiagonal Cholesky factors of the changes' covariance ``l`` (n, K-1), ``b`` (n, K-2).
    """
    p, n = z.shape
    K = prob.K
    step = np.full(n, np.inf)
    r, l = np.full((n, K - 1), np.nan), np.full((n, K - 1), np.nan)
    b = np.full((n, K - 2), np.nan)
    J = np.full((n, K - 1, p), np.nan)
    todo = np.arange(n)
    for _ in range(GN_BLOCKS):  # only the data sets not yet converged go on
        zk, sk, rk, _, Jk, _, lk, bk = prob.run_batch(z[:, todo], P[:, todo])
        z[:, todo] = zk.reshape(p, todo.size, order="F")
        step[todo] = np.ravel(sk)
        r[todo] = rk.reshape(K - 1, todo.size, order="F").T
        l[todo] = np.reshape(lk, (K - 1, todo.size), order="F").T
        b[todo] = np.reshape(bk, (K - 2, todo.size), order="F").T
        J[todo] = Jk.reshape(K - 1 + p, p, todo.size, order="F").transpose(2, 0, 1)[:, : K - 1]  # [J_1 | J_2 | ...]
        todo = todo[~(step[todo] < GN_STEP_TOL) & np.all(np.isfinite(z[:, todo]), axis=0)]
        if not todo.size:
            break
    return z.T, step, r, J, l, b


def _check_inputs(robot, theta_cmd, readings, names):
    """``theta_cmd`` (K, m) and ``readings`` (N, K) as float arrays, or the error that says what is wrong where."""
    m = robot.m
    th = np.asarray(theta_cmd, float)
    if th.ndim != 2 or th.shape[1] != m:
        hint = " (transposed? one row per pose)" if th.ndim == 2 and th.shape[0] == m else ""
        raise ValueError(f"theta_cmd must have shape (K, m) = (K, {m}), the {m} commanded joint angles of robot "
                         f"{robot.name!r} at each of the K poses, got {th.shape}{hint}")
    K = th.shape[0]
    R = np.asarray(readings, float)
    given = R.shape
    if R.ndim == 1:  # one data set
        R = R[None, :]
    if R.ndim != 2 or R.shape[1] != K:
        hint = (" (transposed? one row per data set, one column per pose)"
                if R.ndim == 2 and R.shape[0] == K else "")
        raise ValueError(f"readings must have shape (N, K) = (N, {K}) for the {K} poses of theta_cmd (one row per "
                         f"data set), got {given}{hint}")
    p = len(names)
    if K - 1 < p:  # as the CLI: every data set would be rank deficient (no Gaussian prior here to make up for it)
        raise IdentificationError(f"{K} poses give {K - 1} measured changes: fewer than the {p} parameters "
                                  f"{', '.join(names)}: every data set would be rank deficient (not identifiable; "
                                  "the batch takes no Gaussian prior to make up for it)")
    bad = ~np.isfinite(th)
    if bad.any():
        k = np.flatnonzero(bad.any(axis=1))
        raise ValueError(f"theta_cmd must be finite: NaN or inf joint angles at pose(s) {index_list(k)} "
                         f"(theta_cmd[{k[0]}] = {th[k[0]].tolist()})")
    bad = ~np.isfinite(R)
    if bad.any():
        rows, poses = np.flatnonzero(bad.any(axis=1)), np.flatnonzero(bad.any(axis=0))
        i, k = np.argwhere(bad)[0]
        raise ValueError(f"readings must be finite: {int(bad.sum())} NaN or inf value(s) in data set(s) (row) "
                         f"{index_list(rows)} at pose(s) (column) {index_list(poses)}; the first: readings[{i}, {k}] "
                         f"= {R[i, k]}")
    return th, R


def identify_batch(robot, theta_cmd, readings, params="paper", noise: NoiseModel | str | None = None,
                   prior=None, nonfinite: str = "raise") -> BatchResult:
    """Identify N data sets measured at the same commanded joints.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joint angles, rad.
    readings : ndarray, shape (N, K), or (K,) for one data set
        Scale readings, mm, one row per data set.  ``readings[:, 0]`` (the
        reference pose, 0 by definition) is not used, as in
        :func:`~zerocal_sym.identify.nlls.identify_nlls`: only the K - 1
        changes ``readings[:, 1:]`` enter.
    params, prior
        As :func:`zerocal_sym.identify.nlls.identify_nlls` (no bounds, no Gaussian prior).
    noise : NoiseModel, str or None
        As :func:`zerocal_sym.identify.nlls.identify_nlls`: a
        :class:`~zerocal_sym.model.noise.NoiseModel`, one of the names the
        CLI's ``--noise`` takes (``paper``, ``scale-only``, ``servo-only``,
        ``none``: :meth:`NoiseModel.named`) or None (the paper's).
    nonfinite : {"raise", "fail"}
        Readings with NaN or inf: a ``ValueError`` naming them (default), or
        (``"fail"``, for simulations: a pose the simulated robot cannot reach
        reads NaN) those data sets are not identified and count as failed
        (``success`` and ``confirmed`` False, NaN estimates).

    Returns
    -------
    BatchResult

    Raises
    ------
    ValueError
        ``theta_cmd`` or ``readings`` of the wrong shape, or not finite
        (the message names the data sets (rows) and poses); an unknown
        parameter or noise name.
    TypeError
        ``noise`` neither a NoiseModel, a name nor None.
    IdentificationError
        Fewer measured changes (K - 1) than parameters: without a Gaussian
        prior every data set would be rank deficient (as the CLI refuses).
    """
    noise = NoiseModel.coerce(noise, robot=robot)
    errors = robot.errors
    names = errors.resolve(params)
    if nonfinite not in ("raise", "fail"):
        raise ValueError(f"nonfinite must be 'raise' or 'fail', got {nonfinite!r}")
    if nonfinite == "fail":
        R = np.asarray(readings, float)
        keep = np.isfinite(R).all(axis=-1) if R.ndim == 2 else None
        if keep is not None and not keep.all():  # identify the others; the non-finite rows failed
            sub = identify_batch(robot, theta_cmd, R[keep], params, noise, prior)
            est = np.full((R.shape[0], len(names)), np.nan)
            std, chi2, pv = est.copy(), np.full(R.shape[0], np.nan), np.full(R.shape[0], np.nan)
            pvm = pv.copy()
            success, confirmed = np.zeros(R.shape[0], bool), np.zeros(R.shape[0], bool)
            est[keep], std[keep], chi2[keep], pv[keep] = sub.estimate, sub.std, sub.chi2, sub.p_value
            pvm[keep] = sub.p_value_max
            success[keep], confirmed[keep] = sub.success, sub.confirmed
            return BatchResult(params=names, estimate=est, std=std, success=success, confirmed=confirmed,
                               chi2=chi2, dof=sub.dof, p_value=pv, p_value_max=pvm)
    theta_cmd, readings = _check_inputs(robot, theta_cmd, readings, names)
    N, K = readings.shape
    prior_q = errors.zeros() if prior is None else errors.check_vector(prior, "prior")
    p = len(names)
    scale = fisher.parameter_scale(robot, names)
    prob = get_problem(robot, K, names)
    if N >= HOT_BATCH:
        prob.hot()
    mu = errors.take(prior_q, names)
    par = prob.pack(theta_cmd, robot.geometry, prior_q, np.zeros(K - 1), scale, mu, np.zeros((p, p)),
                    *noise_terms(noise))
    srows = prob.s_slice(len(robot.geometry), len(errors))
    z0 = mu * scale
    est = np.full((N, p), np.nan)
    std = np.full((N, p), np.nan)
    chi2, tmax, ntest = np.full(N, np.nan), np.full(N, np.nan), np.zeros(N, int)
    confirmed = np.zeros(N, bool)
    # the shared revisit error makes the covariance more than the bands the batch whitens by: the single path
    for a in range(0, 0 if noise.has_shared else N, CHUNK):
        n = min(CHUNK, N - a)
        P = np.repeat(par[:, None], n, axis=1)
        P[srows] = readings[a:a + n, 1:].T
        z, step, r, J, lb, bb = _gauss_newton_blocks(prob, np.repeat(z0[:, None], n, axis=1), P)
        ok = np.isfinite(step) & (step < GN_STEP_TOL) & np.all(np.isfinite(z), axis=1)
        F = np.einsum("nki,nkj->nij", J, J)
        try:
            cov = np.linalg.inv(F[ok])
        except np.linalg.LinAlgError:  # a singular design: leave every data set to the single path
            ok[:] = False
            cov = np.zeros((0, p, p))
        s2 = 1.0
        if noise.is_zero:  # unit weights: the covariance from the residuals
            dof = K - 1 - p
            s2 = (np.sum(r[ok] ** 2, axis=1) * noise_terms(noise)[0] / dof)[:, None] if dof > 0 else np.nan
        sl = np.arange(a, a + n)[ok]
        est[sl] = z[ok] / scale
        std[sl] = np.sqrt(np.abs(np.diagonal(cov, axis1=1, axis2=2)) * s2) / scale
        chi2[sl] = np.sum(r[ok] ** 2, axis=1)
        if K - 1 > p and ok.any():  # the largest |standardised residual| (the fit check's second test)
            t = np.abs(standardised_many(r[ok], J[ok], lb[ok], bb[ok])[0])
            ntest[sl] = np.sum(np.isfinite(t), axis=1)
            tmax[sl] = np.max(np.where(np.isfinite(t), t, -np.inf), axis=1)
        confirmed[sl] = True
    success = confirmed.copy()
    for k in np.flatnonzero(~confirmed):  # the single path decides
        res = identify_nlls(robot, Measurements(theta_cmd=theta_cmd, readings=readings[k]), names, noise=noise,
                            prior=prior_q, fit_alpha=0.0)  # no rejection here: p_value below
        if res.success:
            est[k] = res.estimate
            std[k] = [res.std(nm) for nm in names]
            chi2[k] = res.info["chi2"]
            mr = res.info["fit"].get("max_reading") or {}
            if mr.get("p_value") is not None:
                tmax[k], ntest[k] = abs(mr["standardised"]), mr["readings"]
            success[k] = True
    from zerocal_sym.identify.chi2 import chi2_sf_array

    dof = K - 1 - p
    pv, pvm = np.full(N, np.nan), np.full(N, np.nan)
    if dof > 0 and not noise.is_zero:
        pv = np.where(np.isfinite(chi2), chi2_sf_array(np.where(np.isfinite(chi2), chi2, 0.0), dof), np.nan)
        has = np.isfinite(tmax) & (ntest > 0)
        pvm[has] = max_p_values(tmax[has], ntest[has])
    return BatchResult(params=names, estimate=est, std=std, success=success, confirmed=confirmed, chi2=chi2,
                       dof=dof, p_value=pv, p_value_max=pvm)
