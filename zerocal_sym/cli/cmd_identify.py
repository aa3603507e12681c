"""Identify the zero offsets (and MAEMM) from a measurement file.

Any mechanism: the columns of the file are the robot's (``--robot``;
``theta1_deg, ..., thetam_deg``), the identified parameters its source
errors by name.

``--method nlls`` (default): maximum likelihood on the exact distance model
with Ipopt (CasADi), weights from the noise model with the servo error
propagated, Gauss-Newton Hessian, warm start from TSVD; optional Gaussian
priors (MAP) and bounds.  ``--method tsvd``: the paper's truncated SVD of the
linearised model (Eq. 29): the m zero offsets and the n MAEMM components.

Output: the zero offsets with their standard deviations, the MAEMM, the
solver status, the identifiability of the parameters from these poses, the
error budget of the offsets (their 1 sigma from the data against the bias the
robot-file entries held at their values can put on them within their
``[tolerances]``; ``error_budget`` and ``limited_by`` in the JSON:
:mod:`zerocal_sym.identify.budget.error_budget`, docs/trust.md), and
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
    zerocal identify d.csv --robot examples/delta.toml --maemm-prior 1 0.5 -0.5 --json
    zerocal identify d.csv --robot examples/delta_arms.toml --params auto --test-groups
"""
from zerocal_sym.cli._identify_text import SIGMA_FRACTION  # (the verdict's fraction, in the help)

NAME = "identify"
HELP = "identify zero offsets and MAEMM from a measurement file (Ipopt or TSVD)"


