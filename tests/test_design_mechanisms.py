"""``zerocal design`` on the linear Delta (prismatic joints, mm) and the hexapod (6-D poses, the corner scheme).

The numbers are those of the model pages (the linear Delta's ring table, the hexapod's corner scheme),
compared at the digits the page gives them with; the keys carry the joints' unit; the boundary scheme's K comes
from the workspace (2n on a cylinder, n on a box); ``--optimize`` on both robots.
"""
import json
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.cli import main
from zerocal_sym.model.robot import load_robot, paper_robot

ROOT = Path(__file__).resolve().parents[1]
LINEAR = ("--robot", str(ROOT / "examples" / "linear_delta.toml"))
HEXAPOD = ("--robot", str(ROOT / "examples" / "hexapod.toml"))
ROTARY = ("--robot", str(ROOT / "examples" / "delta.toml"))


def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out


def zj(capsys, *argv):
    return json.loads(zc(capsys, *argv, "--json"))


def one_line_error(capsys, argv, pattern):
    """Exit status 2 and one line on stderr matching ``pattern``, no traceback."""
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == 2, (argv, rc, out, err)
    lines = err.strip().split("\n")
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("zerocal design: error: ") and pattern in lines[0], err
    return lines[0]


def at_digits(value, page: str):
    """``value`` rounds to the page's number ``page`` at the page's digits (half a unit of its last digit)."""
    decimals = len(page.split(".")[1]) if "." in page else 0
    return abs(value - float(page)) <= 0.5 * 10.0 ** -decimals * (1 + 1e-9)


@pytest.fixture(scope="module")
def linear():
    return load_robot(ROOT / "examples" / "linear_delta.toml")


@pytest.fixture(scope="module")
def hexapod():
    return load_robot(ROOT / "examples" / "hexapod.toml")


# --------------------------------------------------------------------------- the linear Delta's ring scheme
def test_linear_delta_ring_numbers_and_keys(capsys):
    d = zj(capsys, "design", *LINEAR, "--scheme", "ring", "--n", "6")
    assert d["n"] == 6 and d["K"] == 12 and d["joint_unit"] == "mm"
    # the page's ring table, n = 6
    assert at_digits(d["kappa_1"], "9.884")
    both, scale = d["crlb_zero_offsets_mm"], d["crlb_zero_offsets_mm_scale_only"]
    assert all(at_digits(v, p) for v, p in zip(both, ("0.00907", "0.00925", "0.00887"))), both
    assert all(at_digits(v, p) for v, p in zip(scale, ("0.00307", "0.00354", "0.00306"))), scale
    # the keys carry the joints' unit; nothing of a revolute robot's
    assert "joints_mm" in d and np.asarray(d["joints_mm"]).shape == (12, 3)
    assert not [k for k in d if k.endswith("_deg") or "_deg_" in k], d.keys()
    assert d["params"] == ["s1", "s2", "s3", "rMx", "rMy"]
    # the robot's noise, described as the robot's (its file's [noise])
    assert d["noise"] == {"sigma_scale_mm": 0.002, "sigma_joint_mm": 0.005}
    assert "Eq. 34" not in d["crlb_noise"] and "robot file [noise]" in d["crlb_noise"]
    # the ring starts above tower 1 (azimuth 90 deg) on the top circle
    P = np.asarray(d["poses"])
    np.testing.assert_allclose(P[0], [0, 100, 220], atol=1e-9)
    np.testing.assert_allclose(P[6], [0, 100, 20], atol=1e-9)


def test_linear_delta_ring_table(capsys):
    d = zj(capsys, "design", *LINEAR)
    assert d["selected_by"].startswith("default") and d["n"] == 6
    table = {row["n"]: row for row in d["n_table"]}
    assert min(table) == 3  # 2n - 1 = 5 changes for the 5 parameters
    assert all(row["K"] == 2 * n for n, row in table.items())
    for n, cond in ((3, "16.36"), (4, "14.43"), (5, "10.69"), (6, "9.884")):
        assert at_digits(table[n]["kappa_1"], cond), (n, table[n]["kappa_1"])
    # the RMS of the page's per-carriage CRLB at n = 4 (0.01060, 0.01031, 0.00995 mm)
    rms4 = float(np.sqrt(np.mean(np.square([0.01060, 0.01031, 0.00995]))))
    assert table[4]["crlb_rms_mm"] == pytest.approx(rms4, abs=1e-5)
    assert "crlb_rms_mm_scale_only" in table[4]
    text = zc(capsys, "design", *LINEAR)
    assert "kappa_1 = 9.884" in text and " mm (scale error alone)" in text and "<- default" in text


