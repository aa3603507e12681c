"""A mechanism of one's own, outside the repository, without editing zerocal_sym.

The recipe of docs/new-mechanism.md ("A mechanism of your own, outside the
repository") is run as the page writes it: its derivation and robot file are
taken from the page into a directory outside the repository, and each line of
its command block is run there in a shell (``zerocal regen --derivation``,
``regen --check``, ``zerocal robot``, the contract suite with
``--contract-robot``, ``simulate --noise none`` and ``identify``).  Then: the
data file names the mechanism and is read with its robot file (without a
``# mechanism:`` line too); ``regen --derivation``'s one-line errors; the
inputs hash of a derivation anywhere; a mechanism found through an installed
package's entry point.
"""
import os
import re
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("sympy")

from derivations import codegen  # noqa: E402
from derivations.external import GENERATED_SUFFIX, default_out, derivation_of  # noqa: E402
from zerocal_sym.cli import main  # noqa: E402
from zerocal_sym.io.measurements import load_measurements  # noqa: E402
from zerocal_sym.model import mechanism as mechanism_module  # noqa: E402
from zerocal_sym.model.robot import load_robot  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "new-mechanism.md"
SECTION = "## A mechanism of your own, outside the repository"
NAME = "my_fivebar"
#: the true errors of the page's simulate line, and what identify prints for them (noise none: exact)
TRUTH = {"theta1": "+1.500000", "theta2": "-0.800000", "rMx": "+0.400000", "rMy": "-0.300000"}


def doc_recipe():
    """The files (name -> text) and the shell commands of the page's outside-the-repository section."""
    text = DOC.read_text(encoding="utf-8")
    start = text.index(SECTION)
    end = text.index("\n## ", start + len(SECTION))
    files, commands = {}, []
    for lang, body in re.findall(r"```(\w+)\n(.*?)```", text[start:end], re.S):
        m = re.fullmatch(r"# (\S+\.(?:py|toml))", body.split("\n", 1)[0])
        if m:
            files[m.group(1)] = body
        elif lang == "bash":
            commands += [ln for ln in body.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return files, commands


def shell_env(tmp: Path) -> dict:
    """The environment of the page's commands: ``zerocal`` and ``python`` of this interpreter, ``$ZEROCAL`` the
    checkout, pytest without its cache (nothing written into the checkout)."""
    bin_dir = tmp / "bin"
    bin_dir.mkdir(exist_ok=True)
    for name, body in (("zerocal", f'exec "{sys.executable}" -m zerocal_sym "$@"\n'),
                       ("python", f'exec "{sys.executable}" "$@"\n')):
        f = bin_dir / name
        f.write_text("#!/bin/sh\n" + body)
        f.chmod(f.stat().st_mode | stat.S_IXUSR)
    return {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}", "ZEROCAL": str(ROOT),
            "PYTEST_ADDOPTS": "-p no:cacheprovider"}


@pytest.fixture(scope="module")
def recipe(tmp_path_factory):
    """The page's recipe run in a directory outside the repository: ``(directory, [(command, result)])``."""
    files, commands = doc_recipe()
    assert set(files) == {f"{NAME}.py", f"{NAME}.toml"} and len(commands) >= 6, (files.keys(), commands)
    tmp = tmp_path_factory.mktemp("outside")
    work = tmp / NAME
    work.mkdir()
    assert not work.resolve().is_relative_to(ROOT)
    for name, text in files.items():
        (work / name).write_text(text, encoding="utf-8")
    env = shell_env(tmp)
    runs = [(cmd, subprocess.run(["bash", "-c", cmd], cwd=work, env=env, capture_output=True, text=True,
                                 timeout=1800)) for cmd in commands]
    return work, runs


def _run_of(runs, prefix):
    found = [r for cmd, r in runs if cmd.startswith(prefix)]
    assert found, f"the page has no command starting with {prefix!r}"
    return found[0]


