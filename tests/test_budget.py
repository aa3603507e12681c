"""The error budget of every answer, its tolerances, and the remedies (docs/trust.md)."""
import json
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.errors import RobotFileError
from zerocal_sym.model import tolerances as tl
from zerocal_sym.model.robot import load_robot, paper_robot

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
ARMS = EX / "delta_arms.toml"
#: the Delta case: the robot's offsets (deg), its upper arms 1 mm shorter than the file's 331 mm
TRUTH = {"theta1": 1.2, "theta2": -0.7, "theta3": 0.3}
ARMS_OFF = ["--set", "L1=-1", "--set", "L2=-1", "--set", "L3=-1"]


def zc(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def simulate(capsys, path, robot, *extra):
    rc, _, err = zc(capsys, "simulate", "--robot", robot, *extra, "--out", path)
    assert rc == 0, err
    return path


def identify_json(capsys, *argv, rc_expected=0):
    rc, out, err = zc(capsys, "identify", *argv, "--json")
    assert rc == rc_expected, err
    return json.loads(out)


# ------------------------------------------------------------------ the robot file's [tolerances]
def test_tolerance_keys_groups_sets_and_precedence(tmp_path):
    robot = load_robot(EX / "delta.toml")
    e = robot.errors
    t = tl.resolve(e, [("lengths", 0.3), ("L", 1.0), ("L2", 2.0)])
    assert (t["L1"], t["L2"], t["l1"], t["R1"]) == (1.0, 2.0, 0.3, tl.DEFAULT_LENGTH_TOLERANCE_MM)
    assert t["phi2"] == tl.DEFAULT_ANGLE_TOLERANCE_DEG and "theta1" not in t
    # a key naming fewer entries wins whatever the order; between equal ones the later
    assert tl.resolve(e, [("L2", 2.0), ("L", 1.0)])["L2"] == 2.0
    assert tl.resolve(e, [("R", 1.0), ("L", 2.0)])["L3"] == 2.0
    text = (EX / "delta.toml").read_text() + "\n[tolerances]\nL = 1.0\nphi = 0.2\n"
    r = load_robot(_write(tmp_path, text))
    tol = r.tolerances()
    assert tol["L3"] == 1.0 and tol["phi1"] == pytest.approx(np.radians(0.2)) and tol["l1"] == 0.5
    assert r.sha256 == robot.sha256  # a data file stays this robot's


@pytest.mark.parametrize("table,message,line", [
    ("L = 1\ntheta1 = 0.1\n", "theta1 is a zero offset", 3),
    ("L = 1\nnope = 0.1\n", "unknown tolerance key 'nope'", 3),
    ("L = -1\n", "is a tolerance: >= 0", 2),
    ("L = 'a'\n", "must be a number", 2),
])
def test_bad_tolerance_tables_name_the_line(tmp_path, table, message, line):
    text = (EX / "delta.toml").read_text()
    n = len(text.splitlines())
    path = _write(tmp_path, text + "[tolerances]\n" + table)
    with pytest.raises(RobotFileError) as exc:
        load_robot(path)
    assert message in str(exc.value) and f"{path}:{n + line}" in str(exc.value), str(exc.value)


def test_the_paper_robot_keeps_table_2_set_a():
    from zerocal_sym.paper.tables import SET_A

    built_in, example = paper_robot().tolerances(), load_robot(EX / "paper_robot.toml").tolerances()
    assert built_in == example
    assert {k: abs(v) for k, v in SET_A.items()} == {k: built_in[k] for k in SET_A}
    # another planar robot gets the defaults of a robot measured by hand
    mine = load_robot(EX / "my_robot.toml").tolerances()
    assert set(mine.values()) == {tl.DEFAULT_LENGTH_TOLERANCE_MM}


# ------------------------------------------------------------------ the budget itself
def test_budget_is_the_bias_bound_split_by_entry(capsys, tmp_path):
    """robot_file_bias is the first-order worst case of identify's bias report; its dominant entries are the three
    largest |S_ij| t_j; limited_by follows it against the 1 sigma; the results reader applies the same rule."""
    from zerocal_sym.identify.budget.error_budget import limited_by

    data = simulate(capsys, tmp_path / "d.csv", EX / "delta.toml", "--set", "theta1=1", "--set", "theta2=-0.5",
                    "--noise", "scale-only")
    for method in ("nlls", "tsvd"):
        d = identify_json(capsys, data, "--robot", EX / "delta.toml", "--method", method, "--noise", "scale-only")
        b = d["bias"]
        S = np.array(b["sensitivity"]["values"])
        t = np.array([b["tolerances"][c] for c in b["sensitivity"]["columns"]])
        for j, entry in enumerate(d["error_budget"]):
            assert entry["name"] == f"theta{j + 1}" and entry["unit"] == "deg"
            assert entry["noise_std"] == d["std_zero_offsets_deg"][j]
            row = np.abs(S[b["sensitivity"]["rows"].index(entry["name"])]) * t
            # the bound reported: the worst case, the larger of the first-order bound and the exact search's;
            # split by entry at first order (the dominant entries' contributions add up to at most it)
            assert entry["robot_file_bias"] == pytest.approx(b["zero_offsets"]["worst_case_deg"][j], rel=1e-12)
            assert entry["robot_file_bias"] >= b["zero_offsets"]["worst_case_first_order_deg"][j] * (1 - 1e-12)
            top = sorted(row, reverse=True)[:3]
            assert [e["contribution"] for e in entry["dominant_entries"]] == pytest.approx(top, rel=1e-12)
        assert d["limited_by"] == limited_by(d["error_budget"])
        # hand-measured defaults (0.5 mm) against a scale-only noise: the robot file limits this answer
        assert d["limited_by"] == "robot file"
        path = tmp_path / f"r_{method}.json"
        d["limited_by"] = "data"
        path.write_text(json.dumps(d))
        rc, _, err = zc(capsys, "compensate", path, "--robot", EX / "delta.toml", "--out", tmp_path / "t.csv")
        assert rc == 2 and "limited_by" in err and "robot file" in err, err
    # tight tolerances: the data limit it
    d = identify_json(capsys, data, "--robot", EX / "delta.toml", "--noise", "scale-only", "--tolerance-scale",
                      "0.001")
    assert d["limited_by"] == "data" and all(e["robot_file_bias"] < e["noise_std"] for e in d["error_budget"])


@pytest.mark.parametrize("robot,extra", [
    (None, ["--group", 1, "--n", 3]),
    (EX / "delta.toml", ["--set", "theta1=1"]),
    (EX / "linear_delta.toml", ["--set", "s1=0.3"]),
    (EX / "hexapod.toml", ["--set", "L1=0.3", "--n", 16]),
], ids=["planar", "delta", "linear_delta", "hexapod"])
def test_every_mechanism_and_method_carries_the_budget(capsys, tmp_path, robot, extra):
    rob = ["--robot", robot] if robot else []
    rc, _, err = zc(capsys, "simulate", *rob, *extra, "--out", tmp_path / "d.csv")
    assert rc == 0, err
    names = (load_robot(robot) if robot else paper_robot()).errors.zero_offsets
    for method in ("nlls", "tsvd"):
        path = tmp_path / f"{method}.json"
        rc, out, err = zc(capsys, "identify", tmp_path / "d.csv", *rob, "--method", method, "--accept-misfit",
                          "--out", path)
        assert rc == 0, err
        d = json.loads(path.read_text())
        assert [e["name"] for e in d["error_budget"]] == list(names)
        assert d["limited_by"] in ("data", "robot file")
        assert all(e["robot_file_bias"] >= 0 and len(e["dominant_entries"]) <= 3 for e in d["error_budget"])
        assert "error budget of the offsets" in out and f"limited by the {d['limited_by']}" in out
        rc, _, err = zc(capsys, "compensate", path, *rob, "--out", tmp_path / "t.csv")
        assert rc == 0, err


def test_results_written_before_keep_loading(capsys, tmp_path):
    from zerocal_sym.io.results import load_result

    data = simulate(capsys, tmp_path / "d.csv", EX / "delta.toml", "--set", "theta1=1")
    d = identify_json(capsys, data, "--robot", EX / "delta.toml")
    for key in ("error_budget", "limited_by", "remedy"):
        d.pop(key)
    path = tmp_path / "old.json"
    path.write_text(json.dumps(d))
    assert load_result(path).zero_offsets_user.shape == (3,)


# ------------------------------------------------------------------ the Delta case (docs/trust.md)
def test_delta_arms_case_limited_by_the_robot_file_and_the_remedy(capsys, tmp_path):
    """Upper arms of 330 mm, a robot file saying 331 mm with [tolerances] L = 1.0, K = 12 crlb-optimised poses:
    the fit passes, the offsets are ~1 deg off against a 1 sigma of ~0.017 deg, and the answer says it is limited
    by the robot file, with a bias bound that covers the error.  With the design made for identifying the arms too,
    the offsets come back within 3 sigma."""
    truth = [f"{k}={v}" for k, v in TRUTH.items()]
    sets = [w for t in truth for w in ("--set", t)] + ARMS_OFF
    data = simulate(capsys, tmp_path / "a.csv", ARMS, "--poses", EX / "delta_arms_k12.json", *sets)
    rc, out, err = zc(capsys, "identify", data, "--robot", ARMS)
    assert rc == 0, err
    verdict = out.strip().splitlines()[-1]
    assert verdict.startswith("verdict: accepted: fit p-value")
    assert "limited by the robot file (L1-L3 at +-1 mm)" in verdict and "--params paper+L1,L2,L3" in verdict
    d = identify_json(capsys, data, "--robot", ARMS)
    err_deg = np.abs(np.array(d["zero_offsets_deg"]) - list(TRUTH.values()))
    assert d["limited_by"] == "robot file"
    assert np.all(err_deg > 20 * np.array(d["std_zero_offsets_deg"]))  # what the fit check cannot see
    assert np.all(err_deg <= [e["robot_file_bias"] for e in d["error_budget"]])  # what the budget says
    assert all({x["name"] for x in e["dominant_entries"]} == {"L1", "L2", "L3"} for e in d["error_budget"])
    # --tolerance overrides the file's group for one run: arms known to 1 um take their share away
    tight = identify_json(capsys, data, "--robot", ARMS, "--tolerance", "L=0.001")
    # (at first order, where the bound is the sum of the entries' shares; the exact worst corner is not additive)
    share = [sum(x["contribution"] for x in e["dominant_entries"]) for e in d["error_budget"]]
    first = [b["bias"]["zero_offsets"]["worst_case_first_order_deg"] for b in (d, tight)]
    for e, t, c in zip(first[0], first[1], share):
        assert t == pytest.approx(e - 0.999 * c, rel=1e-6)
    assert all(t["robot_file_bias"] <= e["robot_file_bias"] - 0.9 * c  # and the bound reported falls with it
               for e, t, c in zip(d["error_budget"], tight["error_budget"], share))
    # the remedy: a design for the set that frees the arms, then identify that set
    data = simulate(capsys, tmp_path / "b.csv", ARMS, "--poses", EX / "delta_arms_k12_free_L.json", *sets)
    d = identify_json(capsys, data, "--robot", ARMS, "--params", "paper+L1,L2,L3")
    z = (np.array(d["zero_offsets_deg"]) - list(TRUTH.values())) / d["std_zero_offsets_deg"]
    assert np.all(np.abs(z) < 3), z
    assert [d["estimate"][n] for n in ("L1", "L2", "L3")] == pytest.approx([-1, -1, -1], abs=0.75)
    # --params auto chooses that set at these poses; the group test names the arms
    auto = identify_json(capsys, data, "--robot", ARMS, "--params", "auto")
    assert auto["params_choice"]["chosen"] == "paper+L1,L2,L3"
    assert auto["zero_offsets_deg"] == pytest.approx(d["zero_offsets_deg"], abs=1e-9)
    held = identify_json(capsys, data, "--robot", ARMS, rc_expected=1)  # the arms held at 331 mm: refused
    assert held["robot_file_test"]["explained_by"] == "L"


def test_design_takes_a_parameter_set(capsys):
    rc, _, err = zc(capsys, "design", "--robot", ARMS, "--params", "paper+L1,L2,L3")
    assert rc == 2 and "--optimize" in err
    rc, _, err = zc(capsys, "design", "--robot", ARMS, "--optimize", "--params", "paper+nope")
    assert rc == 2 and "nope" in err and len(err.strip().splitlines()) == 1
    rc, out, err = zc(capsys, "design", "--robot", ARMS, "--optimize", "--K", 12, "--choose-params", "--starts", 1,
                      "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["params_choice"]["chosen"] == "paper+L1,L2,L3" and d["params_spec"] == "paper+L1,L2,L3"
    assert d["params_choice"]["expected"] < d["params_choice"]["base_expected"]
    assert "L1" in d["params"] and d["method"].startswith("approximate")


# ------------------------------------------------------------------ nothing accepted unchecked
def test_robust_fit_without_a_spare_degree_of_freedom_is_refused(capsys, tmp_path):
    """Delta ring n = 4 (K = 8: one spare degree of freedom), one reading 0.182 mm off: the Huber loss leaves one
    reading out and nothing is left to check the fit: refused, or kept with --accept-misfit saying so."""
    from test_cli_trust import edit_reading

    data = simulate(capsys, tmp_path / "d.csv", EX / "delta.toml", "--scheme", "ring", "--n", 4, "--set",
                    "theta1=0.62", "--set", "theta2=-1.73", "--set", "theta3=0.32")
    edit_reading(data, 3, 0.182)
    out_json = tmp_path / "r.json"
    rc, out, err = zc(capsys, "identify", data, "--robot", EX / "delta.toml", "--loss", "huber", "--out", out_json)
    assert rc == 1 and not out_json.exists(), (out, err)
    assert "no spare degree of freedom" in err and out.strip().splitlines()[-1].startswith("verdict: rejected")
    rc, out, err = zc(capsys, "identify", data, "--robot", EX / "delta.toml", "--loss", "huber", "--accept-misfit")
    assert rc == 0, err
    assert "accepted despite misfit (--accept-misfit; NOT checked" in out.strip().splitlines()[-1]
    assert "fit not checked" not in out


def _write(tmp_path, text, name="r.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p
