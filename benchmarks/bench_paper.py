"""One TSVD identification and one full `zerocal reproduce`, against baselines of the same run.

* identification: ``identify_tsvd`` on one simulated round of the paper's six
  poses (FK of the nominal poses, G, SVD, exact-model residuals) against a
  plain ``numpy.linalg.lstsq`` on the same G and right-hand side, and the bare
  ``tsvd_solve`` against the same lstsq;
* reproduce: the six groups of Table 2 through 20 identifications each, in
  process (``paper.reproduce``) and as the command ``zerocal reproduce``
  (subprocess, includes interpreter start and imports) against ``python -c pass``.

The columns of each comparison are timed interleaved (benchmarks/_harness.py), CPU time (this process's,
or the child's for a command) beside wall time, the ratios from the CPU times of the same pass; the load
average printed.

Target: ``zerocal reproduce`` finishes well under a minute.
Usage: python benchmarks/bench_paper.py [--repeat N] [--json]
"""
import argparse
import sys

import numpy as np
from _harness import commands, emit, interleaved, load, load_line, median, ratio, summary


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", "--passes", dest="passes", type=int, default=5)
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    a = ap.parse_args()

    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.noise import VirtualPlant
    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.paper.reproduction import reproduce
    from zerocal_sym.paper.tables import group_errors
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.identify.estimate.truncated_svd import tsvd_solve
    from zerocal_sym.identify.tsvd import identify_tsvd

    load0 = load()
    robot = paper_robot()
    P = paper_poses(robot, 3)
    meas = simulate_round(robot, VirtualPlant(robot, group_errors(1)), P, noise=NoiseModel.paper(), rng=0)
    G, lam = identification_matrix(robot, kin.fk(robot, meas.theta_cmd))
    b = meas.readings[1:] - np.diff(lam)
    n = 500

    def loop(fn, k):
        def col():
            for _ in range(k):
                fn()
            return k
        return col

    cols = {"numpy.linalg.lstsq on G (baseline)": loop(lambda: np.linalg.lstsq(G, b, rcond=None), n),
            "tsvd_solve (SVD, rule, filter factors)": loop(lambda: tsvd_solve(G, b), n),
            "identify_tsvd (FK, G, SVD, exact residuals)": loop(lambda: identify_tsvd(robot, meas), n // 4),
            "identify_tsvd with noise model (covariance)": loop(lambda: identify_tsvd(robot, meas,
                                                                                      noise=NoiseModel.paper()), n // 4)}
    t = interleaved(cols, a.passes)
    base = "numpy.linalg.lstsq on G (baseline)"
    rep = {}

    def rep_col():
        rep["r"] = reproduce(robot)
        return 1

    tr = interleaved({"reproduce": rep_col}, a.passes)
    n_id = sum(len(g["history"]["kappa"]) for g in rep["r"]["groups"])
    tc = commands({"zerocal reproduce": [sys.executable, "-m", "zerocal_sym", "reproduce"],
                   "python -c pass": [sys.executable, "-c", "pass"]}, a.passes)
    cli = median(tc, "zerocal reproduce", "wall")
    res = {"load_before": load0, "passes": a.passes, "identification_us": {k: {kk: 1e3 * v for kk, v in d.items()
                                                                              if kk.endswith("_ms")}
                                                                          for k, d in summary(t).items()},
           "x_lstsq_cpu": {k: ratio(t, k, base) for k in cols},
           "reproduce_in_process": {**summary(tr, "s")["reproduce"], "identifications": n_id,
                                    "cpu_per_identification_ms": 1e3 * median(tr, "reproduce") / n_id},
           "reproduce_command": summary(tc, "s"), "target": {"reproduce wall s": 60, "met": cli < 60},
           "load_after": load()}
    if emit(res, a.json):
        return
    print(f"{'one identification (K = 6)':46s} {'CPU [us]':>9s} {'wall [us]':>10s} {'x lstsq CPU':>12s}   "
          f"(medians, {a.passes} interleaved passes)")
    for k in cols:
        d = res["identification_us"][k]
        print(f"{k:46s} {d['cpu_ms']:9.1f} {d['wall_ms']:10.1f} {res['x_lstsq_cpu'][k]:12.1f}")
    r = res["reproduce_in_process"]
    print(f"\nreproduce in process: {r['cpu_s']:.3f} s CPU ({r['wall_s']:.3f} s wall), {n_id} identifications, "
          f"{r['cpu_per_identification_ms']:.2f} ms CPU each")
    c = res["reproduce_command"]
    print(f"`zerocal reproduce` (subprocess): {c['zerocal reproduce']['wall_s']:.3f} s wall, "
          f"{c['zerocal reproduce']['cpu_s']:.3f} s CPU; python -c pass: {c['python -c pass']['wall_s']:.3f} s wall")
    print(f"target: zerocal reproduce well under a minute: {'met' if cli < 60 else 'NOT met'} ({cli:.2f} s)")
    print(load_line(load0, res["load_after"]))


if __name__ == "__main__":
    main()
