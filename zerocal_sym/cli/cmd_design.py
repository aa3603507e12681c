"""Measurement-pose design.

``--scheme paper`` (default): the paper's Section 5 scheme, n evenly spaced
poses on each of the boundaries y = H and y = H + h (order: along y = H from
x = -b/2 to +b/2, then along y = H + h again from -b/2 to +b/2); without
``--n`` the smallest n with eps = (kappa_1 - kappa_m)/kappa_1 <= eps0.

``--optimize``: K poses chosen by a constrained optimisation (CasADi/Ipopt)
for a criterion, compared with the paper's scheme at the same K.
"""
NAME = "design"
HELP = "measurement poses: the paper's scheme or an optimised design"


def add_arguments(p):
    p.add_argument("--scheme", choices=["paper"], default="paper", help="pose scheme (default: paper)")
    p.add_argument("--n", type=int, default=None, help="poses per boundary (paper scheme); default: eps0 rule")
    p.add_argument("--eps0", type=float, default=0.01, help="threshold of the eps rule (default 0.01)")
    p.add_argument("--maemm-prior", nargs=2, type=float, metavar=("X", "Y"), default=None,
                   help="MAEMM prior (mm) for kappa_m (default: see docs/reproduction.md)")
    p.add_argument("--optimize", action="store_true", help="optimise the poses instead of the paper's scheme")
    p.add_argument("--K", type=int, default=6, help="number of poses (--optimize)")
    p.add_argument("--criterion", choices=["cond", "D", "A", "E", "crlb"], default="crlb",
                   help="design criterion (--optimize)")
    p.add_argument("--region", nargs=4, type=float, metavar=("XMIN", "XMAX", "YMIN", "YMAX"), default=None,
                   help="design region in mm (default: the workspace)")
    p.add_argument("--seed", type=int, default=0, help="seed of the multi-start")
    p.add_argument("--verify", type=int, default=0, metavar="N", help="Monte Carlo trials to verify the CRLB")
    p.add_argument("--plot", metavar="PNG", default=None, help="plot the poses in the workspace")
    p.add_argument("--json", action="store_true", help="print JSON")
    # --optimize constraints and settings (issue 5; defaults in zerocal_sym.design)
    p.add_argument("--l0", type=float, default=350.0, metavar="MM",
                   help="scale range l0 in mm (--optimize; default 350, the paper's)")
    p.add_argument("--travel-mode", choices=["range", "consecutive"], default="range",
                   help="l0 bounds the span of rho over all poses (range, default) or each change (consecutive)")
    p.add_argument("--margin", type=float, default=None,
                   help="min |sin| of every transmission angle (--optimize; default: the robot's)")
    p.add_argument("--joint-limits", nargs=4, type=float, metavar=("LO1", "HI1", "LO2", "HI2"), default=None,
                   help="joint limits in deg (--optimize; default none)")
    p.add_argument("--min-separation", type=float, default=1.0, metavar="MM",
                   help="min distance between two poses in mm (--optimize; default 1)")
    p.add_argument("--noise", choices=["paper", "scale-only", "servo-only"], default="paper",
                   help="noise model of the Fisher-information criteria (--optimize; default paper)")
    p.add_argument("--starts", type=int, default=8, help="random Ipopt starts and exchange starts (--optimize)")


def run(args):
    if args.optimize:
        from zerocal_sym.cli import _design_optimize

        return _design_optimize.run(args)
    from zerocal_sym.cli import _design_paper

    return _design_paper.run(args)
