"""Simulate one identification round of the calibration (any mechanism).

A virtual robot with the given true source errors is commanded to the
measurement poses through the nominal inverse kinematics minus the
compensation, and the measuring mechanism's scale readings are written in
the measurement CSV format of the robot's mechanism
(``zerocal_sym/io/measurements.py``: ``theta1_deg, ..., reading_mm, x_mm,
...``), atomically.

True errors (exactly one of):

* ``--set NAME=VALUE`` (repeatable): source errors by name, in the robot's
  frame, degrees for angles and mm otherwise, the others zero; the names are
  the robot mechanism's source errors (an unknown name is an error that
  lists them), e.g.
  ``--set theta1=2 --set theta2=-1 --set theta3=0.5 --set rMz=0.3``;
* ``--group G``: Table 2's group G of the paper (its planar robot only),
  read in the paper's frame, i.e. ours mirrored about the x axis, unless
  ``--frame literal`` (docs/reproduction.md).

``--group`` and ``--set`` are mutually exclusive: Table 2 is read in the
paper's frame, ``--set`` in the robot's; to change one value of a group, give
the group's values by ``--set`` (the file's ``# true_errors:`` line lists
them).

Poses: the robot's boundary scheme (``--scheme``, default the robot's own:
the paper's on a rectangular workspace, the ring scheme on a cylinder) with
``--n`` poses per boundary (default 3 for the paper's scheme, 6 for the
ring), or ``--poses FILE`` (a pose list, ``[pose,]x_mm,y_mm[,z_mm]``, or the
JSON of ``zerocal design``).

``--compensation`` (one value per joint in the joints' unit: deg for
revolute, mm for prismatic joints) and the commanded joints in
the file are in the robot's frame (the frame of the robot file and of
identification results).

Examples:

    zerocal simulate --group 1 --out d.csv
    zerocal simulate --robot examples/delta.toml --scheme ring --n 6 \\
        --set theta1=2 --set theta2=-1 --set theta3=0.5 --noise none --out d.csv
"""
NAME = "simulate"
HELP = "simulate one identification round (true errors by --set, or a Table 2 group) into a measurement CSV"


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputFile

    truth = p.add_mutually_exclusive_group(required=True)
    truth.add_argument("--set", action="append", default=None, metavar="NAME=VALUE",
                       help="a true source error (robot frame; deg for angles, mm otherwise), repeatable; "
                            "not with --group")
    truth.add_argument("--group", type=int, default=None,
                       help="Table 2 group 1..6 (the paper's planar robot only); not with --set")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model (default: paper, Eq. 34 + Eq. 35)")
    poses = p.add_mutually_exclusive_group()
    poses.add_argument("--scheme", choices=["paper", "ring", "corners"], default=None,
                       help="pose scheme (default: the robot's: paper on a rectangle, ring on a cylinder)")
    poses.add_argument("--poses", metavar="FILE", default=None, type=InputFile("the pose file"),
                       help="pose list instead of a scheme: CSV [pose,]x_mm,y_mm[,z_mm] or design JSON")
    p.add_argument("--n", type=int, default=None,
                   help="the scheme's size: poses per boundary, K = 2n (default: 3 paper, 6 ring), or the corners, K = n "
                        "(16, 32 or 64; default 64)")
    p.add_argument("--compensation", nargs="+", type=float, metavar="X", default=None,
                   help="compensation already applied, one value per joint in the joints' unit (deg for revolute, "
                        "mm for prismatic joints; robot frame): commanded = IK - compensation")
    p.add_argument("--frame", choices=["paper", "literal"], default=None,
                   help="how Table 2 is read with --group (default: paper = mirrored about x)")
    p.add_argument("--out", required=True, metavar="FILE.csv", type=OutputFile(), help="output measurement file")
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "the pose file (--poses)")


