"""``zerocal design --optimize``: measurement poses optimised for a criterion.

Runs :func:`zerocal_sym.design.optimize_design` (discrete exchange + Ipopt
multi-start + order search + polish) and prints the poses, every criterion
of the design beside the paper's scheme with the same K, the CRLB of the zero
offsets and their ratio; ``--verify N`` adds a Monte Carlo with the Ipopt
estimator (:func:`zerocal_sym.design.verify_design`) for both designs;
``--plot PNG`` draws them in the workspace.  Nothing is written (plot) unless
everything succeeded.  On a terminal a progress bar (tqdm) counts its steps
on stderr; in a log or a pipe it is quiet.

Any mechanism: the design region is the robot's workspace shape (a rectangle
``XMIN XMAX YMIN YMAX``, a cylinder ``RW ZMIN ZMAX``, a box ``X_MIN X_MAX ...
YAW_MIN YAW_MAX`` in mm and deg), the baseline the workspace's boundary scheme
with the same K (the paper's scheme, the ring scheme, the corner scheme),
joint limits one ``LO HI`` pair per joint in the joints' unit (deg for
revolute, mm for prismatic joints); K defaults to the K of the scheme's
default n (6 for the paper's robot, 12 for a Delta, 64 for the hexapod).
Every joint quantity is printed and keyed in the joints' unit
(``crlb_zero_offsets_deg`` or ``crlb_zero_offsets_mm``, ...); the options
that carry one (``--joint-limits``, ``--target-crlb``) take it, and may be
spelt with it (``--joint-limits-deg``, ``--target-crlb-mm``, ...:
:func:`resolve_unit_options`).

Also: ``--region reachable [--bounds ...]`` and ``--region polygon X1 Y1
...`` (the reachable non-singular set, clipped); ``--method
auto|exact|approx`` (the approximate design with its certificate beyond
K = 24); ``--criterion position|mse``; ``--tolerance NAME=VALUE``,
``--tolerance-file``, ``--tolerance-scale`` (the omitted errors' tolerances:
bias and ``mse``); ``zerocal design --target-crlb X`` -- the fewest poses
whose design reaches an RMS zero-offset CRLB of X (the joints' unit), with
the certified lower bound (JSON keys ``K`` and ``K_lower_bound``).
"""
from __future__ import annotations


def add_arguments(p):
    """The options of the reachable set, the approximate design, the bias and --target-crlb (called by :mod:`zerocal_sym.cli.cmd_design`)."""
    p.add_argument("--bounds", nargs="+", metavar="MM", default=None,
                   help="clip of --region reachable: XMIN XMAX YMIN YMAX [ZMIN ZMAX] ('open' for an open side), "
                        "or RW ZMIN ZMAX (a cylinder on the z axis, 3-D)")
    p.add_argument("--method", choices=["auto", "exact", "approx"], default="auto",
                   help="exact (exchange + Ipopt), approx (the optimal design measure, rounded, with a "
                        "certificate) or auto: exact up to K = 24 (default)")
    p.add_argument("--tolerance", action="append", default=[], metavar="NAME=VALUE",
                   help="tolerance of an error the identification leaves out, or of a group of them (L for L1 L2 "
                        "L3) (mm; deg for angles), repeatable; default the robot file's [tolerances], else 0.5 mm "
                        "per length and 0.05 deg per angle (a robot measured by hand; the paper's robot: Table 2's "
                        "set A)")
    from zerocal_sym.cli._paths import InputFile

    p.add_argument("--tolerance-file", default=None, metavar="FILE", type=InputFile("the tolerance file"),
                   help="tolerances as name = value (TOML or JSON; mm, deg)")
    p.add_argument("--tolerance-scale", type=float, default=1.0, metavar="S",
                   help="every tolerance times S (e.g. 10)")
    p.add_argument("--bias-model", choices=["rms", "worst"], default="rms",
                   help="how --criterion mse counts the bias: rms (expected, errors uniform within the "
                        "tolerances; default) or worst (the worst case within them)")
    from zerocal_sym.design import power as pw

    p.add_argument("--power", type=float, default=pw.DEFAULT_POWER, metavar="P",
                   help="the power the fit check of a checked design keeps against each error it must see")
    p.add_argument("--bad-reading-mm", type=float, default=pw.DEFAULT_BAD_READING_MM, metavar="MM",
                   help="the size of the one bad reading a design is judged against, mm")
    p.add_argument("--fit-alpha", type=float, default=pw.DEFAULT_ALPHA, metavar="A",
                   help="the level of the fit check a design is judged with (identify's)")
    p.add_argument("--require-entries", action="store_true",
                   help="a checked design must also see each robot-file entry at its tolerance that would move an "
                        "offset by a standard deviation (reported only, by default)")
    p.add_argument("--target-crlb", type=float, default=None, metavar="X",
                   help="the fewest poses whose design reaches this RMS zero-offset CRLB, in the joints' unit: deg "
                        "for revolute, mm for prismatic joints; the region and constraint options apply")
    p.add_argument("--target-crlb-deg", type=float, default=None, metavar="DEG",
                   help="--target-crlb spelt with its unit (revolute joints)")
    p.add_argument("--target-crlb-mm", type=float, default=None, metavar="MM",
                   help="--target-crlb spelt with its unit (prismatic joints)")


