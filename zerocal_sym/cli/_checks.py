"""Checks of a command's options before it runs: what applies to the mode, numbers in range, outputs vs inputs.

:func:`check_args` is called by :func:`zerocal_sym.cli.main` after parsing
and before the command's ``run``, with the set of options the user gave
explicitly (an option left at its default is not "given").  Every failure is
a :class:`~zerocal_sym.errors.ZerocalError`: one line, exit status 2, nothing
computed and nothing written.

The rules:

* **An option that does not apply to the chosen mode is an error**, not
  ignored: ``design``'s optimisation settings without ``--optimize`` and the
  boundary scheme's ``--n/--eps0/--maemm-prior`` with it; ``identify``'s
  nlls-only options (``--params --prior-std --bound --max-iter``) with
  ``--method tsvd`` and the tsvd-only ones (``--truncation --rule``) with
  nlls; ``--truncation`` together with ``--rule`` (a fixed t has no rule);
  ``compare``'s loop settings (``--mu0 --max-iter``) without a loop method;
  ``compensate --max-offset-deg`` without a result, its ``--endstop-mm
  --homed-height-mm`` with the csv table and its poses with a controller
  format; ``--report`` with
  ``--json`` (the JSON holds the report); ``regen``/``study --robot``;
  ``regen --out`` without ``--derivation`` and ``--out-dir`` with it.
* **Numbers**: seeds are integers >= 0; counts in their range (``--n`` at most
  :data:`MAX_N` poses per boundary); thresholds finite and positive.
* **Files**, first, for every command alike: the options declare what they
  read and write (:mod:`zerocal_sym.cli._paths`); no empty names; an output
  that lands on one of the command's inputs (the same file however named) or
  on another of its outputs is refused
  (:func:`zerocal_sym.cli._paths.check_paths`).
"""
from __future__ import annotations

import math

from zerocal_sym.errors import ZerocalError

#: the most poses per boundary of a scheme (--n): K = 2n = 100,000 poses
MAX_N = 50_000
#: Monte Carlo trials at most of compare (per group) and design --verify: every trial's estimates are held in
#: memory until the summary; a larger Monte Carlo is a study (chunked on disk, resumable)
MAX_TRIALS = 1_000_000
#: a MAEMM prior beyond this is not a manufacturing error of the measuring mechanism (mm)
MAEMM_PRIOR_LIMIT_MM = 1000.0

#: design options that belong to --optimize (dest names)
DESIGN_OPTIMIZE_ONLY = ("K", "criterion", "region", "seed", "verify", "plot", "l0", "travel_mode", "margin",
                        "joint_limits", "joint_limits_deg", "joint_limits_mm", "min_separation", "noise", "starts",
                        "workers", "scheduler",
                        "bounds", "method", "tolerance", "tolerance_file", "tolerance_scale", "bias_model",
                        "power", "bad_reading_mm", "fit_alpha", "require_entries")
#: design --target-crlb X: what it takes besides the region and constraint options (it chooses K, crlb)
DESIGN_TARGET_NOT = ("K", "criterion", "seed", "verify", "plot", "starts", "workers", "scheduler", "method",
                     "tolerance", "tolerance_file", "tolerance_scale", "bias_model", "power", "bad_reading_mm",
                     "fit_alpha", "require_entries")
#: design options of the boundary scheme, not --optimize
DESIGN_SCHEME_ONLY = ("n", "eps0", "maemm_prior")

LOOP_METHODS = ("tsvd-loop", "nlls-loop", "nlls-seq")
#: compare methods that take --params (the TSVD ones identify the paper's set)
PARAM_METHODS = ("nlls", "nlls-loop", "nlls-seq", "scipy")


def _opt(dest: str) -> str:
    return "--" + dest.replace("_", "-")


def _opts(dests) -> str:
    return ", ".join(_opt(d) for d in dests)


def _given(args, *dests) -> list:
    given = getattr(args, "_given", None)
    if given is None:  # not through main(): what differs from None/False counts
        return [d for d in dests if getattr(args, d, None) not in (None, False, [], ())]
    return [d for d in dests if d in given]


def _seed(args) -> None:
    seed = getattr(args, "seed", None)
    if seed is not None and seed < 0:
        raise ZerocalError(f"--seed must be an integer >= 0 (it seeds numpy's random generator), got {seed}")


