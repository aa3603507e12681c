"""``zerocal report``: the page's sections and numbers per mechanism, the error budget, bad input; the accuracy
maps' uncertainty against a Monte Carlo of the offsets (no browser here: tests/test_report_browser.py)."""
import json
import math
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
SECTIONS = ["verdict", "offsets", "error-budget", "fit-check", "residuals", "robot", "accuracy"]
#: mechanism -> (robot file, simulate's options): the README's rounds (the hexapod's on a 32-corner fraction)
ROUNDS = {
    "planar_2dof": ("my_robot.toml", ["--group", "4", "--noise", "scale-only"]),
    "delta_rotary": ("delta.toml", ["--set", "theta1=2", "--set", "theta2=-1", "--set", "theta3=0.5",
                                    "--noise", "scale-only"]),
    "delta_linear": ("linear_delta.toml", ["--set", "s1=0.8", "--set", "s2=-0.5", "--set", "s3=0.3"]),
    "hexapod": ("hexapod.toml", ["--scheme", "corners", "--n", "32", "--set", "L1=0.3", "--set", "L2=-0.2",
                                 "--set", "L3=0.1", "--set", "L4=0.25", "--set", "L5=-0.15", "--set", "L6=0.05"]),
}


class Page(HTMLParser):
    """The parts of a page the tests read: sections (id -> text), numbers (section -> [data-value]), tags."""

    def __init__(self, text):
        super().__init__()
        self.sections, self.values, self.tags, self.srcs = {}, {}, [], []
        self._section, self._title = None, False
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append(tag)
        self._title = tag == "h2"
        if tag == "section":
            self._section = a["id"]
            self.sections[self._section] = ""
            self.values[self._section] = []
        if "data-value" in a and self._section:
            self.values[self._section].append(a["data-value"])
        for key in ("src", "href"):
            if key in a:
                self.srcs.append(a[key])

    def handle_endtag(self, tag):
        self._title = False
        if tag == "section":
            self._section = None

    def handle_data(self, data):
        if self._section and not self._title:  # a section's text without its title
            self.sections[self._section] += data


