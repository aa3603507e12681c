"""What the committed reference sets share (tests/compare_cases.py, design_cases.py, confirmation_cases.py,
reference_cases.py): the library versions that wrote a file, a report without its times, and writing the
file case by case.

A reference is compared bit for bit only on the versions that wrote it (other builds may change the last
bits); its writer records them with :func:`versions`.
"""
from __future__ import annotations

import json
import platform
import time
from pathlib import Path


def versions() -> dict:
    """The versions of the libraries and the interpreter that compute a reference, and the machine."""
    import casadi
    import numpy
    import scipy

    return {"numpy": numpy.__version__, "casadi": casadi.__version__, "scipy": scipy.__version__,
            "python": platform.python_version(), "machine": platform.machine()}


def without_times(rep, timing_keys, drop=()) -> dict:
    """``rep`` after a JSON round trip, without the keys ``timing_keys`` at any depth and the top-level keys
    ``drop``."""
    rep = json.loads(json.dumps(rep, default=float))
    for k in drop:
        rep.pop(k, None)

    def strip(x):
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items() if k not in timing_keys}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return x

    return strip(rep)


def write_reference(path: Path, cases, run_case, with_versions: bool = True, note=None) -> None:
    """Run every case (``cases``: tuples whose first item is the case id) and write ``{"versions": ...,
    "cases": {id: run_case(case)}}`` (or the bare ``{id: ...}`` without versions) to ``path``, printing each
    case's time (and ``note(result)`` when given)."""
    out = {}
    for case in cases:
        t = time.perf_counter()
        out[case[0]] = run_case(case)
        extra = f"  {note(out[case[0]])}" if note else ""
        print(f"{case[0]}: {time.perf_counter() - t:.2f} s{extra}", flush=True)
    ref = {"versions": versions(), "cases": out} if with_versions else out
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(ref, sort_keys=True, separators=(",", ":")) + "\n")
    print(f"wrote {path}")
