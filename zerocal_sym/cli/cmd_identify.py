"""Identify the zero offsets (and MAEMM) from a measurement file.

``--method nlls`` (default): maximum likelihood on the exact distance model
with Ipopt (CasADi), weights from the noise model with the servo error
propagated, Gauss-Newton Hessian, warm start from TSVD; optional Gaussian
priors (MAP) and bounds.  ``--method tsvd``: the paper's truncated SVD of the
linearised model (Eq. 29).

Output: the zero offsets with their standard deviations, the MAEMM, the
solver status, the identifiability of the parameters from these poses, and
the compensation (sign convention: ``theta_cmd = IK(P) - offset``; the actual
joint angle is the commanded one plus the offset).  ``--json`` prints the
results JSON that ``zerocal compensate`` reads; ``--out`` writes it
(atomically).  A failed identification (Ipopt did not converge, zero
offsets not identifiable, TSVD failure) exits with status 1 and writes no
file: it must not be used as a calibration.

Examples:

    zerocal identify round1.csv --json --out result.json
    zerocal identify round1.csv --method tsvd
    zerocal identify round1.csv --params paper+L1,L2 --prior-std L1=0.05 --prior-std L2=0.05
"""
NAME = "identify"
HELP = "identify zero offsets and MAEMM from a measurement file (Ipopt or TSVD)"


