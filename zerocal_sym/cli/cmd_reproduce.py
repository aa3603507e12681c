"""Reproduce the paper's simulation study (Section 6, Tables 3-6, Figs. 8-9).

Runs Table 2's six groups through the whole calibration loop (simulate,
identify by TSVD, compensate, re-measure, ... ``--max-iter`` identifications;
the tables report the state at the first ``mu < mu0``, the mean condition
number is over all identifications as in the paper's Table 6) and prints
Tables 3, 4, 5 and 6 beside the paper's values.  ``--trials N``: mean ± std
over N seeds.  ``--out DIR``: ``fig8.png``, ``fig9.png`` and ``results.json``
(written to a temporary directory and moved into place when complete).

Table 2 is read in the paper's frame (ours mirrored about the x axis), which
reproduces Tables 3-4 "before"; see docs/reproduction.md for what reproduces
and what does not (the servo error of Eq. 35 dominates the attainable
accuracy).

It is the paper's study: on a robot of another mechanism (the rotary Delta)
it is an error -- run ``simulate``/``identify``/``compare --set`` there.
"""
NAME = "reproduce"
HELP = "run Table 2's six groups through the loop; Tables 3-6 and Figs. 8-9 vs the paper"
ROBOT_HELP = ("robot TOML file of the paper's planar 2-DOF mechanism, the one whose source errors Table 2 gives "
              "(default: the paper's robot, Table 1, as examples/paper_robot.toml)")


#: the files ``--out DIR`` writes into DIR
FILES = (("fig8.png", "fig9.png", "results.json") + tuple(f"fig12_group{g}.png" for g in range(1, 7))
         + tuple(f"convergence_group{g}.png" for g in range(1, 7)))


def add_arguments(p):
    from zerocal_sym.cli._paths import OutputDir

    p.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    p.add_argument("--trials", type=int, default=1, help="seeds per group; mean ± std (default 1)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model (default: paper, Eq. 34 + Eq. 35)")
    p.add_argument("--n", type=int, default=3, help="poses per boundary (default 3)")
    p.add_argument("--frame", choices=["paper", "literal"], default="paper",
                   help="how Table 2 is read (default: paper = mirrored about x)")
    p.add_argument("--mu0", type=float, default=0.1, help="stopping threshold of mu, deg (default 0.1)")
    p.add_argument("--max-iter", type=int, default=20, help="identifications per loop (default 20)")
    p.add_argument("--truncation", type=int, default=None, metavar="T",
                   help="fixed TSVD truncation level 1..4 (default: the --rule)")
    p.add_argument("--rule", choices=["threshold", "gcv", "discrepancy"], default="threshold",
                   help="automatic TSVD truncation rule (default threshold: keeps all 4)")
    p.add_argument("--out", metavar="DIR", default=None, type=OutputDir(FILES),
                   help="write fig8.png, fig9.png, results.json and, per group, fig12_group{g}.png "
                        "(position error on the 42 boundary positions before/after) and "
                        "convergence_group{g}.png here")
    p.add_argument("--json", action="store_true", help="print the results as JSON")


def _progress(total, stream=None):
    """``report(done, total)`` for :func:`reproduce`: a bar on a terminal; in a log or a pipe a line at each
    quarter (four at most)."""
    from zerocal_sym.identify.progress import Progress

    bar = Progress(total, "reproduce", stream=stream, unit="loop", every_pct=25)

    def report(done, _total):
        bar(done)

    return report


def _write_out(out_dir, rep, robot, n):
    """The figures and results.json into ``out_dir``, all or nothing (:func:`zerocal_sym.io.files.staged_directory`)."""
    from zerocal_sym.io.files import staged_directory, write_json
    from zerocal_sym.paper.figures import fig8, fig8_data, fig9, reproduce_plots

    with staged_directory(out_dir) as tmp:
        d8 = fig8_data(robot, range(3, 22))
        fig8(tmp / "fig8.png", d8)
        fig9(tmp / "fig9.png", rep["groups"], rep["settings"]["mu0_deg"])
        reproduce_plots(tmp, rep, robot)
        write_json(tmp / "results.json", dict(rep, fig8=d8))


def run(args):
    import functools

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.paper.reproduction import format_tables, reproduce
    from zerocal_sym.identify.tsvd import identify_tsvd

    from zerocal_sym.cli._common import require_paper_tables

    robot = load_robot_arg(args)
    require_paper_tables(robot, "reproduce", "run 'zerocal compare --set NAME=VALUE ...' (or simulate, identify, "
                                             "verify) on it instead")
    if args.trials < 1:
        raise ZerocalError(f"--trials must be >= 1, got {args.trials}")
    if args.max_iter < 2:
        raise ZerocalError(f"--max-iter must be >= 2 (mu needs two identifications), got {args.max_iter}")
    if not args.mu0 > 0:
        raise ZerocalError(f"--mu0 must be positive, got {args.mu0}")
    if args.truncation is not None and not 1 <= args.truncation <= 4:
        raise ZerocalError(f"--truncation must be 1..4, got {args.truncation}")
    identify = functools.partial(identify_tsvd, t=args.truncation, rule=args.rule,
                                 noise=NoiseModel.named(args.noise))
    identify.__name__ = f"identify_tsvd(t={args.truncation}, rule={args.rule})"
    total = 6 * args.trials
    progress = _progress(total) if total > 6 else None
    rep = reproduce(robot, seed=args.seed, trials=args.trials, noise=args.noise, n=args.n, frame=args.frame,
                    mu0_deg=args.mu0, max_iter=args.max_iter, identify=identify, progress=progress)
    if args.out:
        _write_out(args.out, rep, robot, args.n)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(rep))
    else:
        print(format_tables(rep))
        if args.out:
            print(f"wrote fig8.png, fig9.png, fig12_group*.png, convergence_group*.png, results.json "
                  f"to {args.out}")
    return 0
