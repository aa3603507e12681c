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
and time per identification.  Errors are in Table 2's frame (as
``zerocal reproduce``).  A progress bar goes to stderr.

Examples:

    zerocal compare --trials 500
    zerocal compare --all --trials 100 --json
    zerocal compare --poses poses.csv --params paper --noise scale-only
"""
NAME = "compare"
HELP = "Monte Carlo of TSVD vs Ipopt (one-shot, in the loop) vs scipy on the same simulated data"


def add_arguments(p):
    p.add_argument("--trials", type=int, default=100, help="trials per group (default 100)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--group", type=int, default=1, help="Table 2 group 1..6 (default 1)")
    g.add_argument("--all", action="store_true", help="all six groups")
    p.add_argument("--poses", default="paper", metavar="paper|FILE.csv",
                   help="measurement poses: the paper's scheme (with --n) or a pose file [pose,]x_mm,y_mm")
    p.add_argument("--n", type=int, default=3, help="poses per boundary for --poses paper (default 3)")
    p.add_argument("--params", default="paper",
                   help="Ipopt parameter set: paper | all | names joined by , or + (e.g. paper+L1,L2)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="simulation noise and Ipopt weights (default paper)")
    p.add_argument("--methods", default=",".join(["tsvd-loop", "tsvd", "nlls", "nlls-loop", "nlls-seq", "scipy"]),
                   help="comma-separated subset of tsvd-loop,tsvd,nlls,nlls-loop,nlls-seq,scipy")
    p.add_argument("--frame", choices=["paper", "literal"], default="paper",
                   help="how Table 2 is read (default paper, as 'zerocal reproduce')")
    p.add_argument("--no-geometric", action="store_true",
                   help="leave Table 2's geometric errors out of the plant (the 4-parameter model is then exact)")
    p.add_argument("--mu0", type=float, default=0.1, help="loop threshold of mu, deg (default 0.1)")
    p.add_argument("--max-iter", type=int, default=20, help="identifications per loop (default 20)")
    p.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, help="also write the JSON here")


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.identify.montecarlo import Progress, format_compare
    from zerocal_sym.paper.compare import compare
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.io.files import to_json, write_json
    from zerocal_sym.model.noise import NoiseModel

    robot = load_robot_arg(args)
    if args.trials < 1:
        raise ZerocalError("--trials must be >= 1")
    groups = list(range(1, 7)) if args.all else [args.group]
    if any(g not in range(1, 7) for g in groups):
        raise ZerocalError(f"--group must be 1..6, got {args.group}")
    if args.poses == "paper":
        from zerocal_sym.paper.scheme import paper_poses

        poses = paper_poses(robot, args.n)
    else:
        from zerocal_sym.io.poses import load_poses

        poses = load_poses(args.poses, robot)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    try:
        params = robot.errors.resolve(args.params)
    except ValueError as exc:
        raise ZerocalError(f"--params: {exc}") from None
    total = args.trials * len(groups)
    bar = Progress(total, "compare", enabled=not args.quiet and total >= 5)
    rep = compare(robot, groups=groups, trials=args.trials, poses=poses, params=params,
                  noise=NoiseModel.named(args.noise), seed=args.seed, frame=args.frame, methods=methods,
                  mu0_deg=args.mu0, max_iter=args.max_iter, progress=bar,
                  geometric=not args.no_geometric)
    rep["settings"]["robot_sha256"] = robot.sha256
    if args.out:
        write_json(args.out, rep)
    print(to_json(rep) if args.json else format_compare(rep))
    return 0
