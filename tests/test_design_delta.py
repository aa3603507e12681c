"""Measurement-pose design on the rotary Delta (n = 3 pose coordinates, m = 3 joints, cylinder workspace).

Reference values from an independent implementation (docs/delta.md): ring scheme cond(G) = 3186
at n = 4 (K = 8) and 233.4 at n = 6 (K = 12); CRLB of each zero offset
0.0264-0.0274 deg with the scale error alone and 0.382 deg with the servo
error too (n = 6).
"""
import ast
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.design import criteria
from zerocal_sym.design import nlp as design_nlp
from zerocal_sym.identify import fisher, linear
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from roundoff import log_objective_tol

NOISE = NoiseModel.paper()
DELTA_FILE = Path(__file__).resolve().parents[1] / "examples" / "delta.toml"
DELTA_KEYS = {"mechanism": "delta_rotary",
              "geometry": {"R": 200, "r": 50, "L": 350, "l": 800, "cx": 0, "cy": 0, "cz": -100,
                           "dx": 0, "dy": 0, "dz": -50},
              "workspace": {"rw": 200, "H": 700, "h": 200}}


@pytest.fixture(scope="module")
def delta():
    from zerocal_sym.model.robot import _from_keys, load_robot

    if DELTA_FILE.exists():
        return load_robot(DELTA_FILE)
    return _from_keys(DELTA_KEYS, "delta", "test")


@pytest.fixture(scope="module")
def dcons(delta):
    return design.make_constraints(delta)


def _fast(robot, cons, K=8, criterion="crlb", starts=2):
    return design.optimize_design(robot, K, criterion, cons, NOISE, seed=0, n_starts=starts, exchange_starts=starts,
                                  certificate=False)  # (the certificates are test_design_approx's)


@pytest.fixture(scope="module")
def crlb8(delta, dcons):
    return design.optimize_design(delta, 8, "crlb", dcons, NOISE, seed=0, n_starts=3, exchange_starts=3,
                                  certificate=False)


def _assert_feasible(robot, cons, P):
    """Inside the cylinder, reachable, singularity margin: checked independently of check_design."""
    ws = robot.workspace
    assert np.all(np.hypot(P[:, 0], P[:, 1]) <= ws.rw + 1e-6)
    assert np.all(P[:, 2] >= -ws.H - ws.h - 1e-6) and np.all(P[:, 2] <= -ws.H + 1e-6)
    assert np.all(robot.workspace.contains(P))
    th = kin.check_poses(robot, P, margin=cons.singularity_margin - 1e-6)  # raises if unreachable / too singular
    np.testing.assert_allclose(kin.fk(robot, th), P, atol=1e-8)
    assert design.check_design(robot, P, cons) == []


# ----------------------------------------------------------------- the ring scheme as the baseline
def test_design_package_is_generic():
    """No module of zerocal_sym.design imports the paper package."""
    pkg = Path(design.__file__).parent
    for path in pkg.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                assert not (node.module or "").startswith("zerocal_sym.paper"), path.name
            elif isinstance(node, ast.Import):
                assert not any(a.name.startswith("zerocal_sym.paper") for a in node.names), path.name


def test_ring_scheme_baseline_k12(delta, dcons):
    P = design.paper_baseline(delta, 12)
    np.testing.assert_array_equal(P, delta.workspace.boundary_scheme(6))
    _assert_feasible(delta, dcons, P)
    rep = design.evaluate(delta, P, "crlb", NOISE, dcons)
    G, _ = linear.identification_matrix(delta, P)
    assert G.shape == (11, 6)
    kappa = linear.condition_number(G)
    print(f"ring scheme n = 6: kappa {kappa:.4f}, CRLB {rep['crlb_zero_offsets_deg']} deg")
    assert rep["kappa"] == pytest.approx(kappa, rel=1e-12)
    assert rep["criterion"]["values"]["cond"] == pytest.approx(kappa, rel=1e-9)
    assert kappa == pytest.approx(233.4, rel=1e-3)  # the reference value
    assert rep["violations"] == []
    np.testing.assert_allclose(rep["crlb_zero_offsets_deg"], 0.382, atol=5e-4)  # the reference value, servo error too
    scale = design.evaluate(delta, P, "crlb", NoiseModel.paper(servo=0.0))["crlb_zero_offsets_deg"]
    assert 0.0263 < min(scale) and max(scale) < 0.0275  # reference 0.0264-0.0274 deg
    assert rep["crlb_rms_deg"] == pytest.approx(rep["criterion"]["values"]["crlb"], rel=1e-9)
    assert rep["criterion"]["units_all"]["D"] == "log(1/mm^12)"


