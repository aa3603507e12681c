"""docs/nonlinear.md's scripts [A] and [B] run as written, and print the numbers the page quotes."""
import contextlib
import io
import re
from pathlib import Path

import numpy as np
import pytest

import planar_gauge as pg
from roundoff import FLOORS, distance_unit, estimate_floor, shown
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.model.robot import paper_robot
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors

DOC = Path(__file__).resolve().parents[1] / "docs" / "nonlinear.md"


def _script(tag):
    """The python block that follows the line starting with ``[tag]`` in docs/nonlinear.md."""
    text = DOC.read_text()
    at = text.index(f"\n[{tag}] ")
    start = text.index("```python\n", at) + len("```python\n")
    return text[start:text.index("\n```", start)]


def _run(code):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, f"{DOC.name}:[script]", "exec"), {"__name__": "__docs__"})
    return out.getvalue()


def _table_rows():
    """The noise-free table of the page: group -> its cells (strings, the page's minus signs as '-')."""
    rows = {}
    for line in DOC.read_text().splitlines():
        m = re.match(r"\| ([1-6]) \| (.+) \|$", line)
        if m:
            rows[int(m.group(1))] = [c.strip().replace("\u2212", "-") for c in m.group(2).split("|")]
    return rows


def _at_shown_digits(value, text):
    """``value`` equals the page's ``text`` to the digits the page shows."""
    want, half = shown(text)
    return abs(value - want) <= half * (1 + 1e-9)


def test_script_a_prints_the_noise_free_table():
    out = _run(_script("A"))
    rows = _table_rows()
    r = paper_robot()
    th12 = kin.ik(r, paper_poses(r, 6))
    floors = {g: estimate_floor(r, th12, "gauge_fixed", NoiseModel.paper(), pg.to_base_gauge(r, table2_errors(g)))
              for g in rows}
    assert sorted(rows) == [1, 2, 3, 4, 5, 6]
    for g, cells in rows.items():
        line = next(ln for ln in out.splitlines() if ln.startswith(f"{g} | "))
        printed = [c.strip() for c in line.split("||")[0].split("|")[1:]]
        # errors and the first-order bias to the page's 5 decimals; the ratios to the digits it shows
        assert printed[:3] == cells[:3], (g, printed, cells)
        assert _at_shown_digits(float(printed[3]), cells[3]) and _at_shown_digits(float(printed[4]), cells[4])
        # the 9-parameter errors are round-off: held to their floor (the page says so), not to the page's digits
        lengths, offsets = (float(x) for x in line.split(":")[-1].split(","))
        assert "True rank 9" in line
        assert lengths <= FLOORS * floors[g][2:].max() and offsets <= FLOORS * floors[g][:2].max()
    # the floors the page quotes, at its digits
    m = re.search(r"(\S+)–(\S+) mm for the lengths,\s+(\S+)–(\S+) rad for the offsets", DOC.read_text())
    assert m, "the sentence quoting the round-off floors changed: update this test"
    assert _at_shown_digits(min(f[2:].max() for f in floors.values()), m.group(1))
    assert _at_shown_digits(max(f[2:].max() for f in floors.values()), m.group(2))
    assert _at_shown_digits(min(f[:2].max() for f in floors.values()), m.group(3))
    assert _at_shown_digits(max(f[:2].max() for f in floors.values()), m.group(4))
    assert "n=4 K=8: rank 7 of 9" in out and "all 12, K=12: rank 9 null space rigid: True" in out
    for n, std in ((5, 180), (6, 142), (8, 117)):  # the page's "std 180 / 142 / 117 mm"
        assert f"n={n} K={2 * n}: rank 9 of 9" in out and f"(std {std} mm)" in out
    # rigid invariance: two distances' round-off (FLOORS of it each)
    assert float(out.splitlines()[-1].split(":")[-1]) <= 2 * FLOORS * distance_unit(r, th12, table2_errors(1))


def test_script_b_prints_the_start_dependence():
    out = _run(_script("B"))
    worst = {int(m.group(1)): float(m.group(2)) for m in re.finditer(r"reweight=(\d): max \|cold - tsvd start\| = "
                                                                      r"(\S+) deg", out)}
    page = DOC.read_text()
    # "differ by at most 1.1e-3 deg with `reweight=0`, and with `reweight=1` by round-off only (... the round-off
    # floor of these offsets, ..., is 2.3e-11 deg"
    m = re.search(r"at most\s+(\S+) deg with `reweight=0`, and with `reweight=1` by round-off only.*?"
                  r"is\s+(\S+) deg", page, re.S)
    assert m, "the sentence quoting script [B] changed: update this test"
    # reweight=0: a real difference (the weights at two starts), at the page's digits
    assert _at_shown_digits(worst[0], m.group(1))
    # reweight=1: round-off, the difference of two estimates of one problem: within twice FLOORS of the floor
    # (the script's first data set's truth is table2_errors(1); the floor moves < 1e-3 with the estimate)
    r = paper_robot()
    th6 = kin.ik(r, paper_poses(r, 3))
    floor = np.degrees(estimate_floor(r, th6, "paper", NoiseModel.paper(), table2_errors(1))[:2].max())
    assert _at_shown_digits(floor, m.group(2))
    assert worst[1] <= 2 * FLOORS * floor
    assert worst[3] == worst[1]  # any non-zero reweight is the same


def test_script_d_prints_what_the_page_shows():
    out = _run(_script("D"))
    text = DOC.read_text()
    at = text.index("### Batched identification")
    shown = text[text.index("```\n", at) + 4:text.index("\n```", text.index("```\n", at) + 4)]
    assert out.strip() == shown.strip()
