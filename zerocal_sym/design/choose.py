"""Which parameter set to design for: the one whose offsets' expected error at K is least.

``zerocal design --optimize --choose-params``: for a parameter set ``S`` (the
robot's identified set plus whole groups of the robot-file entries it holds,
:func:`zerocal_sym.identify.budget.choose.held_groups`) a K-pose design is made for
``S`` and scored by the offsets' expected error at its poses,
``sqrt(mean_i (CRLB_i(S)^2 + sum_{j held} S_ij^2 t_j^2 / 3))``
(:func:`zerocal_sym.identify.budget.choose.expected_error`: the variance of what is
identified, the squared bias from the tolerances of what is held).  The sets
are searched forward: from the robot's set, add the group whose design scores
least, while that lowers the score by more than
:data:`zerocal_sym.identify.budget.choose.MARGIN`.  The designs of the search are
approximate designs (the design measure rounded to K poses, about a second
each; :func:`zerocal_sym.design.optimize.optimize_design` with
``method="approx"``); the chosen set's design is then made as asked.
"""
from __future__ import annotations

import math

from zerocal_sym.design.limits import DesignError


def choose_design_params(robot, K: int, criterion: str, cons, noise, tolerances, seed: int = 0, starts: int = 8,
                         progress=None) -> dict:
    """The parameter set whose K-pose design gives the least expected offset error (module docstring).

    Parameters
    ----------
    robot : Robot
        Its :attr:`identified_set` is where the search starts.
    criterion : str
        The designs' criterion (``cond``, which has no approximate design: ``crlb``).
    tolerances : dict
        name -> tolerance (internal units) of every entry the robot's set holds.
    progress : callable, optional
        Called with a line of text per set scored.

    Returns
    -------
    dict
        ``chosen`` (spec), ``freed`` (groups), ``expected`` (its score, the offsets' unit), ``base_expected``,
        ``table`` (per set scored: ``groups``, ``params``, ``expected``, ``crlb``, ``bias_rms``, ``reason`` when
        no design was found; least first), ``search``, ``model``.
    """
    from zerocal_sym.design.optimize import optimize_design
    from zerocal_sym.identify.budget.choose import expected_error, forward_select, held_groups, set_spec
    from zerocal_sym.model import kinematics as kin

    base = robot.identified_set
    gs = held_groups(robot, base)
    crit = "crlb" if criterion == "cond" else criterion
    rows = []

    def score(combo):
        spec = set_spec(robot, base, [gs[g] for g in combo])
        r = robot.identifying(spec)
        try:
            res = optimize_design(r, K, crit, cons, noise, seed=seed, n_starts=starts, exchange_starts=starts,
                                  tolerances=tolerances, method="approx", certificate=False)
            row = expected_error(r, kin.ik(r, res.poses), spec, tolerances, noise)
            row["reason"] = None
        except DesignError as exc:
            inf = [math.inf] * len(robot.errors.zero_offsets)
            row = {"params": spec, "crlb": inf, "bias_rms": inf, "expected": math.inf, "identifiable": False,
                   "reason": str(exc)}
        row["groups"] = list(combo)
        rows.append(row)
        if progress is not None:
            progress(f"  {spec}: expected offset error {row['expected']:.4g} {robot.errors.offset_user_unit}"
                     + (f" ({row['reason']})" if row["reason"] else ""))
        return row

    best, current = forward_select(score, gs)
    rows.sort(key=lambda r: (r["expected"], len(r["groups"])))
    base_row = next(r for r in rows if not r["groups"])
    return {"chosen": best["params"], "base": base, "freed": list(current), "expected": best["expected"],
            "base_expected": base_row["expected"], "table": rows, "search": "forward, approximate designs",
            "unit": robot.errors.offset_user_unit,
            "model": "sqrt(mean_i (CRLB_i^2 + sum_j S_ij^2 t_j^2 / 3)) at each set's own K-pose design"}