def test_revolute_keys_unchanged(capsys):
    d = zj(capsys, "design", *ROTARY, "--n", "6")
    for key in ("joints_deg", "crlb_zero_offsets_deg", "crlb_zero_offsets_deg_scale_only"):
        assert key in d, key
    assert not [k for k in d if k.endswith("_mm") and k.startswith(("joints", "crlb"))]
    assert d["crlb_noise"] == "paper (Eq. 34 scale + Eq. 35 servo)"
    p = zj(capsys, "design", "--n", "3")
    assert "crlb_zero_offsets_deg" in p and "joints_deg" in p and p["K"] == 6


# --------------------------------------------------------------------------- the hexapod's corner scheme
def test_hexapod_corners_numbers(capsys):
    d = zj(capsys, "design", *HEXAPOD, "--scheme", "corners", "--n", "64")
    assert d["n"] == 64 and d["K"] == 64 and d["scheme"] == "corners"
    assert at_digits(d["kappa_1"], "138.8")
    both = ("0.02796", "0.02827", "0.02981", "0.03333", "0.03078", "0.02729")
    scale = ("0.01327", "0.01317", "0.01637", "0.01716", "0.01561", "0.01367")
    assert all(at_digits(v, p) for v, p in zip(d["crlb_zero_offsets_mm"], both)), d["crlb_zero_offsets_mm"]
    assert all(at_digits(v, p) for v, p in zip(d["crlb_zero_offsets_mm_scale_only"], scale))
    assert d["params"] == ["L1", "L2", "L3", "L4", "L5", "L6", "rMx", "rMy", "rMz", "ddx", "ddy", "ddz"]
    # poses in file units (orientations in degrees), corner 0 at every minimum
    assert d["pose_units"] == ["mm", "mm", "mm", "deg", "deg", "deg"]
    P = np.asarray(d["poses"])
    np.testing.assert_allclose(P[0], [-60, -60, 250, -10, -10, -15], atol=1e-9)
    np.testing.assert_allclose(P[63], [60, 60, 350, 10, 10, 15], atol=1e-9)
    L = np.asarray(d["joints_mm"])
    home = load_robot(ROOT / "examples" / "hexapod.toml").home_joints()
    assert L.shape == (64, 6) and all(at_digits(h, "339.026") for h in home)  # the page's home leg length
    # the page's leg range over the corners: home -106.61 / +122.70 mm
    assert at_digits(home[0] - L.min(), "106.61") and at_digits(L.max() - home[0], "122.70")


def test_hexapod_fractions_and_table(capsys):
    d16 = zj(capsys, "design", *HEXAPOD, "--n", "16")
    assert d16["K"] == 16 and at_digits(d16["kappa_1"], "366.4")
    both, scale = d16["crlb_zero_offsets_mm"], d16["crlb_zero_offsets_mm_scale_only"]
    assert at_digits(min(scale), "0.049") and at_digits(max(scale), "0.070")  # the page: 0.049-0.070
    assert at_digits(min(both), "0.093") and at_digits(max(both), "0.133")  # and 0.093-0.133 mm
    d = zj(capsys, "design", *HEXAPOD)
    assert d["n"] == 64 and [row["n"] for row in d["n_table"]] == [16, 32, 64]
    assert all(row["K"] == row["n"] for row in d["n_table"])
    one_line_error(capsys, ["design", *HEXAPOD, "--n", "20"], "64")
    one_line_error(capsys, ["design", *HEXAPOD, "--n", "8"], "too few")
    one_line_error(capsys, ["design", *HEXAPOD, "--scheme", "ring"], "--scheme corners")


def test_scheme_sizes(linear, hexapod):
    from zerocal_sym.cli import _common
    from zerocal_sym.cli._design_scheme import table_parameters

    planar = paper_robot()
    for robot, nmin, ndef, kdef in ((planar, 3, 3, 6), (linear, 3, 6, 12), (hexapod, 16, 64, 64)):
        assert _common.min_n(robot) == nmin
        assert _common.default_n(robot) == ndef
        assert robot.workspace.scheme_size(ndef) == kdef
    assert table_parameters(hexapod, 64, 16) == [16, 32, 64]
    assert table_parameters(linear, 6, 3) == list(range(3, 13))
    P, n = _common.scheme_poses(hexapod, None, 32)
    assert n == 32 and P.shape == (32, 6)
    with pytest.raises(Exception, match="too few"):
        _common.scheme_poses(linear, None, 2)


