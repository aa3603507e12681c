"""Never lose an input: every path a command reads or writes, by the one rule (cli/_paths.py, io/files.py).

The cases are generated from the CLI's own parser: every command, every
option it declares an input (``InputFile``), every option it declares an
output (``OutputFile``/``OutputDir``), and five ways of naming the input as
the output (through a missing directory and ``..``, two levels of them, a
symbolic link, a symbolic link to a directory and ``..``, a hard link).  A
new option is covered by declaring it; an option that looks like a path and
is not declared fails :func:`test_every_path_option_is_declared`.
"""
import argparse
import os
import re
from pathlib import Path

import pytest

from zerocal_sym.cli import build_parser, main
from zerocal_sym.cli._paths import InputDir, InputFile, OutputDir, OutputFile, PathType, option_name

#: what a command needs besides its path options to get past argparse (not which options are paths)
REQUIRED = {"simulate": ["--group", "1"]}
SPELLINGS = ("missing-dir", "two-missing-dirs", "symlink", "dir-symlink-dotdot", "hardlink")


def commands():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def triples():
    """(command, input option, output option) for every command, from the declarations on its options."""
    out = []
    for name, p in commands().items():
        ins = [a for a in p._actions if isinstance(a.type, InputFile) and not isinstance(a.type, InputDir)]
        outs = [a for a in p._actions if isinstance(a.type, (OutputFile, OutputDir))]
        out += [(name, option_name(i), option_name(o)) for i in ins for o in outs]
    return out


def test_the_generated_cases_cover_every_command_that_writes():
    """The generator sees the inputs and outputs: every command with an output has cases, the known ones among them."""
    cases = set(triples())
    writers = {name for name, p in commands().items() if any(isinstance(a.type, (OutputFile, OutputDir))
                                                             for a in p._actions)}
    assert writers == {c for c, _, _ in cases}
    for case in [("identify", "DATA.csv", "--out"), ("identify", "--tolerance-file", "--out"),
                 ("design", "--tolerance-file", "--out"), ("design", "--robot", "--plot"),
                 ("compensate", "RESULT.json", "--out"), ("compensate", "--poses", "--out"),
                 ("verify", "RESULT.json", "--plot"), ("simulate", "--robot", "--out"),
                 ("compare", "--poses", "--out"), ("study", "SPEC.toml", "--out"), ("reproduce", "--robot", "--out")]:
        assert case in cases, case


PATHLIKE = re.compile(r"FILE|DIR|PNG|\.csv|\.json|\.toml")


def test_every_path_option_is_declared():
    """An option whose metavar names a file or directory, or that is called --out/--plot, declares what it is."""
    for name, p in commands().items():
        for a in p._actions:
            looks = bool(PATHLIKE.search(str(a.metavar or ""))) or a.dest in ("out", "plot", "out_dir")
            if looks:
                assert isinstance(a.type, PathType), f"{name} {option_name(a)}: a path option without a declaration"
            if not a.option_strings and a.dest != "help" and not isinstance(a, argparse._SubParsersAction):
                assert isinstance(a.type, PathType), f"{name} {option_name(a)}: a positional the test cannot fill"


def _victim_and_output(tmp: Path, out_type, how: str):
    """(input file to protect, the output argument naming it by ``how``)."""
    d = tmp / "in"
    d.mkdir()
    if isinstance(out_type, OutputDir):
        name = next(n for n in out_type.names).replace("*", "x")
        target = d / "outdir"  # the output directory; the input is a file it would write
        victim = target.joinpath(*name.split("/"))
        victim.parent.mkdir(parents=True)
    else:
        target = victim = d / "victim.dat"
    victim.write_bytes(b"an input file: must survive\n")
    rel = os.path.relpath(target, d)
    if how == "missing-dir":
        spelled = str(d / "nosuch" / ".." / rel)
    elif how == "two-missing-dirs":
        spelled = str(d / "a" / "b" / ".." / ".." / rel)
    elif how == "symlink":
        spelled = str(tmp / "link")
        os.symlink(target, spelled)
    elif how == "dir-symlink-dotdot":  # ln -> in/sub, so ln/.. is in/ (not tmp/, as lexical .. would say)
        (d / "sub").mkdir()
        os.symlink(d / "sub", tmp / "ln")
        spelled = str(tmp / "ln" / ".." / rel)
    else:  # a hard link of the input where the output goes
        spelled = str(tmp / "hard")
        if isinstance(out_type, OutputDir):
            hard = Path(spelled).joinpath(*os.path.relpath(victim, target).split(os.sep))
            hard.parent.mkdir(parents=True)
            os.link(victim, hard)
        else:
            os.link(victim, spelled)
    return victim, spelled


def _argv(command, in_opt, out_opt, victim, spelled, tmp):
    p = commands()[command]
    positional, optional = [], []
    for a in p._actions:
        if not isinstance(a.type, PathType):
            continue
        opt = option_name(a)
        if opt == in_opt:
            value = str(victim)
        elif opt == out_opt:
            value = spelled
        elif not a.option_strings:  # another input the command needs: a file of its own
            value = str(tmp / f"other-{a.dest}")
            Path(value).write_text("another input\n")
        else:
            continue
        (optional if a.option_strings else positional).extend([opt, value] if a.option_strings else [value])
    return [command] + positional + REQUIRED.get(command, []) + optional