def _n(args) -> None:
    n = getattr(args, "n", None)
    if n is not None and n > MAX_N:
        raise ZerocalError(f"--n {n}: at most {MAX_N} poses per boundary (K = 2n = {2 * MAX_N} poses)")


def _maemm_prior(args) -> None:
    v = getattr(args, "maemm_prior", None)
    if v is None:
        return
    if not all(math.isfinite(x) for x in v):
        raise ZerocalError("--maemm-prior must be finite numbers (mm)")
    if any(abs(x) > MAEMM_PRIOR_LIMIT_MM for x in v):
        raise ZerocalError(f"--maemm-prior {' '.join(f'{x:g}' for x in v)}: beyond the plausible range "
                           f"+-{MAEMM_PRIOR_LIMIT_MM:g} mm (a manufacturing error of the measuring mechanism)")


def _positive(args, dest, what, allow_zero=False) -> None:
    v = getattr(args, dest, None)
    if v is None:
        return
    ok = math.isfinite(v) and (v >= 0 if allow_zero else v > 0)
    if not ok:
        raise ZerocalError(f"{_opt(dest)} must be a finite {'non-negative' if allow_zero else 'positive'} "
                           f"number{what}, got {v:g}")


def identifiability_problem(robot, theta_cmd, names, err0=None, poses=None):
    """Why the parameters ``names`` cannot be identified from the poses ``theta_cmd`` (a phrase), or None.

    Too few measured changes, or the rank of the sensitivity of the K-1
    changes to the parameters at ``err0``
    (:func:`~zerocal_sym.identify.identifiability.identifiability_report`)
    below p; where the mechanism's gauge motions span the null space, says
    which, and which gauge-fixing parameters to leave out.  ``poses``: how the
    phrase names the poses (default ``these K poses``).
    """
    from zerocal_sym.identify.identifiability import identifiability_report, null_direction_text

    names = list(names)
    K, p = len(theta_cmd), len(names)
    poses = poses or f"these {K} poses"
    if K - 1 < p:
        return f"{poses} give {K - 1} measured changes, fewer than the {p} parameters"
    rep = identifiability_report(robot, theta_cmd, names, err0=err0)
    r = rep["rank"]
    if r >= p:
        return None
    if rep["null_space_rigid"]:
        motions = [lab for labs in rep["null_space_gauge"] for lab in labs]
        fix = [n for n in rep["gauge_fix"] if n in names]
        why = (f"the distances do not see the rigid motion{'s' if len(motions) > 1 else ''} {', '.join(motions)}"
               + (f"; leave {', '.join(fix)} out of the parameters to fix {'them' if len(motions) > 1 else 'it'}"
                  if fix else ""))
    elif p - r <= 2:  # each null direction by its amounts in file units: what a reader can picture
        combos = "; ".join(null_direction_text(robot, comb) for comb in rep["null_space"])
        why = (f"{'this combination changes' if p - r == 1 else 'these combinations change'} no measured distance: "
               f"{combos}; identify fewer parameters or measure other poses")
    else:
        bad = [n for n, ok in rep["identifiable"].items() if not ok]
        why = (f"{p - r} unobservable combinations of "
               + ", ".join(bad[:6]) + (f" and {len(bad) - 6} more" if len(bad) > 6 else "")
               + "; identify fewer parameters or measure other poses")
    return f"the {p} parameters are not identifiable from {poses} (rank {r} of {p}: {why})"



# --------------------------------------------------------------------------- per command

def _trust(args) -> None:
    """identify / verify: the fit check's and plausibility's options."""
    if args.method == "tsvd":
        bad = _given(args, "loss", "loss_scale")
        if bad:
            raise ZerocalError(f"{_opts(bad)}: for --method nlls only (the robust loss is an nlls fit)")
    a = getattr(args, "fit_alpha", None)
    if a is not None and not (math.isfinite(a) and 0 < a < 1):
        raise ZerocalError(f"--fit-alpha must be a significance level in (0, 1), got {a:g}")
    _positive(args, "loss_scale", " (standard deviations of a reading)")
    _positive(args, "max_offset_deg", " of degrees")
    _positive(args, "max_offset", " (in the joints' unit)")
    _positive(args, "max_maemm_mm", " of mm")