def test_ring_scheme_baseline_k8(delta, dcons):
    P = design.paper_baseline(delta, 8)
    _assert_feasible(delta, dcons, P)
    kappa = design.criterion_values(delta, P, NOISE)["cond"]
    assert kappa == pytest.approx(3186, rel=1e-3)  # the reference value: badly conditioned with c on the axis


def test_odd_k_and_region_baseline(delta):
    P = design.paper_baseline(delta, 9)  # 5 on the top circle, 4 on the bottom one
    assert P.shape == (9, 3)
    assert np.all(P[:5, 2] == -700) and np.all(P[5:, 2] == -900)
    np.testing.assert_allclose(np.hypot(P[:, 0], P[:, 1]), 200)
    np.testing.assert_allclose(np.degrees(np.arctan2(P[:5, 1], P[:5, 0])) % 360, [0, 72, 144, 216, 288],
                               atol=1e-9)
    np.testing.assert_allclose(np.degrees(np.arctan2(P[5:, 1], P[5:, 0])) % 360, [0, 90, 180, 270], atol=1e-9)
    region = design.make_region(delta, (120, -850, -750))
    Q = design.paper_baseline(delta, 8, region)
    np.testing.assert_allclose(np.hypot(Q[:, 0], Q[:, 1]), 120)
    assert set(Q[:, 2]) == {-750.0, -850.0}


# ----------------------------------------------------------------- criteria against independent code
@pytest.mark.parametrize("seed, K", [(0, 7), (1, 9), (2, 12), (3, 15)])
def test_criteria_match_fisher_and_linear(delta, dcons, seed, K):
    P = design_nlp._random_start(delta, K, dcons, np.random.default_rng(seed))
    assert P.shape == (K, 3) and design.check_design(delta, P, dcons) == []
    th = kin.ik(delta, P)
    v = design.criterion_values(delta, P, NOISE)
    crlb = fisher.crlb_zero_offsets_deg(delta, th, "paper", NOISE)
    assert crlb.shape == (3,)
    assert v["crlb"] == pytest.approx(np.sqrt(np.mean(crlb ** 2)), rel=1e-7)
    G, _ = linear.identification_matrix(delta, P, theta=th)
    assert v["cond"] == pytest.approx(linear.condition_number(G), rel=1e-7)
    T = np.diag(1 / fisher.parameter_scale(delta, "paper"))
    Fq = T @ fisher.fisher_information(delta, th, "paper", NOISE) @ T
    assert v["D"] == pytest.approx(np.linalg.slogdet(Fq)[1], rel=1e-7, abs=1e-7)
    assert v["A"] == pytest.approx(np.trace(np.linalg.inv(Fq)), rel=1e-6)
    assert v["E"] == pytest.approx(np.linalg.eigvalsh(Fq)[0], rel=1e-6)


@pytest.mark.parametrize("criterion", ["D", "A", "crlb"])
def test_symbolic_objective_matches_numeric(delta, dcons, criterion):
    P = design_nlp._random_start(delta, 9, dcons, np.random.default_rng(3))
    fs, ms = design_nlp._scales(delta, P, NOISE)
    nlp = design_nlp._NLP(delta, 9, criterion, dcons, NOISE, fs, ms)
    f, g = nlp.fg(nlp.x0(P))
    o = criteria._objective(delta, criterion, P, NOISE)
    shift = {"D": 6 * np.log(fs), "A": np.log(fs), "crlb": np.log(fs)}[criterion]  # F_n = F / fs, p = 6
    # two algorithms for one log-objective: at the round-off of F's conditioning (tests/roundoff.py)
    F = criteria._fisher(*criteria._terms_batch(delta, P, NOISE), criteria._noise_terms(NOISE)[0])[0]
    assert float(f) == pytest.approx(o + shift, rel=0, abs=log_objective_tol(F))
    g = g.full().ravel()
    assert np.all(g >= nlp.lbg - 1e-9) and np.all(g <= nlp.ubg + 1e-9)  # a feasible design is NLP-feasible


