"""Robot files: the built-in default, validation errors with file/line/key, CLI exit status."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.errors import RobotFileError
from zerocal_sym.model.robot import load_robot, paper_robot

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "paper_robot.toml"


def write(tmp_path, text, name="r.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def base_text(**over):
    keys = dict(ex=80, ey=0, L=375, l=825, H=632, b=480, h=150, cx=0, cy=79, dx=0, dy=51)
    keys.update(over)
    return "".join(f"{k} = {v}\n" for k, v in keys.items() if v is not None)


def test_example_file_equals_builtin():
    r = load_robot(EXAMPLE)
    assert np.array_equal(r.geometry, paper_robot().geometry)
    assert r.sha256 == paper_robot().sha256


def test_per_limb_lengths(tmp_path):
    r = load_robot(write(tmp_path, base_text(L=None, L1=370, L2=380)))
    assert r.param("L1") == 370 and r.param("L2") == 380


@pytest.mark.parametrize("text,pattern", [
    (base_text(H=1100), r"corner \(-b/2, H\+h\) = \(-240, 1250\) mm is unreachable"),
    (base_text(L=-375), r"r\.toml:3: link length L1 must be positive"),
    (base_text(cy=None), r"missing key\(s\): cy"),
    (base_text() + "Lx = 3\n", r"r\.toml:12: unknown key 'Lx'"),
    (base_text(b='"wide"'), r"r\.toml:6: key 'b' must be a number"),
    (base_text(L=0.375, l=0.825, H=0.632, b=0.48, h=0.15), r"look like metres"),
    (base_text() + 'units = "m"\n', r"units = 'm' is not supported"),
    (base_text(h="= 3"), r"not valid TOML"),
    (base_text(b=-480), r"workspace size b must be positive"),
])
def test_bad_robot_files(tmp_path, text, pattern):
    with pytest.raises(RobotFileError, match=pattern):
        load_robot(write(tmp_path, text))


def test_near_singular_workspace(tmp_path):
    with pytest.raises(RobotFileError, match="near-singular"):
        load_robot(write(tmp_path, base_text() + "singularity_margin = 0.8\n"))


def test_missing_file(tmp_path):
    with pytest.raises(RobotFileError, match="not found"):
        load_robot(tmp_path / "nope.toml")


def test_cli_unreachable_corner_exit_2_one_line(tmp_path):
    p = write(tmp_path, base_text(H=1100))
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "robot", "--robot", str(p)],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert "corner (-b/2, H+h)" in lines[0] and "unreachable" in lines[0] and str(p) in lines[0]


def test_cli_robot_json(capsys):
    assert main(["robot", "--json", "--robot", str(EXAMPLE)]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["home_pose_mm"] == pytest.approx([0, 688.186], abs=5e-4)
    assert set(s["corners"]) == {"(-b/2, H)", "(b/2, H)", "(-b/2, H+h)", "(b/2, H+h)"}
    assert s["min_transmission_sine"] > s["singularity_margin"]


def test_table_instead_of_key_names_its_line(tmp_path):
    with pytest.raises(RobotFileError, match=r"r\.toml:12: unknown key 'extra'"):
        load_robot(write(tmp_path, base_text() + "[extra]\nx = 1\n"))
