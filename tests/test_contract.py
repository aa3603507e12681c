"""The mechanism contract, run for every built-in mechanism and for any other given on the command line.

Each test takes the ``mrobot`` fixture, parametrised over
:data:`zerocal_sym.model.mechanism.REGISTRY` (the robots of ``ROBOTS``: the
paper's robot, the default Delta of examples/delta.toml, ...): a new built-in
mechanism is covered by adding its robot file to ``ROBOTS``.

A mechanism of one's own (outside the repository: a derivation, its generated
module, a robot file naming it with ``mechanism_module``) is added to the
parametrisation by its robot file::

    python -m pytest <checkout>/tests/test_contract.py --contract-robot my_robot.toml -k my_mech

(``--contract-robot`` is defined in tests/conftest.py; repeatable; a robot
file of a built-in mechanism runs the suite on that geometry).  Its scheme's
n is the CLI's default (:func:`zerocal_sym.cli._common.default_n`), and the
tests that compare the generated code with sympy derive the mechanism from
the file its generated module names (``DERIVATION``).
"""
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.cli._common import default_n
from zerocal_sym.identify import fisher
from zerocal_sym.identify import identifiability as idf
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.mechanism import REGISTRY
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot, paper_robot
from roundoff import FLOORS, estimate_floor

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: mechanism -> its robot for the contract suite, and the boundary scheme's n for identification
ROBOTS = {"planar_2dof": (paper_robot, 3), "delta_rotary": (lambda: load_robot(EXAMPLES / "delta.toml"), 6),
          "delta_linear": (lambda: load_robot(EXAMPLES / "linear_delta.toml"), 6),
          "hexapod": (lambda: load_robot(EXAMPLES / "hexapod.toml"), 16)}
#: Monte Carlo trials of the efficiency test (an identification of the hexapod costs ~0.1 s of CPU at K = 16)
MC_TRIALS = {"hexapod": 100}


def test_every_registered_mechanism_has_a_contract_robot():
    assert set(ROBOTS) == set(REGISTRY)


_CASES = pytest.StashKey()


def contract_cases(config) -> dict:
    """Label -> (robot factory, the boundary scheme's n): every built-in mechanism (``ROBOTS``), then the robot
    file of each ``--contract-robot`` (labelled by its mechanism, or mechanism-file stem for a second of one;
    loaded by tests/conftest.py when pytest starts)."""
    if _CASES not in config.stash:
        from conftest import CONTRACT_ROBOTS

        cases = {name: ROBOTS[name] for name in sorted(REGISTRY)}
        for path, robot in config.stash.get(CONTRACT_ROBOTS, []):
            label = robot.mechanism_name
            if label in cases:
                label = f"{label}-{Path(path).stem}"
            cases[label] = (lambda r=robot: r, default_n(robot))
        config.stash[_CASES] = cases
    return config.stash[_CASES]


def pytest_generate_tests(metafunc):
    if "contract_case" in metafunc.fixturenames:
        cases = list(contract_cases(metafunc.config))
        metafunc.parametrize("contract_case", cases, ids=cases, scope="module")


def test_contract_robot_option_adds_a_case(pytestconfig):
    """The built-in mechanisms first, each under its name; a --contract-robot file after them."""
    cases = contract_cases(pytestconfig)
    assert list(cases)[:len(REGISTRY)] == sorted(REGISTRY)
    assert len(cases) == len(REGISTRY) + len(pytestconfig.getoption("contract_robot"))


@pytest.fixture(scope="module")
def mrobot(contract_case, request):
    make, _ = contract_cases(request.config)[contract_case]
    return make()


@pytest.fixture(scope="module")
def scheme(mrobot, contract_case, request):
    return mrobot.workspace.boundary_scheme(contract_cases(request.config)[contract_case][1])


def _inside(robot, rng, N):
    """N uniform random poses inside the workspace (rejection from the bounding box)."""
    lo, hi = robot.workspace_bounds()
    P = lo + rng.uniform(size=(20 * N, robot.n)) * (hi - lo)
    return P[robot.workspace.contains(P)][:N]


#: zero offsets of the truths: deg for revolute joints, mm for prismatic ones
OFFSETS = {"deg": (2.0, -1.0, 0.5), "mm": (0.8, -0.5, 0.3, 0.25, -0.15, 0.05)}


def _truth(robot, maemm=(1.0, 0.5, -0.5, 0.05, 0.0, -0.05), geometry=None):
    e = robot.errors
    return e.assemble(zero_offsets_user=OFFSETS[e.offset_user_unit][:robot.m], geometry=geometry,
                      maemm_mm=maemm[:len(e.measuring)])


