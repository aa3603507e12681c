"""Replicated poses in a design: their visiting sequence, and the shared revisit error in the criteria.

A design realised from an approximate design (:mod:`zerocal_sym.design.rounding`)
visits each support point as many times as its rounded weight says: *true
replicates*, the same pose again, never twice in a row (a zero change carries
no information).  Replicates average the independent errors (scale, servo);
a pose's systematic error shared by its revisits
(:class:`~zerocal_sym.model.noise.NoiseModel` ``sigma_revisit_mm``) they do
not, so with it the CRLB of a replicated design levels off instead of
falling as ``1/sqrt(K)``.

* :func:`cap_counts` -- counts no larger than a sequence without two
  successive visits of one pose allows (``(K + 1) // 2``);
* :func:`no_successive` -- a visiting sequence of the support points without
  two successive visits of one point (a fallback for the stride order);
* :func:`revisit_terms` / :func:`shared_fisher` -- the shared error in a
  design's exact criterion (the independent variances of the poses visited
  once, the low-rank part of the revisited ones:
  :mod:`zerocal_sym.identify.covariance`).  The design searches (exchange,
  NLP, visiting order, the approximate design's measure) use the independent
  noise alone; the shared error only removes information, so the
  approximate design's bound stays a bound.

Shapes: K poses, s support points, p parameters, G revisited poses.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.design.limits import DesignError


def cap_counts(n, w):
    """Counts summing to the same K, none above ``(K + 1) // 2`` (the surplus moved to the point with the
    smallest ``n_i / w_i``, as efficient rounding would), shape (s,)."""
    n = np.array(n, int)
    w = np.asarray(w, float)
    K = int(n.sum())
    if len(n) < 2 and K > 1:
        raise DesignError("a design of one support point cannot be visited without two successive visits of one "
                          "pose (a zero change)")
    cap = (K + 1) // 2
    while n.max() > cap:
        i = int(np.argmax(n))
        n[i] -= 1
        r = np.where(np.arange(len(n)) == i, np.inf, n / np.maximum(w, 1e-300))
        n[int(np.argmin(r))] += 1
    return n


def no_successive(counts, priority=None) -> np.ndarray:
    """A sequence of support-point indices visiting point i ``counts[i]`` times, never the same twice in a row.

    Greedy: the point with the most visits left that is not the previous one (ties by ``priority``, earlier
    first); always succeeds when no count exceeds ``(K + 1) // 2``.  Shape (K,).
    """
    left = np.array(counts, int)
    K = int(left.sum())
    if left.max(initial=0) > (K + 1) // 2:
        raise DesignError(f"counts {left.tolist()}: a point visited more than (K + 1) / 2 times is visited twice "
                          "in a row")
    rank = np.empty(len(left), int)
    rank[np.asarray(np.arange(len(left)) if priority is None else priority)] = np.arange(len(left))
    seq = np.empty(K, int)
    prev = -1
    for k in range(K):
        key = np.where((left > 0) & (np.arange(len(left)) != prev), left - 1e-6 * rank, -np.inf)
        j = int(np.argmax(key))
        seq[k] = j
        left[j] -= 1
        prev = j
    return seq


def revisits_entry(P) -> dict:
    """``{"revisits": "allowed"}`` when the design's poses ``P`` (K, n) revisit a pose (the key a pose file says
    it with, so that its readers accept the replicates), else ``{}``."""
    from zerocal_sym.io.csvtext import REVISITS_ALLOWED, REVISITS_KEY
    from zerocal_sym.model.revisits import REVISIT_TOL, pose_groups

    lab = pose_groups(np.atleast_2d(np.asarray(P, float)), REVISIT_TOL)
    return {REVISITS_KEY: REVISITS_ALLOWED} if lab.size and int(lab.max()) + 1 < lab.size else {}


def revisit_terms(robot, P, noise, v):
    """``(v, B)``: the per-pose variances ``v`` (1, K) with the shared error of the poses visited once, and the
    revisited poses' part ``B`` (K-1, G) of the changes' covariance (None: no shared error or no revisit).

    The poses of a design are revisits when equal to
    :data:`~zerocal_sym.model.revisits.REVISIT_TOL` in file units.
    """
    from zerocal_sym.design.terms import poses_to_user
    from zerocal_sym.identify.covariance import shared_terms
    from zerocal_sym.model.revisits import REVISIT_TOL, pose_groups

    noise = robot.noise if noise is None else noise
    if not noise.has_shared:
        return v, None
    lab = pose_groups(poses_to_user(robot, np.atleast_2d(np.asarray(P, float))), REVISIT_TOL)
    v1, B = shared_terms(np.ravel(v), lab, noise.sigma_revisit_mm)
    return v1[None], B


def shared_fisher(aq, v, sm2, B):
    """The Fisher information in q-units of one ordered design with the revisited poses' part ``B``, (p, p).

    ``aq`` (K, p), ``v`` (K,) (the once-visited poses' shared error included, :func:`revisit_terms`),
    ``sm2`` the scale variance: ``A^T C^-1 A``, ``C`` the bands plus ``B B^T``, exact in O(K (p + G)).
    """
    from zerocal_sym.identify.covariance import ChangeCovariance

    v = np.ravel(v)
    A = np.diff(aq, axis=0)
    C = ChangeCovariance(sm2 + v[:-1] + v[1:], -v[1:-1], B)
    try:
        WA = C.whiten(A)
    except np.linalg.LinAlgError:
        return np.zeros((A.shape[1], A.shape[1]))  # not positive definite: no information (rank-deficient)
    F = WA.T @ WA
    return (F + F.T) / 2


def shared_floor(robot, support, noise) -> float:
    """The RMS zero-offset CRLB (file unit) that replicates of ``support`` (s, n) approach as K grows, with the
    shared revisit error: every support point's own ``u_g`` stays, the independent errors average out::

        F_inf = sum_g (a_g - mean a)(a_g - mean a)^T / sigma_r^2

    (``a_g`` the distance's sensitivity at support point g; the mean: the changes do not see a common
    offset).  ``inf`` when the support cannot identify the parameters; 0 without a shared error.
    """
    from zerocal_sym.design.terms import offset_positions, offsets_to_user
    from zerocal_sym.model import kinematics as kin

    if not noise.has_shared:
        return 0.0
    _, de, _ = kin.distance_jacobians(robot, kin.ik(robot, np.atleast_2d(support)))
    a = de[:, robot.errors.indices("paper")]
    a = a - a.mean(axis=0)
    F = a.T @ a / noise.sigma_revisit_mm**2
    try:
        var = np.diag(np.linalg.inv(F))[offset_positions(robot)]
    except np.linalg.LinAlgError:
        return float("inf")
    if not np.all(np.isfinite(var)) or np.any(var <= 0):
        return float("inf")
    return float(np.sqrt(np.mean(np.square(offsets_to_user(robot, np.sqrt(var))))))
