"""What the CLI shows besides results: --version, each command's help, progress in a log."""
import argparse
import io
import itertools
import time
from importlib.metadata import version

import pytest

import zerocal_sym
from zerocal_sym.cli import _HelpFormatter, build_parser, main


def _subparsers():
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def test_version_is_the_package_metadata(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"zerocal {version('zerocal_sym')}\n"
    assert version("zerocal_sym") == zerocal_sym.__version__  # pyproject.toml and the package agree


def test_regen_offers_no_robot_and_reproduce_only_the_papers(capsys):
    helps = {name: p.format_help() for name, p in _subparsers().items()}
    assert "--robot" not in helps["regen"] and "--robot" not in helps["study"]
    assert "--robot FILE" in helps["reproduce"] and "delta" not in helps["reproduce"].split("--robot FILE")[1]
    assert "planar 2-DOF" in helps["reproduce"]
    assert "examples/delta.toml" in helps["compare"]  # the others take any mechanism
    # what regen and reproduce do with what their helps no longer offer: one line, exit 2
    for argv, words in ((["regen", "--robot", "examples/delta.toml", "--check"], "regen reads no robot file"),
                        (["reproduce", "--robot", "examples/delta.toml"], "reproduce is the paper's")):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and words in err


def test_every_default_is_in_the_help():
    """Each option with a default to state (not None, not an unset flag) states it in its help line."""
    missing = []
    for name, p in _subparsers().items():
        fmt = _HelpFormatter(p.prog)
        for a in p._actions:
            if (a.option_strings and a.help is not argparse.SUPPRESS and a.default not in (None, False, [])
                    and a.default is not argparse.SUPPRESS and "default" not in fmt._get_help_string(a)):
                missing.append(f"{name} {a.option_strings[0]}")
    assert not missing
    text = _subparsers()["design"].format_help()
    for opt, default in (("--criterion", "checked"), ("--seed", "0"), ("--starts", "8"), ("--tolerance-scale", "1.0")):
        line = " ".join(text.split(f"  {opt} ")[1].split("\n  -")[0].split())
        assert f"(default: {default})" in line, (opt, line)


def test_reproduce_progress_off_a_terminal_is_a_few_lines(monkeypatch):
    """In a log (stderr not a terminal) a line at each quarter, however long each loop takes."""
    from zerocal_sym.cli.cmd_reproduce import _progress

    clock = itertools.count()
    monkeypatch.setattr(time, "perf_counter", lambda: float(next(clock)))  # 1 s between two calls
    log = io.StringIO()
    report = _progress(128, stream=log)
    for done in range(1, 129):
        report(done, 128)
    lines = log.getvalue().splitlines()
    assert 1 <= len(lines) <= 4 and "128/128" in lines[-1]


def test_design_optimize_shows_progress_on_a_terminal_only(monkeypatch):
    """``design --optimize`` (tens of seconds): a tqdm bar on stderr when it is a terminal, its steps counted to
    the end (the approximate design, each exchange and Ipopt start, the polish); nothing in a log."""
    from zerocal_sym.cli._design_optimize import progress_bar

    assert progress_bar(io.StringIO()) is None  # a log, a pipe: quiet

    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty = Tty()
    monkeypatch.setattr("sys.stderr", tty)
    assert main(["design", "--optimize", "--K", "5", "--criterion", "crlb", "--starts", "1", "--json"]) == 0
    monkeypatch.undo()
    bar = tty.getvalue()
    steps = 1 + 1 + 1 + 1 + 2  # the certificate's approximate design, one exchange start, the scheme and one random
    # Ipopt start, the polish of the two candidates
    assert "design" in bar and f"{steps}/{steps}" in bar, bar
