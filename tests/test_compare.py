"""zerocal compare: the Monte Carlo comparison and its command."""
import io
import json

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.identify.montecarlo import METHODS, Progress, format_compare, scipy_identify
from zerocal_sym.paper.compare import compare
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import ZerocalError
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors


def test_compare_all_methods_small(robot):
    rep = compare(robot, groups=(1, 4), trials=4, seed=1)
    for g in ("1", "4"):
        go = rep["groups"][g]
        assert set(go["methods"]) == set(METHODS)
        cr = go["crlb_zero_offsets_deg"]
        assert 0.3 < cr[0] < 0.8
        for m, r in go["methods"].items():
            assert r["failures"] == 0, m
            assert np.all(np.isfinite(r["rms_deg"])) and r["time_per_identification_ms"] > 0
            assert r["dp0_rms_mm"] >= 0
        # same first round: the one-shot Ipopt and scipy agree (reweighting aside)
        assert go["scipy_reference"]["max_abs_diff_to_ipopt_deg"] < 1e-4
        assert go["methods"]["tsvd-loop"]["identifications"] >= 2
        assert go["methods"]["nlls"]["identifications"] == 1
    txt = format_compare(rep)
    assert "RMS/CRLB" in txt and "nlls-seq" in txt and "scipy least_squares" in txt


def test_compare_is_reproducible_and_shares_round_one(robot):
    a = compare(robot, trials=3, seed=5, methods=("tsvd", "nlls"))
    b = compare(robot, trials=3, seed=5, methods=("nlls",))
    assert a["groups"]["1"]["methods"]["nlls"]["rms_deg"] == b["groups"]["1"]["methods"]["nlls"]["rms_deg"]


def test_compare_rejects_bad_input(robot):
    with pytest.raises(ZerocalError, match="unknown method"):
        compare(robot, trials=1, methods=("nlls", "magic"))
    with pytest.raises(ZerocalError, match="fewer than"):
        compare(robot, trials=1, params="all")


def test_scipy_reference_matches_ipopt(robot):
    th = kin.ik(robot, paper_poses(robot, 3))
    noise = NoiseModel.paper()
    m = Measurements(th, VirtualPlant(robot, table2_errors(2)).measure(th, noise, 3))
    p, info = scipy_identify(robot, m, "paper", noise)
    ref = identify_nlls(robot, m, "paper", noise=noise, warm_start=None, reweight=0)
    assert info["success"]
    np.testing.assert_allclose(np.degrees(p[:2]), np.degrees(ref.estimate[:2]), atol=1e-5)


def test_progress_bar():
    s = io.StringIO()
    bar = Progress(20, "x", stream=s)
    for k in range(1, 21):
        bar(k)
    lines = s.getvalue().splitlines()
    assert len(lines) == 10 and lines[-1].startswith("x [" + "#" * 30 + "] 20/20")


def test_cli_compare_json_and_text(capsys, tmp_path):
    rc = main(["compare", "--trials", "2", "--methods", "tsvd,nlls,scipy", "--json", "--quiet"])
    out, err = capsys.readouterr()
    d = json.loads(out)
    assert rc == 0 and err == ""
    assert set(d["groups"]["1"]["methods"]) == {"tsvd", "nlls", "scipy"}
    poses = tmp_path / "poses.csv"
    poses.write_text("pose,x_mm,y_mm\n" + "".join(f"{k},{x},{y}\n" for k, (x, y) in enumerate(
        [(-240, 632), (0, 632), (240, 632), (-240, 782), (0, 782), (240, 782), (0, 700)])))
    rc = main(["compare", "--trials", "5", "--methods", "nlls", "--poses", str(poses), "--group", "3"])
    out, err = capsys.readouterr()
    assert rc == 0 and "K = 7" in out and "group 3" in out
    assert "compare [" in err  # progress on stderr


def test_cli_compare_errors(capsys):
    assert main(["compare", "--trials", "0"]) == 2
    assert main(["compare", "--trials", "1", "--params", "nope"]) == 2
    assert main(["compare", "--trials", "1", "--group", "9"]) == 2
    err = capsys.readouterr().err
    assert "--trials" in err and "unknown parameter" in err and "1..6" in err


@pytest.mark.parametrize("params", ["offsets", "theta1,theta2"])
def test_parameter_sets_without_the_maemm(robot, params):
    """The one-shot nlls (the batch) reports the MAEMM it holds at its prior, zero, as scipy's row does
    (it raised ValueError from BatchResult.values after the whole run)."""
    rep = compare(robot, groups=[1], trials=3, params=params, methods=("nlls", "scipy"), seed=1, geometric=False)
    g = rep["groups"]["1"]["methods"]
    assert g["nlls"]["failures"] == 0 and np.all(np.isfinite(g["nlls"]["rms_deg"]))
    # the MAEMM held at zero in every trial: its error is the same constant (minus the truth) each time
    np.testing.assert_allclose(np.abs(g["nlls"]["bias_maemm_mm"]), g["nlls"]["rms_maemm_mm"], rtol=1e-12)
    assert max(g["nlls"]["rms_maemm_mm"]) > 0.1
    assert "group 1: true offsets" in format_compare(rep)
