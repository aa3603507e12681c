"""The design NLP on the hexapod (examples/hexapod.toml): why its Hessian is a limited-memory one, and what an
Ipopt polish of the K = 64 approximate design buys.

Parts (``--parts``, default all):

* ``form``: the NLP for K = 16 (crlb, the robot's noise) from the 16-corner fraction, built with the exact
  Hessian of the Lagrangian and with the limited-memory (L-BFGS) one (``zerocal_sym.design.nlp.nlp_form``):
  build and solve times, Ipopt's status, the CRLB reached;
* ``polish``: ``optimize_design(robot, 64, "crlb")`` (the approximate design, its certificate), then Ipopt
  (the large form) from its poses: build and solve times, the CRLB before and after and the efficiency
  bound of each against the certificate's bound.

One run each, wall times on whatever machine runs it (the numbers in docs/design.md came from a shared 2-core
machine).

Usage: python benchmarks/bench_design_hexapod.py [--parts form polish]
"""
import argparse
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def crlb_of(robot, P):
    from zerocal_sym.design import criterion_values

    return criterion_values(robot, P, robot.noise)["crlb"]


def form(robot):
    from zerocal_sym import design
    from zerocal_sym.design.nlp import _NLP, _scales

    K = 16
    cons = design.make_constraints(robot)
    P0 = design.paper_baseline(robot, K)
    fs, ms = _scales(robot, P0, robot.noise)
    print(f"K = {K}, crlb, from the 16-corner fraction (CRLB {crlb_of(robot, P0):.5g} mm)")
    for f in ("exact", "large"):
        t0 = time.perf_counter()
        nlp = _NLP(robot, K, "crlb", cons, robot.noise, fs, ms, 300, form=f)
        build = time.perf_counter() - t0
        t0 = time.perf_counter()
        P, status, iters = nlp.solve(P0)
        solve = time.perf_counter() - t0
        print(f"  {f:5s} Hessian: build {build:7.1f} s, solve {solve:6.1f} s ({status}, {iters} iterations), "
              f"CRLB {crlb_of(robot, P):.5g} mm, violations {len(design.check_design(robot, P, cons))}", flush=True)


def polish(robot):
    from zerocal_sym import design
    from zerocal_sym.design.nlp import _NLP, _scales

    K = 64
    cons = design.make_constraints(robot)
    t0 = time.perf_counter()
    res = design.optimize_design(robot, K, "crlb", cons, robot.noise)
    t_design = time.perf_counter() - t0
    cert = res.certificate
    v0 = res.report["crlb_rms_mm"]
    print(f"K = {K}, crlb: the approximate design in {t_design:.1f} s, CRLB {v0:.5g} mm (corner scheme "
          f"{res.paper['crlb_rms_mm']:.5g}), bound {cert['bound']:.5g}, efficiency >= "
          f"{cert['efficiency_lower_bound']:.4f}", flush=True)
    fs, ms = _scales(robot, res.poses, robot.noise)
    t0 = time.perf_counter()
    nlp = _NLP(robot, K, "crlb", cons, robot.noise, fs, ms, 300)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    P, status, iters = nlp.solve(res.poses)
    solve = time.perf_counter() - t0
    v = crlb_of(robot, P)
    print(f"  Ipopt polish ({nlp.form} form): build {build:.1f} s, solve {solve:.1f} s ({status}, {iters} "
          f"iterations), CRLB {v:.5g} mm, efficiency >= {(cert['bound'] / v) ** 2:.4f}, violations "
          f"{len(design.check_design(robot, P, cons))}")


def main():
    from zerocal_sym.model.robot import load_robot

    ap = argparse.ArgumentParser()
    ap.add_argument("--parts", nargs="+", choices=["form", "polish"], default=["form", "polish"])
    args = ap.parse_args()
    robot = load_robot(ROOT / "examples" / "hexapod.toml")
    for part in args.parts:
        {"form": form, "polish": polish}[part](robot)


if __name__ == "__main__":
    main()
