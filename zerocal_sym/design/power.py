"""What a design's fit check can see: its power against the errors a calibration is likely to meet.

Every identification ends with a fit check (:mod:`zerocal_sym.identify.fitcheck`): the chi² of the
whitened residuals on ``dof = K - 1 - p`` degrees of freedom, rejected when ``P(chi2_dof >= chi2) <
alpha``.  A systematic error that adds ``delta`` (mm, shape (K-1,)) to the K-1 readings leaves, to
first order, the part of ``L^-1 delta`` the identified parameters cannot absorb in the residuals
(``L`` the Cholesky factor of the readings' covariance ``C``, ``A_w = L^-1 A`` the whitened
sensitivities): the chi² is then non-central with

    lambda = |(I - H) L^-1 delta|^2,    H = A_w (A_w^T A_w)^-1 A_w^T,

and the check's **power** against that error is ``P(chi2_dof(lambda) > chi2_{dof, 1-alpha})``
(:func:`power`, the non-central chi² as a Poisson mixture of central ones).  What the fit absorbs
goes into the estimate: the offsets move by ``b = (A_w^T A_w)^-1 A_w^T L^-1 delta``, reported in
units of their standard deviations (the CRLB) as the error's **harm**.

The errors a design is judged against (:func:`scenario_effects`), at zero source errors (the
design's linearisation point):

* **robot-file entries** (the source errors the identification holds at zero) each at its tolerance
  (:func:`zerocal_sym.identify.budget.bias.make_tolerances`: the mechanism's defaults, or the robot file's,
  and ``--tolerance``): ``delta = D a_o t_j``; and **every length of the robot file** off by the same
  fraction (:func:`scale_column`, a file for another robot of the family, or in other units);
* **the poses visited in reverse order**, and **two consecutive poses swapped** (each pair): the
  readings of the visited order against the file's, ``delta = D rho(pi) - D rho``;
* **one bad reading** of a stated size ``b`` (mm) at each reading in turn: ``delta = b e_k``.

The order scenarios are gross (tens of mm on a reading): their non-centrality is also computed on the
exact model (:func:`detection`: the exact Gauss-Newton fit of the noise-free readings of the wrong
order, :meth:`zerocal_sym.identify.estimate.exact_model._Exact.chi2_fit`, as the fit check's diagnosis refits
them), and the smaller of the two is reported.

What a checked design must see is :mod:`zerocal_sym.design.detection`'s (its :class:`Requirement`).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from zerocal_sym.identify.chi2 import chi2_sf

#: the fit check's level (:data:`zerocal_sym.identify.check.statistics.DEFAULT_ALPHA`)
DEFAULT_ALPHA = 1e-3
#: the power a checked design keeps against every scenario it must see
DEFAULT_POWER = 0.9
#: an unseen robot-file entry or bad reading is harmless when it moves no offset by this many standard deviations
DEFAULT_HARM_SIGMA = 1.0
#: the default size of one bad reading, mm
DEFAULT_BAD_READING_MM = 0.1
#: scenario kinds: which the harm rule may excuse
KINDS = ("entry", "order", "reading")


# --------------------------------------------------------------------------- the non-central chi²
def chi2_isf(alpha: float, dof: float) -> float:
    """The chi² with upper tail ``alpha`` on ``dof`` degrees of freedom (bisection on :func:`chi2_sf`)."""
    lo, hi = 0.0, max(1.0, dof)
    while chi2_sf(hi, dof) > alpha:
        lo, hi = hi, 2.0 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if chi2_sf(mid, dof) > alpha:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return hi


def ncx2_sf(x: float, dof: float, lam: float) -> float:
    """``P(X > x)`` for X non-central chi² with ``dof`` degrees of freedom and non-centrality ``lam``.

    The Poisson mixture ``sum_j Pois(j; lam/2) Q((dof + 2j)/2, x/2)``, summed over the Poisson's mass
    within 12 standard deviations of its mean (the rest is below 1e-30), the upper incomplete gamma by
    its recurrence ``Q(a + 1, y) = Q(a, y) + y^a e^-y / Gamma(a + 1)``.
    """
    x, dof, lam = float(x), float(dof), float(lam)
    if not lam > 0:
        return chi2_sf(x, dof)
    if x <= 0:
        return 1.0
    if not math.isfinite(lam):
        return 1.0
    mu = 0.5 * lam
    sd = math.sqrt(mu)
    lo = max(0, int(mu - 12.0 * sd - 10.0))
    hi = int(mu + 12.0 * sd + 40.0)
    # far in the upper tail of the non-central chi² (mean dof + lam, variance 2 (dof + 2 lam)): power 1
    if (dof + lam - x) > 40.0 * math.sqrt(2.0 * (dof + 2.0 * lam)):
        return 1.0
    y = 0.5 * x
    a = 0.5 * dof + lo
    q = chi2_sf(x, 2.0 * a)
    total = 0.0
    for j in range(lo, hi + 1):
        w = math.exp(-mu + j * math.log(mu) - math.lgamma(j + 1.0))
        total += w * q
        q = min(1.0, q + math.exp(a * math.log(y) - y - math.lgamma(a + 1.0)))
        a += 1.0
    return min(max(total, 0.0), 1.0)


def power(lam: float, dof: int, alpha: float = DEFAULT_ALPHA) -> float:
    """Probability that the chi² check at ``alpha`` on ``dof`` rejects a fit with non-centrality ``lam``.

    ``dof <= 0``: 0 (no spare degree of freedom: the check cannot run).
    """
    if dof <= 0:
        return 0.0
    return ncx2_sf(chi2_isf(alpha, dof), dof, lam)


def required_noncentrality(dof: int, alpha: float = DEFAULT_ALPHA, target: float = DEFAULT_POWER) -> float:
    """The non-centrality at which the check's power is ``target`` (bisection in ``log lam``); inf for dof <= 0."""
    if dof <= 0:
        return math.inf
    x = chi2_isf(alpha, dof)
    lo, hi = 0.0, max(1.0, x)
    while ncx2_sf(x, dof, hi) < target:
        lo, hi = hi, 2.0 * hi
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if ncx2_sf(x, dof, mid) < target:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-9 * hi:
            break
    return hi


