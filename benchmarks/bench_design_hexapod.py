"""The design NLP on the hexapod (examples/hexapod.toml): why its Hessian is a limited-memory one, and what an
Ipopt polish of the K = 64 approximate design buys.

Parts (``--parts``, default all):

* ``form``: the NLP for K = 16 (crlb, the robot's noise) from the 16-corner fraction, built with the exact
  Hessian of the Lagrangian and with the limited-memory (L-BFGS) one (``zerocal_sym.design.nlp.nlp_form``):
  build and solve times, Ipopt's status, the CRLB reached;
* ``polish``: ``optimize_design(robot, 64, "crlb")`` (the approximate design, its certificate), then Ipopt
  (the large form) from its poses: build and solve times, the CRLB before and after and the efficiency
  bound of each against the certificate's bound.

One run each (a build takes minutes: nothing to interleave but the two forms, which run one after the other),
CPU time (this process) beside wall time, the load average printed (benchmarks/_harness.py).

Usage: python benchmarks/bench_design_hexapod.py [--parts form polish] [--json]
"""
import argparse
import time
from pathlib import Path

from _harness import emit, load, load_line

ROOT = Path(__file__).resolve().parents[1]


RESULTS = []


class Clock:
    """Wall and CPU seconds of a block: ``with Clock() as c: ...; c.wall, c.cpu``."""

    def __enter__(self):
        self.w, self.c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall, self.cpu = time.perf_counter() - self.w, time.process_time() - self.c


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
        with Clock() as b:
            nlp = _NLP(robot, K, "crlb", cons, robot.noise, fs, ms, 300, form=f)
        with Clock() as sv:
            P, status, iters = nlp.solve(P0)
        row = {"part": "form", "form": f, "build_wall_s": b.wall, "build_cpu_s": b.cpu, "solve_wall_s": sv.wall,
               "solve_cpu_s": sv.cpu, "status": status, "iterations": iters, "crlb_mm": crlb_of(robot, P),
               "violations": len(design.check_design(robot, P, cons))}
        RESULTS.append(row)
        print(f"  {f:5s} Hessian: build {b.cpu:7.1f} s CPU ({b.wall:.1f} wall), solve {sv.cpu:6.1f} s CPU "
              f"({sv.wall:.1f} wall) ({status}, {iters} iterations), CRLB {row['crlb_mm']:.5g} mm, violations "
              f"{row['violations']}", flush=True)


def polish(robot):
    from zerocal_sym import design
    from zerocal_sym.design.nlp import _NLP, _scales

    K = 64
    cons = design.make_constraints(robot)
    with Clock() as d:
        res = design.optimize_design(robot, K, "crlb", cons, robot.noise)
    t_design = d.cpu
    cert = res.certificate
    v0 = res.report["crlb_rms_mm"]
    print(f"K = {K}, crlb: the approximate design in {t_design:.1f} s CPU ({d.wall:.1f} wall), CRLB {v0:.5g} mm (corner scheme "
          f"{res.paper['crlb_rms_mm']:.5g}), bound {cert['bound']:.5g}, efficiency >= "
          f"{cert['efficiency_lower_bound']:.4f}", flush=True)
    fs, ms = _scales(robot, res.poses, robot.noise)
    with Clock() as b:
        nlp = _NLP(robot, K, "crlb", cons, robot.noise, fs, ms, 300)
    with Clock() as sv:
        P, status, iters = nlp.solve(res.poses)
    build, solve = b.cpu, sv.cpu
    v = crlb_of(robot, P)
    RESULTS.append({"part": "polish", "design_cpu_s": d.cpu, "design_wall_s": d.wall, "crlb_before_mm": v0,
                    "build_cpu_s": b.cpu, "build_wall_s": b.wall, "solve_cpu_s": sv.cpu, "solve_wall_s": sv.wall,
                    "status": status, "iterations": iters, "crlb_after_mm": v, "bound_mm": cert["bound"]})
    print(f"  Ipopt polish ({nlp.form} form): build {build:.1f} s CPU, solve {solve:.1f} s CPU ({status}, {iters} "
          f"iterations), CRLB {v:.5g} mm, efficiency >= {(cert['bound'] / v) ** 2:.4f}, violations "
          f"{len(design.check_design(robot, P, cons))}")


def main():
    from zerocal_sym.model.robot import load_robot

    ap = argparse.ArgumentParser()
    ap.add_argument("--parts", nargs="+", choices=["form", "polish"], default=["form", "polish"])
    ap.add_argument("--json", action="store_true", help="print the figures as JSON (instead of the lines)")
    args = ap.parse_args()
    load0 = load()
    robot = load_robot(ROOT / "examples" / "hexapod.toml")
    import contextlib
    import io

    with contextlib.redirect_stdout(io.StringIO()) if args.json else contextlib.nullcontext():
        for part in args.parts:
            {"form": form, "polish": polish}[part](robot)
    if emit({"load_before": load0, "load_after": load(), "rows": RESULTS}, args.json):
        return
    print(load_line(load0))


if __name__ == "__main__":
    main()
