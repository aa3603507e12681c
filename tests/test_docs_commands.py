"""Every command README.md and docs/*.md show is run, and what it prints is compared with the page.

The convention is in README.md ("Development", "Docs that run") and tests/docs_check.py.  One test per page
runs its commands in order in a scratch directory (the fast ones); each slow block or check is a test of its own,
marked slow, run once per test session (also across pytest-xdist workers) and kept for any page that shows the same
commands.  Another test finds every ``zerocal`` command in a fenced block and asks that it is run or says why not.
"""
from pathlib import Path

import pytest

import docs_check as dc

PAGES = {p.relative_to(dc.ROOT).as_posix(): dc.parse_page(p) for p in dc.PAGES}
FAST = [name for name, page in PAGES.items() if any(not it.slow for it in page.items)]
SLOW = [pytest.param(name, k, id=f"{name}:{it.line}")
        for name, page in PAGES.items() for k, it in enumerate(page.items) if it.slow]


@pytest.mark.parametrize("name", FAST)
def test_page_prints_what_it_shows(name, docs_runs):
    _, problems = docs_runs.page(PAGES[name])
    assert not problems, f"{len(problems)} difference(s) between {name} and what its commands print:\n" + \
        "\n".join(problems)


@pytest.mark.slow
@pytest.mark.parametrize("name,k", SLOW)
def test_slow_item_prints_what_the_page_shows(name, k, docs_runs):
    page = PAGES[name]
    item = page.items[k]
    problems = dc.judge_item(item, docs_runs.slow_results(page, k))
    assert not problems, "\n".join(problems)


def test_every_command_is_run_or_says_why():
    """Each ``zerocal`` command in a fenced block of a page is run by the checker or marked ``not run: REASON``."""
    unchecked = [f"{name}:{line}: {text}" for name, page in PAGES.items()
                 for line, text, reason, run in dc.zerocal_lines(page) if not run and not reason]
    assert not unchecked, ("zerocal commands no test runs (make the block a console or bash block, or put "
                           "'<!-- check-block: not run: REASON -->' before it):\n" + "\n".join(unchecked))
    assert sum(run for page in PAGES.values() for *_, run in dc.zerocal_lines(page)) >= 40


# ----------------------------------------------------------------------------------------------- the checker itself
def test_numbers_compare_at_the_digits_shown():
    assert dc.line_matches("CRLB 0.4910 / 0.4910 deg", "CRLB 0.49104 / 0.490951 deg")[0]
    ok, why = dc.line_matches("CRLB 0.4910 / 0.4910 deg", "CRLB 0.4911 / 0.4910 deg")
    assert not ok and why == "0.4911 where the page shows 0.4910"
    assert dc.line_matches("kappa_1 = 475.342", "kappa_1   =   475.34239")[0]
    assert not dc.line_matches("kappa_1 = 475.342", "kappa_m = 475.342")[0]  # the text must match
    assert dc.line_matches("n = 3 (eps0 rule; ...)", "n = 3 (eps0 rule; eps0 = 0.01 selects 3)")[0]
    assert dc.line_matches("\u22120.5 mm and 1e-06", "-0.50 mm and 1.4e-06")[0]  # the page's minus; 1e-06 at its digit
    assert not dc.line_matches("2e-11", "3e-11")[0]
    # after an ellipsis the number is found by its value, never the tail of another (x59, -0.5)
    assert dc.line_matches("tsvd-loop ... 59 ...", "tsvd-loop  +0.0105, 0.3856  0   59   9.2  0.71")[0]
    assert not dc.line_matches("loop ... 0.5 mm", "loop -0.5 mm")[0] and not dc.line_matches("a ... 9 b", "a 59 b")[0]
    assert dc.line_matches("nlls ... 1.001", "x  nlls  0.63  1.001,1.001", search=True)[0]
    assert dc.line_matches("ours 3185.7 ... reference 3186", "ours 3185.745  reference 3186")[0]
    # digits followed by an ellipsis: the printed number starts with them
    assert dc.line_matches("theta1,-1.0637759...,0.6377426...", "theta1,-1.0637759353196776,0.6377426986548939")[0]
    assert not dc.line_matches("x 0.637743...", "x 0.6377426986548939")[0]
    # the page's text may take a sign before a number: "+-0.5 mm" (plus or minus), not after an ellipsis
    assert dc.line_matches("L2 at +-0.5 mm", "L2 at +-0.5 mm")[0] and not dc.line_matches("at +-0.5", "at +-0.6")[0]
    assert not dc.line_matches("L2 ... 0.5 mm", "L2 at +-0.5 mm")[0]
    # a sign glued to a word is text: M666 X0.120 Y-0.300
    assert dc.line_matches("M666 X0.120 Y-0.300 Z0.050", "M666 X0.120 Y-0.300 Z0.050")[0]
    # words holding digits are text: theta1, P1, a hash
    assert not dc.line_matches("theta1 = 2", "theta2 = 2")[0] and dc.line_matches("sha256: 2eaac3", "sha256: 2eaac3")[0]


def test_console_output_matches_line_by_line_with_ellipses():
    out = "head 1\nP1 (1.00, 2.00)\nP2 (3.00, 4.00)\nP3 (5.00, 6.00)\nCRLB 0.4910\n"
    assert dc.match_output(["head 1", "...", "CRLB 0.491"], out) is None
    assert dc.match_output(["head 1", "P1 (1.0, 2.0)", "...", "CRLB 0.4910"], out) is None
    why = dc.match_output(["head 1", "...", "CRLB 0.4920"], out)
    assert "0.4910 where the page shows 0.4920" in why
    assert "more than the page shows" in dc.match_output(["head 1", "P1 (1.00, 2.00)"], out)
    assert "output ended" in dc.match_output(["head 1", "...", "CRLB 0.4910", "more"], out)


