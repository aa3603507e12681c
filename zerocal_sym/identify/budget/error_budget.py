"""The error budget of an answer: what the data leave open, what the robot file may add.

An identification estimates the zero offsets (and the parameters identified
with them) from the data and holds every other source error at the robot
file's value.  Its error has two parts, reported per zero offset ``i``:

``noise_std``
    the offset's 1 sigma from the data (the result's standard deviation:
    the Cramér-Rao bound at the estimate for ``nlls``, TSVD's total one for
    ``tsvd``); it shrinks as poses are added;
``robot_file_bias``
    the largest bias the entries held at the file's values can put on it
    when each is off by up to its tolerance (first order, worst case):
    ``sum_j |S_ij| t_j``, with ``S = d(estimate) / d(held entries)`` the
    estimator's bias sensitivity (:mod:`zerocal_sym.identify.budget.bias`, e.g.
    deg/mm) and ``t_j`` the entry's tolerance (the robot file's
    ``[tolerances]``, :mod:`zerocal_sym.model.tolerances`; ``--tolerance``
    overrides).  It does not shrink with more poses of the same design: no
    fit check can see a robot-file error that moves the readings as an
    offset would.

``dominant_entries`` (per offset): the three entries with the largest
contributions ``|S_ij| t_j``, each with its tolerance and sensitivity.

``limited_by``: ``"robot file"`` when some offset's ``robot_file_bias``
exceeds its ``noise_std`` (the robot file may move it further than its
stated 1 sigma: more poses will not help), else ``"data"``.

What to do (:func:`remedy`): for an answer limited by the data, more poses
or a better design; for one limited by the robot file, measure the entries
that dominate better (a smaller tolerance in the robot file) or identify them
too (``--params paper+...``, with a design made for that set:
``zerocal design --params ...``).
"""
from __future__ import annotations

import math

import numpy as np

#: how many robot-file entries each offset's budget names
N_DOMINANT = 3
#: the two values of ``limited_by``
LIMITS = ("data", "robot file")


def error_budget(bias: dict, result) -> dict:
    """The error budget of ``result``'s zero offsets from its bias report.

    Parameters
    ----------
    bias : dict
        :func:`zerocal_sym.identify.budget.bias.tolerance_bias` of the result's
        estimator (its ``sensitivity`` in user units per user unit and the
        ``tolerances`` of the entries held).
    result : IdentificationResult
        Its zero offsets' standard deviations are the ``noise_std``.

    Returns
    -------
    dict
        ``error_budget``: one dict per zero offset in joint order with
        ``name``, ``unit``, ``noise_std`` (None when unknown),
        ``robot_file_bias`` (the larger of the first-order bound and, when
        ``bias`` holds it, the exact model's worst corner), ``dominant_entries`` (up to
        :data:`N_DOMINANT` dicts ``name``, ``tolerance``, ``unit``,
        ``sensitivity`` (offset unit per entry unit, signed),
        ``contribution`` (offset unit)); ``limited_by`` (:data:`LIMITS`).
    """
    errors = result.errors
    sens = bias["sensitivity"]
    rows, cols = list(sens["rows"]), list(sens["columns"])
    S = np.asarray(sens["values"], float).reshape(len(rows), len(cols))
    t = np.array([float(bias["tolerances"][c]) for c in cols])
    units_ = bias.get("tolerance_units", {})
    unit = errors.offset_user_unit
    std = np.asarray(result.std_zero_offsets_user, float)
    # the bound reported for each offset: the larger of the first-order bound and the exact model's at its worst
    # corner, when the exact search ran (zerocal_sym.identify.budget.bias_exact); its split by entry is first-order's
    zo = bias.get("zero_offsets") or {}
    worst = dict(zip(zo.get("names", ()), zo.get(f"worst_case_{unit}", ()))) if "names" in zo else {}
    out = []
    for j, name in enumerate(errors.zero_offsets):
        if name in rows:
            c = np.abs(S[rows.index(name)]) * t
            s = S[rows.index(name)]
        else:  # an offset held (not identified): its bias is not this estimate's
            c = s = np.zeros(len(cols))
        order = [int(k) for k in np.argsort(-c, kind="stable")[:N_DOMINANT] if c[k] > 0]
        out.append({
            "name": name, "unit": unit,
            "noise_std": float(std[j]) if math.isfinite(std[j]) else None,
            "robot_file_bias": max(float(np.sum(c)), float(worst.get(name) or 0.0)),
            "dominant_entries": [{"name": cols[k], "tolerance": float(t[k]),
                                  "unit": units_.get(cols[k], errors[cols[k]].user_unit),
                                  "sensitivity": float(s[k]), "contribution": float(c[k])} for k in order],
        })
    return {"error_budget": out, "limited_by": limited_by(out)}


