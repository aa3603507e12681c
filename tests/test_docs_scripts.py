"""docs/nonlinear.md's scripts [A] and [B] run as written, and print the numbers the page quotes."""
import contextlib
import io
import re
from pathlib import Path

import pytest

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


def test_script_a_prints_the_noise_free_table():
    out = _run(_script("A"))
    rows = _table_rows()
    assert sorted(rows) == [1, 2, 3, 4, 5, 6]
    for g, cells in rows.items():
        line = next(ln for ln in out.splitlines() if ln.startswith(f"{g} | "))
        printed = [c.strip() for c in line.split("||")[0].split("|")[1:]]
        # errors and the first-order bias to the page's 5 decimals; the ratios to its digits
        assert printed[:3] == cells[:3], (g, printed, cells)
        assert float(printed[3]) == pytest.approx(float(cells[3]), abs=1e-4)
        assert float(printed[4]) == pytest.approx(float(cells[4]), abs=1e-3)
        lengths, offsets = (float(x) for x in line.split(":")[-1].split(","))
        page_l, page_o = (float(x) for x in cells[5].split(","))
        assert "True rank 9" in line
        assert lengths == pytest.approx(page_l, rel=0.06) and offsets == pytest.approx(page_o, rel=0.06)
    assert "n=4 K=8: rank 7 of 9" in out and "all 12, K=12: rank 9 null space rigid: True" in out
    for n, std in ((5, 180), (6, 142), (8, 117)):  # the page's "std 180 / 142 / 117 mm"
        assert f"n={n} K={2 * n}: rank 9 of 9" in out and f"(std {std} mm)" in out
    assert float(out.splitlines()[-1].split(":")[-1]) < 1e-12


def test_script_b_prints_the_start_dependence():
    out = _run(_script("B"))
    worst = {int(m.group(1)): float(m.group(2)) for m in re.finditer(r"reweight=(\d): max \|cold - tsvd start\| = "
                                                                      r"(\S+) deg", out)}
    page = DOC.read_text()
    # "differ by at most 1.1e-3 deg with `reweight=0` and 1.6e-11 deg with `reweight=1`"
    m = re.search(r"at most\s+(\S+) deg with `reweight=0` and (\S+) deg with\s+`reweight=1`", page)
    assert m, "the sentence quoting script [B] changed: update this test"
    assert worst[0] == pytest.approx(float(m.group(1)), rel=0.05)
    assert worst[1] == pytest.approx(float(m.group(2)), rel=0.05)
    assert worst[3] == worst[1]  # any non-zero reweight is the same


def test_script_d_prints_what_the_page_shows():
    out = _run(_script("D"))
    text = DOC.read_text()
    at = text.index("### Batched identification")
    shown = text[text.index("```\n", at) + 4:text.index("\n```", text.index("```\n", at) + 4)]
    assert out.strip() == shown.strip()