def test_psd_auxiliary_formulation_p6(delta, dcons):
    """cond and E (p x p = 6 x 6 matrix inequalities): Ipopt's auxiliary bounds are the extreme eigenvalues."""
    P0 = design.paper_baseline(delta, 12)
    fs, ms = design_nlp._scales(delta, P0, NOISE)
    for criterion in ("cond", "E"):
        nlp = design_nlp._NLP(delta, 12, criterion, dcons, NOISE, fs, ms)
        sol = nlp.solver(x0=nlp.x0(P0), lbx=nlp.lbx, ubx=nlp.ubx, lbg=nlp.lbg, ubg=nlp.ubg)
        assert nlp.solver.stats()["success"]
        x = sol["x"].full().ravel()
        P = dcons.region.center + dcons.region.half * x[:36].reshape(12, 3)
        val = design.criterion_values(delta, P, NOISE)[criterion]
        f = float(sol["f"])
        got = np.exp(-f) * fs if criterion == "E" else np.exp(f)
        assert got == pytest.approx(val, rel=1e-5)
        assert design.check_design(delta, P, dcons) == []


# ----------------------------------------------------------------- optimised designs over the cylinder
def test_crlb_design_k8_beats_ring(delta, dcons, crlb8):
    d = crlb8.to_dict()
    print(f"K=8 CRLB design {d['crlb_rms_deg']:.5f} deg, ring {d['paper']['crlb_rms_deg']:.5f} deg, "
          f"ratio {d['ratio']['crlb_rms_design_over_paper']:.5f}")
    assert d["baseline"] == "ring" and len(d["poses"]) == 8 and len(d["poses"][0]) == 3
    assert len(d["joints_deg"][0]) == 3 and len(d["crlb_zero_offsets_deg"]) == 3
    _assert_feasible(delta, dcons, crlb8.poses)
    assert d["violations"] == [] and d["paper"]["violations"] == []
    assert d["crlb_rms_deg"] <= d["paper"]["crlb_rms_deg"]
    assert d["ratio"]["crlb_rms_design_over_paper"] < 0.05  # measured 0.0068: the ring scheme at n = 4 is poor
    assert d["constraints"]["region_kind"] == "cylinder" and d["constraints"]["region_mm"] == [200, -900, -700]


@pytest.mark.slow
def test_crlb_design_k12_beats_ring(delta, dcons):
    res = design.optimize_design(delta, 12, "crlb", dcons, NOISE, seed=0, n_starts=3, exchange_starts=3,
                                 certificate=False)
    d = res.to_dict()
    print(f"K=12 CRLB design {d['crlb_rms_deg']:.5f} deg, ring {d['paper']['crlb_rms_deg']:.5f} deg, "
          f"ratio {d['ratio']['crlb_rms_design_over_paper']:.5f}")
    _assert_feasible(delta, dcons, res.poses)
    assert d["paper"]["crlb_rms_deg"] == pytest.approx(0.3821, abs=5e-4)
    assert d["crlb_rms_deg"] <= d["paper"]["crlb_rms_deg"]
    assert d["ratio"]["crlb_rms_design_over_paper"] < 0.1  # measured 0.051
    ex, co = res.exchange["objective"], res.continuous["objective"]
    assert co <= ex + 0.05 and criteria._objective(delta, "crlb", res.poses, NOISE) <= min(ex, co) + 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("criterion", ["cond", "D", "A", "E"])
def test_other_criteria_k8(delta, dcons, criterion):
    res = _fast(delta, dcons, 8, criterion)
    d = res.to_dict()
    _assert_feasible(delta, dcons, res.poses)
    better = design.CRITERIA[criterion][2]
    val, base = d["criterion"]["value"], d["paper"]["criterion"]["value"]
    assert (val <= base) if better == "min" else (val >= base)


# ----------------------------------------------------------------- constraints on the cylinder
def test_constraint_cylinder_region_and_joint_limits(delta):
    limits = ((-5.0, 40.0), (-5.0, 40.0), (-5.0, 40.0))
    cons = design.make_constraints(delta, region=(150, -850, -720), joint_limits_deg=limits)
    assert isinstance(cons.region, design.CylinderRegion)
    res = _fast(delta, cons)
    P = res.poses
    assert np.all(np.hypot(P[:, 0], P[:, 1]) <= 150 + 1e-6)
    assert np.all(P[:, 2] >= -850 - 1e-6) and np.all(P[:, 2] <= -720 + 1e-6)
    deg = np.degrees(kin.ik(delta, P))
    assert np.all(deg >= -5 - 1e-6) and np.all(deg <= 40 + 1e-6)
    assert design.check_design(delta, P, cons) == []
    # the ring rule on the region's circles is tried first; it (and the workspace's ring) break the joint
    # limits, so there is no baseline (a baseline is feasible or left out with a note)
    assert res.paper is None and "joint" not in res.baseline_note or "outside [-5, 40]" in res.baseline_note
    Pp = np.array(res.baseline_rejected[0]["poses"])
    np.testing.assert_allclose(np.hypot(Pp[:, 0], Pp[:, 1]), 150)