def test_a_check_compares_json_values_and_wants_them_in_the_prose():
    data = {"kappa_1": 475.3424, "crlb": [0.5220, 0.5219], "groups": [{"d": [0.031, 0.04]}, {"d": [0.042, 0.035]}],
            "method": "nlls", "err": 2.7e-11}
    assert dc.check_json(data, "kappa_1: 475.342") == (None, ["475.342"])
    assert dc.check_json(data, "crlb: 0.522, 0.522")[0] is None
    assert "0.5219 (page 0.5220)" in dc.check_json(data, "crlb: 0.5220 0.5220")[0]
    assert dc.check_json(data, "groups[*].d: 0.031..0.042") == (None, ["0.031", "0.042"])
    assert dc.check_json(data, "groups[*].d: 0.031..0.041")[0]
    assert dc.check_json(data, "groups[1:].d: 0.042 0.035")[0] is None and dc.check_json(data, "*: 2.7e-11")[0]
    assert dc.check_json(data, 'method: "nlls"')[0] is None and dc.check_json(data, 'method: "tsvd"')[0]
    assert dc.check_json(data, "err: <1e-10")[0] is None and dc.check_json(data, "err: <1e-11")[0]
    assert "no such value" in dc.check_json(data, "kappa_2: 1")[0]
    assert dc.quoted_in_region(["475.342", "-0.5", "0.0267"], "kappa 475.342 and \u22120.5 mm") == ["0.0267"]


def test_a_check_finds_text_patterns_in_order():
    out = "robot x\nhome P0: (0.000, 688.186) mm\nmax |FK(IK(P)) - P| = 2.5e-13 mm\n"
    assert dc.check_text(out, ["P0: (0.000, 688.186)", "= {<1e-12} mm"])[0] is None
    assert dc.check_text(out, ["= {<1e-13} mm"])[0]
    assert dc.check_text(out, ["max", "home"])[0]  # out of order
    why, quoted = dc.check_text(out, ["P0: (0, 688.19)"])
    assert why is None and quoted == ["0", "688.19"]


def test_a_stale_page_fails(tmp_path):
    """A page whose console block shows another number than the command prints is reported, line and numbers."""
    page = tmp_path / "p.md"
    page.write_text("# t\n\n```console\n$ echo 'kappa 1.25'\nkappa 1.4\n$ sh -c 'echo x 2; exit 3'\nx 2\n"
                    "[exit 3]\n```\n\n"
                    "Ours is 1.25.\n<!-- check: echo 'k 1.251'\nk 1.25\n-->\n\n<!-- check: echo 'k 7'\nk 7\n-->\n")
    parsed = dc.parse_page(page)
    assert [it.kind for it in parsed.items] == ["block", "check", "check"]
    problems = dc.run_page(parsed, tmp_path / "run")
    assert len(problems) == 1 + 1 and "which the section's text does not show" in problems[1]
    page.write_text(page.read_text().replace("kappa 1.4", "kappa 1.1"))
    assert "1.25 where the page shows 1.1" in dc.run_page(dc.parse_page(page), tmp_path / "run2")[0]


def test_a_check_reuses_a_block_run_of_its_command(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("# t\n\n```bash\necho $RANDOM > n.txt; cat n.txt   # once\n```\n\n"
                    "It printed a number below 100000.\n<!-- check: echo $RANDOM > n.txt; cat n.txt\n{<100000}\n-->\n")
    parsed = dc.parse_page(page)
    assert dc.command_key(parsed.items[0].commands[0].text) == parsed.items[1].commands[0].text
    assert dc.run_page(parsed, tmp_path / "run") == []
    ran = tmp_path / "run" / ".docs-check"
    assert (ran / "0.out").exists() and not (ran / "1.out").exists()  # the check took the block's output


def test_unchecked_commands_are_found(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("```\nzerocal robot\n```\n\n<!-- check-block: not run: your own files -->\n```bash\n"
                    "zerocal identify "
                    "mine.csv\n```\n\n```\nzerocal identify: error: d.csv:6: missing\n# zerocal measurements v1\n```\n")
    found = dc.zerocal_lines(dc.parse_page(page))
    assert [(ln, reason, run) for ln, _, reason, run in found] == [(2, None, False), (7, "your own files", False)]


def test_the_pages_parse(tmp_path):
    assert set(PAGES) >= {"README.md", "docs/walkthrough.md", "docs/model.md", "docs/delta.md"}
    for name, page in PAGES.items():
        for it in page.items:
            assert it.commands and all(c.text.strip() for c in it.commands), it.where
    bad = tmp_path / "bad.md"
    bad.write_text("<!-- check-block: fast -->\n```console\n$ true\n```\n")
    with pytest.raises(ValueError, match="unknown check-block directive"):
        dc.parse_page(bad)
    for text in ("<!-- check: zerocal robot -->\n", "<!-- check: zerocal robot\nhome P0\n--> and prose\n"):
        bad.write_text(text)
        with pytest.raises(ValueError, match="ends with --> on a line of its own"):
            dc.parse_page(bad)
    assert Path(dc.ROOT / "README.md") in dc.PAGES
