"""Headless Chromium for the calibration report: open a page, probe what it rendered, take a screenshot.

:func:`open_page` copies the page with a probe script at the top of its
``<head>`` (the report itself has no script), runs Debian's ``chromium``
once with ``--dump-dom`` and ``--screenshot``, and returns what the probe saw
after the page's ``load`` event: the console errors and warnings and the
failed loads it caught, each ``<img>``'s natural size, the ``<svg>`` count,
the sections, the page's height; and the browser's own console lines.

Run as a script, it regenerates the walkthrough's screenshot
``docs/img/report.png``: the walkthrough's dry run (steps 3 and 4 on
``examples/my_robot.toml``), ``zerocal report`` on its result, a screenshot
of the whole page::

    python tests/browser.py
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS_PNG = ROOT / "docs" / "img" / "report.png"
#: the screenshot's width (px)
WIDTH = 1100
#: flags for a headless run as root in a container, nothing fetched from the network
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync", "--hide-scrollbars",
         "--mute-audio", "--enable-logging=stderr", "--v=0")

PROBE = """<script>(function () {
  var seen = [];
  console.error = function () { seen.push("console.error: " + Array.prototype.join.call(arguments, " ")); };
  console.warn = function () { seen.push("console.warn: " + Array.prototype.join.call(arguments, " ")); };
  window.addEventListener("error", function (e) {
    var t = e.target || {};
    seen.push("error: " + (e.message || t.src || t.href || t.tagName || "?"));
  }, true);
  window.addEventListener("load", function () {
    var out = {
      errors: seen,
      images: Array.prototype.map.call(document.images, function (i) {
        return {alt: i.alt, complete: i.complete, width: i.naturalWidth, height: i.naturalHeight};
      }),
      svgs: document.querySelectorAll("svg").length,
      sections: Array.prototype.map.call(document.querySelectorAll("section"), function (s) { return s.id; }),
      height: document.documentElement.scrollHeight
    };
    var pre = document.createElement("pre");
    pre.id = "zerocal-probe";
    pre.style.display = "none";
    pre.textContent = JSON.stringify(out);
    document.body.appendChild(pre);
  });
})();</script>"""


def find_chromium():
    """The chromium binary, or None."""
    for name in ("chromium", "/usr/bin/chromium"):
        path = shutil.which(name)
        if path:
            return path
    return None


def open_page(page, screenshot, height: int = 1400, width: int = WIDTH, timeout: float = 120.0) -> dict:
    """Open ``page`` (an HTML file) in headless Chromium; write the screenshot to ``screenshot``.

    Returns
    -------
    dict
        The probe's findings (module docstring) and ``console``: the browser's console lines (any message the
        page logged: the report logs none).
    """
    chromium = find_chromium()
    if chromium is None:
        raise FileNotFoundError("chromium is not installed (Debian: apt-get install chromium)")
    text = Path(page).read_text(encoding="utf-8")
    at = text.index("<head>") + len("<head>")
    with tempfile.TemporaryDirectory(prefix="zerocal-chromium-") as tmp:
        probed = Path(tmp) / "page.html"
        probed.write_text(text[:at] + PROBE + text[at:], encoding="utf-8")
        profile = Path(tmp) / "profile"  # a fresh profile: nothing from another run
        cmd = [chromium, *FLAGS, f"--user-data-dir={profile}", f"--window-size={width},{height}",
               f"--screenshot={Path(screenshot).resolve()}", "--dump-dom", probed.as_uri()]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=tmp)
    if r.returncode != 0:
        raise RuntimeError(f"chromium exited with {r.returncode}: {r.stderr[-2000:]}")
    m = re.search(r'<pre id="zerocal-probe"[^>]*>(.*?)</pre>', r.stdout, re.S)
    if m is None:
        raise RuntimeError("the probe found nothing: the page's load event did not fire before the DOM was dumped")
    import html

    found = json.loads(html.unescape(m.group(1)))
    found["console"] = [ln for ln in r.stderr.splitlines() if ":CONSOLE" in ln]
    return found


def regenerate_docs_png(out=DOCS_PNG) -> dict:
    """The walkthrough's dry run, its report, the whole page's screenshot at ``out`` (module docstring)."""
    from zerocal_sym.cli import main

    with tempfile.TemporaryDirectory(prefix="zerocal-docs-") as tmp:
        cwd = os.getcwd()
        os.chdir(tmp)
        try:
            shutil.copy(ROOT / "examples" / "my_robot.toml", "my_robot.toml")
            robot = ["--robot", "my_robot.toml"]
            for argv in (["simulate", *robot, "--group", "4", "--seed", "1", "--noise", "scale-only", "--out",
                          "round1.csv"],
                         ["identify", "round1.csv", *robot, "--noise", "scale-only", "--out", "result1.json"],
                         ["report", "result1.json", *robot, "--data", "round1.csv", "--out", "report.html"]):
                if main(argv) != 0:
                    raise RuntimeError(f"zerocal {' '.join(argv)} failed")
            first = open_page("report.html", Path(tmp) / "first.png")
            out = Path(out)
            out.parent.mkdir(parents=True, exist_ok=True)
            return open_page("report.html", out, height=first["height"])
        finally:
            os.chdir(cwd)


if __name__ == "__main__":
    found = regenerate_docs_png()
    print(f"wrote {DOCS_PNG.relative_to(ROOT)}: {len(found['images'])} figures, page height {found['height']} px",
          file=sys.stderr)
