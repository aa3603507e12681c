"""Refusals that say where and why, on the prismatic mechanisms: a true robot that does not assemble names its pose;
a pose set that cannot identify the mechanism's set names its null direction in the errors' units, in every
command; a robot file's mechanism module is an input no output may overwrite; one value per compensation line."""
import json
from pathlib import Path

import pytest

from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]
HEXAPOD = str(ROOT / "examples" / "hexapod.toml")
LINEAR = str(ROOT / "examples" / "linear_delta.toml")
#: the hexapod's first 16 corners (pitch and yaw at their minima, only roll turns): rank 11 of 12; the null
#: direction is the part of d along the only rotation axis, the same as a constant rM = Rz(-15) Ry(-10) e_x
NULL_TEXT = "rMx = +0.951, rMy = -0.255, rMz = +0.174, ddx = +1 mm"


def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out, err


def one_line(err):
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_simulate_names_the_pose_where_the_true_robot_does_not_assemble(tmp_path, capsys):
    out = tmp_path / "d.csv"
    _, err = zc(capsys, "simulate", "--robot", HEXAPOD, "--set", "L1=200", "--noise", "none", "--out", out, expect=2)
    assert "pose 1 (60, -60, 250 mm, -10, -10, -15 deg): with these true errors" in one_line(err)
    assert not out.exists()


@pytest.fixture(scope="module")
def first16(tmp_path_factory):
    """The first 16 corners as a pose file and a noise-free round on them."""
    d = tmp_path_factory.mktemp("first16")
    poses = d / "p.csv"
    rows = [[(-60, 60)[k & 1], (-60, 60)[k >> 1 & 1], (250, 350)[k >> 2 & 1], (-10, 10)[k >> 3 & 1], -10, -15]
            for k in range(16)]
    poses.write_text("pose,x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg\n"
                     + "".join(f"{k}," + ",".join(map(str, r)) + "\n" for k, r in enumerate(rows)))
    data = d / "d.csv"
    assert main(["simulate", "--robot", HEXAPOD, "--poses", str(poses), "--set", "L1=0.3", "--noise", "none",
                 "--out", str(data)]) == 0
    return poses, data


@pytest.mark.parametrize("argv", [
    ("identify", "{data}", "--robot", HEXAPOD),
    ("identify", "{data}", "--robot", HEXAPOD, "--method", "tsvd"),
    ("compensate", "--robot", HEXAPOD, "--poses", "{poses}", "--template", "--out", "{tmp}/t.csv"),
    ("compare", "--robot", HEXAPOD, "--poses", "{poses}", "--set", "L1=0.3", "--trials", "2", "--quiet"),
], ids=["identify-nlls", "identify-tsvd", "compensate-template", "compare"])
def test_a_pose_set_that_cannot_identify_is_refused_naming_its_null_direction(tmp_path, capsys, first16, argv):
    poses, data = first16
    args = [a.format(data=data, poses=poses, tmp=tmp_path) for a in argv]
    _, err = zc(capsys, *args, expect=2)
    assert NULL_TEXT in one_line(err)
    assert not (tmp_path / "t.csv").exists()


def test_a_robot_file_s_mechanism_module_is_never_overwritten(tmp_path, capsys, monkeypatch):
    """The module a robot file names (``mechanism_module``) is read with it: an output onto it is refused."""
    monkeypatch.chdir(tmp_path)
    Path("robot.toml").write_text((ROOT / "examples" / "paper_robot.toml").read_text().replace(
        'mechanism = "planar_2dof"', 'mechanism = "mine"\nmechanism_module = "mine_generated.py"'))
    module = Path("mine_generated.py")
    module.write_text("# the generated module\n")
    for out in ("mine_generated.py", "nosuch/../mine_generated.py"):
        _, err = zc(capsys, "simulate", "--robot", "robot.toml", "--group", "1", "--out", out, expect=2)
        assert "the mechanism module of the robot file (--robot)" in one_line(err)
    assert module.read_text() == "# the generated module\n" and not Path("nosuch").exists()


def test_one_value_per_compensation_line_in_mm(tmp_path, capsys):
    data = tmp_path / "d.csv"
    zc(capsys, "simulate", "--robot", LINEAR, "--set", "s1=0.5", "--out", data)
    text = data.read_text()
    assert "# compensation_mm: 0 0 0\n" in text
    data.write_text(text.replace("# compensation_mm: 0 0 0\n", "# compensation_mm: 0 0 0\n# compensation_mm: 1 1 1\n"))
    _, err = zc(capsys, "identify", data, "--robot", LINEAR, expect=2)
    assert "'# compensation_mm:' given twice with different values" in one_line(err)


@pytest.mark.parametrize("argv", [("compare", "--set", "theta1=1", "--trials", "1000000000000"),
                                  ("design", "--optimize", "--verify", "1000000000000")])
def test_a_monte_carlo_larger_than_memory_holds_is_refused_before_any_work(capsys, argv):
    """``compare --trials 1e12`` grew by about 60 MB/s with no output: refused at once, pointing to a study."""
    _, err = zc(capsys, *argv, expect=2)
    assert "must be" in one_line(err) and "1,000,000" in err and "zerocal study" in err


def test_verify_says_when_mu0_is_below_what_the_round_resolves(tmp_path, capsys):
    """A mu0 under the new offsets' 1 sigma is a test the round passes only by chance: said, and in the JSON."""
    truth = ("--set", "s1=0.8", "--set", "s2=-0.5", "--set", "s3=0.3")
    d1, d2, res = tmp_path / "d1.csv", tmp_path / "d2.csv", tmp_path / "r.json"
    zc(capsys, "simulate", "--robot", LINEAR, *truth, "--out", d1)
    zc(capsys, "identify", d1, "--robot", LINEAR, "--out", res)
    est = json.loads(res.read_text())["zero_offsets_mm"]
    zc(capsys, "simulate", "--robot", LINEAR, *truth, "--compensation", *map(str, est), "--seed", "1", "--out", d2)
    rc = main(["verify", str(res), str(d2), "--robot", LINEAR, "--json"])
    report = json.loads(capsys.readouterr().out)["verification"]
    assert not report["mu0_below_std"] and report["mu0_mm"] > report["std_rms_new_offsets_mm"] > 0, report
    assert rc == (0 if report["passed"] else 1)
    out, _ = zc(capsys, "verify", res, d2, "--robot", LINEAR, "--mu0", "0.001", expect=1)
    assert "note: mu0 = 0.001 mm is not above the new offsets' uncertainty" in out, out
