"""Every command on the rotary Delta (examples/delta.toml, docs/delta.md) through ``--robot``."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.io import measurements as data

ROOT = Path(__file__).resolve().parents[1]
DELTA = str(ROOT / "examples" / "delta.toml")
R = ("--robot", DELTA)
PLANAR_EXAMPLE = ROOT / "examples" / "measurements_example.csv"
SETS = ("--set", "theta1=2", "--set", "theta2=-1", "--set", "theta3=0.5")
PNG = b"\x89PNG\r\n\x1a\n"


def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out


def one_line_error(capsys, argv, pattern, command=None, outfile=None):
    """Exit status 2, one line on stderr naming the command, matching ``pattern``; no output file."""
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == 2, (argv, rc, out, err)
    lines = err.strip().split("\n")
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"zerocal {command or argv[0]}: error: "), err
    assert pattern in lines[0], err
    if outfile is not None:
        assert not Path(outfile).exists(), "an output file was written"
        assert not [p for p in Path(outfile).parent.iterdir() if p.name.startswith("." + Path(outfile).name)]
    return lines[0]


@pytest.fixture(scope="module")
def ring6(tmp_path_factory):
    """A noise-free round on the ring scheme, n = 6, offsets (2, -1, 0.5) deg."""
    d = tmp_path_factory.mktemp("delta") / "d.csv"
    assert main(["simulate", *R, "--scheme", "ring", "--n", "6", *SETS, "--noise", "none", "--out", str(d)]) == 0
    return d


# --------------------------------------------------------------------------- robot, design

def test_robot_json(capsys):
    s = json.loads(zc(capsys, "robot", *R, "--json"))
    assert s["mechanism"] == "delta_rotary" and s["workspace"] == "cylinder"
    np.testing.assert_allclose(s["home_pose_mm"], [0.0, 0.0, -624.500], atol=5e-4)
    lo, hi = s["joint_range_deg"]
    assert lo == pytest.approx(-7.003, abs=1e-3) and hi == pytest.approx(59.13, abs=0.01)  # reference values
    assert s["fk_ik_max_error_mm"] < 1e-9
    assert s["joint_names"] == ["theta1", "theta2", "theta3"] and s["pose_names"] == ["x", "y", "z"]
    assert all(len(c["pose_mm"]) == 3 and len(c["joints_deg"]) == 3 for c in s["corners"].values())
    out = zc(capsys, "robot", *R)
    assert "(0.000, 0.000, -624.500) mm" in out and "delta_rotary" in out and s["sha256"] in out


def test_design_ring_json(capsys):
    d = json.loads(zc(capsys, "design", *R, "--scheme", "ring", "--n", "6", "--json"))
    for key in ("n", "poses", "kappa_1", "crlb_zero_offsets_deg"):
        assert key in d, key
    assert "kappa_m" not in d and "eps_rule_n" not in d  # the paper's eps rule is the paper scheme's
    assert d["n"] == 6 and d["K"] == 12 and d["scheme"] == "ring"
    P = np.array(d["poses"])
    assert P.shape == (12, 3)
    np.testing.assert_allclose(P[0], [200, 0, -700], atol=1e-9)
    np.testing.assert_allclose(P[6], [200, 0, -900], atol=1e-9)
    np.testing.assert_allclose(np.hypot(P[:, 0], P[:, 1]), 200.0)
    assert d["kappa_1"] == pytest.approx(233.4, abs=0.05)  # reference: cond(G) = 233.4
    assert len(d["crlb_zero_offsets_deg"]) == 3
    np.testing.assert_allclose(d["crlb_zero_offsets_deg"], 0.382, atol=0.001)  # reference, paper noise
    assert 0.0263 <= min(d["crlb_zero_offsets_deg_scale_only"]) <= max(d["crlb_zero_offsets_deg_scale_only"]) <= 0.0275


def test_design_default_scheme_and_table(capsys):
    d = json.loads(zc(capsys, "design", *R, "--json"))
    assert d["scheme"] == "ring" and d["n"] == 6 and d["selected_by"].startswith("default")
    table = {row["n"]: row for row in d["n_table"]}
    assert min(table) == 4  # 2n - 1 >= 6 parameters
    assert table[4]["kappa_1"] == pytest.approx(3186, abs=1)  # reference: badly conditioned at n = 4
    out = zc(capsys, "design", *R, "--maemm-prior", "1", "0.5", "-0.5")
    assert "kappa_1 = 233.433" in out and "with the MAEMM prior" in out and "P12" in out


@pytest.mark.slow
def test_design_optimize_cylinder(capsys, tmp_path):
    png = tmp_path / "design.png"
    d = json.loads(zc(capsys, "design", *R, "--optimize", "--K", "8", "--starts", "1", "--criterion", "crlb", "--plot",
                      png, "--json"))
    P = np.array(d["poses"])
    assert d["K"] == 8 and P.shape == (8, 3) and d["baseline"] == "ring"
    assert np.all(np.hypot(P[:, 0], P[:, 1]) <= 200 + 1e-6) and np.all((P[:, 2] >= -900 - 1e-6) & (P[:, 2] <= -700 + 1e-6))
    assert len(d["crlb_zero_offsets_deg"]) == 3 and d["constraints"]["region_kind"] == "cylinder"
    assert d["ratio"]["crlb_rms_design_over_paper"] < 1.0  # better than the ring scheme with the same K
    assert png.read_bytes()[:8] == PNG
    one_line_error(capsys, ["design", *R, "--optimize", "--K", "6"], "too small")
    one_line_error(capsys, ["design", *R, "--optimize", "--region", "100", "-900"], "RW ZMIN ZMAX")
    one_line_error(capsys, ["design", *R, "--optimize", "--joint-limits", "-10", "70", "-10", "70"],
                   "LO1 HI1 LO2 HI2 LO3 HI3")


# --------------------------------------------------------------------------- simulate -> identify

def test_simulate_writes_delta_columns(ring6):
    text = ring6.read_text()
    header = next(ln for ln in text.splitlines() if ln.startswith("pose,"))
    assert header == "pose,theta1_deg,theta2_deg,theta3_deg,reading_mm,x_mm,y_mm,z_mm"
    m = data.load_measurements(ring6)
    assert m.mechanism == "delta_rotary" and m.K == 12
    assert m.meta["true_zero_offsets_deg"] == "2 -1 0.5" and m.meta["true_maemm_mm"] == "0 0 0"


@pytest.mark.parametrize("method", ["nlls", "tsvd"])
def test_simulate_identify_recovers_offsets(capsys, ring6, tmp_path, method):
    out = tmp_path / "r.json"
    res = json.loads(zc(capsys, "identify", ring6, *R, "--method", method, "--json", "--out", out))
    assert res["success"] and res["mechanism"] == "delta_rotary"
    assert res["compensation"]["joints"] == ["theta1", "theta2", "theta3"]
    assert len(res["maemm_mm"]) == 3 and res["params"] == ["theta1", "theta2", "theta3", "rMx", "rMy", "rMz"]
    if method == "nlls":  # the exact model: noise-free data give the truth
        np.testing.assert_allclose(res["zero_offsets_deg"], [2.0, -1.0, 0.5], atol=1e-6)
        np.testing.assert_allclose(res["maemm_mm"], 0.0, atol=1e-6)
    else:  # one linear step at zero errors: off by ~0.1 deg at n = 6 (reference: 0.12 deg with a MAEMM too)
        err = np.abs(np.array(res["zero_offsets_deg"]) - [2.0, -1.0, 0.5])
        assert 0.01 < np.max(err) < 0.2, err
    assert json.loads(out.read_text()) == res


def test_simulate_identify_round_trip_shell(tmp_path):
    """The documented pipe, through the installed console script."""
    bindir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    assert shutil.which("zerocal", path=env["PATH"]), f"console script `zerocal` not installed in {bindir}"
    cmd = (f"zerocal simulate --robot {DELTA} --scheme ring --n 6 --set theta1=2 --set theta2=-1 --set theta3=0.5 "
           f"--noise none --out d.csv && zerocal identify d.csv --robot {DELTA} --json")
    r = subprocess.run(cmd, shell=True, cwd=tmp_path, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout[r.stdout.index("{"):])
    np.testing.assert_allclose(res["zero_offsets_deg"], [2.0, -1.0, 0.5], atol=1e-6)


def test_identify_with_noise_options_and_plot(capsys, tmp_path):
    d = tmp_path / "d.csv"
    zc(capsys, "simulate", *R, *SETS, "--set", "rMx=1", "--set", "rMz=-0.5", "--noise", "scale-only", "--seed", "2",
       "--out", d)
    plots = tmp_path / "plots"
    res = json.loads(zc(capsys, "identify", d, *R, "--noise", "scale-only", "--maemm-prior", "1", "0", "0",
                        "--prior-std", "rMz=1", "--plot", plots, "--json"))
    est, std = np.array(res["zero_offsets_deg"]), np.array(res["std_zero_offsets_deg"])
    assert np.all(np.abs(est - [2.0, -1.0, 0.5]) < 4 * std) and np.all(std < 0.05)
    assert (plots / "residuals.png").read_bytes()[:8] == PNG
    assert (plots / "boundary_errors.png").read_bytes()[:8] == PNG  # simulated data carry the truth
    text = zc(capsys, "identify", d, *R, "--report", "--noise", "scale-only")
    assert "theta3" in text and "rMz" in text and "rank 6 of 6" in text


def test_simulate_poses_file_and_compensation(capsys, tmp_path):
    poses = tmp_path / "poses.json"
    poses.write_text(json.dumps(json.loads(zc(capsys, "design", *R, "--n", "5", "--json"))))
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    zc(capsys, "simulate", *R, *SETS, "--poses", poses, "--noise", "none", "--out", a)
    zc(capsys, "simulate", *R, *SETS, "--poses", poses, "--noise", "none", "--compensation", "1", "-1", "0.5",
       "--out", b)
    ma, mb = data.load_measurements(a), data.load_measurements(b)
    assert ma.K == mb.K == 10
    np.testing.assert_allclose(np.degrees(ma.theta_cmd - mb.theta_cmd), np.tile([1.0, -1.0, 0.5], (10, 1)),
                               atol=1e-9)
    one_line_error(capsys, ["simulate", *R, *SETS, "--compensation", "1", "2", "--out", tmp_path / "c.csv"],
                   "--compensation needs 3 values", outfile=tmp_path / "c.csv")


# --------------------------------------------------------------------------- compensate, verify

def test_compensate_verify_round_trip(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    zc(capsys, "simulate", *R, *SETS, "--set", "rMx=1", "--noise", "scale-only", "--seed", "1", "--out", "round1.csv")
    zc(capsys, "identify", "round1.csv", *R, "--noise", "scale-only", "--out", "result1.json")
    res = json.loads(Path("result1.json").read_text())
    # the controller's table: one row per joint
    zc(capsys, "compensate", "result1.json", *R, "--out", "table.csv")
    rows = [ln.split(",") for ln in Path("table.csv").read_text().splitlines() if ln.startswith("theta")]
    assert [r[0] for r in rows] == ["theta1", "theta2", "theta3"]
    np.testing.assert_allclose([float(r[1]) for r in rows], res["zero_offsets_deg"], atol=1e-12)
    # compensated commands on the ring scheme
    zc(capsys, "compensate", "result1.json", *R, "--scheme", "ring", "--n", "6", "--out", "commands.csv")
    lines = [ln for ln in Path("commands.csv").read_text().splitlines() if not ln.startswith("#")]
    assert lines[0] == ("pose,x_mm,y_mm,z_mm,theta1_nominal_deg,theta2_nominal_deg,theta3_nominal_deg,"
                        "theta1_cmd_deg,theta2_cmd_deg,theta3_cmd_deg")
    cells = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    np.testing.assert_allclose(cells[:, 4:7] - cells[:, 7:10], np.tile(res["zero_offsets_deg"], (12, 1)),
                               atol=1e-9)
    # the next round's sheet, measured (simulated) with the compensation applied, verified until mu < mu0
    result, passed = "result1.json", False
    for j in range(2, 8):
        off = json.loads(Path(result).read_text())["zero_offsets_deg"]
        zc(capsys, "compensate", result, *R, "--scheme", "ring", "--template", "--out", f"round{j}.csv")
        sheet = Path(f"round{j}.csv").read_text()
        assert "theta3_deg" in sheet and "# compensation_deg:" in sheet
        zc(capsys, "simulate", *R, *SETS, "--set", "rMx=1", "--noise", "scale-only", "--seed", j,
           "--compensation", *off, "--out", f"round{j}.csv")
        rc = main(["verify", result, f"round{j}.csv", *R, "--noise", "scale-only", "--out", f"result{j}.json"])
        out, err = capsys.readouterr()
        assert rc in (0, 1), err
        ver = json.loads(Path(f"result{j}.json").read_text())["verification"]
        assert ver["joints"] == ["theta1", "theta2", "theta3"] and ver["applied_offsets_deg"] == off
        assert ver["mu_deg"] == pytest.approx(np.sqrt(np.mean(np.square(ver["remaining_offsets_deg"]))))
        if rc == 0:
            passed = True
            break
        result = f"result{j}.json"
    assert passed, "the loop did not reach mu < mu0"
    final = np.array(json.loads(Path(result).read_text())["zero_offsets_deg"])
    assert np.max(np.abs(final - [2.0, -1.0, 0.5])) < 0.1, final
    # data measured with another compensation than the result's: refused
    zc(capsys, "simulate", *R, *SETS, "--compensation", "0.5", "0.5", "0.5", "--out", "other.csv")
    one_line_error(capsys, ["verify", "result1.json", "other.csv", *R, "--out", "bad.json"],
                   "measured with compensation (0.5, 0.5, 0.5) deg", outfile=tmp_path / "bad.json")


# --------------------------------------------------------------------------- compare

def test_compare_set_truth(capsys, tmp_path):
    out = tmp_path / "cmp.json"
    rep = json.loads(zc(capsys, "compare", *R, *SETS, "--set", "rMx=1", "--trials", "3", "--quiet",
                        "--methods", "tsvd,nlls,nlls-loop", "--json", "--out", out))
    s = rep["settings"]
    assert s["mechanism"] == "delta_rotary" and s["K"] == 12 and s["truth"]["theta3"] == 0.5
    g = rep["groups"]["set"]
    assert g["set_deg"] == [2.0, -1.0, 0.5] and len(g["crlb_zero_offsets_deg"]) == 3
    for m in ("tsvd", "nlls", "nlls-loop"):
        assert g["methods"][m]["failures"] == 0 and len(g["methods"][m]["rms_deg"]) == 3
    assert json.loads(out.read_text()) == rep
    text = zc(capsys, "compare", *R, *SETS, "--trials", "3", "--quiet", "--methods", "nlls")
    assert "group set" in text and "dth3" in text


# --------------------------------------------------------------------------- errors: one line, exit 2, nothing written

def test_unknown_set_name(capsys, tmp_path):
    out = tmp_path / "x.csv"
    line = one_line_error(capsys, ["simulate", *R, "--set", "nope=1", "--out", out], "unknown source error 'nope'",
                          outfile=out)
    assert "known: theta1, theta2, theta3, R1" in line and "rMz" in line


@pytest.mark.parametrize("argv", [
    ["simulate", *R, *SETS, "--scheme", "paper", "--out", "x.csv"],
    ["design", *R, "--scheme", "paper"],
    ["compensate", *R, "--scheme", "paper", "--template", "--out", "x.csv"],
    ["compare", *R, *SETS, "--poses", "paper"],
])
def test_paper_scheme_on_the_delta(capsys, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    line = one_line_error(capsys, argv, "paper does not fit robot", outfile=tmp_path / "x.csv")
    assert "cylinder" in line and "ring" in line


def test_ring_scheme_on_the_paper_robot(capsys):
    one_line_error(capsys, ["design", "--scheme", "ring"], "whose scheme is --scheme paper")


@pytest.mark.parametrize("argv, pattern", [
    (["reproduce", *R], "reproduce is the paper's"),
    (["simulate", *R, "--group", "1", "--out", "x.csv"], "--group is the paper's"),
    (["compare", *R, "--group", "1"], "--group/--all is the paper's"),
    (["compare", *R], "give the true errors by --set"),
    (["simulate", *R, *SETS, "--n", "3", "--out", "x.csv"], "n >= 4 needed"),
    (["design", *R, "--n", "3"], "n >= 4 needed"),
    (["design", *R, "--eps0", "0.01"], "eps rule"),
    (["simulate", *R, "--set", "theta1=abc", "--out", "x.csv"], "bad value"),
    (["simulate", *R, "--set", "theta1", "--out", "x.csv"], "expected NAME=VALUE"),
    (["simulate", *R, *SETS, "--frame", "paper", "--out", "x.csv"], "--frame"),
])
def test_paper_only_and_bad_options(capsys, tmp_path, monkeypatch, argv, pattern):
    monkeypatch.chdir(tmp_path)
    one_line_error(capsys, argv, pattern, outfile=tmp_path / "x.csv")


def test_planar_file_with_the_delta_robot(capsys, tmp_path):
    out = tmp_path / "r.json"
    line = one_line_error(capsys, ["identify", PLANAR_EXAMPLE, *R, "--out", out], "planar_2dof", outfile=out)
    assert "delta_rotary" in line and str(PLANAR_EXAMPLE) in line


def test_delta_file_with_the_planar_robot(capsys, ring6, tmp_path):
    out = tmp_path / "r.json"
    one_line_error(capsys, ["identify", ring6, "--out", out], "delta_rotary", outfile=out)


def test_maemm_prior_needs_n_values(capsys, ring6, tmp_path):
    out = tmp_path / "r.json"
    one_line_error(capsys, ["identify", ring6, *R, "--maemm-prior", "1", "0.5", "--out", out],
                   "--maemm-prior needs 3 values (rMx, rMy, rMz, mm)", outfile=out)


def test_result_of_the_planar_robot_refused(capsys, tmp_path):
    r = tmp_path / "r.json"
    r.write_text(json.dumps({"method": "tsvd", "status": "ok", "success": True, "zero_offsets_deg": [-2.0, 1.0],
                             "maemm_mm": [1.0, -0.5]}))
    out = tmp_path / "t.csv"
    one_line_error(capsys, ["compensate", r, *R, "--out", out], "zero_offsets_deg", outfile=out)
