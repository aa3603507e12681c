"""Report plots: the numbers behind them (not pixels) and valid PNG files."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.io import measurements as data
from zerocal_sym.model import kinematics
from zerocal_sym.report import plots as rp
from zerocal_sym.identify.loop import calibration_loop
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.tables import group_errors
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.identify.tsvd import identify_tsvd

PNG = b"\x89PNG\r\n\x1a\n"
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "measurements_example.csv"


def test_boundary_positions_fig11(robot):
    P = rp.boundary_positions(robot)
    assert P.shape == (42, 2)
    # 1260 mm perimeter, one position every 30 mm
    step = np.linalg.norm(np.diff(np.vstack([P, P[:1]]), axis=0), axis=1)
    np.testing.assert_allclose(step[step > 29], 30.0, atol=1e-9)
    # corners: P1, P17, P22, P38 (1-based)
    np.testing.assert_array_equal(P[[0, 16, 21, 37]], [[-240, 632], [240, 632], [240, 782], [-240, 782]])
    # P1..P17 along y = H towards +x, P22..P38 along y = H + h towards -x, P39..P42 down x = -b/2
    assert np.all(P[:17, 1] == 632) and np.all(np.diff(P[:17, 0]) > 0)
    assert np.all(P[21:38, 1] == 782) and np.all(np.diff(P[21:38, 0]) < 0)
    assert np.all(P[38:, 0] == -240) and np.all(np.diff(P[37:, 1]) < 0)
    lo, hi = robot.workspace_bounds()
    assert np.all(P >= lo) and np.all(P <= hi)
    assert len({tuple(p) for p in P}) == 42
    with pytest.raises(ValueError):
        rp.boundary_positions(robot, 3)


def test_boundary_positions_other_K(robot):
    P = rp.boundary_positions(robot, 10)
    assert P.shape == (10, 2)
    np.testing.assert_array_equal(P[0], [-240, 632])
    s = np.linalg.norm(np.diff(P, axis=0), axis=1)
    assert np.all(s <= 126 + 1e-9)  # spacing 126 mm along the perimeter (chords across corners are shorter)


def test_boundary_errors_before_after(robot):
    err = group_errors(1)
    d = rp.boundary_errors(robot, err, np.degrees(err[:2]))
    assert d["before_mm"].shape == d["after_mm"].shape == (42,)
    np.testing.assert_array_equal(d["index"], np.arange(1, 43))
    # before: the plant's error at nominal commands (paper Table 4 dp_max before 12.906 mm is over the 6 poses,
    # which are among the 42: P1, P9, P17, P22, P30, P38)
    six = rp.boundary_errors(robot, err, [0, 0], P=paper_poses(robot, 3))
    np.testing.assert_allclose(six["before_mm"], d["before_mm"][[0, 8, 16, 37, 29, 21]], atol=1e-9)
    assert abs(six["max_before_mm"] - 12.906) < 0.001
    # exact compensation leaves only the geometric errors (set A, tens of um)
    assert d["max_after_mm"] < 0.1 and d["max_before_mm"] > 10
    # no compensation: after == before; a wrong-sign compensation doubles the offset effect
    same = rp.boundary_errors(robot, err, [0, 0])
    np.testing.assert_allclose(same["after_mm"], same["before_mm"])
    wrong = rp.boundary_errors(robot, err, -np.degrees(err[:2]))
    assert wrong["max_after_mm"] > 1.8 * d["max_before_mm"]


def test_boundary_errors_match_plant(robot):
    err = group_errors(2)
    comp = np.array([-0.9, 0.4])
    d = rp.boundary_errors(robot, err, comp, K=12)
    P = rp.boundary_positions(robot, 12)
    act = VirtualPlant(robot, err).actual_pose(kinematics.ik(robot, P) - np.radians(comp))
    np.testing.assert_allclose(d["after_mm"], np.linalg.norm(act - P, axis=1))


def test_residuals_data(robot):
    meas = data.load_measurements(EXAMPLE, robot)
    res = identify_tsvd(robot, meas, noise=NoiseModel.paper())
    d = rp.residuals_data(res, meas, robot)
    np.testing.assert_array_equal(d["pose"], np.arange(1, 6))
    np.testing.assert_array_equal(d["after_mm"], res.residuals)
    assert d["rms_after_mm"] == pytest.approx(np.sqrt(np.mean(res.residuals**2)))
    # the nominal model (no errors) misses the changes by millimetres, the estimate by tens of um
    assert d["rms_before_mm"] > 1.0 and d["rms_after_mm"] < 0.1
    assert rp.residuals_data(res, meas)["before_mm"] is None
    bad = Measurements(meas.theta_cmd[:5], meas.readings[:5])
    with pytest.raises(ValueError, match="residuals"):
        rp.residuals_data(res, bad)


def test_convergence_data(robot):
    err = group_errors(3)
    loop = calibration_loop(robot, VirtualPlant(robot, err), paper_poses(robot, 3), noise=NoiseModel.paper(),
                            rng=np.random.default_rng(5), max_iter=6, run_all=True)
    d = rp.convergence_data(loop, np.degrees(err[:2]))
    m = len(loop.history)
    assert d["compensation_deg"].shape == (m, 2)
    np.testing.assert_allclose(d["compensation_deg"], [h.compensation_deg for h in loop.history])
    assert np.isnan(d["mu_deg"][0])
    np.testing.assert_allclose(d["mu_deg"][1:], [h.mu_deg for h in loop.history[1:]], rtol=1e-12)
    np.testing.assert_allclose(d["delta_deg"], np.abs(d["compensation_deg"] - np.degrees(err[:2])))
    # the same from run_group's dict history and from plain dicts with radians
    d2 = rp.convergence_data({"compensation_deg": d["compensation_deg"].tolist()})
    np.testing.assert_allclose(d2["mu_deg"][1:], d["mu_deg"][1:])
    d3 = rp.convergence_data([{"compensation": np.radians(c)} for c in d["compensation_deg"]])
    np.testing.assert_allclose(d3["compensation_deg"], d["compensation_deg"])
    with pytest.raises(ValueError):
        rp.convergence_data([{"x": 1}])


def test_pngs_written_atomically(robot, tmp_path):
    err = group_errors(1)
    meas = data.load_measurements(EXAMPLE, robot)
    res = identify_tsvd(robot, meas)
    outs = {
        "res.png": lambda p: rp.plot_residuals(res, meas, p, robot),
        "res1.png": lambda p: rp.plot_residuals(res, meas, p),
        "fig12.png": lambda p: rp.plot_boundary_errors(robot, err, res.zero_offsets_deg, p, title="group 1"),
        "conv.png": lambda p: rp.plot_convergence([{"compensation_deg": [1.0, -0.5]},
                                                   {"compensation_deg": [1.9, -1.1]},
                                                   {"compensation_deg": [2.0, -1.0]}], p, [2, -1]),
    }
    for name, f in outs.items():
        d = f(tmp_path / "sub" / name)
        assert isinstance(d, dict)
        assert (tmp_path / "sub" / name).read_bytes()[:8] == PNG
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == sorted(outs)


def test_command_level_plot_sets(robot, tmp_path):
    from zerocal_sym.paper import reproduction as paper
    from zerocal_sym.paper.figures import reproduce_plots

    meas = data.load_measurements(EXAMPLE, robot)
    res = identify_tsvd(robot, meas)
    d = rp.identify_plots(tmp_path / "id", res, meas, robot)
    assert list(d) == ["residuals.png"] and (tmp_path / "id" / "residuals.png").read_bytes()[:8] == PNG
    rep = paper.reproduce(robot, trials=1, groups=(1, 3), max_iter=4)
    d = reproduce_plots(tmp_path / "rep", rep, robot)
    assert sorted(d) == ["convergence_group1.png", "convergence_group3.png", "fig12_group1.png", "fig12_group3.png"]
    for name in d:
        assert (tmp_path / "rep" / name).read_bytes()[:8] == PNG
    g1 = rep["groups"][0]
    # the plant's error before calibration at the 6 measurement poses is Table 4's 'before' (12.906 mm)
    assert d["fig12_group1.png"]["max_before_mm"] >= g1["dpmax_before_mm"] - 1e-9
    # compensation in Table 2's frame converted back to the robot's: the after-error matches reproduce's dp_max
    six = rp.boundary_errors(robot, group_errors(1), d["fig12_group1.png"]["compensation_deg"],
                             P=paper_poses(robot, 3))
    assert six["max_after_mm"] == pytest.approx(g1["dpmax_after_mm"], rel=1e-9)
    np.testing.assert_allclose(d["convergence_group1.png"]["compensation_deg"], g1["history"]["compensation_deg"])


def test_no_pyplot_no_backend_change():
    code = ("import sys, matplotlib; b = matplotlib.get_backend(); "
            "from zerocal_sym.report import plots as rp; from zerocal_sym.model.robot import paper_robot; "
            "import numpy as np; f = rp.figure_boundary_errors(rp.boundary_errors(paper_robot(), np.zeros(12), [0, 0]));"
            "assert 'matplotlib.pyplot' not in sys.modules; assert matplotlib.get_backend() == b")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_import_is_light():
    r = subprocess.run([sys.executable, "-c", "import sys, zerocal_sym.report.plots; "
                        "assert 'matplotlib' not in sys.modules"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
