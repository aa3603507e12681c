"""Revisited poses: the loaders, the shared revisit error in the covariance, designs of true replicates."""
import json
import math

import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.cli import main
from zerocal_sym.design import approx, rounding
from zerocal_sym.identify import fisher
from zerocal_sym.identify.covariance import ChangeCovariance
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.estimate.revisits import reml_revisit_std
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.revisits import consecutive_repeat, pose_groups
from zerocal_sym.model.robot import paper_robot

from roundoff import cond_tol

PAPER = NoiseModel.paper()
#: six poses of the paper's workspace, visited five times each in turn
SUPPORT = np.array([[-240, 782], [240, 782], [240, 635.74], [-240, 635.74], [0, 632], [0, 700]], float)


def assert_close_in_units(a, b, scale, factor=100.0):
    """``a == b`` to ``factor * eps`` times ``scale`` (:func:`roundoff.cond_tol`): two routes to one number.  The
    callers pass the problem's condition number in ``factor`` where a solve is involved; the 100 beside it
    covers forming the matrices (sums of K terms, a second algorithm)."""
    np.testing.assert_allclose(a, b, rtol=0, atol=cond_tol(factor, 100.0) * scale)


def one_line_error(capsys, argv, pattern):
    """Exit status 2, one line on stderr naming the command and matching ``pattern``, no traceback."""
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert rc == 2, (argv, rc, out, err)
    lines = err.strip().split("\n")
    assert len(lines) == 1 and "Traceback" not in err and lines[0].startswith(f"zerocal {argv[0]}: error: "), err
    assert pattern in lines[0], err


def _shared(tau):
    return NoiseModel(PAPER.sigma_scale_mm, PAPER.sigma_joint, tau)


def _dense(sm2, v, lab, tau):
    """``sigma_m^2 I + D (diag v + tau^2 Z Z^T) D^T``, built directly."""
    K = len(v)
    D = np.eye(K - 1, K, 1) - np.eye(K - 1, K)
    Z = np.eye(lab.max() + 1)[lab]
    return sm2 * np.eye(K - 1) + D @ (np.diag(v) + tau**2 * Z @ Z.T) @ D.T


@pytest.fixture(scope="module")
def robot():
    return paper_robot()


# ----------------------------------------------------------------- the covariance with the shared part
def test_shared_covariance_is_exact():
    """Bands + one low-rank column per revisited pose (Woodbury): every operation as the dense matrix's."""
    rng = np.random.default_rng(1)
    lab = np.array([0, 1, 2, 0, 3, 1, 0, 4, 2, 5, 1, 6])
    v = rng.uniform(0.5, 2.0, lab.size)
    C = ChangeCovariance.from_variances(0.3, v, lab, 0.7)
    Cd = _dense(0.09, v, lab, 0.7)
    assert C.shared.G == 3 and not C.banded  # poses 0, 1, 2 revisited (the others carry it alone)
    A = rng.normal(size=(lab.size - 1, 3))
    W = C.whitener()
    scale = float(np.max(np.abs(Cd)))
    assert_close_in_units(C.dense(), Cd, scale)
    assert_close_in_units(W @ Cd @ W.T, np.eye(lab.size - 1), 1.0, factor=np.linalg.cond(Cd))
    assert_close_in_units(C.solve(A), np.linalg.solve(Cd, A), np.max(np.abs(np.linalg.solve(Cd, A))),
                          factor=np.linalg.cond(Cd))
    assert_close_in_units(C.inverse_diagonal(), np.diag(np.linalg.inv(Cd)), 1.0, factor=np.linalg.cond(Cd))
    assert_close_in_units(C.logdet(), np.linalg.slogdet(Cd)[1], 1.0, factor=lab.size)
    assert_close_in_units(C.sandwich(A.T), A.T @ Cd @ A, np.max(np.abs(A.T @ Cd @ A)))
    assert_close_in_units(C.whiten_transpose(A), W.T @ A, np.max(np.abs(W.T @ A)), factor=np.linalg.cond(Cd))
    keep = np.array([0, 1, 3, 4, 5, 8, 9, 10])
    assert_close_in_units(C.take(keep).dense(), Cd[np.ix_(keep, keep)], scale)


