"""Simulate one identification round of the paper's calibration.

A virtual robot with the source errors of Table 2's group G (read in the
paper's frame, i.e. ours mirrored about the x axis, unless ``--frame literal``;
see docs/reproduction.md) is commanded to the paper's 2n poses through the
nominal inverse kinematics minus the compensation, and the measuring
mechanism's scale readings are written in the measurement CSV format
(``zerocal_sym/io/measurements.py``), atomically.

``--compensation`` and the commanded angles in the file are in the robot's
frame (the frame of the robot file and of identification results).
"""
NAME = "simulate"
HELP = "simulate one identification round (Table 2 group) into a measurement CSV"


def add_arguments(p):
    p.add_argument("--group", type=int, required=True, help="Table 2 group, 1..6")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model (default: paper, Eq. 34 + Eq. 35)")
    p.add_argument("--n", type=int, default=3, help="poses per boundary (default 3, K = 2n)")
    p.add_argument("--compensation", nargs=2, type=float, metavar=("D1", "D2"), default=(0.0, 0.0),
                   help="compensation already applied, deg (robot frame): commanded = IK - compensation")
    p.add_argument("--frame", choices=["paper", "literal"], default="paper",
                   help="how Table 2 is read (default: paper = mirrored about x)")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="output measurement file")


def run(args):
    import numpy as np

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.io.measurements import write_measurements
    from zerocal_sym.errors import PoseError, ZerocalError
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.paper.tables import group_errors
    from zerocal_sym.paper.scheme import paper_poses

    robot = load_robot_arg(args)
    err = group_errors(args.group, args.frame)
    if args.n < 3:
        raise PoseError(f"--n {args.n} gives K = {2 * args.n} < 5 poses: too few to identify 4 parameters")
    comp = np.radians(np.asarray(args.compensation, float))
    if not np.all(np.isfinite(comp)):
        raise ZerocalError("--compensation must be finite numbers (deg)")
    poses = paper_poses(robot, args.n)
    rng = np.random.default_rng([args.seed, args.group])
    meas = simulate_round(robot, VirtualPlant(robot, err), poses, comp, NoiseModel.named(args.noise), rng)
    if not np.all(np.isfinite(meas.readings)):
        raise PoseError("the compensated commands leave the robot's assembly (reading is not finite)")
    fmt = lambda v: " ".join(f"{x:.10g}" for x in v)  # noqa: E731
    meas.meta = {
        "generator": "zerocal simulate",
        "robot": robot.name,
        "robot_sha256": robot.sha256,
        "group": args.group,
        "frame": args.frame,
        "seed": args.seed,
        "noise": args.noise,
        "n": args.n,
        "compensation_deg": fmt(args.compensation),
        "true_zero_offsets_deg": fmt(np.degrees(err[:2])),
        "true_maemm_mm": fmt(err[10:12]),
    }
    write_measurements(args.out, meas)
    print(f"wrote {meas.K} poses of group {args.group} (noise {args.noise}, seed {args.seed}, Table 2 in the "
          f"{args.frame} frame: true offsets {fmt(np.degrees(err[:2]))} deg in the robot frame) to {args.out}")
    return 0
