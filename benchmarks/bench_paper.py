"""One TSVD identification and one full `zerocal reproduce`, against baselines of the same run.

* identification: ``identify_tsvd`` on one simulated round of the paper's six
  poses (FK of the nominal poses, G, SVD, exact-model residuals) against a
  plain ``numpy.linalg.lstsq`` on the same G and right-hand side, and the bare
  ``tsvd_solve`` against the same lstsq;
* reproduce: the six groups of Table 2 through 20 identifications each, in
  process (``paper.reproduce``) and as the command ``zerocal reproduce``
  (subprocess, includes interpreter start and imports) against ``python -c pass``.

Target: ``zerocal reproduce`` finishes well under a minute.
Usage: python benchmarks/bench_paper.py [--repeat N]
"""
import argparse
import statistics
import sys
import time

import numpy as np
from _harness import wall


def per_call(fn, n):
    fn()
    t = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t) / n




def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()

    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.paper.reproduction import reproduce
    from zerocal_sym.paper.tables import group_errors
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.identify.truncated_svd import tsvd_solve
    from zerocal_sym.identify.tsvd import identify_tsvd

    robot = paper_robot()
    P = paper_poses(robot, 3)
    meas = simulate_round(robot, VirtualPlant(robot, group_errors(1)), P, noise=NoiseModel.paper(), rng=0)
    G, lam = identification_matrix(robot, kin.fk(robot, meas.theta_cmd))
    b = meas.readings[1:] - np.diff(lam)
    n = 2000
    t_lstsq = per_call(lambda: np.linalg.lstsq(G, b, rcond=None), n)
    t_solve = per_call(lambda: tsvd_solve(G, b), n)
    t_ident = per_call(lambda: identify_tsvd(robot, meas), n // 4)
    t_ident_cov = per_call(lambda: identify_tsvd(robot, meas, noise=NoiseModel.paper()), n // 4)
    print(f"{'one identification (K = 6)':46s} {'time [us]':>10s} {'x lstsq':>8s}")
    for name, t in (("numpy.linalg.lstsq on G (baseline)", t_lstsq), ("tsvd_solve (SVD, rule, filter factors)", t_solve),
                    ("identify_tsvd (FK, G, SVD, exact residuals)", t_ident),
                    ("identify_tsvd with noise model (covariance)", t_ident_cov)):
        print(f"{name:46s} {t * 1e6:10.1f} {t / t_lstsq:8.1f}")

    times = []
    for _ in range(a.repeat):
        t = time.perf_counter()
        rep = reproduce(robot)
        times.append(time.perf_counter() - t)
    t_rep = statistics.median(times)
    n_id = sum(len(g["history"]["kappa"]) for g in rep["groups"])
    print(f"\nreproduce in process: {t_rep:.3f} s median of {a.repeat} ({n_id} identifications, "
          f"{t_rep / n_id * 1e3:.2f} ms each = {t_rep / n_id / t_ident:.2f} x identify_tsvd)")
    base = wall([sys.executable, "-c", "pass"], a.repeat)[0]
    cli = wall([sys.executable, "-m", "zerocal_sym", "reproduce"], a.repeat)[0]
    print(f"`zerocal reproduce` (subprocess): {cli:.3f} s median; python -c pass: {base:.3f} s; "
          f"ratio {cli / base:.1f}")
    print(f"target: zerocal reproduce well under a minute: {'met' if cli < 60 else 'NOT met'} ({cli:.2f} s)")


if __name__ == "__main__":
    main()