def test_fk_inverts_ik_over_the_workspace(mrobot, rng):
    P = np.vstack([mrobot.workspace_grid(), _inside(mrobot, rng, 200)])
    th = kin.ik(mrobot, P)
    assert np.max(np.linalg.norm(kin.fk(mrobot, th) - P, axis=1)) < 1e-9
    assert kin.ik(mrobot, mrobot.home_pose()[None])[0] == pytest.approx(mrobot.home_joints(), abs=1e-9)


def test_pose_error_jacobian_against_central_differences(mrobot, rng):
    """dP/d(robot source errors), generated by implicit differentiation, against the exact FK."""
    errors = mrobot.errors
    robot_names = [n for n in errors.names if errors[n].role != "measuring"]
    for P in _inside(mrobot, rng, 4):
        th = kin.ik(mrobot, P[None])
        J = kin.pose_error_jacobian(mrobot, P[None], th)[0]
        for j, name in enumerate(robot_names):
            h = 1e-6 if errors[name].unit == "rad" else 1e-4
            e = errors.vector({name: h})
            fd = (VirtualPlant(mrobot, e).actual_pose(th) - VirtualPlant(mrobot, -e).actual_pose(th))[0] / (2 * h)
            assert J[:, j] == pytest.approx(fd, rel=1e-5, abs=1e-6), name


def test_error_jacobian_is_the_lever_scaled_offset_columns(mrobot, rng):
    P = _inside(mrobot, rng, 5)
    Jsrc = kin.pose_error_jacobian(mrobot, P)
    J = kin.error_jacobian(mrobot, P)
    cols = [mrobot.errors.index(n) for n in mrobot.errors.zero_offsets]
    np.testing.assert_allclose(J, Jsrc[:, :, cols] / mrobot.error_scale(mrobot.errors.zero_offsets), rtol=1e-12)


def test_distance_jacobians_against_central_differences(mrobot, rng):
    th = kin.ik(mrobot, _inside(mrobot, rng, 3))
    err0 = _truth(mrobot) * 0.1
    rho, de, dt = kin.distance_jacobians(mrobot, th, err0)
    for j, name in enumerate(mrobot.errors.names):
        h = 1e-6 if mrobot.errors[name].unit == "rad" else 1e-4
        e = mrobot.errors.vector({name: h})
        fd = (kin.distance(mrobot, th, err0 + e) - kin.distance(mrobot, th, err0 - e)) / (2 * h)
        assert de[:, j] == pytest.approx(fd, rel=1e-5, abs=1e-7), name
    assert rho == pytest.approx(kin.distance(mrobot, th, err0), abs=1e-12)


def test_first_order_distance_is_the_g_row(mrobot, rng):
    """d rho = g (lever * dtheta, drM) for small offsets and MAEMM (paper Eq. 28 in n dimensions)."""
    P = _inside(mrobot, rng, 6)
    th = kin.ik(mrobot, P)
    names = mrobot.errors.resolve("offsets+measuring")
    assert kin.g_rows(mrobot, P[:1]).shape == (1, len(names))
    small = mrobot.errors.take(_truth(mrobot), names) * 1e-4
    err = mrobot.errors.embed(names, small)
    g = kin.g_rows(mrobot, P, th)
    lam, _ = kin.measuring_vector(mrobot, P)
    assert kin.distance(mrobot, th, err) - lam == pytest.approx(g @ (small * mrobot.error_scale(names)), abs=1e-8)


def test_distance_changes_are_invariant_under_the_declared_gauge(mrobot, rng):
    th = kin.ik(mrobot, _inside(mrobot, rng, 12))
    for err in (None, _truth(mrobot)):
        assert idf.gauge_invariance(mrobot, th, err, eps=1e-4) < 1e-8
        A = fisher.sensitivity(mrobot, th, "all", err)
        Z = idf.gauge_generators(mrobot, err)
        assert Z.shape == (len(mrobot.mechanism.gauge_names), len(mrobot.errors))
        assert np.max(np.abs(A @ Z.T)) < 1e-9 * np.max(np.abs(A))


def test_null_space_of_all_source_errors_is_the_gauge(mrobot, rng):
    th = kin.ik(mrobot, _inside(mrobot, rng, 40))
    rep = idf.identifiability_report(mrobot, th, "all")
    z = len(mrobot.mechanism.gauge_names)
    assert rep["rank"] == len(mrobot.errors) - z
    assert rep["null_space_rigid"] is True and all(rep["null_space_gauge"])
    assert idf.identifiability_report(mrobot, th, "gauge_fixed")["rank"] == len(mrobot.errors) - z