# --------------------------------------------------------------------------- scenarios
#: the robot-file scale scenario: every length of the robot file off by this fraction
DEFAULT_SCALE_ERROR = 0.01
#: relative step of the scale scenario's difference quotient
_SCALE_STEP = 1e-6


def lengths_scaled(robot, f: float):
    """The robot with every length of its file (every geometry entry in mm) times ``f``, its angles kept: the
    file of another robot of the family, or one in other units."""
    from dataclasses import replace

    mm = np.array([robot.mechanism.geometry_units.get(n, "mm") == "mm" for n in robot.mechanism.geometry_names])
    return replace(robot, geometry=np.where(mm, robot.geometry * f, robot.geometry))


def scale_column(robot, theta) -> np.ndarray:
    """``d rho / d s`` (mm per unit fraction) of each pose when the robot's lengths are ``(1 + s)`` times the
    file's (:func:`lengths_scaled`), the joints ``theta`` (K, m) commanded, shape (K,)."""
    from zerocal_sym.model import kinematics as kin

    scaled = lengths_scaled(robot, 1.0 + _SCALE_STEP)
    theta = np.atleast_2d(theta)
    return (kin.distance(scaled, theta) - kin.distance(robot, theta)) / _SCALE_STEP


def order_permutations(K: int):
    """``(name, description, permutation)`` of the order scenarios: the reverse order, each consecutive swap."""
    yield "reversed", "the poses visited in reverse order", np.arange(K)[::-1]
    for j in range(K - 1):
        pi = np.arange(K)
        pi[[j, j + 1]] = pi[[j + 1, j]]
        yield f"swap{j}", f"poses {j} and {j + 1} visited in each other's place", pi


@lru_cache(maxsize=None)
def order_matrix(K: int) -> np.ndarray:
    """The permutations of :func:`order_permutations` as rows, shape (S_o, K) (read-only, made once per K)."""
    out = np.array([pi for _, _, pi in order_permutations(K)])
    out.setflags(write=False)
    return out


def scenario_names(robot, K: int) -> list:
    """``(name, kind, description)`` of every scenario of a K-pose design, the columns of :func:`scenario_effects`.

    Kinds: ``entry`` (a robot-file entry at its tolerance; ``scale``: every length of the file off by
    :data:`DEFAULT_SCALE_ERROR`), ``order``, ``reading``.
    """
    from zerocal_sym.design.terms import omitted_params

    return list(_scenario_names(tuple(omitted_params(robot)), K))


def scenario_kinds(robot, K: int) -> np.ndarray:
    """The kind of each scenario of :func:`scenario_names`, shape (S,) (read-only)."""
    from zerocal_sym.design.terms import omitted_params

    return _scenario_kinds(tuple(omitted_params(robot)), K)


