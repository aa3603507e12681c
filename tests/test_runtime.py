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


def test_source_error_names_come_from_the_generated_mechanism(robot):
    """One source of truth: the numeric layers read the derivation's names, roles and order."""
    from zerocal_sym.generated import planar_2dof as gen

    assert robot.errors.names == tuple(gen.SOURCE_ERROR_NAMES)
    assert robot.errors.zero_offsets == ("theta1", "theta2") and robot.errors.measuring == ("rMx", "rMy")
    assert robot.mechanism.geometry_names[:8] == ["e1x", "e1y", "e2x", "e2y", "L1", "L2", "l1", "l2"]
