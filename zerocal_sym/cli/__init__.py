"""The ``zerocal`` command line.

Each sub-command lives in its own module ``zerocal_sym/cli/cmd_<name>.py``
that defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args)``
(returning the exit status).  Command modules import numpy/casadi inside
``run`` so that ``zerocal --help`` stays fast.

Exit status: 0 success, 1 a check that failed (``regen --check``), 2 a user
error (bad file, bad pose, bad option): one line on stderr, no traceback, no
output file written.
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from zerocal_sym.errors import ZerocalError


def _command_modules():
    pkg = importlib.import_module(__name__)
    names = sorted(m.name for m in pkgutil.iter_modules(pkg.__path__) if m.name.startswith("cmd_"))
    return [importlib.import_module(f"{__name__}.{n}") for n in names]


def build_parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--robot", metavar="FILE", default=None,
                        help="robot TOML file, any mechanism (default: the paper's robot, Table 1; "
                             "examples/delta.toml: the rotary Delta)")
    parser = argparse.ArgumentParser(
        prog="zerocal",
        description="Zero-offset calibration of parallel robots (Mei et al. 2017, and beyond).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.__doc__, parents=[common],
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def load_robot_arg(args):
    """The robot named by ``--robot`` (or the paper's)."""
    from zerocal_sym.model.robot import load_robot, paper_robot

    return load_robot(args.robot) if args.robot else paper_robot()


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        return int(args._run(args) or 0)
    except ZerocalError as exc:
        print(f"zerocal {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # an unwritable --out, a directory given for a file, a full disk
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"zerocal {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"zerocal {args.command}: interrupted", file=sys.stderr)
        return 130


def entry() -> None:  # console script
    sys.exit(main())
