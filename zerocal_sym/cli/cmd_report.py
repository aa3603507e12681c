"""The calibration report: one self-contained HTML page of a result (no network: figures inline).

The page shows the verdict (as ``identify`` judges it: the fit check, the
plausibility limits, the offsets' 1 sigma against ``--goal`` or the offsets'
scale), the zero offsets with their 1 sigma in the joints' unit (deg or mm),
the error budget when the result file holds one, the fit check with the
worst reading named, the residuals, the robot with its poses in the
workspace, and the position error predicted over the workspace before and
after the compensation with its uncertainty (from the offsets' covariance).
``--data`` (the measurement file the result was identified from: checked,
its residuals at the result's estimate must be the result's) adds the poses
and the nominal model's residuals.

The result, the data and the robot file must be of one robot: a result and
a data file whose ``robot_sha256`` differ are refused, and so is a result of
another robot than ``--robot``'s (default: the paper's robot).  A rejected
result gets a page that says so, without its offsets or accuracy.

Examples:

    zerocal report result1.json --robot my_robot.toml --data round1.csv --out report.html
    zerocal report d.json --robot examples/delta.toml --out report.html
"""
NAME = "report"
HELP = "write the calibration report of a result: one self-contained HTML page"


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputFile

    p.add_argument("result", metavar="RESULT.json", type=InputFile("the results file"),
                   help="results file of 'zerocal identify --out' (or verify)")
    p.add_argument("--data", metavar="DATA.csv", default=None, type=InputFile("the measurement file"),
                   help="the measurement file the result was identified from: the poses and the nominal model's "
                        "residuals")
    p.add_argument("--out", metavar="FILE.html", required=True, type=OutputFile(), help="the page to write")
    p.add_argument("--goal", type=float, default=None, metavar="X",
                   help="the accuracy you need, in the joints' unit (deg or mm): the verdict judges the offsets' "
                        "1 sigma against it (default: against 0.1 x the largest |offset|)")
    p.add_argument("--max-offset", type=float, default=None, metavar="X",
                   help="a zero offset beyond this is implausible, in the joints' unit (default 10 deg or 10 mm)")


def verdict(robot, rf, goal=None, max_offset=None) -> tuple:
    """``(text, accepted)``: the verdict of a results file, worded as ``identify``'s verdict line."""
    from types import SimpleNamespace

    from zerocal_sym.cli._identify_text import accepted_why, offsets_sigma_text
    from zerocal_sym.identify.fitcheck import DEFAULT_ALPHA
    from zerocal_sym.identify.check.plausibility import plausibility

    from zerocal_sym.report.contents import fit_record

    fit = fit_record(rf) or {}
    if not rf.success:
        return f"rejected: {rf.status.removeprefix('rejected: ') or 'the identification failed'}", False
    reasons = plausibility(robot, rf, max_offset=max_offset)
    if reasons:
        return f"rejected: {'; '.join(reasons)}", False
    view = SimpleNamespace(zero_offsets_user=rf.zero_offsets_user, std_zero_offsets_user=rf.std_zero_offsets_user,
                           std_kind=rf.raw.get("std_kind"), offset_unit=rf.offset_unit)
    return f"{accepted_why(fit, DEFAULT_ALPHA)}; {offsets_sigma_text(view, goal)}", True


def check_same_robot(rf, result_path, data_path) -> None:
    """A result and a data file of different robots (their ``robot_sha256``): a DataFileError naming both."""
    from zerocal_sym.errors import DataFileError
    from zerocal_sym.io.measurements import read_metadata

    data_sha = (read_metadata(data_path).get("robot_sha256") or "").lower()
    if rf.robot_sha256 and data_sha and data_sha != rf.robot_sha256:
        raise DataFileError(f"the result {result_path} is of robot {rf.robot_sha256[:12]}..., the data {data_path} of "
                            f"robot {data_sha[:12]}... (robot_sha256): a report is of one robot's result and data",
                            where=data_path)


def run(args):
    from zerocal_sym.cli import load_robot_arg, version
    from zerocal_sym.cli.cmd_compensate import check_result_robot
    from zerocal_sym.cli.cmd_identify import max_offset_arg
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.io.files import atomic_write_text
    from zerocal_sym.io.measurements import load_measurements
    from zerocal_sym.io.results import load_result
    from zerocal_sym.report import figures, html
    from zerocal_sym.report.contents import report_contents

    robot = load_robot_arg(args)
    rf = load_result(args.result, allow_failed=True, robot=robot)
    if args.data is not None:
        check_same_robot(rf, args.result, args.data)
    check_result_robot(rf, robot, args.result)
    meas = load_measurements(args.data, robot) if args.data is not None else None
    text, accepted = verdict(robot, rf, args.goal, max_offset_arg(args, robot))
    c = report_contents(robot, rf, meas, verdict=f"{text}", accepted=accepted)
    pose_rows = None if c["poses"] is None else figures.pose_table(robot, c["poses"])
    page = html.render(c, html.figures_of(robot, c), pose_rows, version())
    try:
        atomic_write_text(args.out, page)
    except OSError as exc:
        raise ZerocalError(f"cannot write the report: {exc.strerror or exc}", where=args.out) from None
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()
    print(f"wrote {args.out}: verdict: {text}")
    return 0