#: the options that carry a value in the joints' unit: dest -> the option (each also spelt OPTION-deg, OPTION-mm)
UNIT_OPTIONS = {"target_crlb": "--target-crlb", "joint_limits": "--joint-limits"}


def resolve_unit_options(args, robot):
    """Each option of :data:`UNIT_OPTIONS` from its plain spelling or the one with the joints' unit.

    ``--joint-limits-deg`` on a robot whose joints are prismatic (or ``--joint-limits-mm`` on revolute ones)
    is a one-line error naming the right spelling; two spellings of one option, likewise.  The value is left
    in ``args.<dest>`` (the joints' file unit).
    """
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.model import units

    ju = units.joint_unit(robot)
    kind = robot.mechanism.joint_kind
    for dest, option in UNIT_OPTIONS.items():
        spelt = {u: getattr(args, f"{dest}_{u}", None) for u in ("deg", "mm")}
        for u, v in spelt.items():
            if v is not None and u != ju:
                raise ZerocalError(f"{option}-{u}: robot {robot.name!r} has {kind} joints "
                                   f"({', '.join(robot.mechanism.joint_names)}, in {ju}): give {option}-{ju} "
                                   f"(or {option}) in {ju}")
        given = [(o, v) for o, v in ((option, getattr(args, dest, None)), (f"{option}-{ju}", spelt[ju]))
                 if v is not None]
        if len(given) > 1:
            raise ZerocalError(f"{given[0][0]} and {given[1][0]} are one option: give it once")
        setattr(args, dest, given[0][1] if given else None)
        for u in ("deg", "mm"):  # resolved: a second call finds the plain spelling alone
            if hasattr(args, f"{dest}_{u}"):
                setattr(args, f"{dest}_{u}", None)


def region_arg(values):
    """``--region`` tokens: a keyword (reachable, polygon ...) as strings, otherwise numbers."""
    from zerocal_sym.design import DesignError

    if values is None:
        return None
    vals = list(values)
    if vals and str(vals[0]).lower() in ("reachable", "polygon"):
        return [str(vals[0]).lower()] + vals[1:]
    out = []
    for v in vals:
        try:
            out.append(float(v))
        except ValueError:
            raise DesignError(f"--region {' '.join(map(str, vals))}: {v!r} is not a number (a region is numbers "
                              "of the workspace's shape, 'reachable' or 'polygon X1 Y1 ...')") from None
    return out


def bounds_arg(values):
    """``--bounds`` tokens as numbers, ``open`` (or ``inf``/``-inf``, ``none``) an open side: -inf for a MIN, inf for a MAX."""
    from zerocal_sym.design import DesignError

    if values is None:
        return None
    out = []
    for i, v in enumerate(values):
        t = str(v).strip().lower()
        if t in ("open", "none", "inf", "+inf", "-inf"):
            out.append(float("-inf") if (i % 2 == 0 and t != "inf" and t != "+inf") or t == "-inf" else float("inf"))
            continue
        try:
            out.append(float(t))
        except ValueError:
            raise DesignError(f"--bounds: {v!r} is not a number or 'open'") from None
    return out