def test_the_page_recipe_runs_outside_the_repository(recipe):
    work, runs = recipe
    for cmd, r in runs:
        assert r.returncode == 0, f"{cmd}\nexit {r.returncode}\n{r.stdout}\n{r.stderr}"
    gen = work / f"{NAME}_generated.py"
    r = _run_of(runs, f"zerocal regen --derivation {NAME}.py")
    assert r.stdout == f"wrote {gen.name} (mechanism {NAME})\n"
    head = gen.read_text()[:800]
    assert f"source: derivations/codegen.py, derivations/geometry.py, derivations/mechanism.py, {NAME}.py" in head
    assert f"DERIVATION = '{NAME}.py'" in head and f"zerocal regen --derivation {NAME}.py" in head
    assert str(work) not in gen.read_text()  # nothing of this machine's paths: the directory may move
    assert "up to date" in _run_of(runs, f"zerocal regen --derivation {NAME}.py --check").stdout
    assert f"({NAME}: planar five-bar" in _run_of(runs, "zerocal robot").stdout
    out = _run_of(runs, "python -m pytest").stdout
    passed = re.search(r"(\d+) passed", out)
    assert passed and int(passed.group(1)) >= 10 and "failed" not in out and "error" not in out, out
    assert (work / "sim.csv").read_text().split("\n")[1] == f"# mechanism: {NAME}"
    ident = _run_of(runs, "zerocal identify").stdout
    for name, value in TRUTH.items():
        assert re.search(rf"^  {name} +=\s+{re.escape(value)} ", ident, re.M), ident


def test_a_data_file_names_the_mechanism_and_is_read_with_its_robot_file(recipe, tmp_path, capsys):
    work, _ = recipe
    robot = load_robot(work / f"{NAME}.toml")  # registers the mechanism in this process
    assert robot.mechanism_name == NAME and NAME in mechanism_module.known_mechanisms()
    sim = work / "sim.csv"
    meas = load_measurements(sim, robot)
    assert meas.mechanism == NAME and meas.theta_cmd.shape == (6, 2)
    # no '# mechanism:' line: read as the robot's mechanism; without a robot as the default one (the columns are
    # the paper robot's too: a file is never matched to a mechanism by its columns)
    bare = tmp_path / "bare.csv"
    bare.write_text("".join(ln for ln in sim.read_text().splitlines(True) if not ln.startswith("# mechanism:")))
    assert load_measurements(bare, robot).mechanism == NAME
    assert load_measurements(bare).mechanism == "planar_2dof"
    rc = main(["identify", str(bare), "--robot", str(work / f"{NAME}.toml"), "--method", "tsvd"])
    out, err = capsys.readouterr()
    assert rc == 0 and f"({NAME})" in out, err
    # a fresh process that read no robot file does not know the mechanism: a one-line error pointing to --robot
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "identify", str(sim)], capture_output=True, text=True,
                       cwd=tmp_path, timeout=600)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, r.stderr
    assert re.match(rf"zerocal identify: error: {re.escape(str(sim))}:2: unknown mechanism '{NAME}' \(known: "
                    r"planar_2dof, .*\bpass --robot\)$", r.stderr), r.stderr


def test_regen_check_after_a_move_and_an_edit(recipe, tmp_path, capsys):
    """The generated module stays fresh when the directory moves; an edit of the derivation makes it stale."""
    work, _ = recipe
    moved = tmp_path / "moved"
    shutil.copytree(work, moved)
    deriv = moved / f"{NAME}.py"
    assert main(["regen", "--derivation", str(deriv), "--check"]) == 0
    assert "up to date" in capsys.readouterr().out
    deriv.write_text(deriv.read_text().replace("with a linear scale, carried", "with a scale, carried"))
    assert main(["regen", "--derivation", str(deriv), "--check"]) == 1
    err = capsys.readouterr().err
    assert f"stale: {default_out(deriv)}" in err and f"zerocal regen --derivation {deriv}" in err
    # --out elsewhere: the DERIVATION path is relative to the generated module, and leads back to the file
    out = moved / "gen" / "other_name.py"
    out.parent.mkdir()
    assert main(["regen", "--derivation", str(deriv), "--out", str(out)]) == 0
    assert capsys.readouterr().out == f"wrote {out} (mechanism {NAME})\n"
    text = out.read_text()
    assert f"DERIVATION = '../{NAME}.py'" in text and "with a scale, carried" in text
    import importlib.util

    spec = importlib.util.spec_from_file_location("zerocal_test_other_name", out)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert derivation_of(mod).description.startswith("planar five-bar (two RR limbs) with a scale")


