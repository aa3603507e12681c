"""The compiled tier (zerocal_sym.model.compiled): the same numbers as the interpreted Functions, cached, optional.

Each test uses its own cache folder and a freshly built problem, so nothing
here changes the problems the other tests use (they run interpreted:
``ZEROCAL_COMPILE=never`` in conftest.py).
"""
import numpy as np
import pytest

from zerocal_sym.errors import ZerocalError
from zerocal_sym.identify.estimate import nlls_problem
from zerocal_sym.identify.batch import identify_batch
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.estimate.nlls_solve import noise_terms
from zerocal_sym.identify.fisher import parameter_scale
from zerocal_sym.model import compiled
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors

pytestmark = pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler on this machine")

K = 6


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache of this test's own."""
    monkeypatch.setenv("ZEROCAL_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("ZEROCAL_COMPILE", "auto")
    return tmp_path / "cache"


@pytest.fixture(scope="module")
def built_dir(tmp_path_factory):
    """A cache holding the K = 6 problem's library, built once for the module (a build takes seconds)."""
    return tmp_path_factory.mktemp("built")


@pytest.fixture
def built(built_dir, monkeypatch):
    monkeypatch.setenv("ZEROCAL_CACHE", str(built_dir))
    monkeypatch.setenv("ZEROCAL_COMPILE", "auto")
    return built_dir


@pytest.fixture(scope="module")
def data(robot):
    th = kin.ik(robot, paper_poses(robot, 3))
    plant = VirtualPlant(robot, table2_errors(1))
    rng = np.random.default_rng(7)
    return th, np.array([plant.measure(th, NoiseModel.paper(), rng) for _ in range(30)])


def _fresh(robot):
    return nlls_problem.NllsProblem(robot.mechanism, K, tuple(robot.errors.indices("paper")))


def _inputs(f, rng):
    return [rng.normal(size=f.sparsity_in(i).shape) * (1e-2 if f.name_in(i) in ("z", "z0", "x") else 1.0)
            for i in range(f.n_in())]


@pytest.mark.slow
def test_compiled_functions_equal_the_interpreted_bit_for_bit(robot, built, data):
    """Every compiled twin returns the interpreted Function's numbers exactly, at the data and at random inputs."""
    prob = _fresh(robot)
    interp = dict(prob.functions)
    assert not prob.compiled
    prob.hot(wait=True)
    assert prob.compiled, compiled.status()[-1]
    comp = prob.functions
    assert set(comp) == set(interp)
    th, R = data
    names = robot.errors.resolve("paper")
    scale = parameter_scale(robot, names)
    par = prob.pack(th, robot.geometry, robot.errors.zeros(), R[0, 1:], scale, np.zeros(4), np.zeros((4, 4)),
                    *noise_terms(NoiseModel.paper()))
    a = [o.full() for o in interp["gauss_newton"].call([np.zeros(4), par])]
    b = [o.full() for o in comp["gauss_newton"].call([np.zeros(4), par])]
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    rng = np.random.default_rng(3)
    for name in ("weights", "residuals", "jfun", "rfun", "nlp_f", "nlp_grad_f", "nlp_hess_l", "fit_terms"):
        f = interp[name]
        args = _inputs(f, rng)
        if name != "fit_terms":  # (r, J, l, b): random; the others take the parameter vector second
            args[1] = np.concatenate([par, np.abs(args[1].ravel()[par.size:]) + 1.0]) if name.startswith("nlp") else par
        for x, y in zip(f.call(args), comp[name].call(args)):
            np.testing.assert_array_equal(x.full(), y.full(), err_msg=name)


def test_identifications_are_unchanged_by_the_compiled_tier(robot, built, data, monkeypatch):
    """identify_nlls (Ipopt on the compiled objective) and identify_batch: the interpreted results exactly."""
    th, R = data
    noise = NoiseModel.paper()
    key = (robot.mechanism_name, K, tuple(robot.errors.indices("paper")))
    results = {}
    for tier in ("interpreted", "compiled"):
        prob = _fresh(robot)
        if tier == "compiled":
            prob.hot(wait=True)
            assert prob.compiled
        monkeypatch.setitem(nlls_problem._CACHE, key, prob)
        single = [identify_nlls(robot, Measurements(th, r), "paper", noise=noise) for r in R[:5]]
        results[tier] = (single, identify_batch(robot, th, R, "paper", noise=noise))
    (s0, b0), (s1, b1) = results["interpreted"], results["compiled"]
    for x, y in zip(s0, s1):
        assert x.success and y.success and x.info["solver_status"] == y.info["solver_status"]
        np.testing.assert_array_equal(x.estimate, y.estimate)
        np.testing.assert_array_equal(x.covariance, y.covariance)
        assert x.info["fit"]["p_value"] == y.info["fit"]["p_value"]
    np.testing.assert_array_equal(b0.estimate, b1.estimate)
    assert b1.confirmed.all()


def test_a_cached_library_is_loaded_not_rebuilt(robot, built):
    first = _fresh(robot)
    first.hot(wait=True)
    libs = list(built.glob("*.so"))
    assert len(libs) == 1
    stamp = libs[0].stat().st_mtime_ns
    n = len(compiled.status())
    second = _fresh(robot)
    second.hot()  # auto mode, cached: loaded at once, no background build
    assert second.compiled
    events = [e for _, _, e in compiled.status()[n:]]
    assert not any(e.startswith("compiled") for e in events) and any(e.startswith("loaded") for e in events)
    assert libs[0].stat().st_mtime_ns == stamp
    assert libs[0].stat().st_mtime_ns == stamp


@pytest.mark.slow
def test_a_damaged_cached_library_is_rebuilt(robot, cache):
    """Garbage where the library should be (never loaded in this process: a loaded one is never rewritten)."""
    prob = _fresh(robot)
    path = compiled.library_path(prob.tier._interp, compiled.compiler(), prob.tier.tag)
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not a shared library")
    n = len(compiled.status())
    prob.hot(wait=True)
    assert prob.compiled
    assert any("unusable" in e for _, _, e in compiled.status()[n:])
    assert path.read_bytes()[:4] == b"\x7fELF"


def test_no_compiler_leaves_the_interpreted_functions(robot, cache, monkeypatch, data):
    monkeypatch.setenv("CC", "/nonexistent/cc")
    prob = _fresh(robot)
    prob.hot(wait=True)
    assert not prob.compiled
    assert "no C compiler" in compiled.status()[-1][2]
    assert not cache.exists() or not list(cache.glob("*.so"))


def test_a_failing_compiler_is_reported_and_the_functions_stay_interpreted(robot, cache, monkeypatch, tmp_path):
    bad = tmp_path / "badcc"
    bad.write_text("#!/bin/sh\necho 'cc: broken' >&2\nexit 1\n")
    bad.chmod(0o755)
    monkeypatch.setenv("CC", str(bad))
    prob = _fresh(robot)
    prob.hot(wait=True)
    assert not prob.compiled
    assert "broken" in compiled.status()[-1][2]


def test_never_mode_never_compiles(robot, cache, monkeypatch):
    monkeypatch.setenv("ZEROCAL_COMPILE", "never")
    prob = _fresh(robot)
    for _ in range(compiled.HOT_CALLS + 1):
        prob.touch()
    prob.hot(wait=True)
    assert not prob.compiled and not cache.exists()


@pytest.mark.parametrize("value", ["sometimes", "2"])
def test_an_unknown_mode_is_a_user_error_naming_the_modes(monkeypatch, value):
    monkeypatch.setenv("ZEROCAL_COMPILE", value)
    with pytest.raises(ZerocalError, match="auto, always, never"):
        compiled.mode()


def _start_build_and_exit(cache, stop):
    """A process that starts a K = 6 background build, waits until the compiler runs, then (stop) stops it, exits."""
    import os
    import subprocess
    import sys

    code = ("from zerocal_sym.model.robot import paper_robot\n"
            "from zerocal_sym.identify.estimate.nlls_problem import get_problem\n"
            "import time\nfrom zerocal_sym.model import compiled\n"
            "p = get_problem(paper_robot(), 6, 'paper')\n"
            "p.hot()\nt0 = time.time()\n"
            "while not compiled._RUNNING and time.time() - t0 < 60: time.sleep(0.02)\n"
            + ("compiled.stop_builds()\n" if stop else "") +
            "print('compiled' if p.compiled else 'interpreted')\n")
    env = dict(os.environ, ZEROCAL_CACHE=str(cache), ZEROCAL_COMPILE="auto")
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "interpreted"


def _compilers_of(cache):
    import subprocess

    return [ln for ln in subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True).stdout.splitlines()
            if str(cache) in ln]