@lru_cache(maxsize=None)
def _scenario_names(omitted: tuple, K: int) -> tuple:
    out = [(n, "entry", f"robot-file entry {n} off by its tolerance") for n in omitted]
    out.append(("scale", "entry", "every length of the robot file off by the same fraction"))
    out += [(nm, "order", d) for nm, d, _ in order_permutations(K)]
    out += [(f"reading{k + 1}", "reading", f"one bad reading (the change into pose {k})") for k in range(K - 1)]
    return tuple(out)


@lru_cache(maxsize=None)
def _scenario_kinds(omitted: tuple, K: int) -> np.ndarray:
    out = np.array([k for _, k, _ in _scenario_names(omitted, K)])
    out.setflags(write=False)
    return out


def scenario_effects(ao, gs, rho, tol, scale_error: float, bad_reading_mm: float):
    """What each scenario adds to the K-1 readings, mm, shape (B, K-1, S) (columns: :func:`scenario_names`).

    Parameters
    ----------
    ao : ndarray, shape (B, K, r)
        ``d rho / d`` (omitted errors) per pose (:func:`zerocal_sym.design.terms.pose_terms`).
    gs : ndarray, shape (B, K)
        :func:`scale_column`.
    rho : ndarray, shape (B, K)
        The distances at zero source errors, mm.
    tol : ndarray, shape (r,)
        Tolerances of the omitted errors, internal units.
    """
    B, K, _ = ao.shape
    ent = np.diff(ao, axis=1) * tol
    perms = order_matrix(K)  # (S_o, K)
    orders = np.diff(rho[:, perms.T], axis=1) - np.diff(rho, axis=1)[:, :, None]  # (B, K-1, S_o)
    bad = np.broadcast_to(bad_reading_mm * np.eye(K - 1), (B, K - 1, K - 1))
    return np.concatenate([ent, scale_error * np.diff(gs, axis=1)[:, :, None], orders, bad], axis=2)


def _whiten_batch(v, sm2, *Ys):
    """``L^-1 Y`` for each ``Y`` (B, K-1, c), ``L`` the lower-bidiagonal Cholesky factor of the readings'
    covariance ``sigma_m^2 I + D diag(v) D^T`` (tridiagonal: diagonal ``sm2 + v_k + v_{k+1}``, off-diagonal
    ``-v_{k+1}``) of each of B designs; forward substitution, O(K) steps over the batch."""
    B, K = v.shape
    diag = sm2 + v[:, :-1] + v[:, 1:]
    off = -v[:, 1:-1]
    ell = np.empty((B, K - 1))
    sub = np.empty((B, max(K - 2, 0)))
    ell[:, 0] = np.sqrt(diag[:, 0])
    for k in range(K - 2):
        sub[:, k] = off[:, k] / ell[:, k]
        ell[:, k + 1] = np.sqrt(diag[:, k + 1] - sub[:, k] ** 2)
    out = []
    for Y in Ys:
        W = np.empty(Y.shape)
        W[:, 0] = Y[:, 0] / ell[:, 0, None]
        for k in range(1, K - 1):
            W[:, k] = (Y[:, k] - sub[:, k - 1, None] * W[:, k - 1]) / ell[:, k, None]
        out.append(W)
    return out


def _factor(aq, v, sm2, *Ys):
    """The whitened differences ``L^-1 D aq`` of B designs factored, ``(Q, R, ok, [L^-1 Y for Y in Ys])``; ``ok``
    (B,): the designs whose ``R`` is of full rank."""
    Aw, *W = _whiten_batch(v, sm2, np.diff(aq, axis=1), *Ys)
    Q, R = np.linalg.qr(Aw)
    d = np.abs(np.diagonal(R, axis1=1, axis2=2))
    ok = d.min(axis=1) > 1e-12 * np.maximum(d.max(axis=1), 1e-300)
    return Q, R, ok, W


def _variances(aq, R, ok):
    """``diag(F^-1)`` of B designs from their ``R`` (inf where not ``ok``), shape (B, p), and ``R[ok]^-1``."""
    var = np.full(aq.shape[::2], np.inf)
    Rinv = None
    if np.any(ok):
        Rinv = np.linalg.inv(R[ok])
        var[ok] = np.sum(Rinv ** 2, axis=2)  # diag((R^T R)^-1) = diag(F^-1)
    return var, Rinv


def crlb_variances(aq, v, sm2):
    """The diagonal of ``F^-1`` of B designs (:func:`noncentralities`' ``var``, the same numbers, without the
    scenarios), shape (B, p)."""
    _, R, ok, _ = _factor(aq, v, sm2)
    return _variances(aq, R, ok)[0]


