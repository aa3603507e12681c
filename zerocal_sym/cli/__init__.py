"""The ``zerocal`` command line.

Each sub-command lives in its own module ``zerocal_sym/cli/cmd_<name>.py``
that defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args)``
(returning the exit status).  Command modules import numpy/casadi inside
``run`` so that ``zerocal --help`` stays fast.

Exit status: 0 success, 1 a check that failed (``regen --check``), 2 a user
error (bad file, bad pose, bad option, an option that does not apply to the
chosen mode, an output that is an input): one line on stderr, no traceback,
no output file written; 130 interrupted (Ctrl-C), 143 terminated (SIGTERM):
stopped, cleaned up, nothing written; 141 the reader of the standard output
went away (``zerocal ... | head -1``): quietly, as a program killed by
SIGPIPE.  A Ctrl-C or SIGTERM that arrives once the command has written its
outputs does not change its status (:mod:`zerocal_sym.cli._interrupt`).
"""
from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys

from zerocal_sym.errors import ZerocalError

#: exit status when the standard output was closed by its reader (128 + SIGPIPE)
EXIT_BROKEN_PIPE = 141


class _Parser(argparse.ArgumentParser):
    """argparse with the CLI's one-line errors (exit status 2)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """A command's docstring as written; each option's default in its help, unless the help states it already
    (or there is none to state: ``None``, an unset flag)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (not action.option_strings or "default" in text or action.default is None or action.default is False
                or action.default is argparse.SUPPRESS or action.default == []):
            return text
        return f"{text} (default: %(default)s)"


def _command_modules():
    pkg = importlib.import_module(__name__)
    names = sorted(m.name for m in pkgutil.iter_modules(pkg.__path__) if m.name.startswith("cmd_"))
    return [importlib.import_module(f"{__name__}.{n}") for n in names]


#: the help of ``--robot`` in a command that takes any mechanism; a command module's ``ROBOT_HELP`` replaces it
#: (``argparse.SUPPRESS``: the option is hidden, and giving it is that command's one-line error, cli/_checks.py)
ROBOT_HELP = ("robot TOML file, any mechanism (default: the paper's robot, Table 1; examples/delta.toml: the "
              "rotary Delta)")


