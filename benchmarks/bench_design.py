"""Design time of `zerocal design --optimize` (issue 5) for K = 6 and K = 20.

For each K and criterion, times the full design (discrete exchange + Ipopt
multi-start + order search + polish, :func:`zerocal_sym.design.optimize_design`)
and, as baselines measured in the same run, one Ipopt start (NLP build + one
solve from the paper's scheme) and the discrete exchange alone; prints the
ratios, the stage breakdown and what the design achieved.

Usage: python benchmarks/bench_design.py [--repeat N] [--K 6 20] [--criteria crlb cond] [--starts 8]
"""
import argparse
import statistics
import time



from zerocal_sym import design
from zerocal_sym.design import nlp as design_nlp
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.model.robot import paper_robot


def timed(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--K", type=int, nargs="+", default=[6, 20])
    ap.add_argument("--criteria", nargs="+", default=["crlb", "cond"])
    ap.add_argument("--starts", type=int, default=8)
    a = ap.parse_args()
    robot = paper_robot()
    noise = NoiseModel.paper()
    cons = design.make_constraints(robot)
    design.pose_terms(robot, robot.workspace_grid(3, 3))  # warm the CasADi function cache
    print(f"paper robot, workspace, paper noise, {a.starts} random Ipopt starts + {a.starts} exchange starts, "
          f"median of {a.repeat}")
    hdr = (f"{'K':>3} {'crit':>5} {'design [s]':>10} {'1 Ipopt [s]':>11} {'x 1 Ipopt':>9} {'exchange [s]':>12} "
           f"{'x exch.':>8} | {'exch/cont/ord+pol [s]':>22} | {'value':>9} {'paper':>9} {'CRLB ratio':>10}")
    print(hdr)
    for K in a.K:
        base = design.paper_baseline(robot, K)
        for crit in a.criteria:
            def one_ipopt():
                fs, ms = design_nlp._scales(robot, base, noise)
                nlp = design_nlp._NLP(robot, K, crit, cons, noise, fs, ms)
                return nlp.solve(base)

            t1, _ = timed(one_ipopt, a.repeat)
            tx, _ = timed(lambda: design.exchange_design(robot, K, crit, cons, noise, 0, a.starts), a.repeat)
            td, res = timed(lambda: design.optimize_design(robot, K, crit, cons, noise, seed=0, n_starts=a.starts,
                                                           exchange_starts=a.starts), a.repeat)
            d = res.to_dict()
            tm = res.timing
            stages = f"{tm['exchange']:.2f}/{tm['continuous']:.2f}/{tm['order_polish']:.2f}"
            print(f"{K:3d} {crit:>5} {td:10.2f} {t1:11.3f} {td / t1:9.1f} {tx:12.2f} {td / tx:8.1f} | {stages:>22} | "
                  f"{d['criterion']['value']:9.4g} {d['paper']['criterion']['value']:9.4g} "
                  f"{d['ratio']['crlb_rms_design_over_paper']:10.4f}")
    print("columns: design = full optimize_design; 1 Ipopt = NLP build + one solve from the paper's scheme; "
          "exchange = the discrete exchange alone; value/paper = the criterion of the design and of the "
          "paper's scheme; CRLB ratio = RMS zero-offset CRLB design / paper")


if __name__ == "__main__":
    main()
