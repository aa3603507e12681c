"""The runtime never imports sympy; the CLI answers --help."""
import subprocess
import sys


def test_import_does_not_pull_sympy():
    code = ("import sys, zerocal_sym, zerocal_sym.model.kinematics, zerocal_sym.identify.fisher, zerocal_sym.io.measurements; "
            "from zerocal_sym.model.robot import paper_robot; paper_robot().home_pose(); "
            "assert 'sympy' not in sys.modules, 'sympy imported'")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_cli_commands_do_not_pull_sympy():
    code = ("import sys; from zerocal_sym.cli import main; rc = main(['robot', '--json']); "
            "assert rc == 0; assert 'sympy' not in sys.modules, 'sympy imported'")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_help():
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "--help"], capture_output=True, text=True)
    assert r.returncode == 0
    assert "robot" in r.stdout and "regen" in r.stdout


def test_help_path_does_not_import_casadi():
    """Command modules import heavy packages inside run(): --help stays fast."""
    code = ("import sys; from zerocal_sym.cli import build_parser; build_parser(); "
            "heavy = [m for m in ('casadi', 'sympy', 'matplotlib', 'scipy') if m in sys.modules]; "
            "assert not heavy, heavy")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_source_error_names_match_the_generated_mechanism(robot):
    """The numeric layers' parameter order is the derivation's (one source of truth)."""
    from zerocal_sym.model.noise import SOURCE_ERROR_NAMES

    assert tuple(robot.mechanism.source_error_names) == SOURCE_ERROR_NAMES
    assert robot.mechanism.geometry_names[:8] == ["e1x", "e1y", "e2x", "e2y", "L1", "L2", "l1", "l2"]