def test_the_inputs_hash_of_a_derivation_anywhere(tmp_path):
    """An outside file is named by its file name: two copies hash alike wherever they are, an edit differs."""
    a, b = tmp_path / "a" / "m.py", tmp_path / "b" / "m.py"
    for p in (a, b):
        p.parent.mkdir()
        p.write_text("def build():\n    pass\n")
    base = [codegen.HERE / "mechanism.py", codegen.HERE / "codegen.py"]
    assert codegen._relative(a) == "m.py" and codegen._relative(base[0]) == "derivations/mechanism.py"
    assert codegen.input_hash(base + [a]) == codegen.input_hash(base + [b])
    b.write_text("def build():\n    return None\n")
    assert codegen.input_hash(base + [a]) != codegen.input_hash(base + [b])
    assert codegen.input_hash(base + [a]) != codegen.input_hash(base)


def _fivebar_source(**edits):
    text = doc_recipe()[0][f"{NAME}.py"]
    for old, new in edits.items():
        assert old in text
        text = text.replace(old, new)
    return text


def _line(text, start):
    return next(i for i, ln in enumerate(text.splitlines(), 1) if ln.strip().startswith(start))


@pytest.mark.parametrize("case", ["missing", "not_python", "syntax", "import_raises", "no_build", "build_raises",
                                  "not_a_mechanism", "bad_gauge_fix", "builtin_name", "out_is_derivation"])
