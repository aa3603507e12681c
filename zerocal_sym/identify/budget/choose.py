"""Which parameters to identify: the set whose offsets' expected error is least.

Identifying more of the robot (an arm length with the zero offsets) trades
bias for variance: an entry held at the robot file's value can bias the
offsets by up to its tolerance times their sensitivity to it
(:mod:`zerocal_sym.identify.budget.bias`); an entry identified costs variance,
because the data must now tell it from the offsets.  For a parameter set
``S`` and poses ``theta_cmd`` the expected squared error of zero offset ``i``
is (first order, the held entries independent and uniform within their
tolerances ``t_j``, as the ``mse`` design criterion counts them)::

    E[(est_i - true_i)^2] = CRLB_i(S)^2 + sum_{j held} S_ij^2 t_j^2 / 3

and the set's score is ``sqrt(mean_i E[...])`` (the offsets' unit).
:func:`choose_params` scores the candidate sets (:func:`candidate_sets`: the
base set plus whole groups of held entries, ``L`` for ``L1 L2 L3``:
:func:`zerocal_sym.model.tolerances.groups`) and returns the least -- of the
sets within :data:`MARGIN` of it, the one that frees the fewest groups.  A
set the poses cannot identify scores infinity.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from zerocal_sym.errors import PoseError
from zerocal_sym.identify import fisher
from zerocal_sym.identify.budget import bias as bias_mod
from zerocal_sym.model import tolerances as tl
from zerocal_sym.model import units

#: with more groups than this the candidate sets are grown one group at a time (forward selection)
EXHAUSTIVE_GROUPS = 8
#: a set that frees more groups is chosen only when it lowers the score by more than this fraction: the score is
#: first order, and every entry identified more is one more direction the data must pin down
MARGIN = 0.05


def held_groups(robot, base="paper") -> dict:
    """Groups (name -> entries) of the source errors ``base`` holds (:func:`zerocal_sym.model.tolerances.groups`),
    each restricted to its held entries that can be identified: not those the mechanism holds to fix its gauge
    (its ``gauge_fixed`` set leaves them out: the Delta's ``phi1``, ``z1``)."""
    errors = robot.errors
    keep = set(errors.resolve(base))
    if "gauge_fixed" in errors.extra_sets:
        keep |= set(errors.names) - set(errors.resolve("gauge_fixed"))
    out = {}
    for g, names in tl.groups(errors).items():
        held = tuple(n for n in names if n not in keep)
        if held:
            out[g] = held
    return out


def set_spec(robot, base, groups_) -> str:
    """The ``--params`` spelling of ``base`` with the entries of ``groups_`` (a list of tuples) added."""
    extra = [n for g in groups_ for n in g]
    return base if not extra else f"{base}+{','.join(extra)}"


def candidate_sets(robot, base="paper") -> list:
    """Every union of held groups added to ``base`` (:data:`EXHAUSTIVE_GROUPS` or fewer groups), as a list of
    (group names tuple, spec)."""
    gs = held_groups(robot, base)
    names = list(gs)
    out = []
    for r in range(len(names) + 1):
        for combo in itertools.combinations(names, r):
            out.append((combo, set_spec(robot, base, [gs[g] for g in combo])))
    return out


def expected_error(robot, theta_cmd, params, tolerances: dict, noise=None, err0=None) -> dict:
    """The offsets' expected error for the set ``params`` at these poses.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
    tolerances : dict
        name -> tolerance (internal units) of every entry that may be held.

    Returns
    -------
    dict
        ``params`` (spec), ``crlb`` and ``bias_rms`` per offset (the offsets' unit), ``expected`` (the score:
        ``sqrt(mean_i (crlb_i^2 + bias_rms_i^2))``; inf when the poses do not identify the set),
        ``identifiable``.
    """
    errors = robot.errors
    names = errors.resolve(params)
    m = len(errors.zero_offsets)
    try:
        crlb = np.asarray(fisher.crlb_zero_offsets_user(robot, theta_cmd, names, noise, err0), float)
    except (PoseError, np.linalg.LinAlgError):
        inf = [math.inf] * m
        return {"params": params, "crlb": inf, "bias_rms": inf, "expected": math.inf, "identifiable": False}
    S, om = bias_mod.bias_sensitivity(robot, theta_cmd, names, noise, err0)
    t = bias_mod.tolerance_vector(robot, tolerances, om)
    off = [names.index(z) for z in errors.zero_offsets]
    rms = units.to_user(np.sqrt((S[off] ** 2) @ (t ** 2) / 3.0), errors.offset_unit)
    exp = float(np.sqrt(np.mean(crlb ** 2 + rms ** 2)))
    return {"params": params, "crlb": crlb.tolist(), "bias_rms": np.asarray(rms).tolist(), "expected": exp,
            "identifiable": bool(np.all(np.isfinite(crlb)))}


def forward_select(score, groups) -> tuple:
    """Forward selection: from no group, add the group that lowers ``score(groups)["expected"]`` most, while
    one lowers it by more than :data:`MARGIN`.  ``score`` takes a tuple of groups and returns a row with
    ``expected`` and ``groups``; returns ``(the last row kept, its groups)``."""
    current = ()
    best = score(current)
    while True:
        trial = [score(current + (g,)) for g in groups if g not in current]
        if not trial:
            break
        top = min(trial, key=lambda r: r["expected"])
        if not top["expected"] < (1 - MARGIN) * best["expected"]:
            break
        best, current = top, tuple(top["groups"])
    return best, current


def parsimonious(rows: list) -> dict:
    """Of ``rows`` (``expected``, ``groups``), the one that frees the fewest groups among those within
    :data:`MARGIN` of the least score (then the least score)."""
    least = min(r["expected"] for r in rows)
    near = [r for r in rows if r["expected"] <= least * (1 + MARGIN)] if math.isfinite(least) else rows
    return min(near, key=lambda r: (len(r["groups"]), r["expected"]))


def choose_params(robot, theta_cmd, tolerances: dict | None = None, noise=None, base="paper", err0=None) -> dict:
    """The parameter set (``base`` plus whole groups of held entries) whose offsets' expected error at these
    poses is least.

    Parameters
    ----------
    tolerances : dict, optional
        name -> tolerance (internal units) of the entries ``base`` holds; default the robot's
        (:meth:`Robot.tolerances <zerocal_sym.model.robot.Robot.tolerances>`).

    Returns
    -------
    dict
        ``chosen`` (spec), ``freed`` (group names), ``expected`` (its score), ``base_expected``, ``table``
        (every set scored: ``groups``, ``params``, ``expected``, ``crlb``, ``bias_rms``, ``identifiable``;
        least first), ``search`` ("exhaustive" or "forward"), ``model``.
    """
    tol = bias_mod.default_tolerances(robot, base) if tolerances is None else dict(tolerances)
    gs = held_groups(robot, base)
    rows = []

    def score(combo):
        spec = set_spec(robot, base, [gs[g] for g in combo])
        row = expected_error(robot, theta_cmd, spec, tol, noise, err0)
        row["groups"] = list(combo)
        rows.append(row)
        return row

    if len(gs) <= EXHAUSTIVE_GROUPS:
        search = "exhaustive"
        for combo, _ in candidate_sets(robot, base):
            score(combo)
    else:
        search = "forward"
        forward_select(score, gs)
    rows.sort(key=lambda r: (r["expected"], len(r["groups"])))
    base_row = next(r for r in rows if not r["groups"])
    best = parsimonious(rows)
    return {"chosen": best["params"], "base": base, "freed": best["groups"], "expected": best["expected"],
            "base_expected": base_row["expected"], "table": rows, "search": search,
            "unit": robot.errors.offset_user_unit,
            "model": "sqrt(mean_i (CRLB_i^2 + sum_j S_ij^2 t_j^2 / 3)): the variance of what is identified and the "
                     "squared bias (first order, uniform within the tolerances) of what is held"}