def test_noise_free_recovery_of_offsets_and_maemm(mrobot, scheme):
    """The exact model recovers the mechanism's default set to round-off (rad, mm) from the boundary scheme."""
    names = mrobot.errors.resolve("default")
    truth = mrobot.errors.embed(names, mrobot.errors.take(_truth(mrobot), names))
    th = kin.ik(mrobot, scheme)
    meas = Measurements(theta_cmd=th, readings=VirtualPlant(mrobot, truth).measure(th))
    res = identify_nlls(mrobot, meas, "default", noise=NoiseModel())
    assert res.success, res.status
    # within FLOORS of the estimate's round-off floor (tests/roundoff.py)
    floor = estimate_floor(mrobot, th, names, NoiseModel(), truth)
    assert np.all(np.abs(res.estimate - mrobot.errors.take(truth, names)) <= FLOORS * floor)
    ts = identify_tsvd(mrobot, meas)  # one linear step at zero: close, not exact
    assert np.max(np.abs(ts.zero_offsets_user - res.zero_offsets_user)) < 5.0


def test_noise_free_recovery_of_every_identifiable_parameter(mrobot, rng):
    """All source errors but the gauge-fixing ones, from 40 random poses, to round-off."""
    errors = mrobot.errors
    names = errors.resolve("gauge_fixed")
    geo = {n: v for n, v in zip(names, rng.normal(0, 0.02, len(names))) if errors[n].role == "geometry"}
    geo = {n: (np.radians(v / 10) if errors[n].unit == "rad" else v) for n, v in geo.items()}
    truth = _truth(mrobot, geometry=geo)
    truth = errors.embed(names, errors.take(truth, names))  # the gauge-fixing errors at zero
    # the hexapod's 36: 40 random poses in its small box leave a weak direction (sigma_min / sigma_max ~ 3e-5 of
    # the sensitivity) that its rank test calls deficient; 80 poses give 8e-5
    th = kin.ik(mrobot, _inside(mrobot, rng, 40 if len(names) <= 30 else 80))
    meas = Measurements(theta_cmd=th, readings=VirtualPlant(mrobot, truth).measure(th))
    res = identify_nlls(mrobot, meas, "gauge_fixed", noise=NoiseModel())
    assert res.success, res.status
    floor = estimate_floor(mrobot, th, names, NoiseModel(), truth)
    assert np.all(np.abs(res.estimate - errors.take(truth, names)) <= FLOORS * floor)


@pytest.mark.slow
def test_monte_carlo_rms_of_the_zero_offsets_is_the_crlb(mrobot, scheme):
    """Ipopt on the exact model is efficient: RMS within 10 % of the CRLB, each offset (400 trials; a mechanism
    with fewer trials gets the tolerance of the same confidence, 10 % * sqrt(400 / trials))."""
    noise = mrobot.noise
    names = mrobot.errors.resolve("default")
    truth = mrobot.errors.embed(names, mrobot.errors.take(_truth(mrobot), names))
    th = kin.ik(mrobot, scheme)
    plant = VirtualPlant(mrobot, truth)
    crlb = fisher.crlb_zero_offsets_user(mrobot, th, "paper", noise, err0=truth)
    E, misfits = [], 0
    trials = MC_TRIALS.get(mrobot.mechanism_name, 400)
    for trial in range(trials):
        meas = Measurements(theta_cmd=th, readings=plant.measure(th, noise, np.random.default_rng([17, trial])))
        # every round counts in the RMS: the fit check rejects clean rounds at its level alpha = 0.001
        res = identify_nlls(mrobot, meas, "paper", noise=noise, accept_misfit=True)
        assert res.success, res.status
        misfits += res.info["fit"]["rejected"]
        E.append(res.zero_offsets - mrobot.errors.take(truth, mrobot.errors.zero_offsets))
    assert misfits <= 3  # expected 0.4 of 400 (fewer with fewer trials); P(>= 4) < 1e-3
    rms = units.to_user(np.sqrt(np.mean(np.square(E), axis=0)), mrobot.errors.offset_unit)
    np.testing.assert_allclose(rms / crlb, 1.0, atol=0.10 * np.sqrt(400 / trials))


