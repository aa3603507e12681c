"""Which options name files: each path option declares, by its argparse ``type``, what it reads or writes.

A command's option that reads a file is added with ``type=InputFile(label)``,
one that writes a file with ``type=OutputFile()``, one that fills a directory
with ``type=OutputDir(names)`` (the names, or ``fnmatch`` patterns such as
``*/cell.json``, of the files it writes there), one that reads a directory
with ``type=InputDir(label)``.  The types return the string unchanged: the
declaration is what :func:`path_options` finds on the parser, and
:func:`check_paths` applies the one rule to every command, before any work:

* no empty names;
* an output never lands on an input (``..`` through missing directories and
  symbolic links resolved, hard links compared by device and inode:
  :func:`zerocal_sym.io.files.check_outputs`), nor on another output.

So a new option is protected by declaring it, and the test that walks the
parser (``tests/test_paths.py``) covers it.  This module imports nothing
heavy (``zerocal --help`` stays fast).
"""
from __future__ import annotations

import argparse


class PathType:
    """An argparse ``type`` that keeps the string and marks the option as a path of some kind."""

    kind = ""

    def __call__(self, text: str) -> str:
        return text

    def __repr__(self) -> str:  # argparse names the type in some errors
        return self.kind


#: the label of a robot file option (its ``mechanism_module`` is an input as well: :func:`check_paths`)
ROBOT_FILE = "the robot file"


class InputFile(PathType):
    """A file the command reads (``label``: how messages name it, e.g. ``the measurement file``).

    ``not_files``: values that are keywords, not file names (``--poses paper``): a tuple, or a function
    returning one (called only when a value is checked).
    """

    kind = "input file"

    def __init__(self, label: str, not_files=()):
        self.label, self.not_files = label, not_files

    def is_file(self, value) -> bool:
        keywords = self.not_files() if callable(self.not_files) else self.not_files
        return value is not None and value not in keywords


class InputDir(InputFile):
    """A directory the command reads (nothing in it is written by this option)."""

    kind = "input directory"


class OutputFile(PathType):
    """A file the command writes."""

    kind = "output file"


class OutputDir(PathType):
    """A directory the command writes into.

    ``names``: the files it writes there (``fnmatch`` patterns, ``/`` between levels).
    """

    kind = "output directory"

    def __init__(self, names=()):
        self.names = tuple(names)


def option_name(action) -> str:
    """How messages name an option: its long option string, or a positional's metavar."""
    if action.option_strings:
        return max(action.option_strings, key=len)
    return action.metavar or action.dest


def path_options(parser: argparse.ArgumentParser) -> list:
    """``[(dest, option name, PathType)]``: the path options of one command's parser, in the parser's order."""
    return [(a.dest, option_name(a), a.type) for a in parser._actions if isinstance(a.type, PathType)]


def given_paths(args, options=None) -> tuple:
    """``(inputs, outputs)`` of ``args``: ``[(option, label, path, is_dir)]``, ``[(option, path[, names])]``.

    ``options``: :func:`path_options` of the command's parser (default: those
    recorded on ``args`` by :func:`zerocal_sym.cli.build_parser`).
    """
    options = getattr(args, "_paths", ()) if options is None else options
    inputs, outputs = [], []
    for dest, opt, t in options:
        value = getattr(args, dest, None)
        if value is None:
            continue
        if isinstance(t, InputFile):
            if t.is_file(value):
                inputs.append((opt, t.label, value, isinstance(t, InputDir)))
        elif isinstance(t, OutputDir):
            outputs.append((opt, value, t.names))
        else:
            outputs.append((opt, value))
    return inputs, outputs


def check_paths(args) -> None:
    """The one rule for every path a command reads or writes (module docstring); an OutputError names the option."""
    from zerocal_sym.io.files import OutputError, check_outputs

    inputs, outputs = given_paths(args)
    for opt, _, value, is_dir in inputs:
        if str(value) == "":
            raise OutputError(f"{opt}: empty {'directory' if is_dir else 'file'} name")
    protected = [(f"{label} ({opt})", value) for opt, label, value, is_dir in inputs if not is_dir]
    if outputs:  # a robot file's mechanism_module is read with it: an input too
        from zerocal_sym.model.robot import module_file

        protected += [(f"the mechanism module of {label} ({opt})", module) for opt, label, value, is_dir in inputs
                      if label == ROBOT_FILE for module in [module_file(value)] if module is not None]
    check_outputs(outputs, protected)