def zc(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def rounds(tmp_path_factory):
    """mechanism -> (robot file, data, result): one simulated round identified, per mechanism."""
    d = tmp_path_factory.mktemp("rounds")
    out = {}
    for mech, (robot, sim) in ROUNDS.items():
        data, res = d / f"{mech}.csv", d / f"{mech}.json"
        assert main(["simulate", "--robot", str(EX / robot), *sim, "--seed", "1", "--out", str(data)]) == 0
        assert main(["identify", str(data), "--robot", str(EX / robot), "--out", str(res),
                     *(["--noise", "scale-only"] if "scale-only" in sim else [])]) == 0
        out[mech] = (EX / robot, data, res)
    return out


@pytest.mark.parametrize("mech", list(ROUNDS))
def test_the_page_of_each_mechanism_holds_the_result_files_numbers(capsys, tmp_path, rounds, mech):
    robot, data, res = rounds[mech]
    out = tmp_path / "report.html"
    rc, stdout, err = zc(capsys, "report", res, "--robot", robot, "--data", data, "--out", out)
    assert rc == 0, err
    r = json.loads(res.read_text())
    text = out.read_text()
    page = Page(text)
    assert list(page.sections) == SECTIONS
    # self-contained: no script, no style sheet or frame from elsewhere, every source inline
    assert not {"script", "link", "iframe", "object"} & set(page.tags)
    assert page.srcs and all(s.startswith("data:image/png;base64,") for s in page.srcs)
    assert "http://" not in text and "https://" not in text and "url(" not in text
    assert page.tags.count("img") == 4  # the fit's readings, the residuals, the robot, the accuracy maps
    # the offsets and their 1 sigma in the joints' unit, digit for digit the file's
    unit = "mm" if "zero_offsets_mm" in r else "deg"
    values = [float(v) for v in page.values["offsets"]]
    m = len(r[f"zero_offsets_{unit}"])
    got = np.array(values[:2 * m]).reshape(m, 2)
    assert got[:, 0].tolist() == r[f"zero_offsets_{unit}"] and got[:, 1].tolist() == r[f"std_zero_offsets_{unit}"]
    assert f"zero offset [{unit}]" in page.sections["offsets"] and f"1 sigma [{unit}]" in page.sections["offsets"]
    # the verdict is identify's (the same words and numbers, without the next command)
    assert page.sections["verdict"].strip() == stdout.split("verdict: ", 1)[1].strip()
    assert page.sections["verdict"].strip().startswith("accepted: fit p-value")
    # the fit check names the worst reading the file names
    worst = r["fit"]["worst"]
    assert f"The worst reading: pose {worst['pose']} (the change from pose {worst['from_pose']})" in " ".join(
        page.sections["fit-check"].split())
    assert float(page.values["fit-check"][0]) == r["fit"]["chi2"]
    # identify's error budget: the file's numbers, and what limits the answer
    budget = " ".join(page.sections["error-budget"].split())
    shown = [float(v) for v in page.values["error-budget"][:2 * m]]
    assert shown == [v for e in r["error_budget"] for v in (e["noise_std"], e["robot_file_bias"])]
    assert f"Limited by: {r['limited_by']}." in budget and "not in this result file" not in budget
    assert r["error_budget"][0]["dominant_entries"][0]["name"] in budget
    # residuals: the file's RMS and, with the data, the nominal model's; the poses from the data
    rms = float(page.values["residuals"][0])
    assert math.isclose(rms, 1e3 * math.sqrt(np.mean(np.square(r["residuals_mm"]))), rel_tol=1e-12)
    assert f"the {r['data']['K']} poses" in page.sections["robot"]
    # the accuracy: the largest error before compensation is far above what the offsets' uncertainty leaves
    before, std_at, _, after, _ = (float(v) for v in page.values["accuracy"][:5])
    assert before > 5 * after > 0 and before > 3 * std_at > 0


def test_without_data_the_page_says_what_is_missing(capsys, tmp_path, rounds):
    robot, _, res = rounds["delta_rotary"]
    out = tmp_path / "r.html"
    rc, _, err = zc(capsys, "report", res, "--robot", robot, "--out", out)
    assert rc == 0, err
    page = Page(out.read_text())
    assert list(page.sections) == SECTIONS
    assert "give --data" in page.sections["residuals"] and "give --data" in page.sections["robot"]
    assert page.tags.count("img") == 4  # the residuals at the estimate are the file's


def _budget_result(rounds, tmp_path, mech="linear", **keys):
    mech = {"linear": "delta_linear", "planar": "planar_2dof"}[mech]
    robot, data, res = rounds[mech]
    r = json.loads(res.read_text())
    r.update(keys)
    path = tmp_path / "budget.json"
    path.write_text(json.dumps(r, indent=2))
    return robot, data, path, r


def test_a_result_without_an_error_budget_says_so(capsys, tmp_path, rounds):
    """A results file written before the error budget (its keys removed here): the page says it is not there."""
    robot, _, res = rounds["delta_linear"]
    r = json.loads(res.read_text())
    for key in ("error_budget", "limited_by"):
        r.pop(key)
    old = tmp_path / "old.json"
    old.write_text(json.dumps(r, indent=2))
    out = tmp_path / "r.html"
    rc, _, err = zc(capsys, "report", old, "--robot", robot, "--out", out)
    assert rc == 0, err
    section = " ".join(Page(out.read_text()).sections["error-budget"].split())
    assert "error budget: not in this result file" in section


def _edited_budget(r, k, **entry):
    b = json.loads(json.dumps(r["error_budget"]))
    b[k].update(entry)
    return b


@pytest.mark.parametrize("edit, words", [
    (lambda r: {"error_budget": [r["error_budget"][1]] * 3}, "entry 1 must be the budget of s1 (joint order)"),
    (lambda r: {"error_budget": _edited_budget(r, 0, noise_std=-1)}, "noise_std must be a number >= 0 or null"),
    (lambda r: {"error_budget": [], "limited_by": "data"}, "must be a list of 3 entries"),
    (lambda r: {"limited_by": "luck"}, "key 'limited_by' must be one of"),
])
def test_a_malformed_error_budget_is_one_line_and_nothing_written(capsys, tmp_path, rounds, edit, words):
    robot, _, res = rounds["delta_linear"]
    r = json.loads(res.read_text())
    r.update(edit(r))
    bad = tmp_path / "budget.json"
    bad.write_text(json.dumps(r, indent=2))
    out = tmp_path / "r.html"
    rc, _, err = zc(capsys, "report", bad, "--robot", robot, "--out", out)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and words in err and str(bad) in err, err
    assert not out.exists()


def test_a_result_and_data_of_different_robots_are_refused_naming_both(capsys, tmp_path, rounds):
    robot, data, res = rounds["planar_2dof"]
    other = tmp_path / "paper.csv"
    assert main(["simulate", "--group", "1", "--seed", "2", "--out", str(other)]) == 0  # the paper's robot
    capsys.readouterr()
    out = tmp_path / "r.html"
    rc, _, err = zc(capsys, "report", res, "--robot", robot, "--data", other, "--out", out)
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert f"the result {res}" in err and f"the data {other}" in err and "robot_sha256" in err
    assert not out.exists()
    # a result of another robot than --robot's (here the default, the paper's): refused too
    rc, _, err = zc(capsys, "report", res, "--out", out)
    assert rc == 2 and "identified on another robot" in err and not out.exists()


def test_an_edited_covariance_is_refused(capsys, tmp_path, rounds):
    _, _, _, r = _budget_result(rounds, tmp_path, mech="planar")
    r["covariance"][0][0] *= 4  # theta1's 1 sigma doubled in one copy only
    robot = rounds["planar_2dof"][0]
    res = tmp_path / "edited.json"
    res.write_text(json.dumps(r))
    rc, _, err = zc(capsys, "report", res, "--robot", robot, "--out", tmp_path / "r.html")
    assert rc == 2 and "key 'covariance': the 1 sigma of theta1" in err and not (tmp_path / "r.html").exists()


def test_a_rejected_result_gets_a_page_without_its_offsets(capsys, tmp_path, rounds):
    _, _, _, r = _budget_result(rounds, tmp_path, mech="planar", success=False,
                                status="rejected: fit p-value 1e-09 < 0.001")
    res = tmp_path / "rejected.json"
    res.write_text(json.dumps(r))
    out = tmp_path / "r.html"
    rc, stdout, err = zc(capsys, "report", res, "--robot", rounds["planar_2dof"][0], "--out", out)
    assert rc == 0, err
    page = Page(out.read_text())
    assert page.sections["verdict"].strip() == "rejected: fit p-value 1e-09 < 0.001"
    assert "not reported" in page.sections["offsets"] and "not reported" in page.sections["accuracy"]
    assert page.values["offsets"] == [] and 'class="verdict bad"' in out.read_text()


def test_the_goal_judges_the_sigma(capsys, tmp_path, rounds):
    from zerocal_sym.cli.cmd_report import verdict
    from zerocal_sym.io.results import load_result
    from zerocal_sym.model.robot import load_robot

    robot, _, res = rounds["planar_2dof"]
    out = tmp_path / "r.html"
    rc, stdout, err = zc(capsys, "report", res, "--robot", robot, "--goal", "0.2", "--out", out)
    assert rc == 0 and "within the goal 0.2 deg" in Page(out.read_text()).sections["verdict"], err
    r = load_robot(robot)
    text, accepted = verdict(r, load_result(res, robot=r), goal=0.01)
    assert accepted and "NOT within the goal 0.01 deg" in text
    rc, _, err = zc(capsys, "report", res, "--robot", robot, "--goal", "0", "--out", tmp_path / "x.html")
    assert rc == 2 and "--goal must be a finite positive number" in err and not (tmp_path / "x.html").exists()


# --------------------------------------------------------------------------- the maps' numbers


@pytest.mark.parametrize("robot_file", ["paper_robot.toml", "delta.toml", "hexapod.toml"])
def test_the_propagated_uncertainty_is_the_monte_carlo_spread(robot_file):
    """At a few poses, offsets drawn from N(estimate, C) (a spread of about 1/20 of the offsets, as a calibration
    gives): the RMS position error left by compensating with the estimate, and the spread of the uncompensated
    error's length, are the maps' -- within 4 standard errors of the Monte Carlo plus the first order's neglect,
    the relative (spread / error)^2 (the length of an error is not linear in it)."""
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.robot import load_robot
    from zerocal_sym.report.accuracy import position_axes, predicted_errors

    robot = load_robot(EX / robot_file)
    rng = np.random.default_rng(7)
    m, pos = robot.m, position_axes(robot)[0]
    scale = 0.02 if robot.errors.offset_unit == "rad" else 0.3  # offsets of about a degree, or 0.3 mm
    offsets = rng.normal(0, scale, m)
    A = rng.normal(0, scale / 100, (m, m))
    cov = A @ A.T + np.eye(m) * (scale / 200) ** 2
    lo, hi = robot.workspace.bounds()
    P = robot.workspace.centre() + (rng.uniform(-0.4, 0.4, (3, robot.n)) * (hi - lo))
    pred = predicted_errors(robot, offsets, cov, P)
    N = 4000
    draws = rng.multivariate_normal(offsets, cov, N)
    theta = kin.ik(robot, P)
    for k in range(len(P)):
        second = (pred["after_mm"][k] / pred["before_mm"][k]) ** 2
        after = kin.fk(robot, theta[k] + draws - offsets)[:, pos] - P[k, pos]  # compensated with the estimate
        sq = np.sum(after**2, axis=1)
        rms, se = math.sqrt(sq.mean()), sq.std() / math.sqrt(N) / (2 * math.sqrt(sq.mean()))
        assert abs(rms - pred["after_mm"][k]) < 4 * se + second * rms, (k, rms, pred["after_mm"][k])
        before = np.linalg.norm(kin.fk(robot, theta[k] + draws)[:, pos] - P[k, pos], axis=1)
        sd = before.std()
        se_sd = sd / math.sqrt(2 * (N - 1))
        assert abs(sd - pred["before_std_mm"][k]) < 4 * se_sd + second * sd, (k, sd, pred["before_std_mm"][k])
        exact = np.linalg.norm(kin.fk(robot, theta[k] + offsets)[0, pos] - P[k, pos])
        assert math.isclose(pred["before_mm"][k], exact, rel_tol=1e-9)


def test_the_robot_is_drawn_by_its_sketch():
    """Every packaged mechanism draws itself: a base that stays where it is and a platform that moves with the
    pose (a translation of the pose moves some segment ends by exactly that); the measuring line is lambda long."""
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.robot import load_robot

    for name in ("paper_robot", "delta", "linear_delta", "hexapod"):
        robot = load_robot(EX / f"{name}.toml")
        P = robot.home_pose()[None, :]
        shift = np.zeros(robot.n)
        shift[0] = 7.0  # mm along x
        seg = kin.sketch(robot, np.vstack([P, P + shift]))
        assert seg is not None and seg.shape[2] == 2 and np.all(np.isfinite(seg)), name
        a, b = (s.reshape(-1, seg.shape[-1]) for s in seg)
        moved = np.linalg.norm(b - a - shift[:seg.shape[-1]], axis=1) < 1e-9
        fixed = np.linalg.norm(b - a, axis=1) < 1e-9
        assert moved.any() and fixed.any(), name
        line = kin.measuring_line(robot, P)[0]
        lam, _ = kin.measuring_vector(robot, P)
        assert math.isclose(np.linalg.norm(line[1] - line[0]), lam[0], rel_tol=1e-12)


def test_a_mechanism_without_a_sketch_is_drawn_without_it(monkeypatch):
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.robot import load_robot
    from zerocal_sym.report import figures

    robot = load_robot(EX / "delta.toml")
    monkeypatch.setattr(kin, "sketch", lambda robot, P, theta=None: None)
    assert figures.png(figures.figure_robot(robot))[:4] == b"\x89PNG"


def test_data_of_another_round_of_the_same_robot_are_refused(capsys, tmp_path, rounds):
    """The same robot and K, another seed: its residuals at the result's estimate are not the result's."""
    robot, data, res = rounds["delta_rotary"]
    other = tmp_path / "other.csv"
    assert main(["simulate", "--robot", str(robot), "--set", "theta1=2", "--set", "theta2=-1", "--set",
                 "theta3=0.5", "--noise", "scale-only", "--seed", "5", "--out", str(other)]) == 0
    capsys.readouterr()
    out = tmp_path / "r.html"
    rc, _, err = zc(capsys, "report", res, "--robot", robot, "--data", other, "--out", out)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and not out.exists(), err
    assert f"{other}: not the data the result {res} was identified from" in err
