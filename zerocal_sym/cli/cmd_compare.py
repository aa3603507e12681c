"""Monte Carlo comparison: TSVD (the paper's loop) against Ipopt on the same data.

Per trial the first measurement round is simulated once and every method
sees it: TSVD in the paper's compensation loop (``tsvd-loop``) and its first
identification alone (``tsvd``), Ipopt one-shot (``nlls``), Ipopt in the same
loop (``nlls-loop``), Ipopt in the loop with sequential MAP (``nlls-seq``),
and scipy's least_squares on the identical whitened problem (``scipy``,
reference for the answer and the speed; needs scipy).

Per method: bias and RMS error of each zero offset (deg) and of the MAEMM
(mm), RMS/CRLB, the home position error dp0 after compensating with the
estimate, failures, loops that did not converge, identifications per trial
and time per identification.  A progress bar goes to stderr.

True errors (one of; any mechanism with ``--set``):

* ``--set NAME=VALUE`` (repeatable): source errors by name in the robot's
  frame, degrees for angles, mm otherwise, the others zero; errors reported
  in the robot's frame;
* ``--group G`` / ``--all``: Table 2's group(s) of the paper (its planar
  robot only), read in ``--frame``; errors reported in Table 2's frame (as
  ``zerocal reproduce``).  The default on the paper's robot is ``--group 1``.

Poses: ``--poses`` the robot's boundary scheme (default; ``paper`` on a
rectangle, ``ring`` on a cylinder) with ``--n``, or a pose file.

Examples:

    zerocal compare --trials 500
    zerocal compare --all --trials 100 --json
    zerocal compare --poses poses.csv --params paper --noise scale-only
    zerocal compare --robot examples/delta.toml --set theta1=2 --set theta2=-1 --set theta3=0.5 --trials 20
    zerocal compare --trials 10000 --workers 2          # local processes; same numbers as --workers 1
    zerocal compare --trials 100000 --scheduler tcp://host:8786   # a Dask cluster (docs/montecarlo.md)
"""
NAME = "compare"
HELP = "Monte Carlo of TSVD vs Ipopt (one-shot, in the loop) vs scipy on the same simulated data"


