"""What one command makes, another accepts: the poses of any design (orientations in degrees; a region of the
design's own beyond the robot file's workspace) and a compensated round, through simulate, identify,
compensate --template and verify; a design made for another mechanism is refused by its mechanism line."""
import json
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.io.poses import load_poses
from zerocal_sym.model.robot import load_robot

ROOT = Path(__file__).resolve().parents[1]
DELTA = str(ROOT / "examples" / "delta.toml")
HEXAPOD = str(ROOT / "examples" / "hexapod.toml")
#: ``zerocal design --optimize --region reachable --bounds -2000 2000 450 2000 --out d.json`` on the paper's robot:
#: its poses (all outside the robot file's 480 x 150 mm workspace) and constraints, as the command wrote them
REACHABLE_DESIGN = {
    "mechanism": "planar_2dof", "pose_names": ["x", "y"], "pose_units": ["mm", "mm"],
    "poses": [[644.9473919112922, 450.0000000464458], [-1020.9976988302893, 450.00000002101234],
              [1020.9976985455837, 450.00000002089786], [455.06158540660005, 1068.2732789556128],
              [-445.5198148013008, 1072.9993583220821], [-644.9473919173304, 450.00000004347066]],
    "constraints": {"region_kind": "reachable", "region_mm": [-2000.0, 2000.0, 450.0, 2000.0], "region_clip": "box",
                    "region": "reachable set within x in [-2000, 2000], y in [450, 2000] (bounding box "
                              "[-1031.26, 1032.4], [450, 1197.19])",
                    "travel_mm": 350.0, "travel_mode": "range", "singularity_margin": 0.2, "joint_limits_deg": None,
                    "min_separation_mm": 1.0},
}
#: the largest error of a noise-free identification (mm, deg): the Gauss-Newton stop, far below any noise
EXACT = 1e-6


def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out, err


def offsets(path, unit):
    return np.array(json.loads(Path(path).read_text())[f"zero_offsets_{unit}"])


def test_a_hexapod_design_is_simulated_identified_and_templated(tmp_path, capsys):
    """The corner scheme's JSON (roll, pitch, yaw in degrees) and the same poses as a CSV: read in degrees, inside
    the workspace, used by simulate, identify and compensate --template (they were refused as outside the box)."""
    d, data, res = tmp_path / "d.json", tmp_path / "d.csv", tmp_path / "r.json"
    zc(capsys, "design", "--robot", HEXAPOD, "--scheme", "corners", "--n", "16", "--out", d)
    truth = {"L1": 0.3, "L2": -0.2, "L3": 0.1, "L4": 0.25, "L5": -0.15, "L6": 0.05}
    sets = [a for k, v in truth.items() for a in ("--set", f"{k}={v}")]
    zc(capsys, "simulate", "--robot", HEXAPOD, "--poses", d, *sets, "--noise", "none", "--out", data)
    zc(capsys, "identify", data, "--robot", HEXAPOD, "--out", res)
    np.testing.assert_allclose(offsets(res, "mm"), list(truth.values()), atol=EXACT)
    zc(capsys, "compensate", res, "--robot", HEXAPOD, "--poses", d, "--template", "--out", tmp_path / "t.csv")
    robot = load_robot(HEXAPOD)
    design = json.loads(d.read_text())
    csv = tmp_path / "p.csv"
    csv.write_text("pose,x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg\n"
                   + "".join(f"{k}," + ",".join(map(repr, p)) + "\n" for k, p in enumerate(design["poses"])))
    P = load_poses(csv, robot)
    np.testing.assert_array_equal(P, load_poses(d, robot))
    np.testing.assert_allclose(np.degrees(P[:, 3:]), np.array(design["poses"])[:, 3:], rtol=1e-15)


def test_a_design_made_for_another_mechanism_is_refused(tmp_path, capsys):
    d = tmp_path / "d.json"
    d.write_text(json.dumps({**REACHABLE_DESIGN, "poses": [[0, 0, -800]], "mechanism": "delta_linear",
                             "pose_units": ["mm"] * 3}))
    _, err = zc(capsys, "simulate", "--robot", DELTA, "--poses", d, "--set", "theta1=1", "--out", tmp_path / "o.csv",
                expect=2)
    assert "made for mechanism 'delta_linear' and are read as mechanism 'delta_rotary'" in err, err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "o.csv").exists()


