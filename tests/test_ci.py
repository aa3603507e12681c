"""CI (.ci/run) runs the README's quick start and test command, and the same tests at the oldest declared versions."""
import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]
RUN = ROOT / ".ci" / "run"
CONSTRAINTS = ROOT / "constraints" / "oldest.txt"


def _quick_start():
    """The README's quick-start commands, one per line."""
    text = (ROOT / "README.md").read_text()
    at = text.index("## Quick start")
    start = text.index("```bash\n", at) + len("```bash\n")
    return [ln for ln in text[start:text.index("\n```", start)].splitlines() if ln.strip()]


def _script_lines():
    return [ln.strip() for ln in RUN.read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]


def _pins():
    """constraints/oldest.txt as {normalised name: version}."""
    pins = {}
    for ln in CONSTRAINTS.read_text().splitlines():
        ln = ln.split("#")[0].strip()
        if ln:
            name, _, version = ln.partition("==")
            assert version, f"constraints/oldest.txt: {ln!r} is not NAME==VERSION"
            pins[re.sub(r"[-_.]+", "-", name.strip().lower())] = Version(version)
    return pins


def test_ci_runs_the_readme_quick_start_and_test_command():
    setup, test = _quick_start()
    assert test.startswith(".venv/bin/python -m pytest ")
    lines = _script_lines()
    assert setup in lines and test in lines
    assert lines.index(setup) < lines.index(test)
    # pytest with no tests exits 5: the command names the test directories, and set -e fails CI on any status
    assert "set -euo pipefail" in lines and " tests notebooks" in test


def test_ci_runs_the_same_test_command_at_the_oldest_versions():
    _, test = _quick_start()
    lines = _script_lines()
    # (without the slow tests, which job 1 ran: two runs of them do not fit CI's budget)
    oldest = test.replace(".venv/", ".venv-oldest/", 1) + ' -m "not slow"'
    assert oldest in lines and lines.index(oldest) > lines.index(test)
    install = [ln for ln in lines if ".venv-oldest/bin/pip install" in ln]
    assert len(install) == 1 and "-c constraints/oldest.txt -e '.[test]'" in install[0]


def test_oldest_constraints_are_the_declared_lower_bounds():
    """Every runtime and test requirement is pinned at its lower bound (or its == version), nothing above it."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    pins = _pins()
    for text in project["dependencies"] + project["optional-dependencies"]["test"]:
        req = Requirement(text)
        name = re.sub(r"[-_.]+", "-", req.name.lower())
        lower = [Version(s.version) for s in req.specifier if s.operator in (">=", "==")]
        assert len(lower) == 1, f"pyproject.toml: {text!r} declares no single lower bound"
        assert name in pins, f"constraints/oldest.txt does not pin {name} (pyproject.toml: {text!r})"
        assert pins[name] == lower[0], f"constraints/oldest.txt pins {name}=={pins[name]}, pyproject.toml {text!r}"
        assert req.specifier.contains(pins[name], prereleases=True)
