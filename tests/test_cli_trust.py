"""Calibrations a user can trust , through the CLI as the user meets it."""
import json
from pathlib import Path

from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]


def zc(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def simulate(capsys, path, *extra):
    rc, out, err = zc(capsys, "simulate", "--group", 1, "--n", 6, *extra, "--out", path)
    assert rc == 0, err
    return path


def drop_sha(path):
    lines = [ln for ln in path.read_text().splitlines(keepends=True) if not ln.startswith("# robot_sha256:")]
    path.write_text("".join(lines))


def edit_reading(path, pose, delta):
    lines = path.read_text().splitlines(keepends=True)
    header = next(i for i, ln in enumerate(lines) if ln.startswith("pose,"))
    cols = lines[header].strip().split(",")
    r = cols.index("reading_mm")
    row = lines[header + 1 + pose].rstrip("\n").split(",")
    assert row[0] == str(pose)
    row[r] = repr(float(row[r]) + delta)
    lines[header + 1 + pose] = ",".join(row) + "\n"
    path.write_text("".join(lines))


def test_wrong_robot_file_rejected(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv")
    drop_sha(data)
    robot = tmp_path / "wrong.toml"
    robot.write_text((ROOT / "examples" / "paper_robot.toml").read_text().replace("L = 375", "L = 380"))
    out = tmp_path / "r.json"
    rc, o, err = zc(capsys, "identify", data, "--robot", robot, "--out", out)
    assert rc == 1 and not out.exists(), (o, err)
    # the paragraph of the fit check (at K = 12 a robot-file error that shows mostly in one change looks like a
    # bad reading: the diagnosis says so)
    assert "rejected" in err and "The noise model rejects this fit" in err and "check the robot file" in err, err


def test_bad_reading_named(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv", "--noise", "scale-only")
    edit_reading(data, 5, 0.9)
    out = tmp_path / "r.json"
    rc, o, err = zc(capsys, "identify", data, "--noise", "scale-only", "--out", out)
    assert rc == 1 and not out.exists(), (o, err)
    assert "rejected" in err and "pose 5" in err, err
    assert "verdict: rejected" in o and "rejected: rejected" not in o
    # --accept-misfit alone: the 0.9 mm reading drags the least-squares offsets to ~ -30 deg, which plausibility
    # refuses (exit 1, no file)
    rc, o, err = zc(capsys, "identify", data, "--noise", "scale-only", "--accept-misfit", "--out", out)
    assert rc == 1 and not out.exists() and "beyond the plausible 10 deg" in err, err
    # the user overrides the fit check and the plausibility limits: a calibration, and the result says so
    rc, o, err = zc(capsys, "identify", data, "--noise", "scale-only", "--accept-misfit", "--max-offset-deg", 45,
                    "--max-maemm-mm", 200, "--json", "--out", out)
    assert rc == 0, err
    d = json.loads(o)
    assert d["accept_misfit"] is True and d["fit"]["accepted_despite_misfit"] is True
    assert d["status"].startswith("accepted despite misfit") and json.loads(out.read_text()) == d


def test_loss_with_tsvd_refused(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv")
    rc, o, err = zc(capsys, "identify", data, "--method", "tsvd", "--loss", "huber")
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "--loss" in err, err


def test_verify_uncompensated_round_refused(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv")
    res = tmp_path / "r.json"
    rc, o, err = zc(capsys, "identify", data, "--out", res)
    assert rc == 0, err
    round2 = simulate(capsys, tmp_path / "round2.csv", "--seed", 1)  # measured without the compensation
    rc, o, err = zc(capsys, "verify", res, round2)  # the file's '# compensation_deg: 0 0' line says so
    assert rc == 2 and "measured with compensation (0, 0) deg" in err, err
    round2.write_text("".join(ln for ln in round2.read_text().splitlines(keepends=True)
                              if not ln.startswith("# compensation_deg:")))  # the commands themselves say so
    rc, o, err = zc(capsys, "verify", res, round2)
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "pose 0" in err and "not compensated with this result" in err, err


def test_compensate_refuses_implausible_offset(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv")
    res = tmp_path / "r.json"
    assert zc(capsys, "identify", data, "--out", res)[0] == 0
    d = json.loads(res.read_text())
    d["zero_offsets_deg"][0] = d["estimate"]["theta1"] = d["compensation"]["offset_deg"][0] = 20.0  # every copy
    res.write_text(json.dumps(d))
    table = tmp_path / "table.csv"
    rc, o, err = zc(capsys, "compensate", res, "--out", table)
    assert rc == 1 and not table.exists() and len(err.strip().splitlines()) == 1, err
    assert "beyond the plausible 10 deg" in err


def test_verdict_line(capsys, tmp_path):
    data = simulate(capsys, tmp_path / "d.csv")
    res = tmp_path / "r.json"
    rc, o, err = zc(capsys, "identify", data, "--out", res)
    assert rc == 0, err
    last = o.strip().splitlines()[-1]
    verdicts = [ln for ln in o.splitlines() if ln.startswith("verdict:")]
    assert verdicts == [last]
    assert last.startswith("verdict: accepted: fit p-value") and "1 sigma" in last
    assert f"next: zerocal compensate {res} --out table.csv" in last


def _next_commands(verdict):
    """The commands after ``next:`` of a verdict line, as argv lists (without the leading ``zerocal``)."""
    import shlex

    cmds = [shlex.split(c) for c in verdict.split("next: ", 1)[1].split(", then ")]
    assert all(c[0] == "zerocal" for c in cmds)
    return [c[1:] for c in cmds]


def test_verdict_next_command_repeats_the_run_on_the_users_robot(capsys, tmp_path, monkeypatch):
    """Without --out the next command is identify again with --robot and every option the result depends on
    (not the output ones), then compensate with --robot: run as printed, they give the same calibration."""
    monkeypatch.chdir(tmp_path)
    robot = ROOT / "examples" / "delta.toml"
    rc, _, err = zc(capsys, "simulate", "--robot", robot, "--set", "theta1=2", "--set", "theta2=-1", "--set",
                    "theta3=0.5", "--noise", "scale-only", "--seed", 3, "--out", "d.csv")
    assert rc == 0, err
    given = ["d.csv", "--robot", str(robot), "--noise", "scale-only", "--maemm-prior", "0.5", "0", "-0.25",
             "--fit-alpha", "0.01", "--tolerance-scale", "2"]
    rc, out, err = zc(capsys, "identify", *given, "--report", "--plot", "plots")
    assert rc == 0, err
    identify, compensate = _next_commands(out.strip().splitlines()[-1])
    # the options in the parser's order, floats as Python writes them; not --report, not --plot
    assert identify == ["identify", "d.csv", "--robot", str(robot), "--noise", "scale-only", "--maemm-prior", "0.5",
                        "0.0", "-0.25", "--tolerance-scale", "2.0", "--fit-alpha", "0.01", "--out", "RESULT.json"]
    assert compensate == ["compensate", "RESULT.json", "--robot", str(robot), "--out", "table.csv"]
    rc, _, err = zc(capsys, *identify)
    assert rc == 0, err
    rc, first, _ = zc(capsys, "identify", *given, "--json")
    assert json.loads(Path("RESULT.json").read_text())["zero_offsets_deg"] == json.loads(first)["zero_offsets_deg"]
    rc, _, err = zc(capsys, *compensate)
    assert rc == 0 and Path("table.csv").exists(), err
    # with --out the next command is compensate on that file, --robot kept
    rc, out, err = zc(capsys, "identify", *given, "--out", "r.json")
    assert rc == 0, err
    assert _next_commands(out.strip().splitlines()[-1]) == [["compensate", "r.json", "--robot", str(robot), "--out",
                                                             "table.csv"]]


def test_verdict_judges_sigma_against_the_largest_offset_or_the_goal(capsys, tmp_path):
    """A true offset near zero does not make a good result "NOT small": 1 sigma is judged against the largest
    |offset| (10 % of it), or against --goal-deg when given."""
    data = tmp_path / "d.csv"
    rc, _, err = zc(capsys, "simulate", "--set", "theta1=2", "--set", "theta2=0.01", "--n", 6, "--noise",
                    "scale-only", "--seed", 1, "--out", data)
    assert rc == 0, err

    def verdict(*extra):
        rc, out, err = zc(capsys, "identify", data, "--noise", "scale-only", *extra)
        assert rc == 0, err
        return out.strip().splitlines()[-1]

    v = verdict()
    sigma = float(v.split("offsets' 1 sigma ")[1].split(",")[0])
    assert 0.01 < sigma < 0.2  # above |theta2|, far below 10 % of theta1
    assert "small against the offsets (<= 0.1 x the largest |offset|, 1.9" in v and "NOT" not in v
    assert "within the goal 0.2 deg" in verdict("--goal-deg", "0.2")
    v = verdict("--goal-deg", "0.01")
    assert "NOT within the goal 0.01 deg; measure more poses" in v and "--goal-deg 0.01" in v
    # and a result whose 1 sigma is large against every offset still says so
    small = tmp_path / "s.csv"
    rc, _, err = zc(capsys, "simulate", "--set", "theta1=0.05", "--set", "theta2=-0.02", "--n", 6, "--noise",
                    "scale-only", "--seed", 1, "--out", small)
    assert rc == 0, err
    rc, out, err = zc(capsys, "identify", small, "--noise", "scale-only")
    assert rc == 0, err
    assert "NOT small against the offsets (> 0.1 x the largest |offset|" in out.strip().splitlines()[-1]


def test_identify_reports_the_bias_from_the_omitted_errors(capsys, tmp_path):
    """identify states the bias its estimate may carry from the errors left out, within their tolerances."""
    data = simulate(capsys, tmp_path / "d.csv", "--noise", "scale-only")
    rc, out, err = zc(capsys, "identify", data, "--json", "--accept-misfit")
    assert rc == 0, err
    b = json.loads(out)["bias"]["zero_offsets"]
    assert b["names"] == ["theta1", "theta2"] and all(w > r > 0 for w, r in zip(b["worst_case_deg"], b["rms_deg"]))
    rc, out, err = zc(capsys, "identify", data, "--json", "--accept-misfit", "--tolerance-scale", "10")
    b10 = json.loads(out)["bias"]["zero_offsets"]
    # the first-order bound scales with the tolerances; the worst case reported is the larger of it and the
    # exact model's at the worst corner, which does not scale exactly
    assert b10["worst_case_first_order_deg"][0] == __import__("pytest").approx(
        10 * b["worst_case_first_order_deg"][0], rel=1e-6)
    assert all(w >= f for w, f in zip(b10["worst_case_deg"], b10["worst_case_first_order_deg"]))
    rc, out, err = zc(capsys, "identify", data, "--tolerance", "nope=1")
    assert rc == 2 and "nope" in err and len(err.strip().splitlines()) == 1


def test_one_gross_reading_among_many_is_refused(capsys, tmp_path):
    """One reading 0.5 mm off among K = 2000, identified with a robot file whose [noise] states 3 x the paper's
    noise: the chi² passes (the overstated noise hides it), the largest standardised residual refuses the fit
    and names the reading -- its pose, the change from the pose before, its estimated error."""
    import numpy as np

    from zerocal_sym.model.robot import paper_robot

    robot = paper_robot()
    lo, hi = robot.workspace.bounds()
    P = lo + (hi - lo) * np.random.default_rng(3).random((6000, 2))
    P = P[robot.workspace.contains(P, -1.0)][:2000]
    assert P.shape == (2000, 2)
    poses = tmp_path / "poses.csv"
    poses.write_text("x_mm,y_mm\n" + "".join(f"{x!r},{y!r}\n" for x, y in P.tolist()))
    data = tmp_path / "d.csv"
    rc, _, err = zc(capsys, "simulate", "--poses", poses, "--set", "theta1=0.5", "--set", "theta2=-0.3",
                    "--seed", 4, "--out", data)
    assert rc == 0, err
    drop_sha(data)
    edit_reading(data, 700, 0.5)
    noisy = tmp_path / "noisy.toml"  # the paper's noise (1.117 um per change, 0.0024 deg per joint) x 3
    noisy.write_text((ROOT / "examples" / "paper_robot.toml").read_text()
                     + "\n[noise]\nscale = 0.00335\njoint = 0.0072\n")
    out = tmp_path / "r.json"
    rc, o, err = zc(capsys, "identify", data, "--robot", noisy, "--out", out)
    assert rc == 1 and not out.exists(), (o, err)
    assert ("rejected: the noise model rejects the fit (one reading: standardised residual" in err
            and "the largest of 1999" in err and "passes; likely: the reading at pose 700 (the change from pose 699 "
            "to pose 700) is off by about +0.4" in err), err
    rc, o, err = zc(capsys, "identify", data, "--robot", noisy, "--out", out, "--accept-misfit")
    assert rc == 0, err
    fit = json.loads(out.read_text())["fit"]
    print(f"chi2 {fit['chi2']:.6g} on {fit['dof']} dof, p = {fit['p_value']:.3g}; largest standardised residual "
          f"{fit['max_reading']['standardised']:.4g} at pose {fit['max_reading']['pose']}, "
          f"p = {fit['max_reading']['p_value']:.3g}; its estimated error {fit['causes'][0]['estimated_error_mm']:+.3g} mm")
    assert fit["p_value"] >= fit["alpha"] and not fit["chi2_rejected"]
    assert fit["max_reading"]["pose"] == 700 and fit["max_reading"]["p_value"] < fit["alpha"]
    assert fit["causes"][0]["pose"] == 700 and abs(fit["causes"][0]["estimated_error_mm"] - 0.5) < 0.05
    assert "largest standardised residual's p-value" in o and "at pose 700" in o
