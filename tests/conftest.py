import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci")
os.environ.setdefault("MPLBACKEND", "Agg")
# the compiled tier (zerocal_sym.model.compiled) would start C compilers in the background of every Monte Carlo
# test on a fresh machine; the tests run interpreted unless asked (tests/test_compiled.py checks the compiled
# Functions against the interpreted ones, bit for bit, in a temporary cache)
os.environ.setdefault("ZEROCAL_COMPILE", "never")


def pytest_addoption(parser):
    parser.addoption("--contract-robot", action="append", default=[], metavar="ROBOT.toml",
                     help="also run the mechanism contract suite (tests/test_contract.py) on this robot file's "
                          "mechanism (repeatable): a mechanism of your own, by its robot file's "
                          "mechanism_module (docs/new-mechanism.md)")


#: the robots of --contract-robot, loaded once when pytest starts: [(path, Robot)]
CONTRACT_ROBOTS = pytest.StashKey()


def pytest_configure(config):
    """Load the ``--contract-robot`` files before collection: a bad one is a one-line usage error."""
    paths = config.getoption("contract_robot", default=None) or []
    robots = []
    if paths:
        from zerocal_sym.errors import ZerocalError
        from zerocal_sym.model.robot import load_robot
    for path in paths:
        try:
            robots.append((path, load_robot(path)))
        except ZerocalError as exc:
            raise pytest.UsageError(f"--contract-robot: {exc}") from None
    config.stash[CONTRACT_ROBOTS] = robots


@pytest.fixture(scope="session")
def docs_runs(tmp_path_factory):
    """The docs checker's runs (tests/docs_check.py), once per session across pytest-xdist workers: a directory
    shared by the workers (their base directories' parent)."""
    import docs_check

    base = tmp_path_factory.getbasetemp()
    return docs_check.SharedCache((base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "docs-check")


@pytest.fixture(scope="session")
def robot():
    from zerocal_sym.model.robot import paper_robot

    return paper_robot()


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# ----------------------------------------------------------------------------- the sympy derivation, once
@pytest.fixture(scope="session")
def derived():
    """Every mechanism derived afresh from ``derivations/`` (sympy), once per test process:
    ``{name: SymbolicMechanism}`` (:func:`derivations.codegen.derive_all`, the paper's forms checked).
    Read-only: a test that edits a derivation builds its own."""
    pytest.importorskip("sympy")
    from derivations import codegen

    return codegen.derive_all()


@pytest.fixture(scope="session")
def generated(derived):
    """The generated modules a fresh derivation writes, ``{path in zerocal_sym/generated: source}``
    (:func:`derivations.codegen.generate` on :func:`derived`), once per test process."""
    from derivations import codegen

    return codegen.generate(derived=derived)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items):
    """The notebooks first, then the tests of the session's derivation (the fixtures above), the rest in order.

    ``pytest -n 2`` distributes by work stealing (``--dist worksteal``, pyproject.toml): each worker starts
    with a contiguous share of this order and, when done, takes the tail of another's.  The long items first
    keep the tails short, so the two workers end together; the derivation's tests together at the start of
    the first share run on one worker and share one derivation (a worker that runs only some of them derives
    for itself: slower, the same checks).
    """
    def rank(item):
        if item.nodeid.endswith(".ipynb") or ".ipynb::" in item.nodeid:
            return 0
        if {"derived", "generated", "symbolic"} & set(getattr(item, "fixturenames", ())):
            return 1
        return 2

    items[:] = sorted(items, key=rank)  # stable: the collection order within each rank


# ----------------------------------------------------------------------------- test time per mechanism
#: a test's mechanism: the first of these its node id names (parametrised ids, file names), else unnamed
_MECHANISM_MARKS = {
    "planar_2dof": ("planar_2dof", "paper"),
    "delta_rotary": ("delta_rotary", "delta.toml", "_delta", "delta]"),
    "delta_linear": ("delta_linear", "linear_delta", "lineardelta"),
    "hexapod": ("hexapod",),
}
_TIMES: dict = {}


def _mechanism_of(nodeid: str) -> str:
    node = nodeid.lower()
    for mech in ("hexapod", "delta_linear", "delta_rotary", "planar_2dof"):  # most specific first
        if any(mark in node for mark in _MECHANISM_MARKS[mech]):
            return mech
    return "unnamed (mostly the paper's robot)"


def pytest_runtest_logreport(report):
    """Sum each test's setup, call and teardown time under its mechanism (the controller sees every worker's)."""
    t = _TIMES.setdefault(_mechanism_of(report.nodeid), [0.0, set()])
    t[0] += report.duration
    t[1].add(report.nodeid)


def pytest_terminal_summary(terminalreporter):
    """The suite's time per mechanism (what each mechanism costs CI), after the results."""
    if not _TIMES:
        return
    parts = [f"{m} {t:.1f} s ({len(ids)} tests)" for m, (t, ids) in sorted(_TIMES.items(), key=lambda kv: -kv[1][0])]
    terminalreporter.write_line("test time per mechanism (summed over the workers): " + "; ".join(parts))