#: the files ``--plot DIR`` writes into DIR
PLOTS = ("residuals.png", "boundary_errors.png")


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputDir, OutputFile

    p.add_argument("data", metavar="DATA.csv", type=InputFile("the measurement file"), help="measurement file (format: docs/data-format.md)")
    p.add_argument("--method", choices=["nlls", "tsvd"], default="nlls", help="identification method (default nlls)")
    p.add_argument("--params", default="paper",
                   help="nlls parameter set: paper (the zero offsets and the MAEMM, e.g. theta1 theta2 rMx rMy) "
                        "| all | gauge_fixed | names joined by , or + (e.g. paper+L1,L2) | auto (of paper plus "
                        "whole groups of robot-file entries, the set whose offsets' expected error at these poses "
                        "is least: docs/trust.md); tsvd always identifies the paper's set")
    p.add_argument("--test-groups", action="store_true",
                   help="free each group of robot-file entries in turn (L for L1 L2 L3; nlls fits with and without "
                        "it) and name those the data contradict (likelihood ratio, p < --fit-alpha); done anyway "
                        "when an nlls fit is rejected without a detected cause")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model for the weights and the covariance (default paper; none: unit weights, "
                        "covariance from the residuals)")
    p.add_argument("--maemm-prior", nargs="+", type=float, metavar="MM", default=None,
                   help="MAEMM prior, one value per pose coordinate (x y [z]), mm (tsvd: Eq. 30 correction; "
                        "nlls: prior mean / start)")
    p.add_argument("--prior-std", action="append", default=[], metavar="NAME=STD",
                   help="nlls Gaussian prior std of a parameter (deg for angles, mm otherwise), around 0 or "
                        "the MAEMM prior; repeatable")
    p.add_argument("--bound", action="append", default=[], metavar="NAME=LO:HI",
                   help="nlls bound of a parameter (deg for angles, mm otherwise); repeatable")
    p.add_argument("--max-iter", type=int, default=None, metavar="N", help="nlls: Ipopt iteration limit (default 200)")
    p.add_argument("--truncation", type=int, default=None, metavar="T",
                   help="tsvd: fixed truncation level 1..m+n")
    p.add_argument("--rule", choices=["threshold", "gcv", "discrepancy"], default=None,
                   help="tsvd truncation rule (default: tsvd's default)")
    p.add_argument("--iterate", type=int, nargs="?", const=20, default=None, metavar="N",
                   help="tsvd: relinearise at the estimate until the increment is below 1e-10 (rad, mm), at most N "
                        "steps (20 without N); default one step, the paper's")
    p.add_argument("--report", action="store_true", help="also print the identifiability report (text output)")
    p.add_argument("--tolerance", action="append", default=[], metavar="NAME=VALUE",
                   help="tolerance of a source error left out of the identification, or of a group of them (L "
                        "for L1 L2 L3) (mm; deg for angles), for the error budget; repeatable (default: the robot "
                        "file's [tolerances], else a robot measured by hand: docs/trust.md)")
    p.add_argument("--tolerance-file", default=None, metavar="FILE", type=InputFile("the tolerance file"),
                   help="tolerances by name (TOML or JSON)")
    p.add_argument("--tolerance-scale", type=float, default=1.0, metavar="S", help="every tolerance times S")
    p.add_argument("--goal", type=float, default=None, metavar="X",
                   help="the accuracy you need, in the joints' unit (deg for revolute, mm for prismatic joints): the "
                        "verdict line judges the offsets' 1 sigma against it (default: against "
                        f"{SIGMA_FRACTION:g} x the largest |offset|)")
    p.add_argument("--goal-deg", type=float, default=None, metavar="DEG",
                   help="the same for revolute joints, in deg")
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "the measurement file")
    p.add_argument("--json", action="store_true", help="print the results JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, type=OutputFile(), help="write the results JSON here")
    p.add_argument("--plot", metavar="DIR", default=None, type=OutputDir(PLOTS),
                   help="write residuals.png (measured minus predicted change per pose) into DIR and, for "
                        "simulated data (a '# true_errors:' line), boundary_errors.png (position error over the "
                        "workspace boundary before/after the compensation)")
    add_trust_arguments(p)


def add_trust_arguments(p, nlls_default=True):
    """The fit-check and plausibility options, shared by identify and verify."""
    p.add_argument("--fit-alpha", type=float, default=0.001, metavar="ALPHA",
                   help="significance level of the fit check: reject the fit when its chi2 p-value or its "
                        "largest standardised residual's p-value < ALPHA (default 0.001)")
    p.add_argument("--accept-misfit", action="store_true",
                   help="keep a calibration the fit check rejects (recorded in the result as accept_misfit)")
    p.add_argument("--loss", choices=["l2", "huber", "soft_l1"], default=None,
                   help="nlls: robust loss (default l2); outlying readings are named and left out")
    p.add_argument("--loss-scale", type=float, default=None, metavar="S",
                   help="nlls: scale of the robust loss, in standard deviations of a reading")
    p.add_argument("--max-offset", type=float, default=None, metavar="X",
                   help="refuse a result with a zero offset beyond this, in the joints' unit: deg for revolute, mm "
                        "for prismatic joints (default 10 deg or 10 mm)")
    p.add_argument("--max-offset-deg", type=float, default=None, metavar="DEG",
                   help="the same for revolute joints, in deg (the former spelling)")
    p.add_argument("--max-maemm-mm", type=float, default=50.0, metavar="MM",
                   help="refuse a result with a MAEMM norm beyond this (default 50 mm)")


def max_offset_arg(args, robot):
    """``--max-offset`` (the joints' unit) or ``--max-offset-deg`` (revolute joints): None for the default.

    Raises
    ------
    ZerocalError
        ``--max-offset-deg`` for prismatic joints, or both given.
    """
    from zerocal_sym.errors import ZerocalError

    a, b = getattr(args, "max_offset", None), getattr(args, "max_offset_deg", None)
    if a is not None and b is not None:
        raise ZerocalError("--max-offset and --max-offset-deg: give one")
    if b is not None and robot.errors.offset_user_unit != "deg":
        raise ZerocalError(f"--max-offset-deg: the zero offsets of {robot.mechanism_name} are in mm (prismatic "
                           "joints): give --max-offset in mm")
    return a if a is not None else b


def trust_kwargs(args, method):
    """Keyword arguments of identify_nlls / identify_tsvd from the trust options."""
    kw = {"fit_alpha": args.fit_alpha, "accept_misfit": bool(args.accept_misfit)}
    if method == "nlls":
        if args.loss is not None:
            kw["loss"] = args.loss
        if args.loss_scale is not None:
            kw["loss_scale"] = args.loss_scale
    return kw


def diagnosis(res) -> str:
    """The fit check's paragraph of a result ('' when there is none)."""
    fit = res.info.get("fit") if isinstance(res.info, dict) else None
    return (fit or {}).get("diagnosis") or ""


def _parse_named(items, robot, names, what, parse):
    """``NAME=VALUE`` items for the parameters ``names`` -> {name: value (internal units)}."""
    from zerocal_sym.errors import ZerocalError

    errors = robot.errors
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
        conv = lambda x: errors.from_user_value(k, x)  # noqa: E731 - deg -> rad for angles
        out[k] = tuple(conv(x) for x in val) if isinstance(val, tuple) else conv(val)
    return out


def maemm_prior_vector(robot, values, option="--maemm-prior"):
    """The source-error vector (q,) with the MAEMM set to ``values`` (n, mm), zero elsewhere."""
    from zerocal_sym.cli._common import vector_arg

    errors = robot.errors
    prior = errors.zeros()
    if values is not None:
        prior = errors.put(prior, errors.measuring, vector_arg(values, len(errors.measuring), option,
                                                               errors.measuring, "mm"))
    return prior


def compensation_block(robot, res) -> dict:
    """The ``compensation`` entry of a results JSON: sign convention, joints, offsets and their std (the joints'
    unit: deg or mm)."""
    import numpy as np

    from zerocal_sym.io.results import offset_keys, sign_convention

    unit = res.offset_unit
    off_key, std_key = offset_keys(unit)[2]
    std = res.std_zero_offsets_user
    return {
        "sign_convention": sign_convention(unit),
        "joints": list(robot.mechanism.joint_names),
        off_key: res.zero_offsets_user.tolist(),
        std_key: [float(s) if np.isfinite(s) else None for s in std],
    }


def result_json(robot, meas, res, report, source, accept_misfit=False) -> dict:
    """The results JSON: IdentificationResult.to_dict plus robot, data, compensation, identifiability."""
    from zerocal_sym.io.files import json_safe

    d = res.to_dict()
    keep = ("solver_status", "iterations", "cost", "chi2", "dof", "time_s", "weighting", "warm_start", "rank",
            "singular_values", "nonidentifiable", "truncation", "rule", "kappa", "filter_factors", "noise")
    d["info"] = {k: v for k, v in res.info.items() if k in keep}
    d["mechanism"] = robot.mechanism_name
    d["joint_names"] = list(robot.mechanism.joint_names)
    d["pose_names"] = list(robot.mechanism.pose_names)
    d["robot_sha256"] = robot.sha256
    d["robot"] = {"name": robot.name, "source": robot.source, "sha256": robot.sha256,
                  "mechanism": robot.mechanism_name}
    d["data"] = {"file": str(source), "K": int(meas.K), "data_robot_sha256": meas.meta.get("robot_sha256")}
    d["compensation"] = compensation_block(robot, res)
    d["identifiability"] = report
    d["accept_misfit"] = bool(accept_misfit)
    return json_safe(d)


def run(args):
    import contextlib
    import sys

    import numpy as np

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli._identify_text import (print_budget, print_choice, print_estimate, print_group_test,
                                                verdict_line)
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.identify.identifiability import format_report, identifiability_report
    from zerocal_sym.io.files import staged_directory, to_json, write_json
    from zerocal_sym.io.measurements import load_measurements
    from zerocal_sym.model.noise import NoiseModel

    robot = load_robot_arg(args)
    errors = robot.errors
    prior = maemm_prior_vector(robot, args.maemm_prior)
    meas = load_measurements(args.data, robot, allow_revisits=args.allow_revisits)  # refuses data of another mechanism or robot (robot_sha256)
    noise = NoiseModel.named(args.noise, robot)
    if args.loss not in (None, "l2") and noise.has_shared:
        raise ZerocalError(f"--loss {args.loss}: a robust loss does not take the robot file's shared revisit error "
                           f"([noise] revisit_std_mm = {noise.sigma_revisit_mm:g}): use --loss l2, or --noise "
                           "scale-only / servo-only")
    from zerocal_sym.identify.budget.bias import make_tolerances

    auto = args.params == "auto"
    try:  # the tolerances of the errors left out, checked before any work
        tol_params = errors.resolve("offsets+measuring" if args.method == "tsvd" else
                                    "paper" if auto else args.params)
    except ValueError:
        tol_params = None  # a bad --params is reported below, with its own message
    tol = (make_tolerances(robot, args.tolerance, args.tolerance_file, args.tolerance_scale, params=tol_params)
           if tol_params is not None else None)
    choice = None
    if args.method == "tsvd":
        if args.params != "paper" or args.prior_std or args.bound or args.max_iter is not None:
            raise ZerocalError("--params, --prior-std, --bound and --max-iter are for --method nlls "
                               "(tsvd identifies the zero offsets and the MAEMM)")
        names = errors.resolve("default")
        if args.truncation is not None and not 1 <= args.truncation <= len(names):
            raise ZerocalError(f"--truncation must be 1..{len(names)} (the parameters {', '.join(names)})")
        from zerocal_sym.identify.tsvd import identify_tsvd

        kw = {}
        if args.rule is not None:
            kw["rule"] = args.rule
        if args.iterate is not None:
            if args.iterate < 1:
                raise ZerocalError(f"--iterate must be >= 1, got {args.iterate}")
            kw["iterations"] = args.iterate
        res = identify_tsvd(robot, meas, prior=prior, t=args.truncation, noise=None if noise.is_zero else noise,
                            **kw, **trust_kwargs(args, "tsvd"))
    else:
        if args.truncation is not None or args.rule is not None or args.iterate is not None:
            raise ZerocalError("--truncation, --rule and --iterate are for --method tsvd")
        if auto:  # the set whose offsets' expected error at these poses is least
            from zerocal_sym.identify.budget.choose import choose_params

            choice = choose_params(robot, meas.theta_cmd, tol, noise if not noise.is_zero else None, "paper", prior)
            names = errors.resolve(choice["chosen"])
        else:
            try:
                names = errors.resolve(args.params)
            except ValueError as exc:
                raise ZerocalError(f"--params: {exc}") from None
        if meas.K - 1 < len(names):
            raise ZerocalError(f"{meas.K} poses give {meas.K - 1} measured changes: fewer than the {len(names)} "
                               f"parameters {', '.join(names)}", where=args.data)
        pstd = _parse_named(args.prior_std, robot, names, "--prior-std", float)
        if not pstd:  # a prior can make any set identifiable; without one, a set the poses cannot see is refused
            from zerocal_sym.cli._checks import identifiability_problem

            problem = identifiability_problem(robot, meas.theta_cmd, names, poses=f"the {meas.K} poses of the data")
            if problem:
                raise ZerocalError(f"--params {args.params}: {problem}", where=args.data)
        if any(v <= 0 for v in pstd.values()):
            raise ZerocalError("--prior-std must be positive")
        bounds = _parse_named(args.bound, robot, names, "--bound",
                              lambda v: tuple(float(x) for x in v.split(":", 1)) if ":" in v else
                              (_ for _ in ()).throw(ValueError(v)))
        if any(lo > hi for lo, hi in bounds.values()):
            raise ZerocalError("--bound: LO must not exceed HI")
        from zerocal_sym.identify.nlls import identify_nlls

        if args.max_iter is not None and args.max_iter < 1:
            raise ZerocalError("--max-iter must be >= 1")
        try:
            res = identify_nlls(robot, meas, names, noise=noise, prior=prior, bounds=bounds or None,
                                prior_std=pstd or None, max_iter=args.max_iter, **trust_kwargs(args, "nlls"))
        except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
            # linear algebra that failed on these data (a robust refit or a leave-one-out where the exact model is
            # not finite): a refusal naming the likely cause, never a traceback
            print(f"zerocal identify: identification failed ({args.method}): the data do not fit the model "
                  f"anywhere near (the linear algebra failed: {exc}); no calibration written", file=sys.stderr)
            print("Likely cause: rows shuffled, reversed, cumulative or dropped, or another robot's file.",
                  file=sys.stderr)
            if not args.json:
                print("verdict: rejected: the identification failed on these data; next: check the rows against "
                      "the poses you visited and the robot file, and identify again")
            return 1
    err0 = evaluation_point(robot, meas, res, prior)
    report = identifiability_report(robot, meas.theta_cmd, names, noise, err0=err0)
    out = result_json(robot, meas, res, report, args.data, args.accept_misfit)
    bias = _bias_report(robot, meas, res, tol, names, noise, err0, prior, args)
    out["bias"] = bias
    out.update(budget_entries(robot, res, bias, names, choice, args, meas, noise, prior, tol))
    if not res.success:
        if args.json:
            print(to_json(out))
        elif args.report:
            print(format_report(report))
        why = "rejected" if res.status.startswith("rejected") else "identification failed"
        print(f"zerocal identify: {why} ({res.method}): {res.status}; no calibration written", file=sys.stderr)
        if diagnosis(res):
            print(diagnosis(res), file=sys.stderr)
        test = out.get("robot_file_test")
        if test and not args.json:
            print_group_test(test)
        if not args.json:
            status = res.status.removeprefix("rejected: ")  # the status of a rejected fit starts so already
            said = f"; {test['summary']}" if test and test["contradicted"] else ""
            print(f"verdict: rejected: {status}{said}; next: see the diagnosis above, fix the data or the robot file "
                  "and identify again")
        return 1
    from zerocal_sym.identify.check.plausibility import plausibility

    reasons = plausibility(robot, res, max_offset=max_offset_arg(args, robot), max_maemm_mm=args.max_maemm_mm)
    if reasons:
        out["plausibility"] = reasons
        if args.json:
            print(to_json(out))
        print("zerocal identify: rejected: implausible result; no calibration written", file=sys.stderr)
        for r in reasons:
            print(f"  {r}", file=sys.stderr)
        if not args.json:
            print(f"verdict: rejected: {reasons[0]}; next: check the robot file, joint zeros and sign convention")
        return 1
    with staged_directory(args.plot) if args.plot else contextlib.nullcontext() as plot_dir:
        if args.plot:  # into a temporary directory, moved into place once everything is written
            from zerocal_sym.cli._common import truth_from_meta
            from zerocal_sym.report.plots import identify_plots

            identify_plots(plot_dir, res, meas, robot, err_true=truth_from_meta(meas, robot))
        if args.out:
            write_json(args.out, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    print(f"{args.data}: K = {meas.K} poses, robot {robot.name} ({robot.mechanism_name}), method {res.method}: "
          f"{res.status}")
    if choice:
        print_choice(choice)
    print_estimate(robot, res)
    print_budget(out)
    if out.get("robot_file_test"):
        print_group_test(out["robot_file_test"])
    info = res.info
    if res.method == "nlls":
        print(f"Ipopt: {info['solver_status']}, {info['iterations']} iterations, cost {info['cost']:.6g}, "
              f"chi2 {info['chi2']:.4g} on {info['dof']} dof; weights: {info['weighting']}")
    if "revisits" in info:
        from zerocal_sym.identify.estimate.revisits import describe

        print(describe(info["revisits"]))
    if args.report:
        print(format_report(report))
    if args.out:
        print(f"wrote {args.out}")
    print(verdict_line(res, args, out.get("remedy"), meas.K))
    return 0


def _bias_report(robot, meas, res, tol, names, noise, err0, prior, args) -> dict:
    """The bias the omitted errors' tolerances may put on this method's estimate: TSVD's own operator (at its last
    step's linearisation point, its truncation) or the weighted fit's sensitivity, linearised at the estimate
    (TSVD's less its linearisation bias), each offset's worst case searched on the exact model
    (:mod:`zerocal_sym.identify.budget.bias_exact`)."""
    import numpy as np

    from zerocal_sym.identify.budget import bias_exact
    from zerocal_sym.identify.budget.bias import tsvd_bias_operator

    errors = robot.errors
    if res.method == "tsvd":
        inc = np.asarray(res.info.get("increment", np.zeros(len(names))), float)
        lin = errors.put(prior, names, res.estimate - inc) if np.all(np.isfinite(inc)) else prior
        op = tsvd_bias_operator(robot, meas.theta_cmd, lin, t=res.info.get("truncation"))
        est = bias_exact.tsvd_estimator(robot, meas.theta_cmd, prior, t=res.info.get("truncation"),
                                        iterations=int(res.info.get("tsvd_iterations", 1)))
        b = np.asarray(res.info.get("linearisation_bias", np.full(len(names), np.nan)), float)
        if np.all(np.isfinite(b)):  # around the truth TSVD's estimate stands for: its estimate less its own bias
            err0 = errors.put(err0, names, res.estimate - b)
        return bias_exact.tolerance_bias_exact(robot, meas.theta_cmd, tol, names, noise, err0, est, operator=op,
                                               estimator_name="tsvd (its unweighted, truncated operator)")
    est = bias_exact.nlls_estimator(robot, meas.theta_cmd, names, noise, err0)
    return bias_exact.tolerance_bias_exact(robot, meas.theta_cmd, tol, names, noise, err0, est)


def budget_entries(robot, res, bias, names, choice, args, meas, noise, prior, tol) -> dict:
    """The results JSON's ``error_budget``, ``limited_by``, ``remedy``, and ``params_choice`` (``--params auto``)
    and ``robot_file_test`` (``--test-groups``, or an nlls fit rejected without a detected cause)."""
    from zerocal_sym.identify.budget import error_budget as bg

    b = bg.error_budget(bias, res)
    spec = choice["chosen"] if choice else ("paper" if res.method == "tsvd" else args.params)
    out = {"error_budget": b["error_budget"], "limited_by": b["limited_by"],
           "remedy": bg.remedy(b["error_budget"], robot, spec)}
    if choice:
        out["params_choice"] = choice
    fit = res.info.get("fit") or {}
    unexplained = (res.method == "nlls" and fit.get("rejected") and not any(c.get("detected") for c in
                                                                            fit.get("causes", []))
                   and (args.loss in (None, "l2")) and not args.bound and not args.prior_std)
    if getattr(args, "test_groups", False) or unexplained:
        from zerocal_sym.identify.budget.freeing import free_each_group
        from zerocal_sym.identify.nlls import identify_nlls

        out["robot_file_test"] = free_each_group(robot, meas, spec, noise=noise, prior=prior, alpha=args.fit_alpha,
                                                 tolerances=tol,
                                                 held=res if res.method == "nlls" and not args.bound
                                                 and not args.prior_std and args.loss in (None, "l2") else None,
                                                 identify=identify_nlls)
    from zerocal_sym.io.files import json_safe

    return json_safe(out)


def evaluation_point(robot, meas, res, prior):
    """Where the identifiability report and the bias are evaluated: the estimate, or the prior when the
    distance model is not finite at the estimate (a failed identification that ended where a pose is not an
    assembly of the robot: the report of these poses is then the one at the prior)."""
    import numpy as np

    from zerocal_sym.model import kinematics as kin

    err = res.full_vector()
    if not np.all(np.isfinite(err)):
        return prior
    with np.errstate(all="ignore"):
        rho, de, dt = kin.distance_jacobians(robot, meas.theta_cmd, err)
    return err if all(np.all(np.isfinite(a)) for a in (rho, de, dt)) else prior