def limited_by(budget: list) -> str:
    """``"robot file"`` when some offset's robot-file bias exceeds its 1 sigma from the data, else ``"data"``."""
    for b in budget:
        s = b.get("noise_std")
        if s is not None and b["robot_file_bias"] > s:
            return "robot file"
    return "data"


def entries_to_free(budget: list) -> list:
    """The robot-file entries that make an answer limited by the robot file, by name in the order of their
    largest contribution: the fewest of the offsets' dominant entries whose tolerances, taken away, leave
    every offset's robot-file bias within its 1 sigma (all of them when none suffice)."""
    contrib: dict = {}
    for b in budget:
        for e in b["dominant_entries"]:
            contrib[e["name"]] = max(contrib.get(e["name"], 0.0), e["contribution"])
    ranked = sorted(contrib, key=lambda n: -contrib[n])
    chosen = []
    for n in ranked:
        if all(_rest(b, chosen) <= (b.get("noise_std") or 0.0) for b in budget):
            break
        chosen.append(n)
    return chosen


def _rest(b: dict, freed) -> float:
    """An offset's robot-file bias without the contributions of the entries ``freed`` (first order)."""
    return b["robot_file_bias"] - sum(e["contribution"] for e in b["dominant_entries"] if e["name"] in freed)


def compact_names(names) -> str:
    """``L1-L3`` for L1, L2, L3; names joined by commas otherwise (``L1-L3, R2``)."""
    import re

    groups: dict = {}
    for n in names:
        m = re.fullmatch(r"(.*?)(\d+)([a-z]*)", n)
        key = (m.group(1), m.group(3)) if m else (n, None)
        groups.setdefault(key, []).append((int(m.group(2)) if m else None, n))
    parts = []
    for (stem, tail), items in groups.items():
        nums = sorted(k for k, _ in items if k is not None)
        if len(nums) >= 3 and nums == list(range(nums[0], nums[0] + len(nums))):
            parts.append(f"{stem}{nums[0]}{tail}-{stem}{nums[-1]}{tail}")
        else:
            parts.extend(n for _, n in items)
    return ", ".join(parts)


def remedy(budget: list, robot, params) -> dict:
    """What to do about an answer: ``limited_by``, ``limiting`` (the robot-file entries that limit it),
    ``free`` (those of them that can be identified too: not the ones that fix the mechanism's gauge), ``params``
    (the set that frees them, joined by ``+``; None when none can) and ``n_params`` (its size), ``text`` (why,
    one clause)."""
    lim = limited_by(budget)
    if lim == "data":
        return {"limited_by": lim, "limiting": [], "free": [], "params": None, "n_params": None,
                "text": "limited by the data: more poses or a better design lower it"}
    errors = robot.errors
    order = {n: k for k, n in enumerate(errors.names)}
    gauge = set(errors.names) - set(errors.resolve("gauge_fixed")) if "gauge_fixed" in errors.extra_sets else set()
    limiting = sorted(entries_to_free(budget), key=order.get)
    free = [n for n in limiting if n not in gauge]  # (the entries that fix the gauge stay held)
    tol = {e["name"]: (e["tolerance"], e["unit"]) for b in budget for e in b["dominant_entries"]}
    by_tol: dict = {}
    for n in limiting:
        by_tol.setdefault(tol[n], []).append(n)
    held = ", ".join(f"{compact_names(ns)} at +-{v:g} {u}" for (v, u), ns in by_tol.items())
    spec = None
    if free:
        spec = "+".join([params if isinstance(params, str) else ",".join(errors.resolve(params)), ",".join(free)])
    worst = max(budget, key=lambda b: b["robot_file_bias"] - (b.get("noise_std") or 0.0))
    s = worst.get("noise_std")
    return {"limited_by": lim, "limiting": limiting, "free": free, "params": spec,
            "n_params": len(errors.resolve(spec)) if spec else None,
            "text": (f"limited by the robot file ({held}): {worst['name']} may be off by up to "
                     f"{worst['robot_file_bias']:.3g} {worst['unit']} from it against a 1 sigma of "
                     + (f"{s:.3g}" if s is not None else "?") + f" {worst['unit']} from the data")}


def format_budget(budget: list) -> list:
    """The budget as text lines (one per offset)."""
    lines = []
    for b in budget:
        u = b["unit"]
        s = b["noise_std"]
        dom = "; ".join(f"{e['name']} {e['contribution']:.3g} ({e['sensitivity']:+.3g} {u}/{e['unit']} x "
                        f"{e['tolerance']:g} {e['unit']})" for e in b["dominant_entries"])
        lines.append(f"  {b['name']}: 1 sigma {('%.3g' % s) if s is not None else '?'} {u} from the data; "
                     f"robot file up to {b['robot_file_bias']:.3g} {u}" + (f" (largest: {dom})" if dom else ""))
    return lines