def test_regen_derivation_errors_are_one_line(case, tmp_path, capsys):
    p = tmp_path / "deriv.py"
    args, line = [], None
    if case == "missing":
        pattern = "no such derivation file"
    elif case == "not_python":
        p = tmp_path / "deriv.txt"
        p.write_text("def build(): pass\n")
        pattern = r"a derivation is a Python file \(.py\) defining build\(\) -> SymbolicMechanism"
    elif case == "syntax":
        p.write_text("import sympy\n\ndef build(:\n    pass\n")
        pattern, line = "not valid Python: ", 3
    elif case == "import_raises":
        p.write_text("import sympy\nimport no_such_module_of_zerocal\n")
        pattern, line = "importing it raised ModuleNotFoundError: No module named 'no_such_module_of_zerocal'", 2
    elif case == "no_build":
        p.write_text("import sympy\nBUILD = 1\n")
        pattern = r"no build\(\) function: a derivation defines build\(\) -> SymbolicMechanism"
    elif case == "build_raises":
        p.write_text("def helper():\n    raise ValueError('the links\\ndo not close')\n\n\ndef build():\n"
                     "    return helper()\n")
        pattern, line = r"build\(\) raised ValueError: the links do not close$", 2
    elif case == "not_a_mechanism":
        p.write_text("def build():\n    return 42\n")
        pattern = r"build\(\) returned int, not a derivations.mechanism.SymbolicMechanism"
    elif case == "bad_gauge_fix":  # derive()'s check of the description, at the line of the derivation calling it
        text = _fivebar_source(**{'gauge_fix=("e1x", "e1y", "e2y")': 'gauge_fix=("e1x", "e1y")'})
        p.write_text(text)
        pattern, line = r"build\(\) raised AssertionError: one fix per gauge$", _line(text, "return derive(mech)")
    elif case == "builtin_name":
        p.write_text("from derivations.mechanisms.planar_2dof import build  # noqa: F401\n")
        pattern = r"mechanism name 'planar_2dof' is a built-in mechanism's: name yours otherwise \(built in: "
    else:
        p.write_text(_fivebar_source())
        args = ["--out", str(p)]
        pattern = r": --out would overwrite .*deriv.py, the derivation \(--derivation\): an input is never overwritten"
    rc = main(["regen", "--derivation", str(p), *args])
    out, err = capsys.readouterr()
    assert rc == 2 and out == "", (rc, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    where = f"{p}:{line}" if line else str(p)
    assert err.startswith(f"zerocal regen: error: {where}: "), err
    assert re.search(pattern, err.strip()), err
    assert not default_out(p).exists() and not (tmp_path / f"deriv{GENERATED_SUFFIX}.py").exists()


@pytest.mark.parametrize("argv,pattern", [
    (["regen", "--out", "x.py"], "--out names the generated module of a --derivation file"),
    (["regen", "--derivation", "d.py", "--out-dir", "gen"], "--out-dir is for the built-in mechanisms"),
])
def test_regen_options_that_do_not_go_together(argv, pattern, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and pattern in err, err
    assert list(tmp_path.iterdir()) == []


def test_a_mechanism_from_an_installed_package_entry_point(monkeypatch, tmp_path):
    """known_mechanisms() lists a package's mechanism from its entry point, and a robot file names it alone.

    The installed package is simulated: a module on sys.path (the paper robot's generated code under another
    name) and ``importlib.metadata.entry_points`` answering for the group with an entry point for it."""
    import importlib.metadata as md

    pkg = tmp_path / "zerocal_test_ep_pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "gen.py").write_text("from zerocal_sym.generated.planar_2dof import *  # noqa: F403\n"
                                "NAME = 'ep_fivebar'\n")
    monkeypatch.syspath_prepend(tmp_path)
    real = md.entry_points
    eps = [md.EntryPoint("ep_fivebar", "zerocal_test_ep_pkg.gen", mechanism_module.ENTRY_POINT_GROUP),
           md.EntryPoint("planar_2dof", "zerocal_test_ep_pkg.gen", mechanism_module.ENTRY_POINT_GROUP)]

    def entry_points(**kw):
        if kw.get("group") == mechanism_module.ENTRY_POINT_GROUP:
            return md.EntryPoints(eps)
        return real(**kw)

    monkeypatch.setattr(md, "entry_points", entry_points)
    known = mechanism_module.known_mechanisms()
    assert known["ep_fivebar"] == "zerocal_test_ep_pkg.gen"
    assert known["planar_2dof"] == mechanism_module.REGISTRY["planar_2dof"]  # a built-in name stays built in
    mech = mechanism_module.Mechanism("ep_fivebar")
    assert mech.name == "ep_fivebar" and mech.joint_names == ["theta1", "theta2"]
    text = (ROOT / "examples" / "paper_robot.toml").read_text().replace('mechanism = "planar_2dof"',
                                                                        'mechanism = "ep_fivebar"')
    assert 'mechanism = "ep_fivebar"' in text
    (tmp_path / "ep.toml").write_text(text)
    robot = load_robot(tmp_path / "ep.toml")
    assert robot.mechanism_name == "ep_fivebar"
    np.testing.assert_array_equal(robot.geometry, load_robot(ROOT / "examples" / "paper_robot.toml").geometry)
    monkeypatch.setattr(md, "entry_points", real)
    assert "ep_fivebar" not in mechanism_module.known_mechanisms()


def test_a_bad_contract_robot_is_a_one_line_usage_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pytest", str(ROOT / "tests" / "test_contract.py"), "--contract-robot",
                        "no_such_robot.toml", "-p", "no:cacheprovider"], capture_output=True, text=True, cwd=tmp_path,
                       timeout=600, env={**os.environ, "PYTEST_ADDOPTS": ""})
    assert r.returncode == pytest.ExitCode.USAGE_ERROR, r.stdout + r.stderr
    assert "ERROR: --contract-robot: no_such_robot.toml: robot file not found" in r.stderr, r.stderr
    assert "Traceback" not in r.stdout + r.stderr