def noncentralities(aq, v, sm2, delta, offsets, sigma=None, offset_range=None):
    """Non-centrality and harm of each scenario for B designs (first order).

    Parameters
    ----------
    aq : ndarray, shape (B, K, p)
        Sensitivities of the identified parameters (any column scaling).
    v : ndarray, shape (B, K)
        The servo error's variance of each pose's distance, mm^2.
    sm2 : float
        The scale error's variance per reading, mm^2.
    delta : ndarray, shape (B, K-1, S)
        :func:`scenario_effects`.
    offsets : list of int
        Columns of ``aq`` that are zero offsets.
    sigma : ndarray, shape (m,), optional
        The standard deviations the harm is counted in (the columns' units); default each design's own.
    offset_range : ndarray, shape (m,), optional
        The zero offsets' range (the columns' units): with it, ``order_harm``.

    Returns
    -------
    lam : ndarray, shape (B, S)
        ``|(I - H) L^-1 delta|^2``; inf where the design cannot identify the parameters.
    harm : ndarray, shape (B, S)
        The largest ``|b_i| / sigma_i`` over the zero offsets (``b`` the fit's shift, ``sigma`` its CRLB, or the
        ``sigma`` given).
    var : ndarray, shape (B, p)
        The diagonal of ``F^-1`` (the CRLB squared, the columns' units), inf where singular.
    order_harm : ndarray, shape (B, S_o), with ``offset_range``
        How far an order error can move an offset at offsets within their range, to first order in them: at
        offsets ``t`` the reordered readings' sensitivities ``D a(pi)`` differ from the model's ``D a``, and
        the fit moves by ``b(0) + G t``, ``G = F^-1 A^T C^-1 (D a(pi) - D a)`` (its offsets' block); the
        largest ``sum_j |G_ij| range_j / sigma_i`` (a mirror-symmetric design's reversed order:
        ``G`` = the mirror less the identity; a swap of two replicates: ``G`` = 0).
    """
    K = aq.shape[1]
    perms = order_matrix(K) if offset_range is not None else None
    extra = ()
    if perms is not None:  # the sensitivities' change of each reordering, only the offsets' columns
        a_off = aq[:, :, offsets]
        dA = np.diff(a_off[:, perms.T], axis=1) - np.diff(a_off, axis=1)[:, :, None]  # (B, K-1, S_o, m)
        extra = (dA.reshape(dA.shape[0], K - 1, -1),)
    Q, R, ok, (Dw, *dAw) = _factor(aq, v, sm2, delta, *extra)
    QtD = np.matmul(np.swapaxes(Q, 1, 2), Dw)
    lam = np.sum((Dw - np.matmul(Q, QtD)) ** 2, axis=1)
    lam[~ok] = np.inf
    harm = np.full(lam.shape, np.inf)
    order_harm = None if perms is None else np.full((aq.shape[0], len(perms)), np.inf)
    var, Rinv = _variances(aq, R, ok)
    if np.any(ok):
        b = np.matmul(Rinv, QtD[ok])[:, offsets]
        sig = np.sqrt(var[ok][:, offsets]) if sigma is None else \
            np.broadcast_to(np.asarray(sigma, float), (len(Rinv), len(offsets)))
        harm[ok] = np.max(np.abs(b) / sig[:, :, None], axis=1)
        if perms is not None:
            m = len(offsets)
            G = np.matmul(Rinv, np.matmul(np.swapaxes(Q[ok], 1, 2), dAw[0][ok]))[:, offsets]  # (B', m, S_o m)
            G = G.reshape(len(Rinv), m, len(perms), m)
            shift = np.einsum("bisj,j->bsi", np.abs(G), np.asarray(offset_range, float))
            order_harm[ok] = np.max(shift / sig[:, None, :], axis=2)
    out = (lam, harm, var)
    return out + (order_harm,) if perms is not None else out


def invisible_entries(robot, ao, aq, rtol: float = 1e-8) -> list:
    """The robot-file entries no design can see: their effect on every pose is one the identified parameters make.

    ``ao`` (N, r), ``aq`` (N, p): the per-pose terms of many poses (the candidates); the entry's
    differences along them (in their order) lie in the span of the identified parameters' up to ``rtol``.
    """
    from zerocal_sym.design.terms import omitted_params

    A, Ao = np.diff(aq, axis=0), np.diff(ao, axis=0)
    Q, _ = np.linalg.qr(A)
    res = Ao - Q @ (Q.T @ Ao)
    frac = np.sum(res ** 2, axis=0) / np.maximum(np.sum(Ao ** 2, axis=0), 1e-300)
    return [n for n, f, a in zip(omitted_params(robot), frac, np.sum(Ao ** 2, axis=0)) if a > 0 and f < rtol]