def constraints_from_args(robot, args):
    """:class:`zerocal_sym.design.Constraints` from the command line."""
    from zerocal_sym import design

    from zerocal_sym.model import units

    jl = getattr(args, "joint_limits", None)
    if jl is not None and len(jl) != 2 * robot.m:
        pairs = " ".join(f"LO{j + 1} HI{j + 1}" for j in range(robot.m))
        raise design.DesignError(f"--joint-limits needs {2 * robot.m} values {pairs} ({units.joint_unit(robot)}; "
                                 f"joints {', '.join(robot.mechanism.joint_names)}), got {len(jl)}")
    return design.make_constraints(
        robot, region=region_arg(getattr(args, "region", None)), travel_mm=getattr(args, "l0", design.SCALE_RANGE_MM),
        travel_mode=getattr(args, "travel_mode", "range"), singularity_margin=getattr(args, "margin", None),
        joint_limits=None if jl is None else [(jl[2 * j], jl[2 * j + 1]) for j in range(robot.m)],
        min_separation_mm=getattr(args, "min_separation", 1.0), bounds=bounds_arg(getattr(args, "bounds", None)))


def tolerances_from_args(robot, args):
    """Tolerances of the omitted errors (internal units) from ``--tolerance``, ``--tolerance-file``, ``--tolerance-scale``."""
    from zerocal_sym.design.terms import design_params
    from zerocal_sym.identify.budget.bias import make_tolerances

    return make_tolerances(robot, getattr(args, "tolerance", None) or [], getattr(args, "tolerance_file", None),
                           getattr(args, "tolerance_scale", 1.0), params=design_params(robot),
                           bias_model=getattr(args, "bias_model", "rms"))


def requirement_from_args(robot, args, tolerances):
    """:class:`zerocal_sym.design.detection.Requirement` from ``--power``, ``--bad-reading-mm``, ``--fit-alpha``,
    ``--require-entries``."""
    from zerocal_sym.design import power as pw
    from zerocal_sym.design.detection import Requirement

    def get(name, default):
        v = getattr(args, name, None)
        return default if v is None else v

    return Requirement(robot, tolerances, alpha=get("fit_alpha", pw.DEFAULT_ALPHA),
                       target=get("power", pw.DEFAULT_POWER), bad_reading_mm=get("bad_reading_mm",
                                                                                 pw.DEFAULT_BAD_READING_MM),
                       entries=bool(getattr(args, "require_entries", False)))


def _fmt(v, spec=".4g"):
    import math

    if v is None:
        return "-"
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    return format(v, spec)


class _Bar:
    """``progress(done, total)`` of :func:`zerocal_sym.design.optimize_design` as a tqdm bar on stderr."""

    def __init__(self, stream):
        self.stream, self.bar = stream, None

    def __call__(self, done, total):
        from zerocal_sym.identify.progress import Progress

        if self.bar is None:
            self.bar = Progress(total, "design", stream=self.stream, unit="step")
        self.bar(done)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def progress_bar(stream=None):
    """A progress bar on a terminal (tqdm, as compare's); none when stderr is not one (a log, a pipe: quiet)."""
    import sys

    stream = sys.stderr if stream is None else stream
    return _Bar(stream) if getattr(stream, "isatty", lambda: False)() else None