def add_arguments(p):
    from zerocal_sym.cli._common import scheme_names
    from zerocal_sym.cli._paths import InputFile, OutputFile

    p.add_argument("--trials", type=int, default=100, help="trials per group (default 100)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--set", action="append", default=None, metavar="NAME=VALUE",
                   help="a true source error (robot frame; deg for angles, mm otherwise), repeatable; "
                        "not with --group/--all")
    g.add_argument("--group", type=int, default=None,
                   help="Table 2 group 1..6 (the paper's robot only; its default: 1)")
    g.add_argument("--all", action="store_true", help="all six groups of Table 2 (the paper's robot only)")
    p.add_argument("--poses", default=None, metavar="paper|ring|corners|FILE", type=InputFile("the pose file", not_files=scheme_names),
                   help="measurement poses: the robot's scheme (default; with --n) or a pose file "
                        "[pose,]x_mm,y_mm[,z_mm]")
    p.add_argument("--n", type=int, default=None, help="poses per boundary of the scheme (default: 3 paper, 6 ring)")
    p.add_argument("--params", default="paper",
                   help="Ipopt parameter set: paper | all | names joined by , or + (e.g. paper+L1,L2)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="simulation noise and Ipopt weights (default paper)")
    p.add_argument("--methods", default=",".join(["tsvd-loop", "tsvd", "nlls", "nlls-loop", "nlls-seq", "scipy"]),
                   help="comma-separated subset of tsvd-loop,tsvd,nlls,nlls-loop,nlls-seq,scipy")
    p.add_argument("--frame", choices=["paper", "literal"], default=None,
                   help="how Table 2 is read with --group/--all (default paper, as 'zerocal reproduce')")
    p.add_argument("--no-geometric", action="store_true",
                   help="leave Table 2's geometric errors out of the plant (with --group/--all: the "
                        "4-parameter model is then exact)")
    p.add_argument("--mu0", type=float, default=None,
                   help="loop threshold of mu, in the joints' unit (default: verify's, 0.1 deg for revolute and "
                        "0.02 mm for prismatic joints)")
    p.add_argument("--max-iter", type=int, default=20, help="identifications per loop (default 20)")
    p.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    from zerocal_sym.cli import _parallel

    _parallel.add_arguments(p)
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "the pose file (--poses)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, type=OutputFile(), help="also write the JSON here")


def run(args):
    from zerocal_sym.cli import _parallel, load_robot_arg
    from zerocal_sym.cli._checks import PARAM_METHODS
    from zerocal_sym.cli._common import (has_paper_tables, parse_named_values, poses_arg, require_paper_tables,
                                         scheme_names)
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.identify.montecarlo import format_compare
    from zerocal_sym.io.files import to_json, write_json
    from zerocal_sym.cli.cmd_verify import MU0_DEFAULT
    from zerocal_sym.model import units
    from zerocal_sym.model.noise import NoiseModel

    robot = load_robot_arg(args)
    if args.trials < 1:
        raise ZerocalError("--trials must be >= 1")
    use_table2 = args.set is None
    if use_table2:
        if args.group is None and not args.all and not has_paper_tables(robot):
            raise ZerocalError(f"give the true errors by --set NAME=VALUE (repeatable; robot {robot.name!r} has "
                               f"the source errors {', '.join(robot.errors.names)})")
        require_paper_tables(robot, "--group/--all")
        groups = list(range(1, 7)) if args.all else [1 if args.group is None else args.group]
        if any(g not in range(1, 7) for g in groups):
            raise ZerocalError(f"--group must be 1..6, got {args.group}")
    else:
        if args.frame is not None or args.no_geometric:
            raise ZerocalError("--frame and --no-geometric are for Table 2 (--group/--all), not --set")
        truth = robot.errors.from_user(parse_named_values(args.set, robot, "--set"))
    if args.n is not None and args.poses is not None and args.poses not in scheme_names():
        raise ZerocalError("--n is the number of poses per boundary of a scheme: not with a pose file")
    poses, _ = poses_arg(robot, args.poses, args.n, allow_revisits=args.allow_revisits)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    try:
        params = robot.errors.resolve(args.params)
    except ValueError as exc:
        raise ZerocalError(f"--params: {exc}") from None
    if any(m in PARAM_METHODS for m in methods):  # before any work: Ipopt would fail every trial
        from zerocal_sym.cli._checks import identifiability_problem
        from zerocal_sym.model import kinematics as kin

        of = (f" of --poses {args.poses}" if args.poses not in (None, *scheme_names())
              else f" of --n {args.n}" if args.n is not None else "")
        problem = identifiability_problem(robot, kin.check_poses(robot, poses), params,
                                          poses=f"the {len(poses)} poses{of}")
        if problem:
            raise ZerocalError(f"--params {args.params}: {problem}")
    noise = NoiseModel.named(args.noise, robot)
    ex = _parallel.execution(args)  # checked (and a scheduler reached) before any work
    common = dict(trials=args.trials, poses=poses, params=params, noise=noise, seed=args.seed, methods=methods,
                  mu0_deg=MU0_DEFAULT[units.joint_unit(robot)] if args.mu0 is None else args.mu0,
                  max_iter=args.max_iter, **ex)
    try:
        rep = _run(args, robot, use_table2, groups if use_table2 else None, None if use_table2 else truth, common)
    finally:
        _parallel.close(ex)
    rep["settings"]["robot_sha256"] = robot.sha256
    rep["settings"]["mechanism"] = robot.mechanism_name
    if args.out:
        write_json(args.out, rep)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    print(to_json(rep) if args.json else format_compare(rep))
    return 0


def _run(args, robot, use_table2, groups, truth, common):
    from zerocal_sym.identify import montecarlo
    from zerocal_sym.identify.montecarlo import Progress

    if use_table2:
        from zerocal_sym.paper.compare import compare

        bar = Progress(args.trials * len(groups), "compare", enabled=not args.quiet and args.trials * len(groups) >= 5)
        try:
            return compare(robot, groups=groups, frame=args.frame or "paper", progress=bar,
                           geometric=not args.no_geometric, **common)
        finally:
            bar.close()
    else:
        bar = Progress(args.trials, "compare", enabled=not args.quiet and args.trials >= 5)
        try:
            return montecarlo.compare(robot, {"set": truth}, progress=bar,
                                      settings={"truth": robot.errors.to_dict(truth, user=True),
                                                "truth_units": {e.name: e.user_unit for e in robot.errors},
                                                "error_frame": "the robot's"}, **common)
        finally:
            bar.close()