def _prior_within_plausible(args) -> None:
    """A MAEMM prior the plausibility check (``--max-maemm-mm``) would refuse is an error now, naming the prior."""
    v, limit = getattr(args, "maemm_prior", None), getattr(args, "max_maemm_mm", None)
    if v is None or limit is None or not all(math.isfinite(x) for x in v):
        return
    norm = math.sqrt(sum(x * x for x in v))
    if norm > limit:
        raise ZerocalError(f"--maemm-prior {' '.join(f'{x:g}' for x in v)}: |rM| = {norm:.4g} mm is beyond "
                           f"--max-maemm-mm {limit:g}: a result near this prior would be refused as implausible "
                           "(a MAEMM that large is a wrong c / d in the robot file)")


def _identify(args) -> None:
    _trust(args)
    _positive(args, "goal_deg", " of degrees")
    _positive(args, "goal", " (in the joints' unit)")
    if args.method == "tsvd":
        bad = _given(args, "params", "prior_std", "bound", "max_iter")
        if bad:
            raise ZerocalError(f"{_opts(bad)}: for --method nlls only (tsvd identifies the zero offsets and the "
                               "MAEMM, by the linearised model)")
        if _given(args, "truncation") and _given(args, "rule"):
            raise ZerocalError("--truncation fixes the truncation level: not with --rule (a rule chooses it)")
        if args.rule == "discrepancy" and args.truncation is None and args.noise == "none":
            raise ZerocalError("--rule discrepancy needs the noise level: not with --noise none (give --noise "
                               "paper|scale-only|servo-only, or another --rule)")
    else:
        bad = _given(args, "truncation", "rule", "iterate")
        if bad:
            raise ZerocalError(f"{_opts(bad)}: for --method tsvd only")
        if args.max_iter is not None and args.max_iter < 1:
            raise ZerocalError(f"--max-iter must be >= 1, got {args.max_iter}")
    _maemm_prior(args)
    _prior_within_plausible(args)
    if args.report and args.json:
        raise ZerocalError("--report is for the text output: the JSON (--json) holds the report under "
                           "'identifiability'")


def _compensate(args) -> None:
    fmt = getattr(args, "format", "csv")
    if fmt != "rrf" and _given(args, "homed_height_mm"):
        raise ZerocalError("--homed-height-mm is RRF's M665 H: for --format rrf only")
    if fmt == "csv":
        if _given(args, "endstop_mm"):
            raise ZerocalError("--endstop-mm: for a controller's configuration (--format klipper or rrf), not the "
                               "csv table")
    else:
        bad = _given(args, "poses", "scheme", "n") + (["template"] if args.template else [])
        if bad:
            raise ZerocalError(f"{_opts(bad)}: not with --format {fmt} (the controller's configuration takes the "
                               "offsets of RESULT.json, no poses)")
        if args.result is None:
            raise ZerocalError(f"--format {fmt} writes the controller's configuration from RESULT.json: give it")
        if args.endstop_mm is not None:
            from zerocal_sym.io.controllers import parse_endstops

            try:
                parse_endstops(args.endstop_mm, fmt)
            except ValueError as exc:
                raise ZerocalError(str(exc)) from None
        h = args.homed_height_mm
        if h is not None and not (math.isfinite(h) and 0 < h <= 1e5):
            raise ZerocalError(f"--homed-height-mm must be a positive number of mm (RRF's M665 H), got {h:g}")
    bad = _given(args, "max_offset_deg", "max_offset")
    if args.result is None and bad:
        raise ZerocalError(f"{_opts(bad)} checks the offsets of RESULT.json: give the result (without one "
                           "there is no offset to check)")
    if args.max_offset_deg is not None:
        _positive(args, "max_offset_deg", " of degrees")
    if args.max_offset is not None:
        _positive(args, "max_offset", " (in the joints' unit)")
    _n(args)


def _verify(args) -> None:
    _trust(args)


def _report(args) -> None:
    _positive(args, "goal", " (in the joints' unit)")
    _positive(args, "max_offset", " (in the joints' unit)")


def _simulate(args) -> None:
    _seed(args)
    _n(args)


def _trials(args, dest: str, lo: int) -> None:
    v = getattr(args, dest, None)
    if v is not None and not lo <= v <= MAX_TRIALS:
        raise ZerocalError(f"{_opt(dest)} must be {lo}..{MAX_TRIALS:,} (every trial's estimates are held in memory; "
                           "a larger Monte Carlo is a study, chunked on disk and resumable: zerocal study)")