def run(args, robot):
    import numpy as np

    from zerocal_sym import design
    from zerocal_sym.design import criteria, limits, optimize
    from zerocal_sym.cli._common import check_scheme, default_n, write_out
    from zerocal_sym.design.terms import okey
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.noise import NoiseModel

    check_scheme(robot, args.scheme)  # the baseline is the robot's own scheme
    resolve_unit_options(args, robot)
    if getattr(args, "target_crlb", None) is not None:
        return _run_target(args, robot)
    if getattr(args, "plot", None) and robot.n not in (2, 3):
        raise design.DesignError(f"--plot draws 2-D and 3-D workspaces; robot {robot.name!r} has {robot.n} pose "
                                 f"coordinates ({', '.join(robot.mechanism.pose_names)}): use --json")
    K = args.K if args.K is not None else robot.workspace.scheme_size(default_n(robot))
    limits._check_k(K, robot)
    criteria._check_criterion(args.criterion, criteria.DESIGN_CRITERIA)
    verify = int(getattr(args, "verify", 0) or 0)
    if verify < 0:
        raise design.DesignError(f"--verify N needs N >= 0, got {verify}")
    from zerocal_sym.cli import _parallel
    from zerocal_sym.identify.parallel import check_execution

    check_execution(getattr(args, "workers", 1), getattr(args, "scheduler", None))
    starts = int(getattr(args, "starts", 8))
    if starts < 1:
        raise design.DesignError(f"--starts needs at least 1, got {starts}")
    tol = tolerances_from_args(robot, args)
    method = getattr(args, "method", "auto")
    if method == "exact" and K > limits.MAX_K_EXACT:
        raise design.DesignError(f"K = {K} is too large for --method exact (at most {limits.MAX_K_EXACT}; "
                                 "--method approx takes any K)")
    cons = constraints_from_args(robot, args)
    noise = NoiseModel.named(getattr(args, "noise", "paper"), robot)
    choice = None
    if getattr(args, "choose_params", False):  # the set too: the least expected offset error at K
        import sys

        from zerocal_sym.design.choose import choose_design_params

        if not args.json:
            print(f"choosing the parameter set (approximate designs, K = {K}):", file=sys.stderr)
        crit = "crlb" if args.criterion == criteria.CHECKED else args.criterion  # (the set by the CRLB alone)
        choice = choose_design_params(robot, K, crit, cons, noise, tol, seed=args.seed, starts=starts,
                                      progress=None if args.json else lambda line: print(line, file=sys.stderr))
        robot = robot.identifying(choice["chosen"])
    req = requirement_from_args(robot, args, tol)
    ex = _parallel.execution(args) if verify and hasattr(args, "workers") else {}  # a scheduler reached first
    bar = progress_bar()
    try:
        res = design.optimize_design(robot, K, args.criterion, cons, noise, seed=args.seed, n_starts=starts,
                                     exchange_starts=starts, tolerances=tol, method=method, progress=bar,
                                     requirement=req)
    except BaseException:
        _parallel.close(ex)
        raise
    finally:
        if bar is not None:
            bar.close()
    out = res.to_dict()
    from zerocal_sym.design.terms import design_params

    out["params"] = list(design_params(robot))
    out["params_spec"] = robot.identified_set
    if choice is not None:
        from zerocal_sym.io.files import json_safe

        out["params_choice"] = json_safe(choice)
    out["robot"] = robot.name
    out["mechanism"] = robot.mechanism_name
    out["seed"] = args.seed
    if verify:
        try:
            vd = design.verify_design(robot, res.poses, verify, noise, seed=args.seed, **ex)
            vp = None
            if res.paper is not None:
                vp = design.verify_design(robot, res.baseline_poses, verify, noise, seed=args.seed, **ex)
        finally:
            _parallel.close(ex)
        rk = okey(robot, "rms_error_rms")
        out["verify"] = {"design": vd, "paper": vp,
                         "rms_ratio_design_over_paper": None if vp is None else optimize._ratio(vd[rk], vp[rk]),
                         "estimator": "zerocal_sym.identify.nlls.identify_nlls (Ipopt, exact model, the zero offsets "
                                      "and the MAEMM)"}
        if out["paper"] is not None:
            out["paper"]["verify"] = vp
    if args.plot:
        design.plot_design(args.plot, robot, res)
        out["plot"] = str(args.plot)
    write_out(args, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    _print_text(out, res, robot)
    return 0


def _print_text(out, res, robot):
    import numpy as np

    from zerocal_sym.design.terms import joint_sigma, noise_source, okey, pose_units

    k = lambda stem: okey(robot, stem)  # noqa: E731
    ju = out.get("joint_unit", "deg")
    fo = ".4f" if ju == "deg" else ".5f"  # offsets: 4 decimals of a degree, 5 of a mm
    crit = out["criterion"]["name"]
    c = out["constraints"]
    jl = c[f"joint_limits_{ju}"]
    base = out.get("baseline", "paper")
    pp = out["paper"]
    coords, joints = out["pose_names"], out["joint_names"]
    pu = out.get("pose_units") or pose_units(robot)
    print(f"Optimised measurement poses: robot {out['robot']}, K = {out['K']}, criterion {crit} "
          f"({_desc(crit)})")
    if out.get("params_choice"):
        ch = out["params_choice"]
        print(f"parameters chosen: {ch['chosen']} (expected offset error {_fmt(ch['expected'])} {ch['unit']} at "
              f"its design; {ch['base']} alone {_fmt(ch['base_expected'])} {ch['unit']}; {len(ch['table'])} sets, "
              f"{ch['search']})")
    if out.get("params") and out["params"] != list(robot.errors.resolve("paper")):
        print(f"designed for identifying: {', '.join(out['params'])} (then: zerocal identify ... --params "
              f"{out['params_spec']})")
    region = c["region"] + (" mm" if set(pu) == {"mm"} or c["region_kind"] != "box" else "")
    print(f"constraints: region {region}; scale range l0 = {c['travel_mm']:g} mm ({c['travel_mode']}); "
          f"|sin transmission| >= {c['singularity_margin']:g}; joint limits "
          f"{'none' if jl is None else str(jl) + ' ' + ju}; distinct poses >= {c['min_separation_mm']:g} mm apart"
          + ("" if set(pu) == {"mm"} else " (a degree counts as a mm)"))
    n = out["noise"]
    print(f"noise: scale {n['sigma_scale_mm'] * 1e3:.4g} um per change, {'servo' if ju == 'deg' else 'joint'} "
          f"{joint_sigma(robot, n):.4g} {ju} per joint per pose"
          + (f" ({noise_source(robot, res.noise)})" if res.noise is not None and noise_source(robot, res.noise)
             else ""))
    ex, co = out["exchange"], out["continuous"]
    if co:
        ok = sum(r["feasible"] for r in co["runs"])
        print(f"method: {out['method']}  (exchange on {ex['n_candidates']} grid candidates: {_fmt(ex['value'])}; "
              f"Ipopt multi-start, {ok}/{len(co['runs'])} feasible ends: {_fmt(co['value'])}; "
              f"total {out['timing_s']['total']:.2f} s)")
    else:
        a = out["approximate"]
        print(f"method: {out['method']}  (design measure on {a['n_candidates']} candidate poses, "
              f"{len(a['support'])} support points, counts {a['counts']}; total {out['timing_s']['total']:.2f} s)")
    P = np.array(out["poses"])
    Pp = np.array(pp["poses"]) if pp is not None else np.full((0, len(coords)), np.nan)
    J = np.array(out[k("joints")])
    print()
    show = len(P) if len(P) <= 40 else 20
    print(f"{'k':>3} " + " ".join(f"{x + ' [' + u + ']':>9}" for x, u in zip(coords, pu)) + " "
          + " ".join(f"{j + ' [' + ju + ']':>12}" for j in joints)
          + ("   | " + " ".join(f"{base + ' ' + x:>9}" for x in coords) if pp is not None else ""))
    for i in range(show):
        print(f"{i + 1:>3} " + " ".join(f"{v:9.3f}" for v in np.round(P[i], 9) + 0.0) + " "
              + " ".join(f"{v:12.4f}" for v in J[i])
              + ("   | " + " ".join(f"{v:9.2f}" for v in np.round(Pp[i], 9) + 0.0) if pp is not None else ""))
    if show < len(P):
        print(f"... ({len(P) - show} more poses: --json)")
    print()
    vals = out["criterion"]["values"]
    pvals = pp["criterion"]["values"] if pp is not None else {c_: None for c_ in vals}
    units_ = out["criterion"]["units_all"]
    print(f"{'':34}{'design':>12}{(base if pp is not None else ''):>12}{('ratio' if pp is not None else ''):>9}")
    for name in vals:
        label = f"{name}{' [' + units_[name] + ']' if units_[name] else ''}{' *' if name == crit else ''}"
        r = vals[name] / pvals[name] if vals[name] is not None and pvals[name] else None
        print(f"  {label:32}{_fmt(vals[name]):>12}{_fmt(pvals[name]):>12}{_fmt(r, '.4g'):>10}")
    cz = out[k("crlb_zero_offsets")]
    pz = pp[k("crlb_zero_offsets")] if pp is not None else []
    print(f"  {'CRLB per offset [' + ju + ']':32}{' '.join(_fmt(v, fo) for v in cz):>12}  "
          f"{' '.join(_fmt(v, fo) for v in pz):>12}")
    b, pb = out.get("bias"), (pp or {}).get("bias")
    if b:
        print(f"  {'bias worst case [' + ju + ']':32}{' '.join(_fmt(v, fo) for v in b[k('worst_case')]):>12}  "
              f"{' '.join(_fmt(v, fo) for v in (pb or {}).get(k('worst_case'), [])):>12}")
        print(f"  {'bias RMS [' + ju + ']':32}{' '.join(_fmt(v, fo) for v in b[k('rms')]):>12}  "
              f"{' '.join(_fmt(v, fo) for v in (pb or {}).get(k('rms'), [])):>12}")
    ps, pps = out.get("position"), (pp or {}).get("position")
    if ps:
        print(f"  {'position error RMS / max [mm]':32}{_fmt(ps['rms_mm']) + ' / ' + _fmt(ps['max_mm']):>12}  "
              f"{(_fmt(pps['rms_mm']) + ' / ' + _fmt(pps['max_mm'])) if pps else '':>12}")
    print(f"  {'kappa (paper kappa_1)':32}{_fmt(out['kappa']):>12}{_fmt((pp or {}).get('kappa')):>12}"
          f"{_fmt(out['ratio']['kappa_design_over_paper'], '.3f'):>9}")
    print(f"  {'rho span [mm]':32}{out['rho_span_mm']:12.2f}{_fmt((pp or {}).get('rho_span_mm'), '.2f'):>12}")
    print(f"  {'min |sin transmission|':32}{out['min_transmission_sine']:12.4f}"
          f"{_fmt((pp or {}).get('min_transmission_sine'), '.4f'):>12}")
    if b:
        tol = ", ".join(f"{k_} {v:g}" for k_, v in b["tolerances"].items())
        print(f"  (bias: first order from the tolerances {tol} (mm, deg); RMS for uniform errors)")
    _print_detection(out, ju)
    print()
    if pp is not None:
        print(f"CRLB ratio design / {out.get('baseline_scheme') or base + ' scheme'} (RMS over the {len(joints)} "
              f"offsets): {_fmt(out['ratio']['crlb_rms_design_over_paper'], '.4f')}")
    else:
        print(f"baseline: none -- {out.get('baseline_note')}")
    cert = out.get("certificate")
    if cert:
        eff = cert.get("efficiency_lower_bound")
        what = cert["criterion"]
        print(f"certificate {cert.get('certificate') or ''}: no {out['K']}-pose design on the "
              f"{cert['n_candidates']} candidate poses (this design's among them) has {what} better than "
              f"{_fmt(cert['bound'])} {units_.get(what, '')}; this design's efficiency >= "
              f"{_fmt(eff, '.4f')}" + (f" ({cert['note']})" if cert.get("note") else ""))
        if cert.get("candidates"):
            print(f"  (candidates: {cert['candidates']})")
    if "verify" in out:
        v = out["verify"]
        print()
        d, p = v["design"], v["paper"]
        te = d["true_errors"]
        m = len(te[k("zero_offsets")])
        print(f"Monte Carlo: {d['n_trials']} trials each, Ipopt estimator (nlls), true zero offsets "
              f"{', '.join(f'{x:g}' for x in te[k('zero_offsets')])} {ju}, MAEMM {te['maemm_mm']} mm, "
              "no geometric errors")
        w = 9 * m
        print(f"{'':10}{'RMS error [' + ju + ']':>{w}}  {'CRLB at truth [' + ju + ']':>{w}}{'RMS':>9}{'CRLB':>9}"
              f"{'failed':>8}")
        for name, x in (("design", d), (base, p)):
            if x is None:
                continue
            print(f"  {name:8}" + "".join(format(e, "9" + fo) for e in x[k("rms_error")]) + "  "
                  + "".join(format(e, "9" + fo) for e in x[k("crlb_at_truth")])
                  + format(x[k('rms_error_rms')], "9" + fo) + format(x[k('crlb_at_truth_rms')], "9" + fo)
                  + f"{x['n_failed']:8d}")
        if p is not None:
            print(f"  ratio design / {base}: RMS error {_fmt(v['rms_ratio_design_over_paper'], '.4f')}, CRLB "
                  f"{_fmt(d[k('crlb_at_truth_rms')] / p[k('crlb_at_truth_rms')], '.4f')}")
    if "plot" in out:
        print(f"plot: {out['plot']}")


#: the detection summary's rows: (key of ``detection.power``, label)
_POWER_ROWS = (("reversed", "poses visited in reverse"), ("swaps", "two poses swapped (least)"),
               ("scale_error", "every length {scale} off"), ("bad_reading", "one bad reading of {bad} mm (least)"),
               ("entries_at_tolerance", "a robot-file entry at its tolerance (least)"))


def _print_detection(out, ju):
    """What the fit check of the design and of the baseline sees (``detection``), and a checked design's cost."""
    d, pd = out.get("detection"), (out.get("paper") or {}).get("detection")
    if not d:
        return
    base = out.get("baseline", "paper") if pd else ""
    print()
    print(f"{'fit check (alpha ' + format(d['alpha'], 'g') + '): power against':48}{'design':>10}{base:>12}")
    print(f"  {'spare degrees of freedom':46}{d['dof']:>10}{(pd or {}).get('dof', ''):>12}")
    scale = next((f"{r['size']:g} %" for r in d["scenarios"] if r["name"] == "scale"), "")
    bad = next((f"{r['size']:g}" for r in d["scenarios"] if r["kind"] == "reading"), "")
    for key, label in _POWER_ROWS:
        pv = (pd or {}).get("power", {}).get(key) if pd else None
        print(f"  {label.format(scale=scale, bad=bad):46}{_fmt(d['power'].get(key), '.3f'):>10}"
              f"{_fmt(pv, '.3f') if pd else '':>12}")
    for name, x in (("design", d), (base, pd)):
        if not x:
            continue
        verdict = "sees what it must" if x["meets"] else ("misses " + ", ".join(x["unmet"]) if x["unmet"]
                                                           else x.get("note", "cannot run"))
        print(f"  {name}: {verdict}")
    inv = d.get("invisible_entries")
    print(f"  (required: power >= {d['power_target']:g} against every order error, and against the scale error and "
          f"a bad reading unless it moves no offset by {d['harm_sigma']:g} sigma ({d['harm_counted_in']}); "
          + ("each entry at its tolerance likewise (--require-entries)" if d.get("entries_required") else
             "a single entry at its tolerance is reported, not required (--require-entries)")
          + (f"; no design sees {', '.join(inv)}" if inv else "") + ")")
    c = out.get("checked")
    if c:
        cd = c["crlb_design"]
        misses = ", ".join(cd.get("unmet") or []) or "nothing"
        print(f"checked: CRLB {_fmt(out['criterion']['value'])} {ju} = {_fmt(c['cost'], '.4f')} x the crlb-optimal "
              f"design's {_fmt(cd['crlb'])} {ju}, whose fit check misses {misses}"
              + (f" ({c['note']})" if c.get("note") else ""))


def _run_target(args, robot):
    """``--target-crlb X``: the fewest poses (crlb criterion), with the certified lower bound."""
    import numpy as np

    from zerocal_sym import design
    from zerocal_sym.cli._common import write_out
    from zerocal_sym.design.fewest import fewest_poses
    from zerocal_sym.design.terms import describe_noise, noise_dict, okey, pose_units, poses_to_user
    from zerocal_sym.io.files import json_safe, to_json
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model import units
    from zerocal_sym.model.noise import NoiseModel

    if getattr(args, "plot", None):
        raise design.DesignError("--plot is for --optimize (a --target-crlb design has K in the hundreds)")
    k = lambda stem: okey(robot, stem)  # noqa: E731
    ju = units.joint_unit(robot)
    cons = constraints_from_args(robot, args)
    noise = NoiseModel.named(getattr(args, "noise", "paper"), robot)
    res = fewest_poses(robot, args.target_crlb, cons, noise)
    P = np.asarray(res["poses"])
    theta = kin.ik(robot, P)
    out = {"robot": robot.name, "mechanism": robot.mechanism_name, "unit": ju,
           k("target_crlb"): res[k("target_crlb")],
           "K": res["K"], "K_lower_bound": res["K_lower_bound"], k("crlb_rms"): res[k("crlb_rms")],
           k("crlb_zero_offsets"): None, "poses": poses_to_user(robot, P).tolist(), "pose_units": pose_units(robot),
           "pose_names": list(robot.mechanism.pose_names),
           k("joints"): units.joints_to_user(robot, theta).tolist(), "joint_names": list(robot.mechanism.joint_names),
           "evaluated": res["evaluated"], "approximate": res["approximate"],
           "constraints": cons.to_dict(), "violations": design.check_design(robot, P, cons),
           "noise": dict(noise_dict(robot, noise), description=describe_noise(robot, noise)),
           "bound": "no design of fewer than K_lower_bound poses on the candidate poses reaches the target "
                    "(certificate of the optimal design measure); K is the fewest poses of the rounded designs",
           "time_s": res["time_s"]}
    from zerocal_sym.design.replicates import revisits_entry

    out.update(revisits_entry(P))  # true replicates: a pose file of the design says revisits are intended
    from zerocal_sym.identify import fisher

    out[k("crlb_zero_offsets")] = fisher.crlb_zero_offsets_user(robot, theta, "paper", noise).tolist()
    out = json_safe(out)
    write_out(args, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    from zerocal_sym.design.constraints import region_text

    print(f"Fewest poses for an RMS zero-offset CRLB of {out[k('target_crlb')]:g} {ju}: robot {out['robot']}, "
          f"region {region_text(cons.region)}")
    print(f"  K = {out['K']} (design CRLB {out[k('crlb_rms')]:.5g} {ju}; per offset "
          f"{', '.join(f'{v:.5g}' for v in out[k('crlb_zero_offsets')])})")
    if out.get("revisits"):
        print(f"  the poses are replicates of {len(np.unique(P, axis=0))} support points, never one twice in a row "
              "(the JSON says \"revisits\": \"allowed\": its readers accept them)")
    print(f"  certified: no design of fewer than {out['K_lower_bound']} poses on the "
          f"{out['approximate']['n_candidates']} candidate poses can reach it")
    a = out["approximate"]
    print("  support of the design measure (file units, weight): "
          + "; ".join(f"{tuple(round(float(x), 2) for x in s_)} {w:.3f}"
                      for s_, w in zip(a["support"], a["support_weights"])))
    print("  evaluated K: " + ", ".join(f"{kk} -> {v:.5g}" for kk, v in out["evaluated"].items()))
    print(f"  ({out['time_s']:.1f} s; the {out['K']} poses: --json)")
    return 0


def _desc(name):
    from zerocal_sym.design import CRITERIA
    from zerocal_sym.design.criteria import CHECKED, CHECKED_DESCRIPTION

    return CHECKED_DESCRIPTION if name == CHECKED else CRITERIA[name][0]
