"""Design time of `zerocal design --optimize` for K = 6 and K = 20, and the extra cases (regions, approximate designs).

For each K and criterion, times the full design (discrete exchange + Ipopt
multi-start + order search + polish, :func:`zerocal_sym.design.optimize_design`)
and, as baselines measured in the same run, one Ipopt start (NLP build + one
solve from the paper's scheme) and the discrete exchange alone; prints the
ratios, the stage breakdown and what the design achieved.

The extra cases (printed after the table; ``--only-extras`` skips the table): the K = 6 crlb design over
the reachable set of the paper's robot with y >= 450 mm, the 350 mm travel limit and the default margin (its
CRLB, the certified bound, the baseline); K = 100 designs (the approximate method: the exact one took
1207 s at K = 100 before the approximate design existed) on the paper's robot and the Delta;
``zerocal design --target-crlb 0.04`` in the paper's workspace (the fewest K and its certified lower bound);
each with its wall time.

Usage: python benchmarks/bench_design.py [--repeat N] [--K 6 20] [--criteria crlb cond] [--starts 8]
                                         [--only-extras] [--no-extras]
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
    ap.add_argument("--only-extras", action="store_true",
                    help="only the extra cases (reachable set, approximate designs, fewest poses)")
    ap.add_argument("--no-extras", action="store_true",
                    help="skip the extra cases")
    a = ap.parse_args()
    if not a.only_extras:
        table(a)
    if not a.no_extras:
        extras()


def extras():
    from zerocal_sym.design import approx
    from zerocal_sym.model.robot import load_robot
    from pathlib import Path

    robot, noise = paper_robot(), NoiseModel.paper()
    print()
    print("extras (paper noise, default margin, l0 = 350 mm range, seed 0, 8 + 8 starts on the exact path)")
    t = time.perf_counter()
    cons = design.make_constraints(robot, region="reachable", bounds=(-float("inf"), float("inf"), 450,
                                                                       float("inf")))
    t_region = time.perf_counter() - t
    t = time.perf_counter()
    res = design.optimize_design(robot, 6, "crlb", cons, noise, seed=0)
    d = res.to_dict()
    print(f"reachable set, y >= 450 mm, K = 6, crlb: CRLB {d['crlb_rms_deg']:.5f} deg per offset "
          f"{[round(v, 5) for v in d['crlb_zero_offsets_deg']]}; certified bound {d['certificate']['bound']:.5f} deg "
          f"(efficiency >= {d['certificate']['efficiency_lower_bound']:.3f}); baseline {d['baseline_scheme']} "
          f"{d['paper']['crlb_rms_deg']:.4f} deg; bias worst/RMS {max(d['bias']['worst_case_deg']):.4f}/"
          f"{max(d['bias']['rms_deg']):.4f} deg; rho span {d['rho_span_mm']:.1f} mm; region {t_region:.2f} s, "
          f"design {time.perf_counter() - t:.2f} s ({d['method']})")
    print("    poses (mm): " + "; ".join(f"({x:.1f}, {y:.1f})" for x, y in res.poses))
    for label, rob in (("paper", robot), ("delta", load_robot(Path(__file__).resolve().parents[1] / "examples"
                                                                  / "delta.toml"))):
        for crit in ("crlb", "D"):
            t = time.perf_counter()
            res = design.optimize_design(rob, 100, crit, None, noise, seed=0)
            td = time.perf_counter() - t
            d = res.to_dict()
            c = d["certificate"]
            print(f"K = 100, {label}, {crit}: {td:.2f} s ({d['method']}); {crit} {d['criterion']['value']:.5g}, "
                  f"bound {c['bound']:.5g}, efficiency >= {c['efficiency_lower_bound']:.3f}; CRLB "
                  f"{d['crlb_rms_deg']:.5f} deg vs {d['baseline_scheme']} {d['paper']['crlb_rms_deg']:.4f}")
    t = time.perf_counter()
    out = approx.fewest_poses(robot, 0.04, design.make_constraints(robot), noise)
    print(f"--target-crlb 0.04 (paper workspace): K = {out['K']} (CRLB {out['crlb_rms_deg']:.5f} deg), certified "
          f"lower bound {out['K_lower_bound']}; {time.perf_counter() - t:.2f} s")
    t = time.perf_counter()
    out = approx.fewest_poses(robot, 0.04, design.make_constraints(robot, min_separation_mm=0.1), noise)
    print(f"--target-crlb 0.04 --min-separation 0.1: K = {out['K']} (CRLB {out['crlb_rms_deg']:.5f} deg), "
          f"lower bound {out['K_lower_bound']}; {time.perf_counter() - t:.2f} s")


def table(a):
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
