"""zerocal identify on the measurement file format."""
import json

import numpy as np
import pytest

from zerocal_sym.model import kinematics as kin
from zerocal_sym.cli import main
from zerocal_sym.io.measurements import write_measurements
from zerocal_sym.io.results import load_result
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.tables import table2_errors
from zerocal_sym.paper.scheme import paper_poses


@pytest.fixture
def csv_file(robot, tmp_path):
    def make(group=1, n=3, noise=None, seed=0, sha=True):
        P = paper_poses(robot, n)
        th = kin.ik(robot, P)
        err = table2_errors(group)
        readings = VirtualPlant(robot, err).measure(th, noise, seed)
        meta = {"robot_sha256": robot.sha256} if sha else {}
        path = tmp_path / f"g{group}_n{n}.csv"
        write_measurements(path, Measurements(th, readings, P, meta))
        return path, err
    return make


def run_json(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, (json.loads(out) if out.strip().startswith("{") else None), err


def test_identify_nlls_json_and_out(csv_file, capsys, tmp_path, robot):
    path, err = csv_file(group=1)
    out = tmp_path / "res.json"
    rc, d, _ = run_json(capsys, ["identify", str(path), "--json", "--out", str(out)])
    assert rc == 0
    for k in ("zero_offsets_deg", "maemm_mm", "std_zero_offsets_deg", "method", "status", "success",
              "robot_sha256", "compensation", "identifiability", "info"):
        assert k in d
    assert d["method"] == "nlls" and d["success"] and d["robot_sha256"] == robot.sha256
    assert d["info"]["solver_status"] == "Solve_Succeeded"
    np.testing.assert_allclose(d["zero_offsets_deg"], np.degrees(err[:2]), atol=0.035)  # model bias, no noise
    assert d["compensation"]["sign_convention"].startswith("theta_cmd = IK(P) - offset")
    assert d["compensation"]["offset_deg"] == d["zero_offsets_deg"]
    assert json.loads(out.read_text()) == d
    r = load_result(out)  # what `zerocal compensate` reads
    np.testing.assert_allclose(r.zero_offsets_deg, d["zero_offsets_deg"])


def test_identify_tsvd_and_text(csv_file, capsys):
    path, _ = csv_file(group=2)
    rc, d, _ = run_json(capsys, ["identify", str(path), "--method", "tsvd", "--json"])
    assert rc == 0 and d["method"] == "tsvd"
    rc = main(["identify", str(path), "--report"])
    out = capsys.readouterr().out
    assert rc == 0 and "theta1" in out and "rank 4 of 4" in out and "Ipopt: Solve_Succeeded" in out


def test_identify_geometric_params_with_enough_poses(csv_file, capsys):
    path, err = csv_file(group=4, n=6)
    rc, d, _ = run_json(capsys, ["identify", str(path), "--params", "theta1,theta2,e2x,L1,L2,l1,l2,rMx,rMy",
                                 "--json"])
    assert rc == 0 and d["identifiability"]["rank"] == 9


def test_not_converged_exits_nonzero_without_file(csv_file, capsys, tmp_path):
    path, _ = csv_file(group=1)
    out = tmp_path / "res.json"
    # the bound keeps Gauss-Newton's point out, so Ipopt has to travel: 1 iteration does not converge
    rc, d, err = run_json(capsys, ["identify", str(path), "--max-iter", "1", "--bound", "rMx=-5:0.5", "--json",
                                   "--out", str(out)])
    assert rc == 1 and not out.exists()
    assert "identification failed" in err and "did not converge" in err
    assert d["success"] is False


def test_non_identifiable_offsets_exit_nonzero(csv_file, capsys, tmp_path):
    """A parameter set the poses cannot identify is refused before any work (exit 2, one line naming the rigid
    motions the distances do not see), as compare and study refuse it."""
    path, _ = csv_file(group=1, n=7)
    out = tmp_path / "res.json"
    rc, _, err = run_json(capsys, ["identify", str(path), "--params", "all", "--out", str(out)])
    assert rc == 2 and not out.exists() and "not identifiable" in err and "rigid motion" in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("argv, msg", [
    (["--params", "paper,bogus"], "unknown parameter"),
    (["--params", "all"], "fewer than the 12"),
    (["--method", "tsvd", "--params", "all"], "for --method nlls"),
    (["--prior-std", "L1=0.1"], "NAME=VALUE"),
    (["--bound", "theta1=2"], "bad value"),
])
def test_bad_options(csv_file, capsys, argv, msg):
    path, _ = csv_file(group=1)
    rc = main(["identify", str(path)] + argv)
    err = capsys.readouterr().err
    assert rc == 2 and msg in err and len(err.strip().splitlines()) == 1


def test_prior_and_bound_options(csv_file, capsys):
    path, _ = csv_file(group=1, noise=NoiseModel.paper(), seed=3)
    rc, d, _ = run_json(capsys, ["identify", str(path), "--bound", "theta1=-0.5:0.5", "--prior-std", "rMx=0.001",
                                 "--accept-misfit", "--json"])
    assert abs(d["zero_offsets_deg"][0]) <= 0.5 + 1e-6 and abs(d["maemm_mm"][0]) < 0.01
    # the bound holds theta1 at 0.5 deg where the data say 3.06 +- 0.44 deg: the fit check rejects it,
    # naming the bound; --accept-misfit keeps it, and the result records the override
    assert rc == 0 and d["success"] and d["status"].startswith("accepted despite misfit")
    assert "bound on theta1" in d["status"] or "bound on theta1" in d["fit"]["diagnosis"]
    assert d["accept_misfit"] is True and d["fit"]["accepted_despite_misfit"] is True


def test_wrong_robot_is_refused(robot, tmp_path, capsys):
    P = paper_poses(robot, 3)
    th = kin.ik(robot, P)
    path = tmp_path / "m.csv"
    write_measurements(path, Measurements(th, VirtualPlant(robot, table2_errors(1)).measure(th), P,
                                          {"robot_sha256": "0" * 64}))
    rc = main(["identify", str(path)])
    assert rc == 2 and "measured on another robot" in capsys.readouterr().err
