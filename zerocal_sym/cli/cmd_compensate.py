"""Turn an identification result into what a controller takes.

Sign convention: the actual joint angle is the commanded one plus the zero
offset, so the controller subtracts the identified offset:

    theta_cmd = IK(P) - offset

Outputs (written atomically to --out, or printed):

* no pose list: the compensation table ``joint,offset_deg,std_deg``;
* with ``--poses FILE.csv`` (``[pose,]x_mm,y_mm[,z_mm]``) or ``--scheme S --n N``
  (the robot's boundary scheme: ``paper`` on a rectangular workspace,
  ``ring`` on a cylinder): the compensated joint commands per pose
  (``pose,x_mm,y_mm[,z_mm],theta1_nominal_deg,...,theta1_cmd_deg,...``, one
  column per joint of the robot's mechanism);
* with ``--template`` as well: a measurement file to fill in (the format of
  ``zerocal identify``, ``reading_mm`` blank) with the compensated commands --
  the next measurement round, or without RESULT the first one;
* ``--format klipper`` / ``--format rrf`` (a linear Delta): the controller's
  configuration instead of the table -- Klipper's ``[printer]`` and
  ``[stepper_a]``..``[stepper_c]`` values, or RepRapFirmware's ``M665`` and
  ``M666`` lines -- with the endstops corrected by the offsets
  (``position_endstop`` / the ``M666`` adjustment + offset; towers matched
  to the controller's by their azimuth).  ``--endstop-mm`` gives the
  controller's current values (Klipper's ``position_endstop``, RRF's ``M666``
  adjustments; one, or three in the controller's tower order a,b,c / X,Y,Z);
  without them the corrections are written as comments.

Examples:

    zerocal compensate result.json --out compensation.csv
    zerocal compensate result.json --scheme paper --n 3 --out commands.csv
    zerocal compensate --scheme paper --n 3 --template --out round1.csv
    zerocal compensate result.json --robot examples/delta.toml --scheme ring --n 6 --template --out round2.csv
    zerocal compensate result.json --robot examples/linear_delta.toml --format klipper --endstop-mm 300
    zerocal compensate result.json --robot examples/linear_delta.toml --format rrf --endstop-mm 0,0,0
"""
NAME = "compensate"
HELP = "write the compensation table / compensated joint commands / a delta controller's configuration from a result"


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputFile

    p.add_argument("result", metavar="RESULT.json", nargs="?", default=None, type=InputFile("the results file"),
                   help="results file of 'zerocal identify --json' (omit for no compensation, with --template)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--poses", metavar="FILE.csv", default=None, type=InputFile("the pose file"),
                   help="target positions: CSV [pose,]x_mm,y_mm[,z_mm] or design JSON")
    g.add_argument("--scheme", choices=["paper", "ring", "corners"], default=None,
                   help="the robot's boundary scheme (paper: rectangle, ring: cylinder, 2n poses; corners: 6-D box, n)")
    p.add_argument("--n", type=int, default=None,
                   help="the size of --scheme: poses per boundary (default: 3 paper, 6 ring) or corners (16, 32, 64; default 64)")
    p.add_argument("--template", action="store_true",
                   help="write a measurement file to fill in (reading_mm blank) instead of a command table")
    p.add_argument("--max-offset", type=float, default=None, metavar="X",
                   help="refuse offsets larger than this, in the joints' unit: deg for revolute, mm for prismatic "
                        "joints (default 10 deg or 10 mm: not a zero offset)")
    p.add_argument("--max-offset-deg", type=float, default=None, metavar="DEG",
                   help="the same for revolute joints, in deg (the former spelling)")
    p.add_argument("--format", choices=["csv", "klipper", "rrf"], default="csv",
                   help="csv: the compensation table (any mechanism, the default); klipper / rrf: a linear delta's "
                        "controller configuration with the endstops corrected")
    p.add_argument("--endstop-mm", metavar="V[,V,V]", default=None,
                   help="klipper / rrf: the controller's current endstop values, mm (Klipper: position_endstop of "
                        "stepper_a,b,c; RRF: the M666 X,Y,Z adjustments): one, or three in that order "
                        "(default: the corrections as comments)")
    p.add_argument("--homed-height-mm", type=float, default=None, metavar="H",
                   help="rrf: the M665 H (homed height, mm) to write (default: left out, RRF keeps its own)")
    p.add_argument("--out", metavar="FILE", default=None, type=OutputFile(), help="output file (default: print)")
    p.add_argument("--json", action="store_true", help="print a JSON summary")
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "the pose file (--poses)")


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
    from zerocal_sym.cli._common import check_round_poses, revisits_meta, scheme_poses
    from zerocal_sym.errors import DataFileError, ZerocalError
    from zerocal_sym.io.compensation import compensated_commands, format_commands, format_compensation, format_offsets
    from zerocal_sym.io.results import sign_convention
    from zerocal_sym.model import units
    from zerocal_sym.io.files import atomic_write_text, to_json
    from zerocal_sym.io.measurements import format_template
    from zerocal_sym.io.poses import load_design_poses
    from zerocal_sym.io.results import load_result

    robot = load_robot_arg(args)
    joints = robot.mechanism.joint_names
    if args.format != "csv":  # a mechanism or robot the format cannot describe: refused before any work
        from zerocal_sym.io.controllers import describe

        describe(args.format, robot)
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
        from zerocal_sym.cli.cmd_identify import max_offset_arg
        from zerocal_sym.identify.check.plausibility import plausibility

        res = load_result(args.result, allow_failed=True, robot=robot)
        check_result_robot(res, robot, args.result)
        reasons = plausibility(robot, res, max_offset=max_offset_arg(args, robot))
        if reasons:  # not a calibration: refused (exit 1), nothing written
            print(f"zerocal compensate: refused {args.result}: {'; '.join(reasons)}", file=sys.stderr)
            return 1
        offsets = res.zero_offsets_user
    else:
        res, offsets = None, np.zeros(robot.m)
    meta = {"robot_sha256": robot.sha256}
    if args.result is not None:
        meta["result"] = args.result
    if args.format != "csv":
        from zerocal_sym.io.controllers import FORMATS, format_controller, parse_endstops

        endstops = None if args.endstop_mm is None else parse_endstops(args.endstop_mm, args.format)
        text = format_controller(args.format, robot, res, endstops, args.homed_height_mm, {"result": args.result})
        what, K = f"{FORMATS[args.format].title} configuration", 0
    elif not has_poses:
        text, what, K = format_compensation(res, {"result": args.result}, mechanism=robot), "compensation table", 0
    else:
        if args.poses is not None:
            (P, region), source = load_design_poses(args.poses, robot, args.allow_revisits, measured=args.template), \
                args.poses
        else:
            P, n = scheme_poses(robot, args.scheme, args.n, identifiable=args.template)
            source, region = f"--scheme {args.scheme} --n {n}", None
        nominal, cmd = compensated_commands(robot, P, offsets)
        K = len(P)
        if args.template:  # a round identify would refuse is refused now, not after the measurements
            check_round_poses(robot, P, cmd, source, allow_revisits=True,  # (the pose file's revisits: read so)
                              region=region)
            meta[units.joint_key(robot, "compensation")] = format_offsets(offsets)
            meta.update(revisits_meta(P))  # the template says its revisits are intended
            meta.update(region or {})  # a design's own region travels with its poses
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
        print(to_json({units.joint_key(robot, "zero_offsets"): [float(v) for v in offsets], "joints": list(joints),
                       "mechanism": robot.mechanism_name, "sign_convention": sign_convention(units.joint_unit(robot)),
                       "output": args.out, "kind": what, "format": args.format, "poses": K}))
    elif args.out:
        print(f"wrote {what} ({K} poses) to {args.out}" if K else f"wrote {what} to {args.out}")
        print(f"offsets [{units.joint_unit(robot)}]: " + ", ".join(f"{j} {v:+.6f}" for j, v in zip(joints, offsets))
              + f"; {sign_convention(units.joint_unit(robot))}")
    else:
        print(text, end="")
    return 0
