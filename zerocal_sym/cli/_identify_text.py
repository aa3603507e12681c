"""The text of ``zerocal identify``: the estimate, the error budget, the robot-file test and the verdict line.

The verdict line is the one line a person acts on::

    verdict: <accepted / rejected and why>; offsets' 1 sigma ...: <small or not>; <limited by the data | limited
    by the robot file (...): ...; to lower it: ...>; next: <the next command(s)>

``next:`` is always last and holds commands joined by ``, then `` (a test parses them).
"""
from __future__ import annotations

#: without --goal-deg, the offsets' 1 sigma is small when at most this fraction of the largest |offset|
SIGMA_FRACTION = 0.1
#: identify's options that change only what is written, not the result nor the verdict: not in the next command
_OUTPUT_ONLY = ("json", "out", "plot", "report")
#: the command these options belong to
NAME = "identify"


def offsets_sigma_text(res, goal=None) -> str:
    """The offsets' 1 sigma and whether it is small: against ``goal`` (``--goal``, in the offsets' unit: deg or
    mm; ``--goal-deg`` for revolute joints) when given, else against the offsets' scale, the largest |offset|
    (one scale for all: an offset near zero is no reason to measure more)."""
    import numpy as np

    off = np.abs(np.asarray(res.zero_offsets_user, float))
    std = np.asarray(res.std_zero_offsets_user, float)
    if not np.all(np.isfinite(std)):
        return "offsets' 1 sigma not available"
    s = ", ".join(f"{x:.3g}" for x in std)
    kind = f" ({res.std_kind})" if getattr(res, "std_kind", None) else ""
    info = getattr(res, "info", None) or {}
    bounds = [n for n, k in (info.get("std_kinds") or {}).items() if k == "bound" and n in res.zero_offset_names]
    if bounds:  # TSVD: an offset whose linearisation bias is not known well enough has an upper bound for its std
        truncated = info.get("truncation", len(res.params)) < len(res.params)
        kind = (f" (an upper bound for {', '.join(bounds)}: " + ("the truncated directions' bias)" if truncated else
                "TSVD's linearisation bias is not small or not known within the noise; --iterate removes it)"))
    worst = float(np.max(std))
    u = getattr(res, "offset_unit", "deg")
    if goal is not None:
        verdict = (f"within the goal {goal:g} {u}" if worst <= goal else
                   f"NOT within the goal {goal:g} {u}; measure more poses")
    else:
        scale = float(np.max(off)) if off.size else 0.0
        verdict = (f"small against the offsets (<= {SIGMA_FRACTION:g} x the largest |offset|, {scale:.3g} {u})"
                   if worst <= SIGMA_FRACTION * scale else
                   f"NOT small against the offsets (> {SIGMA_FRACTION:g} x the largest |offset|, {scale:.3g} {u}); "
                   "measure more poses, or state the accuracy you need with --goal")
    return f"offsets' 1 sigma {s} {u}{kind}: {verdict}"


def print_estimate(robot, res) -> None:
    """The identified parameters with their std (user units) and the compensation, as text."""
    import numpy as np

    from zerocal_sym.io.results import sign_convention

    errors = robot.errors
    for n, v in zip(res.params, res.estimate):
        s = res.std(n)
        std = f" ± {errors.to_user_value(n, s):.4g}" if np.isfinite(s) else ""
        print(f"  {n:7s} = {errors.to_user_value(n, v):+.6f}{std} {errors[n].user_unit}")
    print(f"compensation ({sign_convention(res.offset_unit)}):")
    for j, n in enumerate(robot.mechanism.joint_names):
        s = res.std_zero_offsets_user[j]
        print(f"  {n}: offset {res.zero_offsets_user[j]:+.6f} {res.offset_unit}"
              + (f" (std {s:.4g})" if np.isfinite(s) else ""))


def verdict_line(res, args, remedy=None, K=None) -> str:
    """The one line a person acts on: accepted / why, the offsets' 1 sigma, what limits them (``remedy``:
    :func:`zerocal_sym.identify.budget.error_budget.remedy`) and how to lower it, the next command."""
    why = accepted_why(res.info.get("fit") or {}, args.fit_alpha)
    robot = ["--robot", args.robot] if getattr(args, "robot", None) else []
    compensate = _command("compensate", args.out or "RESULT.json", *robot, "--out", "table.csv")
    nxt = (compensate if args.out else
           f"{_command('identify', *repeat_options(args), '--out', 'RESULT.json')}, then {compensate}")
    goal = getattr(args, "goal", None)
    goal = goal if goal is not None else getattr(args, "goal_deg", None)
    limit = f"{limit_text(remedy, args, K)}; " if remedy else ""
    return f"verdict: {why}; {offsets_sigma_text(res, goal)}; {limit}next: {nxt}"


