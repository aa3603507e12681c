"""TSVD of many rounds at once: the estimate of each as one call per round gives it, bit for bit.

:func:`tsvd_many` batches the kinematics, identification matrices and SVDs
of rounds with the same number of poses; a round the batch cannot take is
handed to the single-round identification given (``alone``).  With a noise
model each result carries its std
(:func:`~zerocal_sym.identify.estimate.tsvd_uncertainty.attach_std_many`).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.estimate.truncated_svd import DEFAULT_RTOL, DEFAULT_RULE, _solve_svd
from zerocal_sym.identify.estimate.tsvd_round import (COLLINEAR_RTOL, RANK_RTOL, _estimate, _lean, _validate,
                                                      tsvd_round)


def _raise_if_interrupt(exc):
    """Re-raise Ctrl-C that C code turned into an error (CasADi's ``RuntimeError("KeyboardInterrupt")``, an
    error made of one): a batch must not swallow it (see ``zerocal_sym.cli._interrupt``)."""
    e, seen = exc, set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt) or (isinstance(e, RuntimeError) and str(e).strip() == "KeyboardInterrupt"):
            raise exc
        seen.add(id(e))
        e = e.__cause__ or e.__context__


def tsvd_many(robot, rounds, priors=None, t=None, rule=DEFAULT_RULE, rtol=DEFAULT_RTOL, noise=None, alone=None) -> list:
    """TSVD's estimates of many rounds at once (module docstring).

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
        As :func:`~zerocal_sym.identify.tsvd.identify_tsvd` (no noise model: not the ``discrepancy`` rule).
    noise : NoiseModel, optional
        With it each result carries its std as ``identify_tsvd`` computes it (``covariance``,
        ``std_kind``, ``info["std_kinds"]``, ``info["linearisation_bias"]``, ...;
        :func:`~zerocal_sym.identify.estimate.tsvd_uncertainty.attach_std_many`), still without the fit check; a
        truncated round (``t < p``) is identified alone.
    alone : callable, optional
        ``alone(meas, prior) -> IdentificationResult``: the identification of a round the batch does not take
        (:func:`~zerocal_sym.identify.tsvd.identify_tsvd_many` passes ``identify_tsvd`` with diagnostics
        when a noise model is given).  Default, without a noise model only: the estimate alone
        (:func:`~zerocal_sym.identify.estimate.tsvd_round.tsvd_round` without diagnostics).

    Returns
    -------
    list
        Per round its :class:`IdentificationResult`, or the exception ``alone`` raised for it.
    """
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.model import kinematics as kin

    rounds = list(rounds)
    priors = [None] * len(rounds) if priors is None else list(priors)
    if len(priors) != len(rounds):
        raise ValueError(f"{len(rounds)} rounds but {len(priors)} priors")
    out = [None] * len(rounds)

    if alone is None:
        if noise is not None:
            raise ValueError("tsvd_many with a noise model needs the single-round identification (alone)")

        def alone(meas, prior):  # the estimate alone
            return tsvd_round(robot, meas, prior, t=t, rule=rule, rtol=rtol, diagnostics=False)[0]
    identify_one = alone

    def alone(i):
        try:
            out[i] = identify_one(rounds[i], priors[i])
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
            from zerocal_sym.identify.estimate.tsvd_uncertainty import attach_std_many

            attach_std_many(robot, pending, noise)
    return out
