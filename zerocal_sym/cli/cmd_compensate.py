"""Turn an identification result into what a controller takes.

Sign convention: the actual joint angle is the commanded one plus the zero
offset, so the controller subtracts the identified offset:

    theta_cmd = IK(P) - offset

Outputs (CSV, written atomically to --out, or printed):

* no pose list: the compensation table ``joint,offset_deg,std_deg``;
* with ``--poses FILE.csv`` (``[pose,]x_mm,y_mm[,z_mm]``) or ``--scheme S --n N``
  (the robot's boundary scheme: ``paper`` on a rectangular workspace,
  ``ring`` on a cylinder): the compensated joint commands per pose
  (``pose,x_mm,y_mm[,z_mm],theta1_nominal_deg,...,theta1_cmd_deg,...``, one
  column per joint of the robot's mechanism);
* with ``--template`` as well: a measurement file to fill in (the format of
  ``zerocal identify``, ``reading_mm`` blank) with the compensated commands --
  the next measurement round, or without RESULT the first one.

Examples:

    zerocal compensate result.json --out compensation.csv
    zerocal compensate result.json --scheme paper --n 3 --out commands.csv
    zerocal compensate --scheme paper --n 3 --template --out round1.csv
    zerocal compensate result.json --robot examples/delta.toml --scheme ring --n 6 --template --out round2.csv
"""
NAME = "compensate"
HELP = "write the compensation table / compensated joint commands from a result"


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputFile

    p.add_argument("result", metavar="RESULT.json", nargs="?", default=None, type=InputFile("the results file"),
                   help="results file of 'zerocal identify --json' (omit for no compensation, with --template)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--poses", metavar="FILE.csv", default=None, type=InputFile("the pose file"),
                   help="target positions: CSV [pose,]x_mm,y_mm[,z_mm] or design JSON")
    g.add_argument("--scheme", choices=["paper", "ring"], default=None,
                   help="the robot's boundary scheme, 2n poses (paper: rectangle, ring: cylinder)")
    p.add_argument("--n", type=int, default=None,
                   help="poses per boundary for --scheme (default: 3 paper, 6 ring)")
    p.add_argument("--template", action="store_true",
                   help="write a measurement file to fill in (reading_mm blank) instead of a command table")
    p.add_argument("--max-offset-deg", type=float, default=10.0,
                   help="refuse offsets larger than this (default 10 deg: not a zero offset)")
    p.add_argument("--out", metavar="FILE.csv", default=None, type=OutputFile(), help="output file (default: print)")
    p.add_argument("--json", action="store_true", help="print a JSON summary")


def check_result_robot(res, robot, where):
    """A result identified on another robot (robot_sha256) is a DataFileError."""
    from zerocal_sym.errors import DataFileError

    if res.robot_sha256 and res.robot_sha256 != robot.sha256:
        raise DataFileError(f"identified on another robot (robot_sha256 {res.robot_sha256[:12]}..., "
                            f"{robot.sha256[:12]}... for {robot.source}): pass the same --robot as to identify",
                            where=where)


def run(args):
    import sys

    import numpy as np

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli._common import check_round_poses, scheme_poses
    from zerocal_sym.errors import DataFileError, ZerocalError
    from zerocal_sym.io.compensation import (SIGN_CONVENTION, compensated_commands, format_commands,
                                             format_compensation, format_offsets)
    from zerocal_sym.io.files import atomic_write_text, to_json
    from zerocal_sym.io.measurements import format_template
    from zerocal_sym.io.poses import load_poses
    from zerocal_sym.io.results import load_result

    robot = load_robot_arg(args)
    joints = robot.mechanism.joint_names
    has_poses = args.poses is not None or args.scheme is not None
    if args.result is None and not (args.template and has_poses):
        raise ZerocalError("give RESULT.json (or, for a first measurement round without compensation, "
                           "--template with --poses or --scheme)")
    if args.template and not has_poses:
        raise ZerocalError(f"--template needs the poses: --poses FILE.csv or --scheme "
                           f"{robot.workspace.scheme_name} --n N")
    if args.n is not None and args.scheme is None:
        raise ZerocalError("--n is the number of poses per boundary of --scheme")
    if args.result is not None:
        from zerocal_sym.identify.fitcheck import plausibility

        res = load_result(args.result, allow_failed=True, robot=robot)
        check_result_robot(res, robot, args.result)
        reasons = plausibility(robot, res, max_offset_deg=args.max_offset_deg)
        if reasons:  # not a calibration: refused (exit 1), nothing written
            print(f"zerocal compensate: refused {args.result}: {'; '.join(reasons)}", file=sys.stderr)
            return 1
        offsets = res.zero_offsets_deg
    else:
        res, offsets = None, np.zeros(robot.m)
    meta = {"robot_sha256": robot.sha256}
    if args.result is not None:
        meta["result"] = args.result
    if not has_poses:
        text, what, K = format_compensation(res, {"result": args.result}, mechanism=robot), "compensation table", 0
    else:
        if args.poses is not None:
            P, source = load_poses(args.poses, robot), args.poses
        else:
            P, n = scheme_poses(robot, args.scheme, args.n, identifiable=args.template)
            source = f"--scheme {args.scheme} --n {n}"
        nominal, cmd = compensated_commands(robot, P, offsets)
        K = len(P)
        if args.template:  # a round identify would refuse is refused now, not after the measurements
            check_round_poses(robot, P, cmd, source)
            meta["compensation_deg"] = format_offsets(offsets)
            text, what = format_template(cmd, P, meta, mechanism=robot), "measurement template"
        else:
            text, what = format_commands(P, nominal, cmd, offsets, meta, mechanism=robot), "compensated commands"
    if args.out:
        try:
            atomic_write_text(args.out, text)
        except OSError as exc:
            raise ZerocalError(f"cannot write the output: {exc.strerror or exc}", where=args.out) from None
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json({"zero_offsets_deg": [float(v) for v in offsets], "joints": list(joints),
                       "mechanism": robot.mechanism_name, "sign_convention": SIGN_CONVENTION,
                       "output": args.out, "kind": what, "poses": K}))
    elif args.out:
        print(f"wrote {what} ({K} poses) to {args.out}" if K else f"wrote {what} to {args.out}")
        print("offsets [deg]: " + ", ".join(f"{j} {v:+.6f}" for j, v in zip(joints, offsets))
              + f"; {SIGN_CONVENTION}")
    else:
        print(text, end="")
    return 0
