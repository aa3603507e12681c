"""Which robot-file entries do the data contradict?  Free each group in turn: a likelihood-ratio test.

The identification holds the robot-file entries outside its set at the
file's values.  For each group of them (:func:`zerocal_sym.identify.budget.choose.held_groups`:
``L`` for ``L1 L2 L3``) :func:`free_each_group` fits the data again with the
group identified too (the exact model, Ipopt: :func:`~zerocal_sym.identify.nlls.identify_nlls`)
and compares the two fits: under the hypothesis that the file is right for
the group, the drop of chi², ``LR = chi2(held) - chi2(freed)``, is chi²
distributed on ``d`` degrees of freedom, ``d`` the number of combinations the
freed fit identifies beyond the held one (its rank minus the held fit's).
A p-value below ``alpha`` says the data contradict the file's values of the
group; the entries the freed fit puts more than :data:`Z_NAMED` standard
deviations from the file are named.

It tests what the poses can see: a group whose effect the identified
parameters absorb (a common arm length against a common offset, on a design
made for the offsets alone) lowers chi² by little whatever its error, and
the test cannot contradict it (its bias is in the error budget:
:mod:`zerocal_sym.identify.budget.error_budget`).  One test per group, each at ``alpha``
(no correction for the number of groups: the result lists them all).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.identify.budget.choose import held_groups, set_spec
from zerocal_sym.identify.check.statistics import DEFAULT_ALPHA
from zerocal_sym.identify.chi2 import _fmt_p, chi2_sf

#: an entry of a contradicted group is named when the freed fit puts it this many standard deviations from the file
Z_NAMED = 3.0


def free_each_group(robot, meas, params="paper", noise=None, prior=None, alpha: float = DEFAULT_ALPHA,
                    held=None, tolerances=None, *, identify) -> dict:
    """The likelihood-ratio test of each group of held robot-file entries (module docstring).

    Parameters
    ----------
    robot, meas, params, noise, prior
        As :func:`~zerocal_sym.identify.nlls.identify_nlls` (the held fit's set ``params``).
    alpha : float
        A group is contradicted when its p-value is below ``alpha``.
    held : IdentificationResult, optional
        The held fit, if already made (its chi² and rank are used).
    tolerances : dict, optional
        name -> tolerance (internal units) of the held entries (default the robot's): how far the freed fit
        puts each entry from the file, in tolerances, ranks the groups that explain the data.
    identify : callable
        The exact fit, ``identify(robot, meas, params, noise=, prior=, fit_alpha=) -> IdentificationResult``:
        :func:`~zerocal_sym.identify.nlls.identify_nlls` (a later stage's, so it is passed in).

    Returns
    -------
    dict
        ``params`` (the held set), ``chi2``, ``rank`` of the held fit, ``alpha``, ``groups``: per group
        ``group``, ``entries``, ``tested`` (False: too few readings, or the freed fit did not converge:
        ``reason``), ``chi2``, ``lr``, ``dof``, ``p_value``, ``contradicted``, ``estimates`` (entry ->
        {``value``, ``std``, ``unit``, ``z``}), ``named`` (entries beyond :data:`Z_NAMED` sigma), ``fits``
        (the freed fit passes the fit check at ``alpha``), ``in_tolerances`` (the largest ``|estimate| /
        tolerance`` of its entries); ``contradicted`` (the groups whose p-value is below ``alpha``: first those
        whose freed fit passes, the nearest to their tolerances first), ``explained_by`` (the first of them if
        its freed fit passes, else None), ``summary`` (a sentence).
    """
    errors = robot.errors
    tol = robot.tolerances() if tolerances is None else dict(tolerances)
    names = errors.resolve(params)
    base = params if isinstance(params, str) else ",".join(names)
    K = np.asarray(meas.theta_cmd).shape[0]
    kw = dict(noise=noise, prior=prior, fit_alpha=0.0)
    if held is None:
        held = identify(robot, meas, names, **kw)
    chi0, rank0 = float(held.info["chi2"]), int(held.info["rank"])
    rows = []
    for g, entries in held_groups(robot, base).items():
        row = {"group": g, "entries": list(entries), "tested": False, "reason": None, "chi2": None, "lr": None,
               "dof": None, "p_value": None, "contradicted": False, "estimates": {}, "named": []}
        rows.append(row)
        spec = set_spec(robot, base, [entries])
        if K - 1 <= len(errors.resolve(spec)):
            row["reason"] = f"{K - 1} readings leave no spare degree of freedom with {g} identified too"
            continue
        try:
            free = identify(robot, meas, spec, **kw)
        except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
            row["reason"] = f"the fit with {g} identified failed ({exc})"
            continue
        chi1, rank1 = float(free.info["chi2"]), int(free.info["rank"])
        d = rank1 - rank0
        if not free.success or not math.isfinite(chi1):
            row["reason"] = f"the fit with {g} identified did not converge ({free.status})"
            continue
        if d <= 0:
            row["reason"] = f"the poses do not identify {g} beyond the parameters already identified"
            continue
        lr = max(chi0 - chi1, 0.0)
        p = chi2_sf(lr, d)
        est = {}
        for n in entries:
            v, s = free.value(n), free.std(n)
            z = abs(v) / s if s > 0 and math.isfinite(s) else math.inf
            est[n] = {"value": errors.to_user_value(n, v), "std": errors.to_user_value(n, s) if math.isfinite(s) else None,
                      "unit": errors[n].user_unit, "z": z if math.isfinite(z) else None}
        named = [n for n in entries if est[n]["z"] is not None and est[n]["z"] > Z_NAMED]
        dof1 = (K - 1) - rank1  # (a rank-deficient fit uses fewer)
        ratio = max((abs(free.value(n)) / tol[n] if tol.get(n, 0) > 0 else math.inf) for n in entries)
        row.update(tested=True, chi2=chi1, lr=lr, dof=d, p_value=p, contradicted=bool(p < alpha), estimates=est,
                   named=named, fits=bool(dof1 > 0 and chi2_sf(chi1, dof1) >= alpha),
                   in_tolerances=ratio if math.isfinite(ratio) else None)
    hit = sorted((r for r in rows if r["contradicted"]),
                 key=lambda r: (not r["fits"], r["in_tolerances"] if r["in_tolerances"] is not None else math.inf,
                                r["p_value"]))
    return {"params": base, "chi2": chi0, "rank": rank0, "alpha": float(alpha), "groups": rows,
            "contradicted": [r["group"] for r in hit],
            "explained_by": hit[0]["group"] if hit and hit[0]["fits"] else None,
            "summary": summary(hit, rows, alpha)}


def summary(hit: list, rows: list, alpha: float) -> str:
    """One sentence: the group that explains what the data contradict (its entries), the others that would."""
    if not hit:
        tested = [r["group"] for r in rows if r["tested"]]
        return (f"no group of robot-file entries is contradicted by the data (tested: {', '.join(tested) or 'none'}, "
                f"each at {alpha:g})")
    first = hit[0]
    named = first["named"] or first["entries"]
    vals = ", ".join(f"{n} {first['estimates'][n]['value']:+.3g} +- {first['estimates'][n]['std']:.2g} "
                     f"{first['estimates'][n]['unit']}" for n in named if first["estimates"][n]["std"] is not None)
    text = (f"the data contradict the robot file's {first['group']}: identified too, chi2 falls from "
            f"{first['chi2'] + first['lr']:.4g} to {first['chi2']:.4g} (LR on {first['dof']} dof, "
            f"{_fmt_p(first['p_value'])})" + (f"; {vals}" if vals else "")
            + (f" ({first['in_tolerances']:.2g} x its tolerance)" if first["in_tolerances"] is not None else ""))
    if not first["fits"]:
        text += "; the fit still does not pass: more than this group is off"
    if hit[1:]:
        text += "; " + ", ".join(r["group"] + (f" ({r['in_tolerances']:.2g} x its tolerance)"
                                               if r["in_tolerances"] is not None else "")
                                 for r in hit[1:]) + " would lower chi2 too"
    return text