def true_errors(args, robot):
    """(vector, description, meta) of the true source errors from ``--set`` or ``--group``."""
    from zerocal_sym.cli._common import parse_named_values, require_paper_tables
    from zerocal_sym.errors import ZerocalError

    if args.group is not None:
        from zerocal_sym.paper.tables import group_errors

        require_paper_tables(robot, "--group")
        frame = args.frame or "paper"
        err = group_errors(args.group, frame)
        return err, f"Table 2 group {args.group} in the {frame} frame", {"group": args.group, "frame": frame}
    if args.frame is not None:
        raise ZerocalError("--frame is how Table 2 is read: it goes with --group, not --set")
    values = parse_named_values(args.set, robot, "--set")
    return robot.errors.from_user(values), "set by --set", {"set": " ".join(args.set)}


def run(args):
    import numpy as np

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli._common import fmt_values, format_named, revisits_meta, scheme_poses, vector_arg
    from zerocal_sym.errors import PoseError
    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.io.compensation import format_offsets
    from zerocal_sym.io.measurements import write_measurements
    from zerocal_sym.model import units
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant

    robot = load_robot_arg(args)
    errors = robot.errors
    err, what, meta_truth = true_errors(args, robot)
    joints = robot.mechanism.joint_names
    ju = units.joint_unit(robot)
    comp_user = np.zeros(robot.m) if args.compensation is None else vector_arg(
        args.compensation, robot.m, "--compensation", joints, ju)
    if args.poses is not None:
        if args.n is not None:
            from zerocal_sym.errors import ZerocalError

            raise ZerocalError("--n is the number of poses per boundary of a scheme: not with --poses")
        from zerocal_sym.io.poses import load_design_poses

        poses, region = load_design_poses(args.poses, robot, args.allow_revisits, measured=True)
        pose_what = str(args.poses)
    else:
        poses, n = scheme_poses(robot, args.scheme, args.n)
        region = None
        pose_what = f"{robot.workspace.scheme_name} scheme, n = {n}"
    rng = np.random.default_rng([args.seed, args.group] if args.group is not None else [args.seed])
    meas = simulate_round(robot, VirtualPlant(robot, err), poses, units.joints_from_user(robot, comp_user),
                          NoiseModel.named(args.noise, robot), rng)
    bad = np.flatnonzero(~np.isfinite(meas.readings))
    if bad.size:  # the true robot does not assemble at these commands (or its forward kinematics do not converge)
        from zerocal_sym.model.kinematics import fmt_pose, fmt_user_pose

        k = int(bad[0])
        raise PoseError(f"pose {k} {fmt_user_pose(robot, poses[k])}: with these true errors the commanded "
                        f"{units.joint_noun(robot)} {fmt_pose(units.joints_to_user(robot, meas.theta_cmd[k]))} {ju} "
                        "are not an assembly of the robot (its forward kinematics find no pose: a limb cannot "
                        f"close, or the solve does not converge); {bad.size} of {meas.K} poses: errors this large "
                        "are not a calibration's")
    offsets_user = units.joints_to_user(robot, errors.take(err, errors.zero_offsets))
    maemm = errors.take(err, errors.measuring)
    meas.meta = {
        "generator": "zerocal simulate",
        "robot": robot.name,
        "robot_sha256": robot.sha256,
        **meta_truth,
        "seed": args.seed,
        "noise": args.noise,
        "poses": pose_what,
        units.joint_key(robot, "compensation"):
            format_offsets(comp_user) if args.compensation is not None else fmt_values(comp_user),
        units.joint_key(robot, "true_zero_offsets"): fmt_values(offsets_user),
        "true_maemm_mm": fmt_values(maemm),
        "true_errors": format_named(robot, err).replace(" deg", "").replace(" mm", ""),
        **revisits_meta(poses),  # the poses revisit on purpose (they were read so): the file says it
        **(region or {}),  # poses of a design's own region, outside the workspace: the region travels with them
    }
    if args.group is not None:
        meas.meta["n"] = len(poses) // 2
    write_measurements(args.out, meas, mechanism=robot)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    print(f"wrote {meas.K} poses ({pose_what}; noise {args.noise}, seed {args.seed}) to {args.out}; true errors "
          f"{what}: {format_named(robot, err)} (robot frame)")
    return 0