def test_corner_rule_baseline(hexapod):
    from zerocal_sym.design.optimize import choose_baseline, paper_baseline, scheme_parameter

    assert [scheme_parameter(hexapod.workspace, K) for K in (16, 20, 32, 64)] == [16, None, 32, 64]
    np.testing.assert_array_equal(paper_baseline(hexapod, 64), hexapod.workspace.boundary_scheme(64))
    P20 = paper_baseline(hexapod, 20)
    np.testing.assert_array_equal(P20, hexapod.workspace.boundary_scheme(32)[:20])  # the 32 fraction's first 20
    cons = design.make_constraints(hexapod)
    P, label, note, _ = choose_baseline(hexapod, 64, cons)
    assert label == "corners scheme" and note is None and len(P) == 64
    P, label, note, _ = choose_baseline(hexapod, 20, cons)
    assert P is not None and "20 corners" in label


# --------------------------------------------------------------------------- units of the design layer
def test_box_region_in_file_units(hexapod):
    reg = design.make_region(hexapod, (-30, 30, -30, 30, 260, 340, -5, 5, -5, 5, -10, 10))
    assert reg.kind == "box"
    np.testing.assert_allclose(reg.lo[3:], np.radians([-5, -5, -10]))
    assert reg.as_list()[6:] == pytest.approx([-5, 5, -5, 5, -10, 10])
    assert "roll in [-5, 5] deg" in reg.describe()
    with pytest.raises(design.DesignError, match="X_MIN X_MAX"):
        design.make_region(hexapod, (-30, 30, -30, 30))
    with pytest.raises(design.DesignError, match="orientation"):
        design.make_region(hexapod, "reachable")
    ws = design.workspace_region(hexapod)
    assert len(ws.grid(3)) == 3 ** 6 and np.all(ws.contains(hexapod.workspace.boundary_scheme(64)))


def test_pose_separation_counts_degrees(hexapod):
    from zerocal_sym.design.terms import pose_distances

    P = hexapod.workspace.boundary_scheme(64)
    # corners 0 and 8 differ in roll alone, by 20 deg: 20 "mm" apart
    assert pose_distances(hexapod, P[[0]], P[[8]])[0, 0] == pytest.approx(20.0)
    cons = design.make_constraints(hexapod)
    assert design.check_design(hexapod, P, cons) == []  # the 64 corners are distinct poses
    close = np.array([P[0], P[0] + np.r_[0, 0, 0, np.radians(0.5), 0, 0]])
    assert any("apart" in v for v in design.check_design(hexapod, close, cons))


def test_joint_limits_in_the_joints_unit(linear, capsys):
    with pytest.raises(design.DesignError, match="joint_limits in mm"):
        design.make_constraints(linear, joint_limits_deg=((200, 500),) * 3)
    cons = design.make_constraints(linear, joint_limits=((220, 530),) * 3)
    assert cons.to_dict()["joint_limits_mm"] == [[220.0, 530.0]] * 3 and cons.joint_limits_deg is None
    P = linear.workspace.boundary_scheme(6)
    assert design.check_design(linear, P, cons) == []
    tight = design.make_constraints(linear, joint_limits=((220, 500),) * 3)
    viol = design.check_design(linear, P, tight)
    assert viol and all(" mm outside [220, 500]" in v for v in viol)
    # revolute: the degrees of old
    planar = paper_robot()
    assert design.make_constraints(planar, joint_limits_deg=((0, 60), (150, 250))).joint_limits == ((0, 60),
                                                                                                    (150, 250))


def test_unit_options_on_the_command_line(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "1000")  # one line per option
    with pytest.raises(SystemExit) as exc:
        main(["design", "--help"])
    assert exc.value.code == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert ("--joint-limits LIM [LIM ...] joint limits in the joints' unit: deg for revolute, mm for prismatic "
            "joints") in help_text
    assert ("--target-crlb X the fewest poses whose design reaches this RMS zero-offset CRLB, in the joints' "
            "unit: deg for revolute, mm for prismatic joints") in help_text
    one_line_error(capsys, ["design", *LINEAR, "--target-crlb-deg", "0.01"], "--target-crlb-mm")
    one_line_error(capsys, ["design", *LINEAR, "--optimize", "--joint-limits-deg", "0", "1", "0", "1", "0", "1"],
                   "--joint-limits-mm")
    one_line_error(capsys, ["design", "--target-crlb-mm", "0.3"], "--target-crlb-deg")
    one_line_error(capsys, ["design", "--target-crlb", "0.3", "--target-crlb-deg", "0.3"], "once")
    one_line_error(capsys, ["design", *LINEAR, "--optimize", "--joint-limits-mm", "0", "1"], "(mm; joints s1")
    one_line_error(capsys, ["design", *HEXAPOD, "--optimize", "--plot", "x.png"], "--json")


