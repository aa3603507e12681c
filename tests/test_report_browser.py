"""The calibration report opened in headless Chromium (Debian's package): it renders, without a console error,
with its figures at their size; a screenshot that is not blank.  The docs' screenshot is the same page's.

Without chromium the browser test is skipped, unless the environment variable ``CI`` is set: then it fails
(``.ci/run`` installs chromium)."""
import os
import re
import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

import browser
from zerocal_sym.cli import main

ROOT = Path(__file__).resolve().parents[1]
SECTIONS = ["verdict", "offsets", "error-budget", "fit-check", "residuals", "robot", "accuracy"]


def _png_size(path) -> tuple:
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", data[16:24])


@pytest.fixture
def chromium():
    if browser.find_chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is not installed, and CI is set: .ci/run installs it (apt-get install chromium)")
        pytest.skip("chromium is not installed (Debian: apt-get install chromium)")


def test_the_report_renders_in_chromium(chromium, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    shutil.copy(ROOT / "examples" / "my_robot.toml", "my_robot.toml")
    robot = ["--robot", "my_robot.toml"]
    assert main(["simulate", *robot, "--group", "4", "--seed", "1", "--noise", "scale-only", "--out", "d.csv"]) == 0
    assert main(["identify", "d.csv", *robot, "--noise", "scale-only", "--out", "r.json"]) == 0
    assert main(["report", "r.json", *robot, "--data", "d.csv", "--out", "report.html"]) == 0
    capsys.readouterr()
    text = Path("report.html").read_text()
    declared = [(int(w), int(h)) for w, h in re.findall(r'<img alt="[^"]*" width="(\d+)" height="(\d+)"', text)]
    found = browser.open_page("report.html", "shot.png", height=1400)
    assert found["errors"] == [] and found["console"] == [], (found["errors"], found["console"])
    assert found["sections"] == SECTIONS
    # every figure loaded, at the size the page declares (the PNG's own)
    assert len(found["images"]) == len(declared) == 4
    for img, (w, h) in zip(found["images"], declared):
        assert img["complete"] and (img["width"], img["height"]) == (w, h) and w > 300 and h > 200, img
    assert found["svgs"] == 0 and found["height"] > 1400  # the page is longer than the screenshot's window
    # the screenshot: the window's size, and a page drawn (text and figures, not a blank or an error page)
    assert _png_size("shot.png") == (browser.WIDTH, 1400)
    from matplotlib.image import imread

    pixels = imread("shot.png")[..., :3]
    ink = np.mean(np.any(pixels < 0.6, axis=-1))  # the share of pixels darker than light grey
    assert 0.01 < ink < 0.5, ink
    assert len(np.unique((pixels * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 100  # colour figures, text


def test_the_docs_screenshot_is_of_the_whole_report():
    """docs/img/report.png (``python tests/browser.py`` makes it): the whole page, at the test's width."""
    width, height = _png_size(browser.DOCS_PNG)
    assert width == browser.WIDTH and height > 2000
    assert "docs/img/report.png" in browser.__doc__
    assert "img/report.png" in (ROOT / "docs" / "walkthrough.md").read_text()


def test_ci_installs_chromium_before_the_tests():
    """.ci/run installs Debian's chromium when it is missing, before the README's test command runs."""
    lines = [ln.strip() for ln in (ROOT / ".ci" / "run").read_text().splitlines()]
    install = next(k for k, ln in enumerate(lines) if "apt-get" in ln and "install" in ln and "chromium" in ln)
    test = next(k for k, ln in enumerate(lines) if ln.startswith(".venv/bin/python -m pytest"))
    assert install < test and any("[ ! -x /usr/bin/chromium ]" in ln for ln in lines[:install])
