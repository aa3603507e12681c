"""A reference set of `zerocal design --optimize` runs and what of each is compared (tests/test_design_reference.py).

``python tests/design_cases.py`` writes ``tests/data/reference_designs.json``: each case's printed report (the
text, without the time on its ``method:`` line) and its JSON report (``--out``, without the times), as the
code at that commit computes them, and the versions of the libraries that computed them.  It was written
before the design's time was cut (one call of the per-pose terms for the feasibility checks and the
sensitivity, the terms through zero-copy mapped calls, the exchange's objective only on the trials that
keep the travel and the separation, ...): the test recomputes every case and asks for the same report, bit
for bit, on the library versions that wrote the file (other builds may change the last bits, and with them
a point of the certificate's search or a local optimum of Ipopt).
"""
from __future__ import annotations

import contextlib
import io
import json
import re
import sys
import tempfile
from pathlib import Path

from reference_files import versions, without_times, write_reference  # noqa: F401 (versions: the tests')

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).resolve().parent / "data" / "reference_designs.json"

_REACH = ["--region", "reachable", "--bounds", "-2000", "2000", "450", "2000"]
_DELTA = ["--robot", str(ROOT / "examples" / "delta.toml")]
_LINEAR = ["--robot", str(ROOT / "examples" / "linear_delta.toml")]

#: (case id, the arguments of `zerocal design --optimize`)
CASES = [
    ("paper-crlb", ["--K", "6", "--criterion", "crlb"]),
    ("paper-D", ["--K", "6", "--criterion", "D"]),
    ("paper-checked", ["--K", "6"]),
    ("paper-reachable-crlb", ["--K", "6", "--criterion", "crlb"] + _REACH),
    ("paper-reachable-D", ["--K", "6", "--criterion", "D"] + _REACH),
    ("paper-reachable-checked", ["--K", "6"] + _REACH),
    ("delta-crlb", _DELTA + ["--K", "12", "--criterion", "crlb"]),
    ("linear_delta-crlb", _LINEAR + ["--K", "12", "--criterion", "crlb"]),
]

#: keys whose values measure the machine, not the computation
TIMING_KEYS = ("time_s", "build_s", "timing_s")
#: the time on the method line of the text (``; total 5.55 s)``)
_TOTAL = re.compile(r"; total [0-9.]+ s\)")


def run_case(case) -> dict:
    """``{"text": ..., "report": ...}`` of one case, without the machine's timings."""
    from zerocal_sym.cli import main

    cid, argv = case
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "design.json"
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            rc = main(["design", "--optimize"] + list(argv) + ["--out", str(out)])
        if rc not in (0, None):
            raise RuntimeError(f"{cid}: zerocal design exited with {rc}")
        report = json.loads(out.read_text())
    return {"text": _TOTAL.sub("; total - s)", buf.getvalue()), "report": strip(report)}


def strip(rep) -> dict:
    """``rep`` (JSON round trip) without the times."""
    return without_times(rep, TIMING_KEYS)


def main():
    write_reference(REFERENCE, CASES, run_case)


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
