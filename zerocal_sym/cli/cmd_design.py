"""Measurement-pose design.

``--scheme`` (default: the robot's own) -- the boundary scheme of the robot's
workspace, n poses on each of its two boundaries, K = 2n:

* ``paper`` (a rectangular workspace, the paper's Section 5): n evenly
  spaced poses on y = H and on y = H + h (each from x = -b/2 to +b/2);
  prints kappa_1, kappa_m (with the MAEMM prior, Eq. 30), the eps rule
  (Eq. 31; without ``--n`` the smallest n with eps <= eps0) and the CRLB of
  the zero offsets;
* ``ring`` (a cylindrical workspace, the rotary Delta of DELTA.md): n poses
  on the top circle at azimuths 360 deg j/n, then on the bottom one; prints
  kappa_1 (the condition number of the paper's G, Eq. 28 in 3-D, no MAEMM
  prior), the CRLB of the zero offsets (paper noise and scale error alone)
  and, without ``--n``, the default n = 6 with kappa_1 and the CRLB for the
  other n.

A scheme that does not fit the robot's workspace is an error naming the
right one.

``--optimize``: K poses chosen by a constrained optimisation (CasADi/Ipopt
and a discrete exchange) for a criterion, over the robot's workspace shape
(a rectangle or a cylinder), compared with the boundary scheme at the same K.
"""
NAME = "design"
HELP = "measurement poses: the robot's boundary scheme (paper, ring) or an optimised design"


def add_arguments(p):
    from zerocal_sym.cli._paths import OutputFile

    p.add_argument("--scheme", choices=["paper", "ring"], default=None,
                   help="pose scheme (default: the robot's: paper on a rectangle, ring on a cylinder)")
    p.add_argument("--n", type=int, default=None,
                   help="poses per boundary; default: the eps0 rule (paper), 6 (ring)")
    p.add_argument("--eps0", type=float, default=None, help="threshold of the paper's eps rule (default 0.01)")
    p.add_argument("--maemm-prior", nargs="+", type=float, metavar="MM", default=None,
                   help="MAEMM prior (mm, one value per pose coordinate) for kappa_m (paper; default: see "
                        "docs/reproduction.md) or kappa with the prior (ring)")
    p.add_argument("--optimize", action="store_true", help="optimise the poses instead of the boundary scheme")
    p.add_argument("--K", type=int, default=None,
                   help="number of poses (--optimize; default 2n of the scheme's default: 6 paper, 12 ring)")
    p.add_argument("--criterion", choices=["cond", "D", "A", "E", "crlb", "position", "mse"], default="crlb",
                   help="design criterion (--optimize)")
    p.add_argument("--region", nargs="+", metavar="SPEC", default=None,
                   help="design region (default: the workspace): XMIN XMAX YMIN YMAX on a rectangle, RW ZMIN ZMAX "
                        "on a cylinder (mm, reachable everywhere); 'reachable' (the reachable non-singular set, "
                        "clipped by --bounds); 'polygon X1 Y1 X2 Y2 ...' (planar)")
    p.add_argument("--seed", type=int, default=0, help="seed of the multi-start")
    p.add_argument("--verify", type=int, default=0, metavar="N", help="Monte Carlo trials to verify the CRLB")
    from zerocal_sym.cli import _parallel

    _parallel.add_arguments(p, "--verify")
    p.add_argument("--plot", metavar="PNG", default=None, type=OutputFile(), help="plot the poses in the workspace")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", metavar="FILE.json", default=None, type=OutputFile(), help="also write the JSON (what --json prints) here")
    # --optimize constraints and settings (issue 5; defaults in zerocal_sym.design)
    p.add_argument("--l0", type=float, default=350.0, metavar="MM",
                   help="scale range l0 in mm (--optimize; default 350, the paper's)")
    p.add_argument("--travel-mode", choices=["range", "consecutive"], default="range",
                   help="l0 bounds the span of rho over all poses (range, default) or each change (consecutive)")
    p.add_argument("--margin", type=float, default=None,
                   help="min |sin| of every transmission angle (--optimize; default: the robot's)")
    p.add_argument("--joint-limits", nargs="+", type=float, metavar="DEG", default=None,
                   help="joint limits in deg, LO HI per joint: LO1 HI1 LO2 HI2 [LO3 HI3] (--optimize; default none)")
    p.add_argument("--min-separation", type=float, default=1.0, metavar="MM",
                   help="min distance between two poses in mm (--optimize; default 1)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only"], default="paper",
                   help="noise model of the Fisher-information criteria (--optimize; default paper)")
    p.add_argument("--starts", type=int, default=8, help="random Ipopt starts and exchange starts (--optimize)")
    from zerocal_sym.cli import _design_optimize

    _design_optimize.add_arguments(p)  # issue 13: --bounds, --method, --tolerance..., --target-crlb


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.cli._common import check_scheme

    robot = load_robot_arg(args)
    if args.optimize or getattr(args, "target_crlb", None) is not None:
        from zerocal_sym.cli import _design_optimize

        return _design_optimize.run(args, robot)
    scheme = check_scheme(robot, args.scheme)
    if scheme == "paper":
        from zerocal_sym.cli import _design_paper

        return _design_paper.run(args, robot)
    from zerocal_sym.cli import _design_scheme

    return _design_scheme.run(args, robot)
