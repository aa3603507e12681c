"""Identifiability of the source errors from distance changes, for every mechanism.

Computed numerically: the rank and the null space of the whitened,
column-scaled sensitivity of the K-1 measured changes to the chosen
parameters at the given poses.  Each unobservable direction is written as a
combination of named parameters, and where the mechanism declares its gauge
motions (rigid motions of the robot against the measuring mechanism, the
generated ``gauge``), the report says which of them a null direction is.

A distance measurement cannot see a rigid motion of everything it measures:
for the planar robot the translations x, y and the rotation about O of the
robot together with the measuring base point ``c + d + rM`` (3 directions of
its 12 source errors); for the Delta a vertical translation and a rotation
about z (2 of 21).  The rotation mixes the common-mode zero offset with the
base: the zero offsets are only defined relative to the base.  Holding the
mechanism's ``gauge_fix`` errors at zero (planar ``e1x e1y e2y``: ``A1``
exact and ``A2`` on the same horizontal; Delta ``z1 phi1``) fixes the gauge;
the parameter set ``gauge_fixed`` is the rest, identifiable from enough poses.

Scaling: the sensitivity is column-scaled by
:func:`zerocal_sym.identify.fisher.parameter_scale` (angles as the arc of
their lever arm, ``L_i dtheta_i`` in mm; lengths in mm) and row-whitened by
the noise model, so a singular value ``sigma`` means the corresponding
combination (unit vector in the scaled mm units) is estimated with standard
deviation ``1/sigma`` mm.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.model.noise import NoiseModel, geometry_error


def gauge_generators(robot, err=None) -> np.ndarray:
    """The mechanism's gauge motions at ``err`` (first order), shape (z, q).

    Rows in the order of ``robot.mechanism.gauge_names``; rad / mm per unit
    of motion.  Evaluated at the actual geometry (nominal + ``err``), so they
    are tangent to the gauge orbit through ``err``.
    """
    from dataclasses import replace

    actual = robot if err is None else replace(robot, geometry=robot.geometry + geometry_error(robot, err))
    return kin.gauge(actual).T


def gauge_invariance(robot, theta_cmd, err=None, eps: float = 1e-4) -> float:
    """Largest change of any measured change ``rho_{k+1} - rho_k`` (mm) when ``err`` moves by
    ``eps`` along each gauge generator (second order in ``eps``: ~1e-9 mm at the default)."""
    err = robot.errors.zeros() if err is None else robot.errors.check_vector(err)
    base = np.diff(kin.distance(robot, theta_cmd, err))
    worst = 0.0
    for z in gauge_generators(robot, err):
        moved = np.diff(kin.distance(robot, theta_cmd, err + eps * z / np.max(np.abs(z))))
        worst = max(worst, float(np.max(np.abs(moved - base))))
    return worst


def scaled_sensitivity(robot, theta_cmd, params="paper", noise: NoiseModel | None = None, err0=None):
    """Whitened, column-scaled sensitivity of the K-1 changes, shape (K-1, p).

    ``noise=NoiseModel()`` (zero) means unweighted (mm per scaled mm);
    default: the paper's noise model.
    """
    noise = NoiseModel.coerce(noise, robot=robot)
    A = fisher.sensitivity(robot, theta_cmd, params, err0) / fisher.parameter_scale(robot, params)
    if noise.is_zero:
        return A
    return fisher.change_covariance(robot, theta_cmd, noise, err0).whiten(A)  # banded: O(K p)


def _combination(robot, names, v, scale, tol=1e-3):
    """A direction (scaled units) as a readable combination in physical units."""
    v = v / np.max(np.abs(v))
    terms = []
    for n, c, sc in zip(names, v, scale):
        if abs(c) >= tol:
            terms.append({"param": n, "weight": float(c), "per_scaled_mm": float(c / sc),
                          "unit": robot.errors[n].unit})
    return terms


def _gauge_in_params(robot, names, scale, err0):
    """The declared gauge motions that are invisible in these parameters (all components estimated).

    Returns ``(labels, Z)`` with ``Z`` shape (p, z') in scaled units.
    """
    idx = robot.errors.indices(names)
    gens, labels = [], []
    for label, g in zip(robot.mechanism.gauge_names, gauge_generators(robot, err0)):
        if np.all(np.isin(np.flatnonzero(np.abs(g) > 1e-12), idx)):
            gens.append(g[idx] * scale)
            labels.append(label)
    return labels, (np.array(gens).T if gens else np.zeros((len(names), 0)))


def _null_space_named(robot, names, scale, null, err0):
    """The null space written, where it can be, as the declared gauge motions.

    Returns ``(rigid, vectors, labels)``: ``rigid`` True if the null space is
    exactly spanned by the gauge motions invisible in these parameters (then
    ``vectors`` are those motions, one per null direction, each labelled
    with its name), False if not (``vectors`` the SVD basis, each labelled
    with the gauge motions it lies in, or none), None without a null space.
    """
    if not null.size:
        return None, null, []
    labels, Z = _gauge_in_params(robot, names, scale, err0)
    if Z.shape[1]:
        Qg, _ = np.linalg.qr(Z)
        in_span = bool(np.allclose(null.T - Qg @ (Qg.T @ null.T), 0.0, atol=1e-6))
        if in_span and Z.shape[1] == null.shape[0]:
            return True, Z.T, [[lab] for lab in labels]
    per = []
    for v in null:
        if not Z.shape[1]:
            per.append([])
            continue
        coef, *_ = np.linalg.lstsq(Z, v, rcond=None)
        inside = np.linalg.norm(Z @ coef - v) < 1e-6 * max(1.0, np.linalg.norm(v))
        per.append([lab for lab, c in zip(labels, coef) if inside and abs(c) > 1e-6 * np.max(np.abs(coef))])
    return False, null, per


def identifiability_report(robot, theta_cmd, params="paper", noise: NoiseModel | None = None,
                           err0=None, rtol: float = 1e-8) -> dict:
    """Rank, singular values and the (weakly) non-identifiable combinations.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joints, rad.
    params : str or sequence of str
        Parameter names or sets (:meth:`SourceErrors.resolve`).
    noise : NoiseModel, optional
        Row whitening (default: the paper's noise; zero model: unweighted).
    err0 : ndarray, shape (q,), optional
        Linearisation point.
    rtol : float
        Singular values below ``rtol * sigma_max`` count as zero.

    Returns
    -------
    dict
        ``params``, ``K``, ``n_equations``, ``rank``, ``singular_values``
        (whitened & scaled), ``condition_number``, ``scaling`` (text),
        ``directions``: for each singular value its combination (weights on
        the scaled parameters, largest 1) and ``std_mm = 1/sigma``;
        ``null_space``: the combinations with ``sigma < rtol sigma_max`` --
        the declared gauge motions themselves when they span it exactly;
        ``null_space_gauge``: for each null combination, the names of the
        gauge motions it is made of (empty: not a gauge motion);
        ``null_space_rigid``: True if the whole null space is spanned by the
        gauge motions (None if there is no null space);
        ``identifiable``: per parameter, whether it is orthogonal to the null
        space; ``crlb_std``: per identifiable parameter, its CRLB std
        (rad / mm) with the others in the null space held at ``err0``
        (pseudo-inverse), None otherwise; ``gauge_fix``: the mechanism's
        gauge-fixing parameters.
    """
    errors = robot.errors
    names = errors.resolve(params)
    noise = NoiseModel.coerce(noise, robot=robot)
    theta_cmd = np.atleast_2d(np.asarray(theta_cmd, float))
    As = scaled_sensitivity(robot, theta_cmd, names, noise, err0)
    scale = fisher.parameter_scale(robot, names)
    p = len(names)
    # Vt (p, p) and the singular values; no U (it would be (K-1) x (K-1))
    _, s, Vt = np.linalg.svd(As, full_matrices=As.shape[0] < p)
    sv = np.zeros(p)
    sv[: s.size] = s
    smax = sv[0] if sv.size else 0.0
    rank = int(np.sum(sv > rtol * smax)) if smax > 0 else 0
    null = Vt[rank:]
    ident = [bool(null.size == 0 or np.max(np.abs(null[:, k])) < 1e-6) for k in range(p)]
    rigid, null_vectors, per = _null_space_named(robot, names, scale, null, err0)
    crlb_std = [None] * p
    if not noise.is_zero and rank:
        Finv = (Vt[:rank].T / sv[:rank] ** 2) @ Vt[:rank]
        for k in range(p):
            if ident[k]:
                crlb_std[k] = float(np.sqrt(Finv[k, k]) / scale[k])
    directions = [{"sigma": float(sv[k]), "std_mm": (float(1.0 / sv[k]) if sv[k] > rtol * smax else None),
                   "combination": _combination(robot, names, Vt[k], scale)} for k in range(p)]
    return {
        "mechanism": robot.mechanism_name,
        "params": list(names),
        "K": int(theta_cmd.shape[0]),
        "n_equations": int(theta_cmd.shape[0] - 1),
        "rank": rank,
        "singular_values": sv.tolist(),
        "condition_number": float(smax / sv[rank - 1]) if rank else float("inf"),
        "condition_number_full": float(smax / sv[-1]) if sv[-1] > 0 else float("inf"),
        "scaling": ("columns: angles as lever*dangle (mm; zero offsets L_i*dtheta_i), lengths in mm; rows: "
                    + ("unweighted (mm)" if noise.is_zero else "whitened by chol(Cov(s)) (paper noise model "
                       "unless given), so 1/sigma is the std (mm) of that combination")),
        "directions": directions,
        "null_space": [_combination(robot, names, v, scale) for v in null_vectors],
        "null_space_gauge": per,
        "null_space_rigid": rigid,
        "gauge_fix": list(robot.mechanism.gauge_fix),
        "identifiable": dict(zip(names, ident)),
        "crlb_std": dict(zip(names, crlb_std)),
    }


def null_direction_text(robot, combination) -> str:
    """A null direction (``identifiability_report``'s ``null_space`` entry) as amounts of the source errors in
    file units, the largest 1: ``ddx = +1, rMx = +0.951, rMy = -0.255, rMz = +0.174 mm``."""
    vals = [(t["param"], float(units.to_user(t["per_scaled_mm"], t["unit"])), robot.errors[t["param"]].user_unit)
            for t in combination]
    big = max(vals, key=lambda v: abs(v[1]))[1]
    vals = [(n, v / big, u) for n, v, u in vals if abs(v / big) >= 1e-3]
    parts = [f"{n} = {v:+.3g}" + (f" {u}" if k + 1 == len(vals) or vals[k + 1][2] != u else "")
             for k, (n, v, u) in enumerate(vals)]
    return ", ".join(parts)


def null_space_phrase(robot, theta_cmd, names, err0=None) -> str:
    """Why ``names`` are not identifiable from the poses: their null directions in file units (at most two
    named; :func:`null_direction_text`), for a refusal's message."""
    rep = identifiability_report(robot, theta_cmd, list(names), noise=NoiseModel(), err0=err0)
    null = rep["null_space"]
    if not null:
        return ""
    if rep["null_space_rigid"]:
        motions = [label for labels in rep["null_space_gauge"] for label in labels]
        return "the distances do not see the rigid motion(s) " + ", ".join(motions)
    if len(null) > 2:
        return f"{len(null)} combinations change no measured distance"
    return ("this combination changes" if len(null) == 1 else "these combinations change") + \
        " no measured distance: " + "; ".join(null_direction_text(robot, c) for c in null)


def format_report(rep: dict) -> str:
    """Human-readable text of :func:`identifiability_report`."""
    lines = [f"parameters: {', '.join(rep['params'])}   poses K = {rep['K']} "
             f"({rep['n_equations']} measured changes)",
             f"rank {rep['rank']} of {len(rep['params'])};  condition number "
             f"{rep['condition_number']:.4g} (identifiable part)",
             f"scaling: {rep['scaling']}",
             "singular values and their combinations (weights on scaled parameters):"]
    for d in rep["directions"]:
        comb = " ".join(f"{t['weight']:+.3f}*{t['param']}" for t in d["combination"])
        std = f"std {d['std_mm']:.3g} mm" if d["std_mm"] is not None else "NOT IDENTIFIABLE"
        lines.append(f"  sigma {d['sigma']:10.4g}  {std:>18s}  {comb}")
    if rep["null_space"]:
        lines.append(f"null space: {len(rep['null_space'])} combination(s)")
        for comb, gauge in zip(rep["null_space"], rep["null_space_gauge"]):
            what = ("gauge: " + " + ".join(gauge)) if gauge else "not a gauge motion: add poses or drop parameters"
            lines.append("  " + " ".join(f"{t['weight']:+.3f}*{t['param']}" for t in comb) + f"   [{what}]")
        if rep["null_space_rigid"]:
            lines.append("  all are rigid motions of robot + measuring base (gauge); fix e.g. "
                         + ", ".join(rep["gauge_fix"]) + " (parameter set 'gauge_fixed')")
    bad = [n for n, ok in rep["identifiable"].items() if not ok]
    lines.append("not identifiable: " + (", ".join(bad) if bad else "none"))
    return "\n".join(lines)
