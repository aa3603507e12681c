"""``zerocal design --optimize``: measurement poses optimised for a criterion.

Runs :func:`zerocal_sym.design.optimize_design` (discrete exchange + Ipopt
multi-start + order search + polish) and prints the poses, every criterion
of the design beside the paper's scheme with the same K, the CRLB of the zero
offsets and their ratio; ``--verify N`` adds a Monte Carlo with the Ipopt
estimator (:func:`zerocal_sym.design.verify_design`) for both designs;
``--plot PNG`` draws them in the workspace.  Nothing is written (plot) unless
everything succeeded.

Any mechanism: the design region is the robot's workspace shape (a rectangle
``XMIN XMAX YMIN YMAX`` or a cylinder ``RW ZMIN ZMAX``), the baseline the
workspace's boundary scheme with the same K (the paper's scheme, the ring
scheme), joint limits one ``LO HI`` pair per joint; K defaults to 2n of the
scheme's default n (6 for the paper's robot, 12 for the Delta).
"""
from __future__ import annotations


def _fmt(v, spec=".4g"):
    import math

    if v is None:
        return "-"
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    return format(v, spec)


def run(args, robot):
    import numpy as np

    from zerocal_sym import design
    from zerocal_sym.design import constraints, criteria, optimize
    from zerocal_sym.cli._common import check_scheme, default_n, write_out
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.noise import NoiseModel

    check_scheme(robot, args.scheme)  # the baseline is the robot's own scheme
    K = args.K if args.K is not None else 2 * default_n(robot)
    constraints._check_k(K, robot)
    criteria._check_criterion(args.criterion)
    verify = int(getattr(args, "verify", 0) or 0)
    if verify < 0:
        raise design.DesignError(f"--verify N needs N >= 0, got {verify}")
    from zerocal_sym.cli import _parallel
    from zerocal_sym.identify.parallel import check_execution

    check_execution(getattr(args, "workers", 1), getattr(args, "scheduler", None))
    starts = int(getattr(args, "starts", 8))
    if starts < 1:
        raise design.DesignError(f"--starts needs at least 1, got {starts}")
    jl = getattr(args, "joint_limits", None)
    if jl is not None and len(jl) != 2 * robot.m:
        pairs = " ".join(f"LO{j + 1} HI{j + 1}" for j in range(robot.m))
        raise design.DesignError(f"--joint-limits needs {2 * robot.m} values {pairs} (deg; joints "
                                 f"{', '.join(robot.mechanism.joint_names)}), got {len(jl)}")
    cons = design.make_constraints(
        robot, region=args.region, travel_mm=getattr(args, "l0", design.SCALE_RANGE_MM),
        travel_mode=getattr(args, "travel_mode", "range"), singularity_margin=getattr(args, "margin", None),
        joint_limits_deg=None if jl is None else [(jl[2 * j], jl[2 * j + 1]) for j in range(robot.m)],
        min_separation_mm=getattr(args, "min_separation", 1.0))
    noise = NoiseModel.named(getattr(args, "noise", "paper"))
    ex = _parallel.execution(args) if verify and hasattr(args, "workers") else {}  # a scheduler reached first
    try:
        res = design.optimize_design(robot, K, args.criterion, cons, noise, seed=args.seed, n_starts=starts,
                                     exchange_starts=starts)
    except BaseException:
        _parallel.close(ex)
        raise
    out = res.to_dict()
    out["robot"] = robot.name
    out["mechanism"] = robot.mechanism_name
    out["seed"] = args.seed
    if verify:
        try:
            vd = design.verify_design(robot, res.poses, verify, noise, seed=args.seed, **ex)
            vp = design.verify_design(robot, np.asarray(res.paper["poses"]), verify, noise, seed=args.seed, **ex)
        finally:
            _parallel.close(ex)
        out["verify"] = {"design": vd, "paper": vp,
                         "rms_ratio_design_over_paper": optimize._ratio(vd["rms_error_rms_deg"],
                                                                        vp["rms_error_rms_deg"]),
                         "estimator": "zerocal_sym.identify.nlls.identify_nlls (Ipopt, exact model, the zero offsets and the MAEMM)"}
        out["paper"]["verify"] = vp
    if args.plot:
        design.plot_design(args.plot, robot, res)
        out["plot"] = str(args.plot)
    write_out(args, out)
    if args.json:
        print(to_json(out))
        return 0
    _print_text(out, res)
    return 0