def accepted_why(fit: dict, alpha: float) -> str:
    """How an accepted result passed the fit check (``fit``: its record, ``info["fit"]`` or a results file's
    ``fit``; ``alpha``: the level when the record has none)."""
    p = fit.get("p_value")
    alpha = fit.get("alpha") or alpha
    if fit.get("accepted_despite_misfit") and fit.get("unchecked_after_removal"):
        return ("accepted despite misfit (--accept-misfit; NOT checked: no spare degree of freedom after the "
                "readings left out)")
    mr = fit.get("max_reading") or {}
    if fit.get("accepted_despite_misfit") and mr.get("rejected") and not (p is not None and p < alpha):
        return (f"accepted despite misfit (--accept-misfit; the largest standardised residual's p-value "
                f"{mr['p_value']:.3g} < {alpha:g}, at pose {mr['pose']:g})")
    if fit.get("accepted_despite_misfit"):
        shown = "?" if p is None else f"{p:.3g}"
        return f"accepted despite misfit (--accept-misfit; fit p-value {shown} < {alpha:g})"
    if fit.get("checked") and p is not None:
        return f"accepted: fit p-value {p:.3g} >= {alpha:g}"
    return f"accepted: fit not checked ({fit.get('reason') or 'no spare degree of freedom'})"


def limit_text(remedy: dict, args, K=None) -> str:
    """What limits the offsets and how to lower it (a clause of the verdict line)."""
    from zerocal_sym.identify.budget.error_budget import compact_names

    if remedy["limited_by"] == "data":
        return remedy["text"]
    measure = (f"{remedy['text']}; to lower it: measure {compact_names(remedy['limiting'])} better and give their "
               "tolerances in the robot file's [tolerances]")
    if not remedy["free"]:
        return measure
    robot = ["--robot", args.robot] if getattr(args, "robot", None) else []
    spec = remedy["params"]
    K = max(K, remedy["n_params"] + 2) if K else None  # (at least one spare degree of freedom)
    design = _command("design", *robot, "--params", spec, "--optimize", *(["--K", K] if K else []))
    return (f"{measure}, or identify {compact_names(remedy['free'])} too: {design} (or --choose-params), measure "
            f"those poses and identify them with --params {spec}")


def _command(*words) -> str:
    import shlex

    return "zerocal " + " ".join(shlex.quote(str(w)) for w in words)


def repeat_options(args) -> list:
    """The data file and every option given but the output ones (:data:`_OUTPUT_ONLY`): ``--robot``,
    ``--method``, ``--noise``, priors, bounds, tolerances, the fit check's, ``--goal-deg``, as words (floats as
    Python writes them, digit for digit): ``identify`` with them repeats this run."""
    import argparse

    from zerocal_sym.cli import build_parser
    from zerocal_sym.cli._checks import _given

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices[NAME]
    words = [args.data]
    for a in sub._actions:
        if (not a.option_strings or a.dest in _OUTPUT_ONLY or a.default is argparse.SUPPRESS
                or not _given(args, a.dest)):
            continue
        value, opt = getattr(args, a.dest), a.option_strings[0]
        if a.nargs == 0:  # a flag
            words.append(opt)
        elif isinstance(a, argparse._AppendAction):
            for v in value:
                words += [opt, v]
        elif isinstance(value, (list, tuple)):
            words += [opt, *value]
        else:
            words += [opt, value]
    return [str(w) for w in words]


def print_budget(out: dict) -> None:
    """The error budget of the offsets (``out["error_budget"]``) and what limits them, as text."""
    from zerocal_sym.identify.budget.error_budget import format_budget

    budget = out.get("error_budget")
    if not budget:
        return
    print("error budget of the offsets (1 sigma from the data; robot file: the largest first-order bias of the "
          "entries held at its values, within their tolerances):")
    for line in format_budget(budget):
        print(line)
    rem = out.get("remedy") or {}
    if rem.get("text"):
        print(f"  -> {rem['text']}")


def print_choice(choice: dict) -> None:
    """``--params auto``: the set chosen and the score of the sets tried."""
    u = choice["unit"]
    print(f"--params auto: {choice['chosen']} (expected offset error {choice['expected']:.3g} {u} at these poses; "
          f"{choice['base']} alone {choice['base_expected']:.3g} {u}; {len(choice['table'])} sets scored, "
          f"{choice['search']})")


def print_group_test(test: dict) -> None:
    """The likelihood-ratio test of each group of robot-file entries, as text."""
    from zerocal_sym.identify.chi2 import _fmt_p

    print(f"robot-file test (each group of entries held at the file's values freed in turn; alpha {test['alpha']:g}):")
    for r in test["groups"]:
        if not r["tested"]:
            print(f"  {r['group']:5s} not tested: {r['reason']}")
            continue
        print(f"  {r['group']:5s} chi2 {test['chi2']:.4g} -> {r['chi2']:.4g}, LR {r['lr']:.4g} on {r['dof']} dof, "
              f"{_fmt_p(r['p_value'])}" + ("  CONTRADICTED" if r["contradicted"] else ""))
    print(f"  -> {test['summary']}")