def test_simulated_shared_error_has_the_model_covariance(robot):
    """VirtualPlant's readings (servo, scale, shared error) whitened by the model: identity covariance."""
    P = SUPPORT[[0, 1, 2, 0, 3, 1, 4, 0]]
    th = kin.ik(robot, P)
    nm = _shared(0.02)
    plant = VirtualPlant(robot, robot.errors.zeros())
    rng = np.random.default_rng(5)
    N = 3000
    S = np.array([plant.measure(th, nm, rng)[1:] for _ in range(N)])
    C = fisher.change_covariance(robot, th, nm)
    Y = C.whiten((S - S.mean(axis=0)).T).T
    cov = Y.T @ Y / (N - 1)
    # entries of a sample covariance of N standard normals: sd 1/sqrt(N) (2/N on the diagonal); 5 sd
    assert np.max(np.abs(cov - np.eye(cov.shape[0]))) < 5 * math.sqrt(2.0 / N)
    # without the shared part the same readings are not white (the model would be wrong)
    C0 = fisher.change_covariance(robot, th, PAPER)
    Y0 = C0.whiten((S - S.mean(axis=0)).T).T
    assert np.max(np.abs(Y0.T @ Y0 / (N - 1) - np.eye(cov.shape[0]))) > 10 * math.sqrt(2.0 / N)


# ----------------------------------------------------------------- identification with the shared error
def test_nlls_and_tsvd_weight_by_the_full_covariance(robot):
    P = SUPPORT[np.tile(np.arange(6), 5)]
    th = kin.ik(robot, P)
    nm = _shared(0.003)
    err = robot.errors.vector({"theta1": math.radians(0.5), "theta2": math.radians(-0.3)})
    rd = VirtualPlant(robot, err).measure(th, nm, np.random.default_rng(3))
    meas = Measurements(th, rd)
    res = identify_nlls(robot, meas, noise=nm)
    assert res.success and "full covariance" in res.info["weighting"]
    full = robot.errors.put(robot.errors.zeros(), res.params, res.estimate)
    # chi2: the residuals whitened by the dense covariance at the estimate
    Cd = fisher.change_covariance(robot, th, nm, full).dense()
    e = rd[1:] - np.diff(kin.distance(robot, th, full))
    chi2 = float(e @ np.linalg.solve(Cd, e))
    assert_close_in_units(res.info["fit"]["chi2"], chi2, chi2, factor=np.linalg.cond(Cd))
    # its covariance is the CRLB at the estimate with the shared part
    crlb = fisher.crlb(robot, th, res.params, nm, full)
    assert_close_in_units(res.covariance, crlb, np.max(np.abs(crlb)), factor=1e3)
    tsvd = identify_tsvd(robot, meas, noise=nm)  # its fit check: the same exact-model minimum, the same weights
    assert_close_in_units(tsvd.info["fit"]["chi2"], chi2, chi2, factor=np.linalg.cond(Cd))
    for r in (res, tsvd):
        rv = r.info["revisits"]
        assert rv["revisited_poses"] == 6 and rv["visits"] == 30 and rv["assumed_mm"] == 0.003
        assert rv["ci95_mm"][0] <= rv["estimate_mm"] <= rv["ci95_mm"][1]
    with pytest.raises(ValueError, match="robust loss"):
        identify_nlls(robot, meas, noise=nm, loss="huber")


def test_restricted_likelihood_is_the_dense_one(monkeypatch):
    """Both forms of the REML likelihood (every pose low-rank, bands fixed; or bands per sigma_r) against the
    dense formula."""
    from zerocal_sym.identify.estimate import revisits

    rng = np.random.default_rng(2)
    lab = np.array([0, 1, 2, 0, 3, 1, 4, 2, 5, 0, 6, 3, 7, 1])
    X = np.diff(rng.normal(size=(8, 3))[lab], axis=0)
    v = rng.uniform(1.0, 2.0, lab.size)
    e = rng.normal(size=lab.size - 1)
    for s in (0.0, 0.4, 2.0):
        C = _dense(0.5, v, lab, s)
        Ci = np.linalg.inv(C)
        P = Ci - Ci @ X @ np.linalg.solve(X.T @ Ci @ X, X.T @ Ci)
        ref = -0.5 * (np.linalg.slogdet(C)[1] + np.linalg.slogdet(X.T @ Ci @ X)[1] + e @ P @ e)
        for most in (200, 0):
            monkeypatch.setattr(revisits, "MAX_POSES_LOW_RANK", most)
            assert_close_in_units(revisits._likelihood(0.5, v, lab, X, e)(s), ref, abs(ref), factor=np.linalg.cond(C))