def _print_text(out, res):
    import numpy as np

    crit = out["criterion"]["name"]
    c = out["constraints"]
    jl = c["joint_limits_deg"]
    base = out.get("baseline", "paper")
    coords, joints = out["pose_names"], out["joint_names"]
    print(f"Optimised measurement poses: robot {out['robot']}, K = {out['K']}, criterion {crit} "
          f"({_desc(crit)})")
    print(f"constraints: region {c['region']} mm; scale range l0 = {c['travel_mm']:g} mm ({c['travel_mode']}); "
          f"|sin transmission| >= {c['singularity_margin']:g}; joint limits "
          f"{'none' if jl is None else str(jl) + ' deg'}; poses >= {c['min_separation_mm']:g} mm apart")
    n = out["noise"]
    print(f"noise: scale {n['sigma_scale_mm'] * 1e3:.4g} um per change, servo {n['sigma_servo_deg']:.4g} deg "
          "per joint per pose")
    ex, co = out["exchange"], out["continuous"]
    ok = sum(r["feasible"] for r in co["runs"])
    print(f"method: {out['method']}  (exchange on {ex['n_candidates']} grid candidates: {_fmt(ex['value'])}; "
          f"Ipopt multi-start, {ok}/{len(co['runs'])} feasible ends: {_fmt(co['value'])}; "
          f"total {out['timing_s']['total']:.2f} s)")
    P, Pp = np.array(out["poses"]), np.array(out["paper"]["poses"])
    J = np.array(out["joints_deg"])
    print()
    print(f"{'k':>3} " + " ".join(f"{x + ' [mm]':>9}" for x in coords) + " "
          + " ".join(f"{j + ' [deg]':>12}" for j in joints) + "   | "
          + " ".join(f"{base + ' ' + x:>9}" for x in coords))
    for k in range(len(P)):
        print(f"{k + 1:>3} " + " ".join(f"{v:9.3f}" for v in np.round(P[k], 9) + 0.0) + " "
              + " ".join(f"{v:12.4f}" for v in J[k]) + "   | "
              + " ".join(f"{v:9.2f}" for v in np.round(Pp[k], 9) + 0.0))
    print()
    print(f"{'':34}{'design':>12}{base:>12}{'ratio':>9}")
    vals, pvals = out["criterion"]["values"], out["paper"]["criterion"]["values"]
    units = out["criterion"]["units_all"]
    for name in vals:
        label = f"{name}{' [' + units[name] + ']' if units[name] else ''}{' *' if name == crit else ''}"
        r = vals[name] / pvals[name] if vals[name] is not None and pvals[name] else None
        print(f"  {label:32}{_fmt(vals[name]):>12}{_fmt(pvals[name]):>12}{_fmt(r, '.3f'):>9}")
    cz, pz = out["crlb_zero_offsets_deg"], out["paper"]["crlb_zero_offsets_deg"]
    print(f"  {'CRLB per offset [deg]':32}{' '.join(_fmt(v, '.4f') for v in cz):>12}  "
          f"{' '.join(_fmt(v, '.4f') for v in pz):>12}")
    print(f"  {'kappa (paper kappa_1)':32}{_fmt(out['kappa']):>12}{_fmt(out['paper']['kappa']):>12}"
          f"{_fmt(out['ratio']['kappa_design_over_paper'], '.3f'):>9}")
    print(f"  {'rho span [mm]':32}{out['rho_span_mm']:12.2f}{out['paper']['rho_span_mm']:12.2f}")
    print(f"  {'min |sin transmission|':32}{out['min_transmission_sine']:12.4f}"
          f"{out['paper']['min_transmission_sine']:12.4f}")
    if out["paper"].get("violations"):
        print(f"  note: the {base} scheme breaks the constraints: {'; '.join(out['paper']['violations'])}")
    print()
    print(f"CRLB ratio design / {base} scheme (RMS over the {len(joints)} offsets): "
          f"{_fmt(out['ratio']['crlb_rms_design_over_paper'], '.4f')}")
    if "verify" in out:
        v = out["verify"]
        print()
        d, p = v["design"], v["paper"]
        te = d["true_errors"]
        m = len(te["zero_offsets_deg"])
        print(f"Monte Carlo: {d['n_trials']} trials each, Ipopt estimator (nlls), true zero offsets "
              f"{', '.join(f'{x:g}' for x in te['zero_offsets_deg'])} deg, MAEMM {te['maemm_mm']} mm, "
              "no geometric errors")
        w = 9 * m
        print(f"{'':10}{'RMS error [deg]':>{w}}  {'CRLB at truth [deg]':>{w}}{'RMS':>9}{'CRLB':>9}{'failed':>8}")
        for name, x in (("design", d), (base, p)):
            print(f"  {name:8}" + "".join(f"{e:9.4f}" for e in x["rms_error_deg"]) + "  "
                  + "".join(f"{e:9.4f}" for e in x["crlb_at_truth_deg"])
                  + f"{x['rms_error_rms_deg']:9.4f}{x['crlb_at_truth_rms_deg']:9.4f}{x['n_failed']:8d}")
        print(f"  ratio design / {base}: RMS error {_fmt(v['rms_ratio_design_over_paper'], '.4f')}, CRLB "
              f"{_fmt(d['crlb_at_truth_rms_deg'] / p['crlb_at_truth_rms_deg'], '.4f')}")
    if "plot" in out:
        print(f"plot: {out['plot']}")


def _desc(name):
    from zerocal_sym.design import CRITERIA

    return CRITERIA[name][0]
