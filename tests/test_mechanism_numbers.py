"""The linear Delta's and the hexapod's measured numbers: recomputed by the example scripts, and quoted by the docs.

``examples/linear_delta_numbers.py`` and ``examples/hexapod_numbers.py`` recompute every number an
independent implementation measured on these mechanisms and check each (exit 1 on a mismatch);
``docs/linear-delta.md`` and ``docs/hexapod.md`` quote them: every figure a script checks appears in its
page (ours, to the reference's digits, where the two differ in the last digit).
"""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
sys.path.insert(0, str(EXAMPLES))
import _pagecheck  # noqa: E402

#: a number as printed, not the tail of a range ("0.98-1.03": 0.98 and 1.03)
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def _run(script, *args):
    r = subprocess.run([sys.executable, str(EXAMPLES / script), *args], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    assert not [line for line in r.stdout.splitlines() if line.startswith("BAD")] and " 0 BAD" in r.stdout
    return r.stdout


def _quoted(out):
    """The figures each ok line compares with: the reference's, or ours at its digits where the last differs."""
    figures = []
    for line in out.splitlines():
        if not line.startswith("ok  "):
            continue
        theirs = line[line.index("(page: ") + len("(page: "):line.rindex(")  [")]
        m = re.search(r"to the page's digits ours is \(([^)]*)\)", line)
        figures.append((line, NUMBER.findall(m.group(1) if m else theirs)))
    return figures


def _assert_quoted(out, doc):
    text = (ROOT / "docs" / doc).read_text().replace("\u2212", "-")
    numbers = set(NUMBER.findall(text))
    missing = [(line.split(":")[0], f) for line, figs in _quoted(out) for f in figs if f not in numbers]
    assert not missing, f"figures the script checks that docs/{doc} does not quote: {missing}"


def test_linear_delta_numbers_reproduce_and_the_docs_quote_them():
    out = _run("linear_delta_numbers.py", "--trials", "100")
    assert out.count("\nok  ") >= 40
    _assert_quoted(out, "linear-delta.md")


@pytest.mark.slow
def test_hexapod_numbers_reproduce_and_the_docs_quote_them():
    out = _run("hexapod_numbers.py", "--trials", "40")
    assert out.count("\nok  ") >= 50
    _assert_quoted(out, "hexapod.md")


# ----------------------------------------------------------------------------- the checks themselves
def test_a_figure_off_by_more_than_its_tolerance_is_bad(capsys):
    page = _pagecheck.Page()
    assert page.value("x", 16.36, "16.36") and page.value("x", 16.5, "16.36")  # 1 %: 0.16
    assert not page.value("x", 16.6, "16.36")
    assert page.value("x", -0.00434, "-0.0043") and not page.value("x", -0.00436, "-0.0043")  # the digit: 5e-5
    assert not page.value("x", [0.0043, 0.0030], ["-0.0043", "-0.0032"])
    assert not page.exact("rank", 10, 11) and not page.roundoff("error", 5e-12, "4e-13")
    assert page.monte_carlo("rms/crlb", [0.9, 1.2], 0.98, 1.03, _pagecheck.rms_ratio_sd, 50, "0.98-1.03")
    assert not page.monte_carlo("rms/crlb", [1.0, 1.4], 0.98, 1.03, _pagecheck.rms_ratio_sd, 50, "0.98-1.03")
    assert page.exit_code() == 1
    out = capsys.readouterr().out
    assert sum(line.startswith("BAD ") for line in out.splitlines()) == 6


def test_the_last_digit_is_reported_even_within_tolerance(capsys):
    page = _pagecheck.Page()
    assert page.value("legs", [232.4194736, 461.7251508], ["232.420", "461.725"])
    assert page.exit_code() == 0
    out = capsys.readouterr().out
    assert "to the page's digits ours is (232.419, 461.725)" in out and "not the page's last printed digit: legs" in out
