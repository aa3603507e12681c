"""Measurement-pose design.

``--scheme`` (default: the robot's own) -- the boundary scheme of the robot's
workspace (``K = robot.workspace.scheme_size(n)``):

* ``paper`` (a rectangular workspace, the paper's Section 5): n evenly
  spaced poses on y = H and on y = H + h (each from x = -b/2 to +b/2),
  K = 2n; prints kappa_1, kappa_m (with the MAEMM prior, Eq. 30), the eps
  rule (Eq. 31; without ``--n`` the smallest n with eps <= eps0) and the
  CRLB of the zero offsets;
* ``ring`` (a cylindrical workspace, the Deltas): n poses on the top circle
  at azimuths 360 deg j/n (from the workspace's ring azimuth), then on the
  bottom one, K = 2n; prints kappa_1 (the condition number of the paper's G
  over the mechanism's identified set, no MAEMM prior), the CRLB of the zero
  offsets (the robot's noise and the scale error alone) and, without
  ``--n``, the default n = 6 with kappa_1 and the CRLB for the other n;
* ``corners`` (a box workspace, the hexapod's 6-D pose): K = n corners of the
  box, all 64 (default) or the regular fraction of 32 or 16; the same numbers.

Joint values, the CRLB of the zero offsets and the options that carry them
are in the joints' unit: deg for revolute joints, mm for prismatic ones (JSON
keys ``joints_deg``, ``crlb_zero_offsets_deg`` or ``joints_mm``,
``crlb_zero_offsets_mm``); the noise is the robot's (its file's ``[noise]``,
its mechanism's default, else the paper's).

A scheme that does not fit the robot's workspace is an error naming the
right one.

``--optimize``: K poses chosen by a constrained optimisation (CasADi/Ipopt
and a discrete exchange, or the approximate design with its certificate) for
a criterion, over the robot's workspace shape (a rectangle, a cylinder, a
box), compared with the boundary scheme at the same K.  ``--params SET``: the
design is made for identifying SET (default ``paper``, the zero offsets and
the MAEMM; e.g. ``paper+L1,L2,L3`` to identify the upper arms too, then
``zerocal identify --params paper+L1,L2,L3``); ``--choose-params``: the set
too, the one whose offsets' expected error at K is least (docs/trust.md).
"""
NAME = "design"
HELP = "measurement poses: the robot's boundary scheme (paper, ring, corners) or an optimised design"


