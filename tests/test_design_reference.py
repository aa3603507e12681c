"""`zerocal design --optimize` prints and writes the same designs, bit for bit, as before its time was cut
(tests/design_cases.py wrote the reference with the code before): the poses, every criterion, the CRLB,
the certificate and its text, the detection block, the Ipopt starts and the exchange."""
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import design_cases as dc  # noqa: E402

REFERENCE = json.loads(dc.REFERENCE.read_text())
SAME_VERSIONS = REFERENCE["versions"] == dc.versions()

#: the cases of a few seconds each run by default; the others are slow-marked
QUICK = ("paper-crlb", "paper-D", "paper-checked")


def _ids():
    return [c[0] if c[0] in QUICK else pytest.param(c[0], marks=pytest.mark.slow) for c in dc.CASES]


@pytest.mark.parametrize("cid", _ids())
def test_design_reports_the_reference_bit_for_bit(cid):
    """The printed report (without its time) and every number of the JSON report (without the times) equal to
    the reference's, on the library versions that wrote it."""
    if not SAME_VERSIONS:
        pytest.skip(f"the reference was written with {REFERENCE['versions']}, this is {dc.versions()}")
    got = dc.run_case(next(c for c in dc.CASES if c[0] == cid))
    ref = REFERENCE["cases"][cid]
    assert got["text"] == ref["text"]
    assert got["report"] == ref["report"]