@pytest.fixture(scope="module")
def symbolic(mrobot, request):
    """The derivation of the mechanism (sympy): a built-in one's from the ``derived`` fixture (once per test
    process, tests/conftest.py); another's from the file (or module) its generated module names
    (``DERIVATION``, :func:`derivations.external.derivation_of`)."""
    sp = pytest.importorskip("sympy")
    from derivations import codegen
    from derivations.external import derivation_of

    if mrobot.mechanism_name in codegen.MECHANISMS:
        return sp, request.getfixturevalue("derived")[mrobot.mechanism_name]
    return sp, derivation_of(mrobot.mechanism.module)


def test_generated_functions_match_sympy(mrobot, symbolic, rng):
    """Every generated function against the sympy expressions it was written from, at random points (a
    numeric solve or determinant the function takes by numpy's)."""
    from derivations.mechanism import numeric_value

    sp, mech = symbolic
    funcs = mrobot.mechanism.functions
    poses = _inside(mrobot, rng, 3)
    for fname, spec in mech.outputs.items():
        if "newton" in spec or "compose" in spec:  # solved, not written out: test_solved_functions_solve
            continue
        syms = [s for _, ss in spec["inputs"] for s in ss]
        solves = spec.get("solves", [])
        steps = [sp.lambdify(syms, [sv.A, sv.B], "numpy", cse=True) for sv in solves]
        placeholders = [x for sv in solves for x in sv.X]
        lam = sp.lambdify(syms + placeholders, [m for _, m in spec["outputs"]], "numpy", cse=True)
        for P in poses:
            g = mrobot.geometry * (1 + rng.normal(0, 1e-3, mrobot.geometry.size))
            th = kin.ik(mrobot, P[None])[0] + rng.normal(0, 1e-3, mrobot.m)
            vals = {"P": P, "theta": th, "theta_cmd": th, "g": g, "err": _truth(mrobot) * rng.uniform(0, 1)}
            args = [vals[n] for n, _ in spec["inputs"]]
            flat = np.concatenate(args)
            solved = [numeric_value(sv, *(np.asarray(a, float) for a in st(*flat))).ravel()
                      for sv, st in zip(solves, steps)]
            want = lam(*flat, *(np.concatenate(solved) if solved else []))
            got = funcs[fname](*args)
            got = got if isinstance(got, tuple) else (got,)
            for w, o in zip(want, got):
                np.testing.assert_allclose(o.full(), np.asarray(w, float).reshape(o.shape), rtol=1e-9, atol=1e-9,
                                           err_msg=fname)


def test_solved_functions_solve(mrobot, symbolic, rng):
    """A forward kinematics solved by Newton steps closes the loop (sympy's loop closure at its answer) and
    the composed exact distance is |measuring vector| at the actual pose; a closed form is covered above."""
    sp, mech = symbolic
    spec = mech.outputs["fk"]
    if "newton" not in spec:
        pytest.skip("closed-form forward kinematics")
    loop = sp.lambdify([*mech.pose, *mech.joints, *mech.geometry], mech.loop_closure, "numpy")
    lam = sp.lambdify([*mech.pose, *mech.geometry], list(mech.measuring_vector), "numpy")
    P = _inside(mrobot, rng, 5)
    th = kin.ik(mrobot, P)
    got = kin.fk(mrobot, th)
    np.testing.assert_allclose(got, P, atol=1e-9)
    scale = np.max(np.abs(th)) ** 2
    for p, t in zip(got, th):
        assert np.max(np.abs(loop(*p, *t, *mrobot.geometry))) < 1e-12 * scale
    err = _truth(mrobot)
    rho = kin.distance(mrobot, th, err)
    from zerocal_sym.model.noise import geometry_error

    g_act = mrobot.geometry + geometry_error(mrobot, err)
    th_act = th + mrobot.errors.take(err, mrobot.errors.zero_offsets)
    from dataclasses import replace

    P_act = kin.fk(replace(mrobot, geometry=g_act), th_act)
    want = [np.linalg.norm(lam(*p, *g_act)) for p in P_act]
    np.testing.assert_allclose(rho, want, rtol=1e-12)


def test_solved_forward_kinematics_refuses_to_guess(mrobot):
    """Joints no pose fits (a leg far beyond any assembly): NaN, never a silent wrong pose."""
    if "newton" not in mrobot.mechanism.module.FUNCTION_SIGNATURES.get("fk", ((), ()))[0][0][0] and \
            not hasattr(mrobot.mechanism.module, "_fk_residual"):
        pytest.skip("closed-form forward kinematics")
    th = mrobot.home_joints()[None, :].copy()
    th[0, 0] *= 10.0
    assert np.all(np.isnan(kin.fk(mrobot, th)))