@pytest.mark.slow
def test_a_build_outlives_its_command_and_lands_in_the_cache(tmp_path):
    """A short command ends mid-build: the build finishes by itself, the library lands, nothing is left over."""
    import time

    cache = tmp_path / "cache"
    _start_build_and_exit(cache, stop=False)
    deadline = time.monotonic() + 90
    while not list(cache.glob("*.so")) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert len(list(cache.glob("*.so"))) == 1
    time.sleep(0.3)
    assert not list(cache.glob(".build-*")) and not _compilers_of(cache)


@pytest.mark.slow
def test_a_stopped_build_leaves_no_compiler_and_no_library(tmp_path):
    """stop_builds (the CLI's Ctrl-C) stops the compiler and its passes; nothing lands, nothing is left."""
    import time

    cache = tmp_path / "cache"
    _start_build_and_exit(cache, stop=True)
    time.sleep(1.0)
    assert not _compilers_of(cache)
    assert not list(cache.glob("*.so")) and not list(cache.glob(".build-*"))


def test_always_warns_when_it_cannot_compile(robot, cache, monkeypatch):
    """ZEROCAL_COMPILE=always asked for compiled code: a fallback is a warning naming why (auto: recorded only)."""
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("ZEROCAL_COMPILE", "always")
    with pytest.warns(RuntimeWarning, match="no C compiler"):
        prob = _fresh(robot)
    assert not prob.compiled