@pytest.mark.slow
def test_reml_interval_covers_the_shared_error():
    """The REML 95 % profile interval of sigma_r, on a linear model with Gaussian data: coverage over 300 rounds
    within 3 binomial sd of 95 %; the test of none rejects at about its level when there is none."""
    rng = np.random.default_rng(11)
    G, reps = 16, 8
    lab = np.concatenate([rng.permutation(G) for _ in range(reps)])
    lab = lab[np.r_[True, lab[1:] != lab[:-1]]]
    K = lab.size
    X = np.diff(rng.normal(size=(G, 4))[lab], axis=0)
    v = rng.uniform(1.0, 2.0, K)
    for tau in (1.0, 0.0):
        Lc = np.linalg.cholesky(_dense(0.5, v, lab, tau))
        n, cover, rejected = 300, 0, 0
        for _ in range(n):
            out = reml_revisit_std(Lc @ rng.normal(size=K - 1), X, 0.5, v, lab)
            lo, hi = out["ci95_mm"]
            cover += lo <= tau <= (np.inf if hi is None else hi)
            rejected += out["p_value_zero"] < 0.05
        sd = math.sqrt(0.95 * 0.05 / n)
        assert abs(cover / n - 0.95) < 3 * sd, (tau, cover / n)
        if tau == 0:
            assert rejected / n < 0.05 + 3 * math.sqrt(0.05 * 0.95 / n)


# ----------------------------------------------------------------- designs of true replicates
def test_replicated_design_levels_off_with_a_shared_error(robot):
    """Replicates average the independent noise: CRLB ~ 1/sqrt(K); a shared error stays: the CRLB levels off
    at the support's floor (every support point's own error, the independent ones averaged away)."""
    cons = design.make_constraints(robot)
    ad = approx.approximate_design(robot, "crlb", cons)
    for tau, expect in ((0.0, "1/sqrt(K)"), (0.01, "floor")):
        nm = _shared(tau)
        c = {}
        for K in (200, 3200):
            P, _ = rounding.realize(robot, ad, K, cons, nm, n_orders=2)
            assert consecutive_repeat(P) is None and design.check_design(robot, P, cons) == []
            assert pose_groups(P).max() + 1 == len(ad.support)  # the support points, nothing else
            c[K] = design.criterion_values(robot, P, nm)["crlb"]
            assert_close_in_units(c[K], math.sqrt(np.mean(fisher.crlb_zero_offsets_user(
                robot, kin.ik(robot, P), "paper", nm) ** 2)), c[K], factor=1e4)
        floor = design.replicates.shared_floor(robot, ad.support, nm)
        if expect == "1/sqrt(K)":
            assert floor == 0 and abs(c[3200] / c[200] - 0.25) < 0.01
        else:  # 16 times the poses gain 0.7 %: at the floor, above it
            assert floor <= c[3200] <= c[200] <= 1.02 * floor and c[3200] / c[200] > 0.98