def test_constraint_travel_and_separation(delta):
    cons = design.make_constraints(delta, travel_mm=120.0, min_separation_mm=60.0)
    res = _fast(delta, cons)
    rho = kin.measuring_vector(delta, res.poses)[0]
    assert np.ptp(rho) <= 120.0 + 1e-6
    d = np.linalg.norm(res.poses[:, None] - res.poses[None], axis=2)
    assert d[np.triu_indices(8, 1)].min() >= 60.0 - 1e-6
    # the ring scheme spans 191 mm: no baseline, the rejected scheme's violations say why
    assert res.paper is None and "scale travel" in res.baseline_note
    assert any("scale travel" in v for v in res.baseline_rejected[0]["violations"])


def test_check_design_messages_cylinder(delta):
    cons = design.make_constraints(delta, joint_limits_deg=((0, 10), (0, 10), (0, 10)), min_separation_mm=5)
    P = np.array([[250, 0, -800], [0, 0, -800], [0, 0, -801], [0, 150, -900], [-100, 0, -700],
                  [0, -100, -750], [100, 100, -850]])
    text = " | ".join(design.check_design(delta, P, cons))
    for word in ("outside the region x^2 + y^2 <= 200^2", "(250, 0, -800)", "theta3", "apart"):
        assert word in text


@pytest.mark.parametrize("kwargs, match", [
    (dict(region=(200, -900, -700, 0)), "3 numbers RW ZMIN ZMAX"),
    (dict(region=(2000, -900, -700)), "not reachable"),
    (dict(region=(200, -700, -900)), "ZMIN < ZMAX"),
    (dict(region=(0.5, -900, -700)), "thinner than 1 mm"),
    (dict(region=design.Region(-100, 100, 650, 750)), "does not fit"),
    (dict(joint_limits_deg=((0, 10), (0, 10))), "one pair per joint"),
    (dict(joint_limits_deg=((0, 10), (0, 10), (10, 0))), "lo < hi"),
])
def test_bad_constraints_delta(delta, kwargs, match):
    with pytest.raises(design.DesignError, match=match):
        design.make_constraints(delta, **kwargs)


def test_min_k_delta(delta, dcons):
    assert design.min_k(delta) == 7
    with pytest.raises(design.DesignError, match="at least 7 poses .* 6 parameters"):
        design.optimize_design(delta, 6, "crlb", dcons)


# ----------------------------------------------------------------- plot and Monte Carlo
def test_plot_3d(delta, crlb8, tmp_path):
    png = tmp_path / "delta.png"
    design.plot_design(png, delta, crlb8)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_default_true_errors_by_name(delta, robot):
    e = design.default_true_errors(delta)
    d = delta.errors.to_dict(e, user=True)
    assert (d["theta1"], d["theta2"], d["theta3"]) == pytest.approx((2, -1, 0.5))
    assert (d["rMx"], d["rMy"], d["rMz"]) == pytest.approx((1, 0.5, -0.5))
    assert sum(abs(v) for k, v in d.items() if k in delta.errors.geometry) == 0
    # the planar default is Table 2 group 1 without its geometric errors
    np.testing.assert_array_equal(design.default_true_errors(robot),
                                  robot.errors.assemble(zero_offsets_deg=(2, -1), maemm_mm=(1, 0.5)))


@pytest.mark.slow
def test_monte_carlo_delta(delta, crlb8):
    """The Ipopt estimator's RMS error follows the CRLB of the optimised K = 8 design."""
    v = design.verify_design(delta, crlb8.poses, 200, NOISE, seed=5)
    print(f"MC RMS {v['rms_error_rms_deg']:.5f} deg (CRLB {v['crlb_at_truth_rms_deg']:.5f}), failed {v['n_failed']}")
    assert v["n_failed"] == 0 and v["offset_names"] == ["theta1", "theta2", "theta3"]
    assert v["rms_error_rms_deg"] == pytest.approx(v["crlb_at_truth_rms_deg"], rel=0.15)
    assert v["true_errors"]["by_name"]["theta3"] == pytest.approx(0.5)
    assert v["true_errors"]["maemm_mm"] == pytest.approx([1, 0.5, -0.5])
