"""Verify a compensation by re-identification (the paper's stopping rule).

Measure again with the compensation applied (commands ``IK(P) - offset``:
``zerocal compensate RESULT.json --scheme paper --template`` gives the sheet
(``--scheme ring`` on a cylindrical workspace); ``zerocal simulate
--compensation D1 D2 [D3]`` simulates it), then

    zerocal verify RESULT.json ROUND2.csv [--out RESULT2.json]

identifies the offsets again, linearised at the applied compensation and
MAEMM estimate (paper Eq. 30), and compares: the remaining offset is
``new - applied`` and the compensation accuracy
``mu = sqrt(((new1 - applied1)^2 + ... + (newm - appliedm)^2) / m)`` over
the m joints (the paper's with m = 2).  Exit status
0 if ``mu < mu0`` (default 0.1 deg, the paper's), 1 if not: then apply the
new result (``--out``, a results file like identify's) and verify again.

Re-identification checks repeatability: a bias common to both rounds (e.g.
from geometric errors outside the 4-parameter model) is not seen; an external
position measurement (laser tracker) is the independent check.
"""
NAME = "verify"
HELP = "re-identify with the compensation applied; pass if the remaining offset mu < mu0"


#: the files ``--plot DIR`` writes into DIR
PLOTS = ("residuals.png",)


def add_arguments(p):
    from zerocal_sym.cli._paths import InputFile, OutputDir, OutputFile

    p.add_argument("result", metavar="RESULT.json", type=InputFile("the results file"), help="the applied result (zerocal identify --json / verify --out)")
    p.add_argument("data", metavar="DATA.csv", type=InputFile("the measurement file"), help="measurements taken with that compensation applied")
    p.add_argument("--method", choices=["tsvd", "nlls"], default="tsvd", help="identification method (default tsvd)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only", "none"], default="paper",
                   help="noise model for weights and covariance (default paper)")
    p.add_argument("--mu0", type=float, default=None,
                   help="threshold of the compensation accuracy mu, in the joints' unit (default 0.1 deg, the "
                        "paper's, for revolute joints; 0.02 mm for prismatic ones)")
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "the measurement file")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, type=OutputFile(),
                   help="write the new result (readable by compensate and verify), atomically")
    p.add_argument("--plot", metavar="DIR", default=None, type=OutputDir(PLOTS),
                   help="write residuals.png (residuals per pose of the re-identification) into DIR")
    from zerocal_sym.cli.cmd_identify import add_trust_arguments

    add_trust_arguments(p)


#: commanded angles within this of IK(target) - the result's offsets (deg) are "compensated with that result"
COMMAND_TOL_DEG = 1e-3
#: the same in each file unit of the joints (deg: revolute, mm: prismatic)
COMMAND_TOL = {"deg": COMMAND_TOL_DEG, "mm": 1e-3}
#: the default threshold mu0 of the compensation accuracy per file unit of the offsets: the paper's 0.1 deg; for
#: prismatic joints 0.02 mm, about twice the CRLB of a linear Delta's ring scheme
MU0_DEFAULT = {"deg": 0.1, "mm": 0.02}


def check_compensated(robot, meas, offsets_deg, data) -> None:
    """Refuse a round whose commands are not IK(target) - offsets (it was not compensated with that result)."""
    import numpy as np

    from zerocal_sym.errors import DataFileError
    from zerocal_sym.io.compensation import compensated_commands
    from zerocal_sym.model import units

    if meas.target is None:
        return
    try:
        _, cmd = compensated_commands(robot, meas.target, offsets_deg)
    except (ValueError, Exception) as exc:  # noqa: BLE001 - an unreachable target: the commands cannot match
        raise DataFileError(f"the targets cannot be compensated with the result's offsets: {exc}",
                            where=data) from None
    u = units.joint_unit(robot)
    diff = units.joints_to_user(robot, np.abs(np.asarray(meas.theta_cmd, float) - cmd))
    bad = np.flatnonzero(np.max(diff, axis=1) > COMMAND_TOL[u])
    if bad.size:
        k = int(bad[0])
        j = int(np.argmax(diff[k]))
        joints = robot.mechanism.joint_names
        line = meas.lines[k] if len(meas.lines) > k else None
        raise DataFileError(
            f"pose {k}: commanded {joints[j]} differs from IK(target) - the result's offset by {diff[k, j]:.4g} {u} "
            f"(> {COMMAND_TOL[u]:g}): this round was not compensated with this result (zerocal compensate RESULT.json "
            f"--template gives the compensated commands)", where=f"{data}:{line}" if line else data)