def test_target_crlb_is_within_two_percent_of_its_bound(capsys, tmp_path):
    out = tmp_path / "t.json"
    assert main(["design", "--target-crlb", "0.04", "--json", "--out", str(out)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["crlb_rms_deg"] <= 0.04 and d["K"] <= 1.02 * d["K_lower_bound"]
    P = np.asarray(d["poses"])
    assert d["revisits"] == "allowed" and consecutive_repeat(P) is None and pose_groups(P).max() + 1 == 6
    # the design's replicates go through simulate (the file says revisits are intended) and identify
    data = tmp_path / "d.csv"
    assert main(["simulate", "--set", "theta1=0.5", "--set", "theta2=-0.3", "--poses", str(out),
                 "--out", str(data)]) == 0
    assert "# revisits: allowed" in data.read_text()
    capsys.readouterr()
    result = tmp_path / "r.json"
    assert main(["identify", str(data), "--json", "--out", str(result)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["success"] and res["revisits"]["visits"] == d["K"] - 2  # two support points visited once
    # verify: a second round of the design with that compensation applied
    again = tmp_path / "v.csv"
    assert main(["simulate", "--set", "theta1=0.5", "--set", "theta2=-0.3", "--poses", str(out), "--seed", "1",
                 "--compensation", *map(str, res["zero_offsets_deg"]), "--out", str(again)]) == 0
    capsys.readouterr()
    assert main(["verify", str(result), str(again), "--json"]) in (0, 1)  # (1: not yet within mu0)
    assert json.loads(capsys.readouterr().out)["revisits"]["revisited_poses"] == 4
    # compare and a study's spec read the design's poses as rounds
    assert main(["compare", "--poses", str(out), "--set", "theta1=0.5", "--trials", "2", "--methods", "tsvd",
                 "--quiet", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)
    from zerocal_sym.cli.study_spec import load_spec

    spec = tmp_path / "s.toml"
    spec.write_text(f'name = "r"\ntrials = 2\nrobots = ["paper"]\n[[design]]\nposes = "{out.name}"\n'
                    '[[truth]]\nname = "t"\ntheta1 = 0.5\n')
    assert load_spec(spec) is not None


# ----------------------------------------------------------------- the loaders
def _data(tmp_path, seq, meta=""):
    """A measurement file visiting ``SUPPORT[seq]`` (simulated readings), with ``meta`` lines before the header."""
    robot = paper_robot()
    th = kin.ik(robot, SUPPORT[seq])
    rd = VirtualPlant(robot, robot.errors.vector({"theta1": 0.01})).measure(th, PAPER, np.random.default_rng(0))
    f = tmp_path / "m.csv"
    f.write_text(meta + "pose,theta1_deg,theta2_deg,reading_mm\n" + "".join(
        f"{k},{a!r},{b!r},{r!r}\n" for k, ((a, b), r) in enumerate(zip(np.degrees(th).tolist(), rd.tolist()))))
    return f


SEQ = [0, 1, 2, 3, 4, 5, 0]


def test_revisits_refused_unless_intended_and_never_in_a_row(capsys, tmp_path):
    """A revisit: refused with the way to allow it; the metadata line or --allow-revisits allow it; a pose right
    after itself (a zero change) refused either way."""
    one_line_error(capsys, ["identify", _data(tmp_path, SEQ)],
                   "pose 6 repeats the commanded joint angles of pose 0 (line 2); a revisit: if the file revisits "
                   "poses on purpose (a design's replicates), add the line '# revisits: allowed' to it or pass "
                   "--allow-revisits")
    for extra, meta in (([], "# revisits: allowed\n"), (["--allow-revisits"], "")):
        assert main(["identify", str(_data(tmp_path, SEQ, meta)), "--json", *extra]) == 0
        assert json.loads(capsys.readouterr().out)["revisits"]["revisited_poses"] == 1
    for meta, extra in (("# revisits: allowed\n", []), ("", ["--allow-revisits"])):
        one_line_error(capsys, ["identify", _data(tmp_path, [0, 1, 2, 2, 3, 4, 5], meta), *extra],
                       "pose 3 repeats the commanded joint angles of the pose before it, pose 2 (line "
                       f"{5 if meta else 4}): a zero change")
    one_line_error(capsys, ["identify", _data(tmp_path, SEQ, "# revisits: maybe\n")],
                   "'# revisits:' can only be 'allowed'")


def test_pose_files_of_a_round(capsys, tmp_path):
    """A pose file read as a measurement round (simulate, compensate --template, compare, study): the same
    rules; its JSON form says it with a key; a command table may repeat poses."""
    poses = [[-240, 782], [240, 782], [240, 640], [-240, 640], [0, 632], [-240, 782]]
    f = tmp_path / "p.json"
    f.write_text(json.dumps({"poses": poses}))
    out = tmp_path / "t.csv"
    one_line_error(capsys, ["compensate", "--poses", f, "--template", "--out", out],
                   'add the key "revisits": "allowed" to it or pass --allow-revisits')
    one_line_error(capsys, ["simulate", "--set", "theta1=1", "--poses", f, "--out", out], "duplicated pose")
    assert main(["compensate", "--poses", str(f), "--template", "--out", str(out), "--allow-revisits"]) == 0
    assert "# revisits: allowed" in out.read_text()
    f.write_text(json.dumps({"poses": poses, "revisits": "allowed"}))
    assert main(["simulate", "--set", "theta1=1", "--poses", str(f), "--out", str(out)]) == 0
    f.write_text(json.dumps({"poses": poses[:2] + poses[1:], "revisits": "allowed"}))
    one_line_error(capsys, ["simulate", "--set", "theta1=1", "--poses", f, "--out", out], "a zero change")


def test_robot_file_revisit_std(tmp_path):
    from zerocal_sym.errors import RobotFileError
    from zerocal_sym.model.robot import load_robot

    from pathlib import Path

    base = (tmp_path / "r.toml")
    text = (Path(__file__).resolve().parents[1] / "examples" / "paper_robot.toml").read_text() + "\n[noise]\n"
    base.write_text(text + "revisit_std_mm = 0.004\n")
    assert load_robot(base).noise.sigma_revisit_mm == 0.004
    assert NoiseModel.named("servo-only", load_robot(base)).sigma_revisit_mm == 0  # the robot's full noise only
    base.write_text(text + "scale = 0\njoint = 0\nrevisit_std_mm = 0.004\n")
    with pytest.raises(RobotFileError, match="needs an independent term"):
        load_robot(base)