def test_default_true_errors(linear, hexapod):
    e = design.default_true_errors(linear)
    d = linear.errors.to_dict(e, user=True)
    assert d["s1"] == 0.3 and d["rMx"] == 1.0 and d["rMz"] == 0.0  # rMz is not identified: held at zero
    e = design.default_true_errors(hexapod)
    assert hexapod.errors.to_dict(e)["L6"] == 0.05 and hexapod.errors.to_dict(e)["ddz"] == -0.05


def test_target_crlb_in_mm(capsys):
    d = zj(capsys, "design", *LINEAR, "--target-crlb", "0.006")
    assert d["unit"] == "mm" and d["target_crlb_mm"] == 0.006 and d["crlb_rms_mm"] <= 0.006
    assert d["K"] >= d["K_lower_bound"] and len(d["joints_mm"]) == d["K"]
    assert float(np.sqrt(np.mean(np.square(d["crlb_zero_offsets_mm"])))) == pytest.approx(d["crlb_rms_mm"], rel=1e-9)


def test_singular_candidates_are_a_design_error(hexapod):
    from zerocal_sym.design.measure import solve_measure
    from zerocal_sym.design.posemodel import PoseModel

    X = np.array([hexapod.workspace.corner(k) for k in range(16)])  # the page: rank 11 of 12
    with pytest.raises(design.DesignError, match="cannot identify"):
        solve_measure(PoseModel(hexapod, X, hexapod.noise, "crlb"), "crlb")


# --------------------------------------------------------------------------- --optimize
@pytest.mark.slow
def test_optimize_linear_delta(capsys):
    d = zj(capsys, "design", *LINEAR, "--optimize", "--K", "12", "--starts", "2")
    assert d["K"] == 12 and d["baseline"] == "ring" and d["joint_unit"] == "mm"
    assert d["criterion"]["units"] == "mm" and d["criterion"]["units_all"]["mse"] == "mm"
    assert d["ratio"]["crlb_rms_design_over_paper"] < 1.0  # better than the ring scheme with the same K
    assert d["criterion"]["value"] == pytest.approx(d["crlb_rms_mm"], rel=1e-9)
    assert d["paper"]["crlb_rms_mm"] == pytest.approx(
        float(np.sqrt(np.mean(np.square([0.00907, 0.00925, 0.00887])))), abs=1e-5)  # the ring at n = 6
    cert = d["certificate"]
    assert cert["bound"] <= d["crlb_rms_mm"] and 0 < cert["efficiency_lower_bound"] <= 1
    P = np.asarray(d["poses"])
    assert np.all(np.hypot(P[:, 0], P[:, 1]) <= 100 + 1e-6) and np.all((P[:, 2] >= 20 - 1e-6) & (P[:, 2] <= 220 + 1e-6))
    assert d["violations"] == [] and "joints_mm" in d and "worst_case_mm" in d["bias"]
    assert d["noise"]["sigma_joint_mm"] == 0.005


@pytest.mark.slow
def test_optimize_hexapod_64(capsys):
    d = zj(capsys, "design", *HEXAPOD, "--optimize", "--K", "64", "--criterion", "crlb")
    assert d["K"] == 64 and d["baseline"] == "corners" and d["baseline_scheme"] == "corners scheme"
    corners = d["paper"]
    assert at_digits(corners["kappa"], "138.8")
    assert d["crlb_rms_mm"] <= corners["crlb_rms_mm"]  # no worse than the corner scheme
    cert = d["certificate"]
    assert cert["criterion"] == "crlb" and cert["bound"] <= d["crlb_rms_mm"]
    assert 0 < cert["efficiency_lower_bound"] <= 1 and "3-per-coordinate grid" in cert["candidates"]
    P = np.asarray(d["poses"])
    assert P.shape == (64, 6) and d["pose_units"] == ["mm", "mm", "mm", "deg", "deg", "deg"]
    tol = 1e-6
    assert np.all(np.abs(P[:, :2]) <= 60 + tol) and np.all((P[:, 2] >= 250 - tol) & (P[:, 2] <= 350 + tol))
    assert np.all(np.abs(P[:, 3:5]) <= 10 + tol) and np.all(np.abs(P[:, 5]) <= 15 + tol)
    assert d["violations"] == []
    L = np.asarray(d["joints_mm"])
    home = 339.026  # the page's home leg length; stroke 125 mm either side
    assert np.all(np.abs(L - home) <= 125 + 1e-3)
