"""``zerocal design --scheme paper``, ``simulate`` and ``reproduce``."""
import json
import os
import stat

import numpy as np
import pytest

from zerocal_sym.cli import main
from zerocal_sym.io.measurements import load_measurements
from zerocal_sym.identify.tsvd import identify_tsvd


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_design_paper_n3_json(capsys):
    rc, out, _ = run(capsys, "design", "--scheme", "paper", "--n", "3", "--json")
    assert rc == 0
    d = json.loads(out)
    assert d["n"] == 3 and len(d["poses"]) == 6
    assert d["poses"][0] == [-240.0, 632.0] and d["poses"][3] == [-240.0, 782.0]
    assert d["kappa_1"] == pytest.approx(475.34, abs=0.01)
    assert abs(d["kappa_m"] - 472.54) < 0.3
    assert d["eps_rule_n"] == 3
    assert d["maemm_prior_mm"] == [1.0, -0.5]
    np.testing.assert_allclose(d["crlb_zero_offsets_deg"], [0.522, 0.522], atol=0.002)
    np.testing.assert_allclose(d["crlb_zero_offsets_deg_scale_only"], [0.048, 0.048], atol=0.001)
    readings = {v["maemm_prior_mm"][0] * 10 + v["maemm_prior_mm"][1]: v["kappa_m"]
                for v in d["kappa_m_readings"].values()}
    assert readings[10.5] == pytest.approx(478.146, abs=1e-3)
    assert readings[9.5] == pytest.approx(472.348, abs=1e-3)
    assert readings[-10.5] == pytest.approx(472.576, abs=1e-3)


def test_design_eps_rule_selects_n3(capsys):
    rc, out, _ = run(capsys, "design", "--json")
    d = json.loads(out)
    assert rc == 0 and d["n"] == 3 and d["selected_by"] == "eps0 rule" and d["eps"] <= 0.01


def test_design_text_and_prior(capsys):
    rc, out, _ = run(capsys, "design", "--n", "5", "--maemm-prior", "1", "0.5")
    assert rc == 0 and "kappa_1 =" in out and "P10" in out and "CRLB" in out


@pytest.mark.parametrize("argv", [["design", "--n", "2"], ["design", "--eps0", "0"],
                                  ["simulate", "--group", "7", "--out", "x.csv"],
                                  ["simulate", "--group", "1", "--n", "2", "--out", "x.csv"],
                                  ["reproduce", "--trials", "0"], ["reproduce", "--truncation", "5"]])
def test_bad_input_is_one_line_exit_2(capsys, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and err.count("\n") == 1 and err.startswith(f"zerocal {argv[0]}: error:")
    assert not (tmp_path / "x.csv").exists()


def test_simulate_writes_the_data_format(capsys, tmp_path, robot):
    f = tmp_path / "g1.csv"
    rc, out, _ = run(capsys, "simulate", "--group", "1", "--noise", "none", "--out", str(f))
    assert rc == 0 and "wrote 6 poses" in out
    m = load_measurements(f, robot=robot)
    assert m.K == 6 and m.meta["group"] == "1" and m.meta["true_zero_offsets_deg"] == "-2 1"
    res = identify_tsvd(robot, m)
    np.testing.assert_allclose(res.zero_offsets_deg, [-2.0, 1.0], atol=0.2)
    # with the compensation applied the commanded angles move by it
    g = tmp_path / "g1c.csv"
    run(capsys, "simulate", "--group", "1", "--noise", "none", "--compensation", "-2", "1", "--out", str(g))
    m2 = load_measurements(g, robot=robot)
    np.testing.assert_allclose(np.degrees(m.theta_cmd - m2.theta_cmd), np.tile([-2.0, 1.0], (6, 1)), atol=1e-9)
    # the same seed gives the same file
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    run(capsys, "simulate", "--group", "2", "--seed", "5", "--out", str(a))
    run(capsys, "simulate", "--group", "2", "--seed", "5", "--out", str(b))
    assert a.read_text() == b.read_text()


def test_reproduce_json(capsys):
    rc, out, _ = run(capsys, "reproduce", "--noise", "none", "--json")
    assert rc == 0
    d = json.loads(out)
    keys = ["group", "compensation_deg", "delta_deg", "dp0_before_mm", "dp0_after_mm", "dpmax_before_mm",
            "dpmax_after_mm", "delta_maemm_mm", "kappa_mean"]
    assert [g["group"] for g in d["groups"]] == [1, 2, 3, 4, 5, 6]
    for g, p in zip(d["groups"], d["paper"]):
        assert all(k in g for k in keys)
        assert g["dp0_before_mm"] == pytest.approx(p["dp0_before_mm"], abs=0.002)
        assert g["kappa_mean"] == pytest.approx(p["kappa_mean"], abs=0.05)


def test_reproduce_text_trials_and_out(capsys, tmp_path):
    out_dir = tmp_path / "rep"
    old = os.umask(0o027)  # the directory and its files honour the umask (tests/test_hardening.py for the rest)
    try:
        rc, out, err = run(capsys, "reproduce", "--trials", "2", "--out", str(out_dir))
    finally:
        os.umask(old)
    assert rc == 0
    assert stat.S_IMODE(out_dir.stat().st_mode) == 0o750
    assert {stat.S_IMODE(p.stat().st_mode) for p in out_dir.iterdir()} == {0o640}
    for t in ("Table 3", "Table 4", "Table 5", "Table 6", "±"):
        assert t in out
    assert err.splitlines()[-1].startswith("reproduce [") and " 12/12 " in err.splitlines()[-1]  # a quarter each
    names = {p.name for p in out_dir.iterdir()}  # every figure (one run serves the figure-set check too)
    expected = {"fig8.png", "fig9.png", "results.json"} | {f"fig12_group{g}.png" for g in range(1, 7)} | {
        f"convergence_group{g}.png" for g in range(1, 7)}
    assert expected <= names
    assert not [n for n in names if n.startswith(".")], "temporary files left behind"
    for name in expected - {"results.json"}:
        assert (out_dir / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    d = json.loads((out_dir / "results.json").read_text())
    assert d["settings"]["trials"] == 2 and "compensation_deg_std" in d["groups"][0]
    assert len(d["fig8"]["n"]) == 19
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]  # no temporary directory left


def test_reproduce_out_is_all_or_nothing(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    rc, _, err = run(capsys, "reproduce", "--out", str(blocker))
    assert rc == 2 and "not a directory" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