def add_arguments(p):
    from zerocal_sym.cli._paths import OutputFile

    p.add_argument("--scheme", choices=["paper", "ring", "corners"], default=None,
                   help="pose scheme (default: the robot's: paper on a rectangle, ring on a cylinder, corners on a "
                        "box)")
    p.add_argument("--n", type=int, default=None,
                   help="poses per boundary (paper, ring: K = 2n) or corners (corners: K = n = 64, 32 or 16); "
                        "default: the eps0 rule (paper), 6 (ring), 64 (corners)")
    p.add_argument("--eps0", type=float, default=None, help="threshold of the paper's eps rule (default 0.01)")
    p.add_argument("--maemm-prior", nargs="+", type=float, metavar="MM", default=None,
                   help="MAEMM prior (mm, one value per measuring error) for kappa_m (paper; default: see "
                        "docs/reproduction.md) or kappa with the prior (ring, corners)")
    p.add_argument("--optimize", action="store_true", help="optimise the poses instead of the boundary scheme")
    p.add_argument("--K", type=int, default=None,
                   help="number of poses (--optimize; default the K of the scheme's default n: 6 paper, 12 ring, "
                        "64 corners)")
    p.add_argument("--criterion", choices=["cond", "D", "A", "E", "crlb", "position", "mse", "checked"],
                   default="checked",
                   help="design criterion (--optimize): checked, the least CRLB among designs whose fit check "
                        "sees reversed or swapped poses, a bad reading and a robot file off in scale; crlb, the least "
                        "CRLB alone")
    p.add_argument("--region", nargs="+", metavar="SPEC", default=None,
                   help="design region (default: the workspace): XMIN XMAX YMIN YMAX on a rectangle, RW ZMIN ZMAX "
                        "on a cylinder (mm), X_MIN X_MAX ... YAW_MIN YAW_MAX on a box (mm, deg for orientations); "
                        "reachable everywhere; 'reachable' (the reachable non-singular set, clipped by --bounds; "
                        "poses of positions only); 'polygon X1 Y1 X2 Y2 ...' (planar)")
    p.add_argument("--seed", type=int, default=0, help="seed of the multi-start")
    p.add_argument("--verify", type=int, default=0, metavar="N", help="Monte Carlo trials to verify the CRLB")
    from zerocal_sym.cli import _parallel

    _parallel.add_arguments(p, "--verify")
    p.add_argument("--plot", metavar="PNG", default=None, type=OutputFile(), help="plot the poses in the workspace")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, type=OutputFile(), help="also write the JSON (what --json prints) here")
    # --optimize constraints and settings (defaults in zerocal_sym.design)
    p.add_argument("--l0", type=float, default=350.0, metavar="MM",
                   help="scale range l0 in mm (--optimize; default 350, the paper's)")
    p.add_argument("--travel-mode", choices=["range", "consecutive"], default="range",
                   help="l0 bounds the span of rho over all poses (range, default) or each change (consecutive)")
    p.add_argument("--margin", type=float, default=None,
                   help="min |sin| of every transmission angle (--optimize; default: the robot's)")
    p.add_argument("--joint-limits", nargs="+", type=float, metavar="LIM", default=None,
                   help="joint limits in the joints' unit: deg for revolute, mm for prismatic joints; LO HI per "
                        "joint: LO1 HI1 LO2 HI2 ... (--optimize; default none)")
    p.add_argument("--joint-limits-deg", nargs="+", type=float, metavar="DEG", default=None,
                   help="--joint-limits spelt with its unit (revolute joints)")
    p.add_argument("--joint-limits-mm", nargs="+", type=float, metavar="MM", default=None,
                   help="--joint-limits spelt with its unit (prismatic joints)")
    p.add_argument("--min-separation", type=float, default=1.0, metavar="MM",
                   help="min distance between two distinct poses in mm (a replicate is the same pose again); for "
                        "a pose with orientations a degree counts as a mm (--optimize; default 1)")
    p.add_argument("--noise", choices=["default", "paper", "scale-only", "servo-only", "joint-only"],
                   default="default",
                   help="noise model of the Fisher-information criteria (--optimize): the robot's (default: its "
                        "file's [noise], its mechanism's, else the paper's Eqs. 34-35; 'paper' is the same), its "
                        "scale term alone, its joint term alone (servo-only = joint-only)")
    p.add_argument("--starts", type=int, default=8, help="random Ipopt starts and exchange starts (--optimize)")
    p.add_argument("--params", default="paper", metavar="SET",
                   help="the parameters the design is for (--optimize): paper (default: the zero offsets and the "
                        "MAEMM) or names and sets joined by + or , (e.g. paper+L1,L2,L3: the upper arms too)")
    p.add_argument("--choose-params", action="store_true",
                   help="(--optimize) also choose the set: of --params plus whole groups of robot-file entries "
                        "(L for L1 L2 L3), the one whose offsets' expected error (variance of what is identified, "
                        "squared bias from the tolerances of what is held) is least at K")
    from zerocal_sym.cli import _design_optimize

    _design_optimize.add_arguments(p)  # --bounds, --method, --tolerance..., --target-crlb


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli._common import check_scheme

    from zerocal_sym.cli._design_optimize import resolve_unit_options

    robot = load_robot_arg(args)
    resolve_unit_options(args, robot)
    robot = _identifying(args, robot)
    if args.optimize or getattr(args, "target_crlb", None) is not None:
        from zerocal_sym.cli import _design_optimize

        return _design_optimize.run(args, robot)
    scheme = check_scheme(robot, args.scheme)
    if scheme == "paper":
        from zerocal_sym.cli import _design_paper

        return _design_paper.run(args, robot)
    from zerocal_sym.cli import _design_scheme

    return _design_scheme.run(args, robot)


def _identifying(args, robot):
    """The robot with the set of ``--params`` (the designs are made for it); ``--params`` and
    ``--choose-params`` are for ``--optimize``."""
    from zerocal_sym.errors import ZerocalError

    params = getattr(args, "params", "paper")
    if params == "paper" and not getattr(args, "choose_params", False):
        return robot
    if not args.optimize:
        raise ZerocalError("--params and --choose-params are for --optimize (a design made for that set)")
    try:
        robot = robot.identifying(params)
    except ValueError as exc:
        raise ZerocalError(f"--params: {exc}") from None
    missing = [z for z in robot.errors.zero_offsets if z not in robot.errors.resolve(params)]
    if missing:
        raise ZerocalError(f"--params {params}: the zero offsets {', '.join(missing)} must be among them (a design "
                           "is made for the offsets)")
    return robot
