"""docs/walkthrough.md's dry run (its commands run by the docs checker, the files they write checked here), and
the simulate -> identify round trip (set values recovered within the noise)."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.io import measurements as data
from zerocal_sym.model import kinematics
from zerocal_sym.cli import main
from zerocal_sym.errors import DataFileError

ROOT = Path(__file__).resolve().parents[1]


def zc(capsys, *argv, expect=0):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == expect, (argv, rc, out, err)
    return out


def true_offsets(path):
    m = data.load_measurements(path)
    return np.array([float(v) for v in m.meta["true_zero_offsets_deg"].split()])


def test_walkthrough(capsys, tmp_path, monkeypatch, docs_runs):
    """The files docs/walkthrough.md's dry run writes (the docs checker runs its commands, once per session, and
    compares what they print with the page): the result, the compensation table and commands, the verification,
    and the alternatives the page names (the sheet of the optimised design, verify's plots)."""
    import docs_check

    ran, problems = docs_runs.page(docs_check.parse_page(docs_check.ROOT / "docs" / "walkthrough.md"))
    assert not problems, "\n".join(problems)
    for name in ("my_robot.toml", "design.json", "round1.csv", "result1.json", "report.html", "compensation.csv",
                 "commands.csv", "round2.csv", "result2.json"):
        shutil.copy(ran / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    R = ("--robot", "my_robot.toml")
    from zerocal_sym.model.robot import load_robot

    robot = load_robot("my_robot.toml")
    n = 3  # the page's eps rule (its design block shows n = 3)

    # 2. the optimised design's sheet (the page's alternative to --scheme paper --n 3)
    design = json.loads(Path("design.json").read_text())
    assert len(design["poses"]) == 6
    zc(capsys, "compensate", *R, "--poses", "design.json", "--template", "--out", "design_round1.csv")
    with pytest.raises(DataFileError, match=r"empty cell \(fill in the scale reading\)"):
        data.load_measurements("design_round1.csv", robot)

    # 3. the simulated round, 4. its result
    m1 = data.load_measurements("round1.csv", robot)
    assert m1.K == 2 * n
    res = json.loads(Path("result1.json").read_text())
    assert res["robot_sha256"] == robot.sha256 and res["success"]
    for key in ("zero_offsets_deg", "maemm_mm", "std_zero_offsets_deg", "method", "status", "covariance", "units"):
        assert key in res, key

    # 4, the calibration report the page writes (the line it prints and the accuracy the page quotes from its
    # data-value attributes are the docs checker's): one self-contained page
    page = Path("report.html").read_text()
    assert '<section id="accuracy">' in page and "<script src=" not in page and "<link " not in page

    # 5. apply: the controller's table and the compensated commands
    table = Path("compensation.csv").read_text()
    assert "theta_cmd = IK(P) - offset_deg" in table
    rows = [ln.split(",") for ln in table.splitlines() if ln.startswith("theta")]
    np.testing.assert_allclose([float(r[1]) for r in rows], res["zero_offsets_deg"], rtol=0, atol=1e-12)
    rows = [ln.split(",") for ln in Path("commands.csv").read_text().splitlines() if not ln.startswith("#")]
    cmd = {c: np.array([float(r[j]) for r in rows[1:]]) for j, c in enumerate(rows[0])}
    P = np.column_stack([cmd["x_mm"], cmd["y_mm"]])
    expect = np.degrees(kinematics.ik(robot, P)) - res["zero_offsets_deg"]
    np.testing.assert_allclose(np.column_stack([cmd["theta1_cmd_deg"], cmd["theta2_cmd_deg"]]), expect, atol=1e-9)

    # 6. the verification the page shows passed, with the first result's offsets applied
    ver = json.loads(Path("result2.json").read_text())["verification"]
    assert ver["passed"] and ver["applied_offsets_deg"] == res["zero_offsets_deg"]
    rc = main(["verify", "result1.json", "round2.csv", *R, "--noise", "scale-only", "--out", "again.json",
               "--plot", "plots"])
    out, err = capsys.readouterr()
    assert rc == 0 and "PASS" in out, err
    assert Path("plots/residuals.png").read_bytes()[:4] == b"\x89PNG"

    # the compensation applied is close to the truth (scale noise ~0.05 deg; TSVD/NLLS model bias small for group 4)
    truth = true_offsets("round1.csv")
    final = np.array(res["zero_offsets_deg"])
    assert np.max(np.abs(final - truth)) < 0.25, (final, truth)


def test_verify_rejects_data_measured_with_another_compensation(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    zc(capsys, "simulate", "--group", 1, "--seed", 1, "--out", "r1.csv")
    zc(capsys, "identify", "r1.csv", "--method", "tsvd", "--out", "res.json")
    zc(capsys, "simulate", "--group", 1, "--seed", 2, "--compensation", 0.5, 0.5, "--out", "r2.csv")
    rc = main(["verify", "res.json", "r2.csv", "--out", "res2.json"])
    err = capsys.readouterr().err
    assert rc == 2 and "measured with compensation (0.5, 0.5) deg, not with the result's offsets" in err
    assert "r2.csv:" in err and not Path("res2.json").exists()


# --------------------------------------------------------------------------- the round trip through the shell

def test_simulate_identify_round_trip_shell(tmp_path):
    """``zerocal simulate ... --out d.csv && zerocal identify d.csv --json``: the set values come back.

    Runs the installed console script (the one beside this interpreter, so it
    works without an activated venv, as in CI).
    """
    bindir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    assert shutil.which("zerocal", path=env["PATH"]), f"console script `zerocal` not installed in {bindir}"
    cmd = ("zerocal simulate --group 4 --seed 3 --noise scale-only --out d.csv && "
           "zerocal identify d.csv --noise scale-only --json")
    r = subprocess.run(cmd, shell=True, cwd=tmp_path, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout[r.stdout.index("{"):])
    truth = true_offsets(tmp_path / "d.csv")
    est, std = np.array(res["zero_offsets_deg"]), np.array(res["std_zero_offsets_deg"])
    assert np.all(np.abs(est - truth) < 4 * std), (est, truth, std)
    assert np.all(std < 0.1)  # scale error alone: ~0.06 deg


@pytest.mark.parametrize("group,noise,seed", [(1, "paper", 1), (2, "paper", 2), (3, "paper", 3), (4, "scale-only", 4),
                                              (5, "scale-only", 5), (6, "scale-only", 6)])
def test_simulate_identify_round_trip(capsys, tmp_path, group, noise, seed):
    """Ipopt (identify's default) on the exact model: |estimate - set| < 4 std, offsets and MAEMM."""
    d = tmp_path / "d.csv"
    zc(capsys, "simulate", "--group", group, "--seed", seed, "--noise", noise, "--out", d)
    res = json.loads(zc(capsys, "identify", d, "--noise", noise, "--json"))
    m = data.load_measurements(d)
    truth = np.array([float(v) for v in m.meta["true_zero_offsets_deg"].split()])
    maemm = np.array([float(v) for v in m.meta["true_maemm_mm"].split()])
    est, std = np.array(res["zero_offsets_deg"]), np.array(res["std_zero_offsets_deg"])
    assert np.all(np.abs(est - truth) < 4 * std), (est, truth, std)
    std_m = np.sqrt(np.diag(np.array(res["covariance"]))[2:4])
    assert np.all(np.abs(np.array(res["maemm_mm"]) - maemm) < 4 * std_m + 0.02)


def test_round_trip_tsvd_linearisation_bias(capsys, tmp_path):
    """One TSVD identification (linearised at zero offsets, paper Eq. 29) is biased by ~0.1-0.2 deg for
    2-deg offsets even without noise; the identify-compensate loop (re-linearised) removes it."""
    d = tmp_path / "d.csv"
    zc(capsys, "simulate", "--group", 4, "--seed", 0, "--noise", "none", "--out", d)
    res = json.loads(zc(capsys, "identify", d, "--method", "tsvd", "--noise", "scale-only", "--json"))
    err = np.abs(np.array(res["zero_offsets_deg"]) - true_offsets(d))
    assert 0.05 < np.max(err) < 0.3, err
    res = json.loads(zc(capsys, "identify", d, "--method", "nlls", "--noise", "scale-only", "--json"))
    assert np.max(np.abs(np.array(res["zero_offsets_deg"]) - true_offsets(d))) < 0.01


def test_console_script_runs_compensate(tmp_path):
    r = subprocess.run([sys.executable, "-m", "zerocal_sym", "compensate", "--scheme", "paper", "--template"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.startswith(data.FORMAT_LINE)
