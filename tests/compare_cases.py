"""A reference set of seeded `compare` runs, every mechanism, and what of each report is compared
(tests/test_compare_reference.py).

``python tests/compare_cases.py`` writes ``tests/data/reference_compare.json``: each case's report as the
code at that commit computes it, without what measures the machine (times, the execution record), and the
versions of the libraries that computed it.  It was written before the Ipopt loops of ``compare`` ran in
lockstep through the mapped Gauss-Newton and before the confirmation of a converged Gauss-Newton point
was taken from Ipopt's own first-order test: the test recomputes every case and asks for the same numbers,
bit for bit, on the library versions that wrote the file.
"""
from __future__ import annotations

import sys
from pathlib import Path

from reference_files import versions, without_times, write_reference  # noqa: F401 (versions: the tests')

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).resolve().parent / "data" / "reference_compare.json"

#: (case id, robot, keyword arguments of the compare); ``set`` robots get true errors by name (file units)
CASES = [
    ("paper-g1-g4", "paper", dict(groups=(1, 4), trials=6, seed=3)),
    ("paper-g2-scale-only-params", "paper", dict(groups=(2,), trials=4, seed=1, noise="scale-only",
                                                  params="paper+L1,L2", chunk=3, n=5)),
    ("paper-g5-noise-free-loop", "paper", dict(groups=(5,), trials=3, seed=2, noise="none", mu0_deg=0.05,
                                               max_iter=6)),
    ("delta", "delta", dict(trials=3, seed=4, set={"theta1": 0.8, "theta2": -0.5, "theta3": 0.3, "rMx": 0.4})),
    ("linear_delta", "linear_delta", dict(trials=3, seed=5, set={"s1": 0.4, "s2": -0.3, "s3": 0.2, "rMy": 0.3})),
    ("hexapod", "hexapod", dict(trials=1, seed=6, max_iter=2, methods=("nlls", "nlls-loop", "nlls-seq"),
                                set={"L1": 0.2, "L2": -0.1, "L4": 0.15, "rMz": 0.3})),
]

#: keys whose values measure the machine, not the computation
TIMING_KEYS = ("time_per_identification_ms", "time_scipy_ms", "time_ipopt_ms", "time_ratio_ipopt_over_scipy")


def robot_of(which):
    from zerocal_sym.model.robot import load_robot, paper_robot

    return paper_robot() if which == "paper" else load_robot(ROOT / "examples" / f"{which}.toml")


def run_case(case) -> dict:
    """The report of one case, without the machine's timings."""
    from zerocal_sym.cli._common import scheme_poses
    from zerocal_sym.identify import montecarlo
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.paper.compare import compare

    cid, which, kw = case
    robot = robot_of(which)
    kw = dict(kw)
    if "noise" in kw:
        kw["noise"] = NoiseModel.named(kw["noise"], robot)
    if which == "paper":
        if "n" in kw:
            from zerocal_sym.paper.scheme import paper_poses

            kw["poses"] = paper_poses(robot, kw.pop("n"))
        rep = compare(robot, **kw)
    else:
        truth = robot.errors.from_user(kw.pop("set"))
        poses, _ = scheme_poses(robot)
        rep = montecarlo.compare(robot, {"set": truth}, poses, **kw)
    return strip(rep)


def strip(rep) -> dict:
    """``rep`` (JSON round trip) without the execution record and the times."""
    return without_times(rep, TIMING_KEYS, drop=("execution",))


def main():
    write_reference(REFERENCE, CASES, run_case)


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