def run(args):
    import contextlib

    import numpy as np

    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli.cmd_compensate import check_result_robot
    from zerocal_sym.cli.cmd_identify import compensation_block, trust_kwargs
    from zerocal_sym.errors import DataFileError, ZerocalError
    from zerocal_sym.io.compensation import parse_offsets
    from zerocal_sym.io.files import json_safe, staged_directory, to_json, write_json
    from zerocal_sym.io.measurements import load_measurements
    from zerocal_sym.io.results import load_result
    from zerocal_sym.model import units
    from zerocal_sym.model.noise import NoiseModel

    if args.mu0 is not None and not (args.mu0 > 0 and np.isfinite(args.mu0)):
        raise ZerocalError(f"--mu0 must be a positive number (the joints' unit), got {args.mu0}")
    from pathlib import Path

    for opt, path in (("--out", args.out), ("--plot", args.plot)):
        if path and Path(path).exists() and (Path(path).is_dir() if opt == "--out" else not Path(path).is_dir()):
            raise ZerocalError(f"{opt} {path}: {'is a directory' if opt == '--out' else 'is not a directory'}",
                               where=path)
    robot = load_robot_arg(args)
    errors = robot.errors
    joints = robot.mechanism.joint_names
    u = units.joint_unit(robot)
    mu0 = MU0_DEFAULT[u] if args.mu0 is None else args.mu0
    applied = load_result(args.result, robot=robot)
    check_result_robot(applied, robot, args.result)
    from zerocal_sym.cli.cmd_identify import max_offset_arg
    from zerocal_sym.identify.check.plausibility import plausibility

    reasons = plausibility(robot, applied, max_offset=max_offset_arg(args, robot), max_maemm_mm=args.max_maemm_mm)
    if reasons:  # as compensate: not a calibration to verify (and not a prior for the re-identification)
        import sys

        print(f"zerocal verify: refused {args.result}: {'; '.join(reasons)}", file=sys.stderr)
        return 1
    meas = load_measurements(args.data, robot, allow_revisits=args.allow_revisits)
    comp_key = units.joint_key(robot, "compensation")
    declared = parse_offsets(meas.meta.get(comp_key), robot.m)
    if declared is not None and np.max(np.abs(declared - applied.zero_offsets_user)) > 1e-4:
        line = meas.meta_lines.get(comp_key)
        fmt = lambda v: "(" + ", ".join(f"{x:g}" for x in v) + ")"  # noqa: E731
        raise DataFileError(
            f"the data were measured with compensation {fmt(declared)} {u}, not with the "
            f"result's offsets {fmt(applied.zero_offsets_user)} {u}",
            where=f"{args.data}:{line}" if line else args.data)
    check_compensated(robot, meas, applied.zero_offsets_user, args.data)
    noise = NoiseModel.named(args.noise, robot)
    prior = errors.put(errors.zeros(), errors.zero_offsets, applied.zero_offsets)
    if np.all(np.isfinite(applied.maemm_mm)):
        prior = errors.put(prior, errors.measuring, applied.maemm_mm)
    if args.method == "tsvd":
        from zerocal_sym.identify.tsvd import identify_tsvd

        res = identify_tsvd(robot, meas, prior=prior, noise=None if noise.is_zero else noise,
                            **trust_kwargs(args, "tsvd"))
    else:
        from zerocal_sym.identify.nlls import identify_nlls

        res = identify_nlls(robot, meas, "paper", noise=noise, prior=prior, **trust_kwargs(args, "nlls"))
    if not res.success:
        import sys

        from zerocal_sym.cli.cmd_identify import diagnosis

        print(f"zerocal verify: re-identification {'rejected' if res.status.startswith('rejected') else 'failed'} "
              f"({res.method}): {res.status}; no result written", file=sys.stderr)
        if diagnosis(res):
            print(diagnosis(res), file=sys.stderr)
        return 1
    reasons = plausibility(robot, res, max_offset=max_offset_arg(args, robot), max_maemm_mm=args.max_maemm_mm)
    if reasons:
        import sys

        print(f"zerocal verify: re-identification rejected: {'; '.join(reasons)}; no result written", file=sys.stderr)
        return 1
    new = res.zero_offsets_user
    remaining = new - applied.zero_offsets_user
    mu = float(np.sqrt(np.mean(remaining**2)))
    std = res.std_zero_offsets_user
    passed = mu < mu0
    # mu of a perfect compensation is about the RMS of the new offsets' std: a mu0 below it is a test this round
    # cannot pass but by chance (the hexapod's corner scheme: std about 0.03 mm against the default 0.02 mm)
    resolution = float(np.sqrt(np.mean(np.square(std)))) if np.all(np.isfinite(std)) else None
    report = {
        "passed": bool(passed),
        f"mu_{u}": mu,
        f"mu0_{u}": mu0,
        f"std_rms_new_offsets_{u}": resolution,
        "mu0_below_std": bool(resolution is not None and mu0 <= resolution),
        "joints": list(joints),
        f"applied_offsets_{u}": applied.zero_offsets_user.tolist(),
        f"new_offsets_{u}": new.tolist(),
        f"remaining_offsets_{u}": remaining.tolist(),
        f"std_new_offsets_{u}": [float(s) if np.isfinite(s) else None for s in std],
        "method": res.method,
        "data": str(args.data),
        "applied_result": str(args.result),
    }
    out = res.to_dict()
    out.update(mechanism=robot.mechanism_name, robot_sha256=robot.sha256, verification=report,
               accept_misfit=bool(args.accept_misfit),
               compensation=compensation_block(robot, res))
    target = args.plot
    try:
        with staged_directory(args.plot) if args.plot else contextlib.nullcontext() as plot_dir:
            if args.plot:  # into a temporary directory, moved into place once everything is written
                from zerocal_sym.report.plots import identify_plots

                identify_plots(plot_dir, res, meas, robot)
            target = args.out
            if args.out:
                write_json(args.out, json_safe(out))
            target = args.plot
    except OSError as exc:
        raise ZerocalError(f"cannot write the output: {exc.strerror or exc}", where=exc.filename or target) from None
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(json_safe(out)))
    else:
        vec = lambda v: ", ".join(f"{x:+.4f}" for x in v)  # noqa: E731
        print(f"{args.data}: re-identified ({res.method}) with the compensation of {args.result} applied "
              f"(joints {', '.join(joints)})")
        print(f"  applied   offsets: {vec(applied.zero_offsets_user)} {u}")
        print(f"  new       offsets: {vec(new)} {u} (std {', '.join(f'{s:.3g}' for s in std)})")
        print(f"  remaining offsets: {vec(remaining)} {u}")
        verdict = "PASS" if passed else "FAIL: apply the new result and measure again"
        print(f"  mu = {mu:.4f} {u} {'<' if passed else '>='} mu0 = {mu0:g} {u}: {verdict}")
        if report["mu0_below_std"]:
            print(f"  note: mu0 = {mu0:g} {u} is not above the new offsets' uncertainty ({resolution:.3g} {u}, 1 sigma "
                  "RMS): even a perfect compensation gives mu about that large, so this round cannot show mu < mu0 "
                  "but by chance; measure more (or better) poses, or judge with a larger --mu0")
        if args.out:
            print(f"wrote {args.out}")
    return 0 if passed else 1