def add_arguments(p):
    p.add_argument("data", metavar="DATA.csv", help="measurement file (format: docs/data-format.md)")
    p.add_argument("--method", choices=["nlls", "tsvd"], default="nlls", help="identification method (default nlls)")
    p.add_argument("--params", default="paper",
                   help="nlls parameter set: paper (theta1 theta2 rMx rMy) | all | names joined by , or + "
                        "(e.g. paper+L1,L2); tsvd always identifies the paper's 4")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model for the weights and the covariance (default paper; none: unit weights, "
                        "covariance from the residuals)")
    p.add_argument("--maemm-prior", nargs=2, type=float, metavar=("X", "Y"), default=None,
                   help="MAEMM prior, mm (tsvd: Eq. 30 correction; nlls: prior mean / start)")
    p.add_argument("--prior-std", action="append", default=[], metavar="NAME=STD",
                   help="nlls Gaussian prior std of a parameter (deg for theta*, mm otherwise), around 0 or "
                        "the MAEMM prior; repeatable")
    p.add_argument("--bound", action="append", default=[], metavar="NAME=LO:HI",
                   help="nlls bound of a parameter (deg for theta*, mm otherwise); repeatable")
    p.add_argument("--max-iter", type=int, default=None, metavar="N", help="nlls: Ipopt iteration limit (default 200)")
    p.add_argument("--truncation", type=int, default=None, metavar="T", help="tsvd: fixed truncation level 1..4")
    p.add_argument("--rule", choices=["threshold", "gcv", "discrepancy"], default=None,
                   help="tsvd truncation rule (default: tsvd's default)")
    p.add_argument("--report", action="store_true", help="also print the identifiability report (text output)")
    p.add_argument("--json", action="store_true", help="print the results JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, help="write the results JSON here")
    p.add_argument("--plot", metavar="DIR", default=None,
                   help="write residuals.png (measured minus predicted change per pose) into DIR")


def _unit(name):
    return "deg" if name.startswith("theta") else "mm"


def _parse_named(items, names, what, parse):
    import numpy as np

    from zerocal_sym.errors import ZerocalError

    out = {}
    for it in items:
        k, sep, v = it.partition("=")
        k = k.strip()
        if not sep or k not in names:
            raise ZerocalError(f"{what} {it!r}: expected NAME=VALUE with NAME one of {', '.join(names)}")
        try:
            val = parse(v)
        except ValueError:
            raise ZerocalError(f"{what} {it!r}: bad value {v!r}") from None
        conv = np.radians if k.startswith("theta") else (lambda x: x)
        out[k] = tuple(float(conv(x)) for x in val) if isinstance(val, tuple) else float(conv(val))
    return out



def result_json(robot, meas, res, report, source) -> dict:
    """The results JSON: IdentificationResult.to_dict plus robot, data, compensation, identifiability."""
    import numpy as np

    from zerocal_sym.io.compensation import SIGN_CONVENTION

    d = res.to_dict()
    keep = ("solver_status", "iterations", "cost", "chi2", "dof", "time_s", "weighting", "warm_start", "rank",
            "singular_values", "nonidentifiable", "truncation", "rule", "kappa", "filter_factors", "noise")
    d["info"] = {k: v for k, v in res.info.items() if k in keep}
    d["robot_sha256"] = robot.sha256
    d["robot"] = {"name": robot.name, "source": robot.source, "sha256": robot.sha256}
    d["data"] = {"file": str(source), "K": int(meas.K), "data_robot_sha256": meas.meta.get("robot_sha256")}
    std = res.std_zero_offsets_deg
    d["compensation"] = {
        "sign_convention": SIGN_CONVENTION,
        "joints": ["theta1", "theta2"],
        "offset_deg": res.zero_offsets_deg.tolist(),
        "std_deg": [float(s) if np.isfinite(s) else None for s in std],
    }
    d["identifiability"] = report
    from zerocal_sym.io.files import json_safe

    return json_safe(d)


def run(args):
    import sys

    import numpy as np

    from zerocal_sym.identify import fisher
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.io.measurements import load_measurements
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.identify.identifiability import format_report, identifiability_report
    from zerocal_sym.io.files import to_json, write_json
    from zerocal_sym.model.noise import NoiseModel

    robot = load_robot_arg(args)
    meas = load_measurements(args.data, robot)  # refuses data measured on another robot (robot_sha256)
    noise = NoiseModel.named(args.noise)
    prior = np.zeros(12)
    if args.maemm_prior is not None:
        prior[10:12] = args.maemm_prior
    if args.method == "tsvd":
        if args.params != "paper" or args.prior_std or args.bound or args.max_iter is not None:
            raise ZerocalError("--params, --prior-std, --bound and --max-iter are for --method nlls "
                               "(tsvd identifies the paper's 4)")
        from zerocal_sym.identify.tsvd import identify_tsvd

        kw = {}
        if args.rule is not None:
            kw["rule"] = args.rule
        res = identify_tsvd(robot, meas, prior=prior, t=args.truncation, noise=None if noise.is_zero else noise,
                            **kw)
        names = ("theta1", "theta2", "rMx", "rMy")
    else:
        if args.truncation is not None or args.rule is not None:
            raise ZerocalError("--truncation and --rule are for --method tsvd")
        try:
            names = fisher.param_names(args.params)
        except ValueError as exc:
            raise ZerocalError(f"--params: {exc}") from None
        if meas.K - 1 < len(names):
            raise ZerocalError(f"{meas.K} poses give {meas.K - 1} measured changes: fewer than the {len(names)} "
                               f"parameters {', '.join(names)}", where=args.data)
        pstd = _parse_named(args.prior_std, names, "--prior-std", float)
        if any(v <= 0 for v in pstd.values()):
            raise ZerocalError("--prior-std must be positive")
        bounds = _parse_named(args.bound, names, "--bound",
                              lambda v: tuple(float(x) for x in v.split(":", 1)) if ":" in v else
                              (_ for _ in ()).throw(ValueError(v)))
        if any(lo > hi for lo, hi in bounds.values()):
            raise ZerocalError("--bound: LO must not exceed HI")
        from zerocal_sym.identify.nlls import identify_nlls

        if args.max_iter is not None and args.max_iter < 1:
            raise ZerocalError("--max-iter must be >= 1")
        res = identify_nlls(robot, meas, names, noise=noise, prior=prior, bounds=bounds or None,
                            prior_std=pstd or None, max_iter=args.max_iter)
    report = identifiability_report(robot, meas.theta_cmd, names, noise, err0=res.full_vector())
    out = result_json(robot, meas, res, report, args.data)
    if not res.success:
        if args.json:
            print(to_json(out))
        elif args.report:
            print(format_report(report))
        print(f"zerocal identify: identification failed ({res.method}): {res.status}; no calibration written",
              file=sys.stderr)
        return 1
    if args.plot:
        from zerocal_sym.report.plots import identify_plots

        identify_plots(args.plot, res, meas, robot)
    if args.out:
        write_json(args.out, out)
    if args.json:
        print(to_json(out))
        return 0
    print(f"{args.data}: K = {meas.K} poses, method {res.method}: {res.status}")
    for n, v, s in zip(res.params, res.estimate, [res.std(n) for n in res.params]):
        conv = np.degrees if n.startswith("theta") else (lambda x: x)
        std = f" ± {conv(s):.4g}" if np.isfinite(s) else ""
        print(f"  {n:7s} = {conv(v):+.6f}{std} {_unit(n)}")
    print(f"compensation ({out['compensation']['sign_convention']}):")
    for j, n in enumerate(("theta1", "theta2")):
        s = out["compensation"]["std_deg"][j]
        print(f"  {n}: offset {out['compensation']['offset_deg'][j]:+.6f} deg" + (f" (std {s:.4g})" if s else ""))
    info = res.info
    if res.method == "nlls":
        print(f"Ipopt: {info['solver_status']}, {info['iterations']} iterations, cost {info['cost']:.6g}, "
              f"chi2 {info['chi2']:.4g} on {info['dof']} dof; weights: {info['weighting']}")
    if args.report:
        print(format_report(report))
    if args.out:
        print(f"wrote {args.out}")
    return 0