def test_a_compensated_delta_round_with_offsets_near_the_limit_is_verified(tmp_path, capsys):
    """The rotary Delta's round 2 after offsets (3.4, 2.9, -1.0) deg: its commands are IK - compensation, tens of mm
    from the targets; checked with the compensation undone (it was refused as outside the workspace)."""
    truth = ("--set", "theta1=3.4", "--set", "theta2=2.9", "--set", "theta3=-1.0", "--noise", "none")
    d1, d2, res = tmp_path / "d1.csv", tmp_path / "d2.csv", tmp_path / "r.json"
    zc(capsys, "simulate", "--robot", DELTA, *truth, "--out", d1)
    zc(capsys, "identify", d1, "--robot", DELTA, "--out", res)
    est = offsets(res, "deg")
    np.testing.assert_allclose(est, [3.4, 2.9, -1.0], atol=EXACT)
    zc(capsys, "simulate", "--robot", DELTA, *truth, "--compensation", *(repr(float(v)) for v in est), "--out", d2)
    out, _ = zc(capsys, "verify", res, d2, "--robot", DELTA, "--noise", "none")
    assert "PASS" in out, out
    zc(capsys, "compensate", res, "--robot", DELTA, "--scheme", "ring", "--template", "--out", tmp_path / "t.csv")


def test_a_reachable_region_design_travels_with_its_poses(tmp_path, capsys):
    """Poses of a design on the reachable region, outside the workspace: simulate writes the region into the data,
    identify, compensate --template and verify accept them (checked for reachability and the design's margin)."""
    d, data, res, round2 = (tmp_path / n for n in ("d.json", "d.csv", "r.json", "d2.csv"))
    d.write_text(json.dumps(REACHABLE_DESIGN))
    truth = ("--set", "theta1=1", "--set", "theta2=-0.5", "--noise", "none")
    zc(capsys, "simulate", "--poses", d, *truth, "--out", data)
    text = data.read_text()
    assert "# region: reachable set within" in text and "# region_singularity_margin: 0.2" in text
    zc(capsys, "identify", data, "--out", res)
    np.testing.assert_allclose(offsets(res, "deg"), [1, -0.5], atol=EXACT)
    zc(capsys, "compensate", res, "--poses", d, "--template", "--out", tmp_path / "t.csv")
    assert "# region: reachable set within" in (tmp_path / "t.csv").read_text()
    applied = [repr(float(v)) for v in offsets(res, "deg")]
    zc(capsys, "simulate", "--poses", d, *truth, "--compensation", *applied, "--out", round2)
    out, _ = zc(capsys, "verify", res, round2, "--noise", "none")
    assert "PASS" in out, out
    plain = tmp_path / "plain.json"  # the same poses without the design's region: outside the workspace
    plain.write_text(json.dumps({k: v for k, v in REACHABLE_DESIGN.items() if k != "constraints"}))
    _, err = zc(capsys, "simulate", "--poses", plain, *truth, "--out", tmp_path / "x.csv", expect=2)
    assert "is outside the workspace" in err


@pytest.mark.parametrize("edit, message", [
    (("# region_singularity_margin: 0.2", "# region_singularity_margin: 2"), "must be a number in [0, 1), got '2'"),
    (("# region_singularity_margin: 0.2\n", ""), "'# region:' and '# region_singularity_margin:' go together"),
    (("# region_singularity_margin: 0.2", "# region_singularity_margin: 0.95"), "too close to a singular"),
    (("# region: reachable", "# region: reachable\n# region: another"), "given twice with different values"),
])
def test_a_round_s_region_lines_are_checked(tmp_path, capsys, edit, message):
    d, data = tmp_path / "d.json", tmp_path / "d.csv"
    d.write_text(json.dumps(REACHABLE_DESIGN))
    zc(capsys, "simulate", "--poses", d, "--set", "theta1=1", "--out", data)
    data.write_text(data.read_text().replace(*edit, 1))
    _, err = zc(capsys, "identify", data, expect=2)
    assert message in err and len(err.strip().splitlines()) == 1, err


def test_compare_s_loop_stops_at_verify_s_threshold_in_the_joints_unit(capsys):
    """compare's loop and verify judge a compensation alike: mu0 0.02 mm on a linear Delta (was 0.1, read as mm)."""
    linear = str(ROOT / "examples" / "linear_delta.toml")
    for robot, key, mu0 in ((linear, "mu0_mm", 0.02), (DELTA, "mu0_deg", 0.1)):
        out, _ = zc(capsys, "compare", "--robot", robot, "--set", f"{'s1' if robot == linear else 'theta1'}=0.5",
                    "--trials", "1", "--methods", "tsvd-loop", "--quiet", "--json")
        assert json.loads(out)["settings"][key] == mu0


def test_compare_s_table_names_prismatic_offsets_by_their_joints(capsys):
    """The linear Delta's columns are ds1, ds2, ds3 [mm] (not dth1 ... in mm); the angles keep dth1, dth2 [deg]."""
    out, _ = zc(capsys, "compare", "--robot", ROOT / "examples" / "linear_delta.toml", "--set", "s1=0.5", "--trials",
                "1", "--methods", "tsvd", "--quiet")
    assert "bias ds1,ds2,ds3 [mm]" in out and "dth" not in out, out