def _tree(root: Path) -> dict:
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() and not p.is_symlink() else None)
            for p in sorted(root.rglob("*"))}


@pytest.mark.parametrize("how", SPELLINGS)
@pytest.mark.parametrize("command, in_opt, out_opt", triples())
def test_an_output_never_lands_on_an_input(capsys, tmp_path, command, in_opt, out_opt, how):
    """Every command x input option x output option x spelling: exit 2, one line, the input byte for byte."""
    out_type = next(a.type for a in commands()[command]._actions if option_name(a) == out_opt)
    victim, spelled = _victim_and_output(tmp_path, out_type, how)
    argv = _argv(command, in_opt, out_opt, victim, spelled, tmp_path)
    before = _tree(tmp_path)
    rc = main(argv)
    _, err = capsys.readouterr()
    assert rc == 2, (argv, err)
    assert len(err.strip().splitlines()) == 1 and "an input is never overwritten" in err, (argv, err)
    assert f"{out_opt} would overwrite" in err and spelled in err
    assert victim.read_bytes() == b"an input file: must survive\n"
    assert _tree(tmp_path) == before, "something was written (a directory made, a file replaced)"


# --------------------------------------------------------------------------- the cases the campaign found

def test_identify_out_through_a_missing_directory_onto_its_data(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--group", "1", "--noise", "none", "--out", "p.csv"]) == 0
    before = Path("p.csv").read_bytes()
    capsys.readouterr()
    assert main(["identify", "p.csv", "--method", "tsvd", "--out", "nosuch/../p.csv"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("zerocal identify: error: nosuch/../p.csv: --out would overwrite p.csv, the measurement "
                          "file"), err
    assert Path("p.csv").read_bytes() == before and not Path("nosuch").exists()


def test_study_out_holding_its_spec_under_a_name_it_writes(capsys, tmp_path, monkeypatch):
    """``study summary.json --out .``: the spec is the summary it would write."""
    monkeypatch.chdir(tmp_path)
    spec = Path("summary.json")
    spec.write_text('trials = 2\nrobots = ["paper"]\n[[design]]\nscheme = "paper"\n[[truth]]\ntheta1 = 1\n')
    before = spec.read_bytes()
    assert main(["study", "summary.json", "--out", "."]) == 2
    assert "the study spec" in capsys.readouterr().err
    assert spec.read_bytes() == before and os.listdir(".") == ["summary.json"]


def test_study_out_holding_a_robot_file_its_spec_names(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    root = Path(__file__).resolve().parents[1]
    Path("st").mkdir()
    robot = Path("st/summary.json")
    robot.write_bytes((root / "examples" / "paper_robot.toml").read_bytes())
    Path("spec.toml").write_text('trials = 2\nrobots = ["st/summary.json"]\n[[design]]\nscheme = "paper"\n'
                                 '[[truth]]\ntheta1 = 1\n')
    before = robot.read_bytes()
    assert main(["study", "spec.toml", "--out", "st"]) == 2
    assert "a robot file of the spec" in capsys.readouterr().err
    assert robot.read_bytes() == before and os.listdir("st") == ["summary.json"]


@pytest.mark.parametrize("name", ["o.json/", "o.json/.", "sub/o.json/"])
def test_a_file_name_ending_in_a_slash_is_refused(capsys, tmp_path, monkeypatch, name):
    monkeypatch.chdir(tmp_path)
    assert main(["design", "--out", name]) == 2
    err = capsys.readouterr().err
    assert "which names a directory: give a file name" in err and len(err.strip().splitlines()) == 1
    assert os.listdir(".") == []


def test_a_255_character_output_name_is_written(capsys, tmp_path, monkeypatch):
    """The longest name the file system takes: the temporary name beside it is short."""
    monkeypatch.chdir(tmp_path)
    name = "d" * 250 + ".json"
    assert len(name) == 255
    assert main(["design", "--out", name]) == 0, capsys.readouterr().err
    assert os.listdir(".") == [name] and Path(name).read_text().startswith("{")


def test_landing_is_where_the_writer_writes(tmp_path):
    """landing() resolves .. after a missing directory and after a symlink to a directory as the write does."""
    from zerocal_sym.io.files import atomic_write_text, landing

    (tmp_path / "a" / "deep").mkdir(parents=True)
    os.symlink(tmp_path / "a" / "deep", tmp_path / "ln")
    for spelled, lands in [(tmp_path / "nosuch" / ".." / "f1", tmp_path / "f1"),
                           (tmp_path / "ln" / ".." / "f2", tmp_path / "a" / "f2"),
                           (tmp_path / "new" / "x" / ".." / "f3", tmp_path / "new" / "f3")]:
        assert landing(spelled) == str(lands)
        atomic_write_text(spelled, "x")
        assert lands.read_text() == "x"
    assert not (tmp_path / "nosuch").exists() and not (tmp_path / "new" / "x").exists()
