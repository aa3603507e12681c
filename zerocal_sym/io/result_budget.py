"""The error budget of a results file (``error_budget``, ``limited_by``), checked against the rest of it.

What :func:`zerocal_sym.io.results.load_result` checks of these keys (files
written before them keep loading): one entry per zero offset in joint order,
each ``name`` the joint's offset, ``noise_std`` the same as the offset's
standard deviation (or null), ``robot_file_bias`` >= 0 and at least the sum
of its ``dominant_entries``' contributions (each ``|sensitivity| x
tolerance`` of a robot-file entry of the mechanism that is not a zero
offset); ``limited_by`` is ``"data"`` or ``"robot file"``, the latter exactly
when some offset's ``robot_file_bias`` exceeds its ``noise_std`` (the rule of
:func:`zerocal_sym.identify.budget.error_budget.limited_by`).
"""
from __future__ import annotations

import json
import math

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import _finite_number, _where


#: the values of ``limited_by`` (:data:`zerocal_sym.identify.budget.error_budget.LIMITS`)
LIMITED_BY = ("data", "robot file")


def _budget_entry(b, j, name, held, mech, std, unit, where, same_tol) -> bool:
    """One offset's budget, checked; whether its robot-file bias exceeds its noise_std."""
    what = f"key 'error_budget': entry {j + 1}"
    if not isinstance(b, dict) or b.get("name") != name:
        raise DataFileError(f"{what} must be the budget of {name} (joint order), got {json.dumps(b)[:60]}",
                            where=where)
    if b.get("unit", unit) != unit:
        raise DataFileError(f"{what} ({name}): unit {json.dumps(b.get('unit'))[:20]} is not the offsets' {unit!r}",
                            where=where)
    s = b.get("noise_std")
    if s is not None and not (_finite_number(s) and s >= 0):
        raise DataFileError(f"{what} ({name}): noise_std must be a number >= 0 or null, got {json.dumps(s)[:30]}",
                            where=where)
    if s is not None and math.isfinite(std[j]) and not math.isclose(s, std[j], rel_tol=same_tol,
                                                                      abs_tol=same_tol):
        raise DataFileError(f"{what} ({name}): noise_std {s!r} disagrees with the offset's standard deviation "
                            f"({float(std[j])!r}): one of the two copies was edited", where=where)
    bias = b.get("robot_file_bias")
    if not (_finite_number(bias) and bias >= 0):
        raise DataFileError(f"{what} ({name}): robot_file_bias must be a number >= 0, got {json.dumps(bias)[:30]}",
                            where=where)
    entries = b.get("dominant_entries") or []
    if not isinstance(entries, list):
        raise DataFileError(f"{what} ({name}): dominant_entries must be a list", where=where)
    total = 0.0
    for e in entries:
        ok = (isinstance(e, dict) and isinstance(e.get("name"), str) and e["name"] in held
              and all(_finite_number(e.get(k)) for k in ("tolerance", "sensitivity", "contribution"))
              and e["tolerance"] >= 0 and e["contribution"] >= 0)
        if not ok:
            raise DataFileError(f"{what} ({name}): a dominant entry names a robot-file entry of {mech.name} that "
                                "is not a zero offset, with a tolerance >= 0, a sensitivity and a contribution >= 0; "
                                f"got {json.dumps(e)[:80]}", where=where)
        if not math.isclose(e["contribution"], abs(e["sensitivity"]) * e["tolerance"], rel_tol=1e-9, abs_tol=1e-12):
            raise DataFileError(f"{what} ({name}): the contribution of {e['name']} is not |sensitivity| x tolerance",
                                where=where)
        total += e["contribution"]
    if total > bias * (1 + 1e-9) + 1e-12:
        raise DataFileError(f"{what} ({name}): its dominant entries add up to {total:.6g}, more than its "
                            f"robot_file_bias {bias!r}", where=where)
    return s is not None and bias > s


def check_error_budget(obj, mech, std, unit, text, src, same_tol: float) -> None:
    """The ``error_budget`` and ``limited_by`` keys of ``obj``, if any, checked against each other and the
    offsets' standard deviations ``std`` (agreeing within ``same_tol``); DataFileError naming the file and line."""
    lim = obj.get("limited_by")
    if lim is not None and lim not in LIMITED_BY:
        raise DataFileError(f"key 'limited_by' must be one of {', '.join(json.dumps(v) for v in LIMITED_BY)}, got "
                            f"{json.dumps(lim)[:40]}", where=_where(text, "limited_by", src))
    budget = obj.get("error_budget")
    if budget is None:
        return
    where = _where(text, "error_budget", src)
    names = mech.errors.zero_offsets
    if not isinstance(budget, list) or len(budget) != len(names):
        raise DataFileError(f"key 'error_budget' must be a list of {len(names)} entries, one per zero offset "
                            f"({', '.join(names)})", where=where)
    held = set(mech.errors.names) - set(names)
    over = [_budget_entry(b, j, name, held, mech, std, unit, where, same_tol) for j, (b, name) in enumerate(zip(budget, names))]
    says = LIMITED_BY[int(any(over))]
    if lim is not None and lim != says:
        raise DataFileError(f"key 'limited_by' is {lim!r}, but the error budget says {says!r} (the robot file when "
                            "some offset's robot_file_bias exceeds its noise_std)", where=_where(text, "limited_by", src))
