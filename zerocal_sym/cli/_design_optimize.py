"""``zerocal design --optimize``: measurement poses optimised for a criterion.

Runs :func:`zerocal_sym.design.optimize_design` (discrete exchange + Ipopt
multi-start + order search + polish) and prints the poses, every criterion
of the design beside the paper's scheme with the same K, the CRLB of the zero
offsets and their ratio; ``--verify N`` adds a Monte Carlo with the Ipopt
estimator (:func:`zerocal_sym.design.verify_design`) for both designs;
``--plot PNG`` draws them in the workspace.  Nothing is written (plot) unless
everything succeeded.
"""
from __future__ import annotations


def _fmt(v, spec=".4g"):
    import math

    if v is None:
        return "-"
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    return format(v, spec)


def run(args):
    import numpy as np

    from zerocal_sym import design
    from zerocal_sym.design import constraints, criteria, optimize
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.noise import NoiseModel

    robot = load_robot_arg(args)
    K = args.K
    constraints._check_k(K)
    criteria._check_criterion(args.criterion)
    verify = int(getattr(args, "verify", 0) or 0)
    if verify < 0:
        raise design.DesignError(f"--verify N needs N >= 0, got {verify}")
    starts = int(getattr(args, "starts", 8))
    if starts < 1:
        raise design.DesignError(f"--starts needs at least 1, got {starts}")
    jl = getattr(args, "joint_limits", None)
    cons = design.make_constraints(
        robot, region=args.region, travel_mm=getattr(args, "l0", design.SCALE_RANGE_MM),
        travel_mode=getattr(args, "travel_mode", "range"), singularity_margin=getattr(args, "margin", None),
        joint_limits_deg=None if jl is None else ((jl[0], jl[1]), (jl[2], jl[3])),
        min_separation_mm=getattr(args, "min_separation", 1.0))
    noise = NoiseModel.named(getattr(args, "noise", "paper"))
    res = design.optimize_design(robot, K, args.criterion, cons, noise, seed=args.seed, n_starts=starts,
                                 exchange_starts=starts)
    out = res.to_dict()
    out["robot"] = robot.name
    out["seed"] = args.seed
    if verify:
        vd = design.verify_design(robot, res.poses, verify, noise, seed=args.seed)
        vp = design.verify_design(robot, np.asarray(res.paper["poses"]), verify, noise, seed=args.seed)
        out["verify"] = {"design": vd, "paper": vp,
                         "rms_ratio_design_over_paper": optimize._ratio(vd["rms_error_rms_deg"],
                                                                        vp["rms_error_rms_deg"]),
                         "estimator": "zerocal_sym.identify.nlls.identify_nlls (Ipopt, exact model, paper's 4 parameters)"}
        out["paper"]["verify"] = vp
    if args.plot:
        design.plot_design(args.plot, robot, res)
        out["plot"] = str(args.plot)
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
    print(f"Optimised measurement poses: robot {out['robot']}, K = {out['K']}, criterion {crit} "
          f"({_desc(crit)})")
    print(f"constraints: region x in [{c['region_mm'][0]:g}, {c['region_mm'][1]:g}], y in [{c['region_mm'][2]:g}, "
          f"{c['region_mm'][3]:g}] mm; scale range l0 = {c['travel_mm']:g} mm ({c['travel_mode']}); "
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
    print(f"{'k':>3} {'x [mm]':>9} {'y [mm]':>9} {'th1 [deg]':>10} {'th2 [deg]':>10}   |"
          f" {'paper x':>8} {'paper y':>8}")
    for k in range(len(P)):
        print(f"{k + 1:>3} {P[k, 0]:9.3f} {P[k, 1]:9.3f} {J[k, 0]:10.4f} {J[k, 1]:10.4f}   |"
              f" {Pp[k, 0]:8.2f} {Pp[k, 1]:8.2f}")
    print()
    print(f"{'':34}{'design':>12}{'paper':>12}{'ratio':>9}")
    vals, pvals = out["criterion"]["values"], out["paper"]["criterion"]["values"]
    units = out["criterion"]["units_all"]
    for name in vals:
        label = f"{name}{' [' + units[name] + ']' if units[name] else ''}{' *' if name == crit else ''}"
        r = vals[name] / pvals[name] if vals[name] is not None and pvals[name] else None
        print(f"  {label:32}{_fmt(vals[name]):>12}{_fmt(pvals[name]):>12}{_fmt(r, '.3f'):>9}")
    cz, pz = out["crlb_zero_offsets_deg"], out["paper"]["crlb_zero_offsets_deg"]
    print(f"  {'CRLB dtheta1, dtheta2 [deg]':32}{_fmt(cz[0], '.4f') + ' ' + _fmt(cz[1], '.4f'):>12}"
          f"{_fmt(pz[0], '.4f') + ' ' + _fmt(pz[1], '.4f'):>14}")
    print(f"  {'kappa (paper kappa_1)':32}{_fmt(out['kappa']):>12}{_fmt(out['paper']['kappa']):>12}"
          f"{_fmt(out['ratio']['kappa_design_over_paper'], '.3f'):>9}")
    print(f"  {'rho span [mm]':32}{out['rho_span_mm']:12.2f}{out['paper']['rho_span_mm']:12.2f}")
    print(f"  {'min |sin transmission|':32}{out['min_transmission_sine']:12.4f}"
          f"{out['paper']['min_transmission_sine']:12.4f}")
    if out["paper"].get("violations"):
        print(f"  note: the paper's scheme breaks the constraints: {'; '.join(out['paper']['violations'])}")
    print()
    print(f"CRLB ratio design / paper (RMS over both offsets): "
          f"{_fmt(out['ratio']['crlb_rms_design_over_paper'], '.4f')}")
    if "verify" in out:
        v = out["verify"]
        print()
        d, p = v["design"], v["paper"]
        te = d["true_errors"]
        print(f"Monte Carlo: {d['n_trials']} trials each, Ipopt estimator (nlls), true zero offsets "
              f"{te['zero_offsets_deg'][0]:g}, {te['zero_offsets_deg'][1]:g} deg, MAEMM {te['maemm_mm']} mm, "
              "no geometric errors")
        print(f"{'':10}{'RMS error [deg]':>28}{'CRLB at truth [deg]':>28}{'RMS':>9}{'CRLB':>9}{'failed':>8}")
        for name, x in (("design", d), ("paper", p)):
            print(f"  {name:8}{x['rms_error_deg'][0]:14.4f}{x['rms_error_deg'][1]:14.4f}"
                  f"{x['crlb_at_truth_deg'][0]:14.4f}{x['crlb_at_truth_deg'][1]:14.4f}"
                  f"{x['rms_error_rms_deg']:9.4f}{x['crlb_at_truth_rms_deg']:9.4f}{x['n_failed']:8d}")
        print(f"  ratio design / paper: RMS error {_fmt(v['rms_ratio_design_over_paper'], '.4f')}, CRLB "
              f"{_fmt(d['crlb_at_truth_rms_deg'] / p['crlb_at_truth_rms_deg'], '.4f')}")
    if "plot" in out:
        print(f"plot: {out['plot']}")


def _desc(name):
    from zerocal_sym.design import CRITERIA

    return CRITERIA[name][0]