def version() -> str:
    """The installed package's version (its metadata), or the source's when it is not installed."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as dist_version

    try:
        return dist_version("zerocal_sym")
    except PackageNotFoundError:
        from zerocal_sym import __version__

        return __version__


def build_parser() -> argparse.ArgumentParser:
    from zerocal_sym.cli._paths import ROBOT_FILE, InputFile, path_options

    parser = _Parser(
        prog="zerocal",
        description="Zero-offset calibration of parallel robots (Mei et al. 2017, and beyond).")
    parser.add_argument("--version", action="version", version=f"zerocal {version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in _command_modules():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.__doc__,
                           formatter_class=_HelpFormatter)
        p.add_argument("--robot", metavar="FILE", default=None, type=InputFile(ROBOT_FILE),
                       help=getattr(mod, "ROBOT_HELP", ROBOT_HELP))
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run, _paths=path_options(p))  # the files it reads and writes (cli/_paths.py)
    return parser


def load_robot_arg(args):
    """The robot named by ``--robot`` (or the paper's)."""
    from zerocal_sym.model.robot import load_robot, paper_robot

    return load_robot(args.robot) if args.robot else paper_robot()


def _given_options(argv) -> set:
    """The destinations of the options given on the command line (not left at their defaults)."""
    parser = build_parser()
    stack = [parser]
    while stack:
        p = stack.pop()
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                stack.extend(action.choices.values())
            else:
                action.default = argparse.SUPPRESS
    return set(vars(parser.parse_args(argv)))


def main(argv=None) -> int:
    from zerocal_sym.cli import _interrupt

    _interrupt.reset()
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    try:
        from zerocal_sym.cli._checks import check_args

        from zerocal_sym.cli._interrupt import installed

        args._given = _given_options(argv)
        check_args(args)  # options of the mode, numbers, outputs vs inputs: before any work
        with installed() as guard:  # Ctrl-C that a solver swallows is raised again (cli/_interrupt.py)
            status = int(guard.call(args._run, args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return status
    except ZerocalError as exc:
        if _from_interrupt(exc):  # e.g. Ctrl-C inside an import that was turned into "needs X"
            return _interrupted(args)
        print(f"zerocal {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError as exc:
        if exc.filename is None:  # our standard output: its reader has gone (| head -1)
            return _stdout_closed()
        print(f"zerocal {args.command}: error: {exc.filename}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # an unwritable --out, a directory given for a file, a full disk
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"zerocal {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return _interrupted(args)
    except Exception as exc:
        if _from_interrupt(exc):  # Ctrl-C inside a C extension (CasADi): "SystemError: ... exception set"
            return _interrupted(args)
        raise


#: set by the console entry point: an interrupted command there ends the process (see _interrupted)
_CONSOLE = False


def _interrupted(args) -> int:
    from zerocal_sym.cli._interrupt import ignore_signals, interrupt_status
    from zerocal_sym.model.compiled import stop_builds

    if _CONSOLE:  # the process ends with 130: a burst of Ctrl-C (GNU timeout signals twice) must not cut that short
        ignore_signals()
    stop_builds()  # a compiler building in the background stops too (zerocal_sym.model.compiled)
    status, word = interrupt_status()  # 130 interrupted (Ctrl-C), 143 terminated (SIGTERM)
    print(f"zerocal {args.command}: {word}", file=sys.stderr)
    return status


def _from_interrupt(exc) -> bool:
    """Whether ``exc`` was caused by Ctrl-C (:func:`zerocal_sym.cli._interrupt.is_interrupt`)."""
    from zerocal_sym.cli._interrupt import is_interrupt

    return is_interrupt(exc)


def _stdout_closed() -> int:
    """The reader of stdout went away: point stdout at /dev/null (no error at exit), status 141."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError):  # not a real file (captured in tests)
        pass
    return EXIT_BROKEN_PIPE


def entry(held=()) -> None:
    """The ``zerocal`` console script (through :func:`zerocal_sym.__main__.console`).

    ``held``: the signals (SIGINT, SIGTERM) that arrived while the CLI was imported (they were held then).
    """
    global _CONSOLE
    _CONSOLE = True
    from zerocal_sym.cli import _interrupt

    try:
        _interrupt.install_startup_handlers()  # from here until the command's own: KeyboardInterrupt
        for signum in held:  # a Ctrl-C or SIGTERM while importing: acted on now, as any other
            _interrupt.note(signum)
        if held:
            raise KeyboardInterrupt
        status = main()
    except KeyboardInterrupt:  # before a command ran (while parsing, importing)
        _interrupt.ignore_signals()
        status, word = _interrupt.interrupt_status()
        print(f"zerocal: {word}", file=sys.stderr)
    except BrokenPipeError:
        status = _stdout_closed()
    _interrupt.ignore_signals()  # the command is over: a late signal does not change its status
    if status in _interrupt.EXIT_STATUS.values():
        _exit_interrupted(status)
    sys.exit(status)


def _exit_interrupted(status: int = 130) -> None:
    """End with ``status`` (130, 143) after Ctrl-C or SIGTERM, cleanly, whatever CPython noted.

    A Ctrl-C that lands inside ``exec`` of a string (dataclasses and
    namedtuples are made so) makes CPython note the interrupt as unhandled,
    and after a normal exit it ends the process by SIGINT (status -2 to a
    parent process) although we handled it.  So: the exit functions, the
    streams, then ``os._exit(130)``.
    """
    import atexit

    try:
        atexit._run_exitfuncs()
    except BaseException:  # noqa: BLE001 - exiting anyway
        pass
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(status)