def _compare(args) -> None:
    _seed(args)
    _n(args)
    _trials(args, "trials", 1)
    methods = [m.strip() for m in str(args.methods).split(",") if m.strip()]
    if not methods:
        raise ZerocalError("--methods: no method given (a comma-separated subset of tsvd-loop, tsvd, nlls, "
                           "nlls-loop, nlls-seq, scipy)")
    loop = [m for m in methods if m in LOOP_METHODS]
    bad = _given(args, "mu0", "max_iter")
    if bad and not loop:
        raise ZerocalError(f"{_opts(bad)}: for the loop methods ({', '.join(LOOP_METHODS)}) only; --methods "
                           f"{','.join(methods)} has none")
    if _given(args, "params") and not [m for m in methods if m in PARAM_METHODS]:
        raise ZerocalError(f"--params: for the Ipopt/scipy methods ({', '.join(PARAM_METHODS)}) only; the TSVD "
                           f"methods identify the zero offsets and the MAEMM (--methods {','.join(methods)})")
    if args.max_iter is not None and args.max_iter < 1:
        raise ZerocalError(f"--max-iter must be >= 1 (identifications per loop), got {args.max_iter}")
    _positive(args, "mu0", " (in the joints' unit)")


def _design(args) -> None:
    if any(getattr(args, d, None) is not None for d in ("target_crlb", "target_crlb_deg", "target_crlb_mm")):
        bad = _given(args, *DESIGN_TARGET_NOT, *DESIGN_SCHEME_ONLY) + (["optimize"] if args.optimize else [])
        if bad:
            raise ZerocalError(f"{_opts(bad)}: not with --target-crlb (it chooses K for the crlb criterion; the "
                               "region and constraint options apply)")
    elif not args.optimize:
        bad = _given(args, *DESIGN_OPTIMIZE_ONLY)
        if bad:
            raise ZerocalError(f"{_opts(bad)}: for --optimize only (the boundary scheme has no "
                               f"{'such setting' if len(bad) == 1 else 'such settings'}); add --optimize")
    else:
        bad = _given(args, *DESIGN_SCHEME_ONLY)
        if bad:
            raise ZerocalError(f"{_opts(bad)}: for the boundary scheme (without --optimize); with --optimize "
                               "--K sets the number of poses")
        bad = [d for d in ("workers", "scheduler") if _given(args, d)]
        if bad and not (getattr(args, "verify", 0) or 0):
            raise ZerocalError(f"{_opts(bad)}: where the --verify Monte Carlo runs: give --verify N")
    _seed(args)
    _n(args)
    _trials(args, "verify", 0)
    _maemm_prior(args)


def _reproduce(args) -> None:
    _seed(args)
    _n(args)
    if _given(args, "truncation") and _given(args, "rule"):
        raise ZerocalError("--truncation fixes the truncation level: not with --rule (a rule chooses it)")


def _regen(args) -> None:
    if _given(args, "robot"):
        raise ZerocalError("--robot: regen reads no robot file (it regenerates the code of every mechanism "
                           "from derivations/, or of one derivation file with --derivation)")
    if _given(args, "out") and not _given(args, "derivation"):
        raise ZerocalError("--out names the generated module of a --derivation file: without one, regen writes "
                           "every built-in mechanism (--out-dir DIR for another directory)")
    if _given(args, "out_dir") and _given(args, "derivation"):
        raise ZerocalError("--out-dir is for the built-in mechanisms: a --derivation file's generated module is "
                           "chosen with --out FILE.py (default: beside the derivation)")


def _study(args) -> None:
    if _given(args, "robot"):
        raise ZerocalError("--robot: a study's robots are in its spec (robots = [...])")


CHECKS = {"identify": _identify, "compensate": _compensate, "verify": _verify, "simulate": _simulate,
          "compare": _compare, "design": _design, "reproduce": _reproduce, "regen": _regen, "study": _study,
          "report": _report}


def check_args(args) -> None:
    """Check the options of ``args.command`` (module docstring); a ZerocalError names the option."""
    from zerocal_sym.cli._paths import check_paths

    check_paths(args)  # every command alike, from the options' declarations
    check = CHECKS.get(getattr(args, "command", None))
    if check is not None:
        check(args)
