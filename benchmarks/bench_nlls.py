"""Time per identification against scipy's least_squares on the same problems, same run.

Problems: simulated measurement rounds (Table 2 group 1 read literally, the
paper's noise) of the paper's robot at
  K = 6  -- the paper's six poses (n = 3), 4 parameters;
  K = 42 -- the 42 boundary positions of the paper's Fig. 11, 4 parameters.
Timed per identification, the columns interleaved (each pass runs every column once over the rounds, in
an order that rotates from pass to pass), CPU time (this process) beside wall time:

  identify       identify_nlls as shipped in a loop of identifications: Gauss-Newton
                 in one CasADi call, Ipopt confirms, covariance, rank, the fit
                 check (the whole function), on the compiled tier (a loop makes
                 the problem hot: zerocal_sym.model.compiled; built before timing)
  identify-int   the same on the interpreted Functions (CasADi's virtual machine)
  scipy-lm       scipy.optimize.least_squares(method="lm") on the same whitened,
                 scaled residuals and Jacobian, ordinary callbacks (numpy in,
                 CasADi Function __call__, numpy out), solver call alone
  scipy-zc       the same with zero-copy callbacks (CasADi buffers)
  scipy-zc-c     zero-copy callbacks of the compiled Functions (like with like
                 for the compiled tier; an extra column)
  batch          identify_batch over all rounds at once (per identification)

and the ratios (scipy's CPU time over ours in the same pass, median over the passes; > 1: ours is faster):

  x lm           scipy-lm / identify       (the "speedup" asked for)
  x zc           scipy-zc / identify
  int x lm       scipy-lm / identify-int
  x zc-c         scipy-zc-c / identify

and the batched path at scale: N = 10,000 identifications at K = 6 in one
process (one core), the compiled and interpreted tiers interleaved.  The answers
are compared too (max |ours - scipy| over the offsets, deg).

Targets: K = 6 x lm >= 4 and x zc >= 1.2; K = 42 x lm >= 5 and x zc >= 1.2; the same problem's answers
within 1e-6 deg of scipy's.  The load average is printed with the figures.

With ZEROCAL_COMPILE=never (or no C compiler) the compiled columns are the
interpreted ones and the header says so.

Usage: python benchmarks/bench_nlls.py [--rounds N] [--repeat R] [--batch N] [--json]

--json prints {"load_before", "load_after", "rows": one entry per K (K, the CPU medians identify_ms,
scipy_lm_ms, ..., their wall twins *_wall_ms, the ratios speedup, speedup_zero_copy, ... and their
per-pass spread, targets and whether they are met), "batch_at_scale"}.
"""
import argparse
import os
import time

import numpy as np
from _harness import emit, interleaved, load, load_line, median, ratio, spread, summary


def positive_int(text):
    """argparse type: an integer >= 1."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {v}")
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=positive_int, default=50, help="simulated rounds per K (default 50)")
    ap.add_argument("--repeat", type=positive_int, default=15,
                    help="interleaved timing passes, medians reported (default 15)")
    ap.add_argument("--batch", type=positive_int, default=10000,
                    help="identifications of the batch-at-scale run (default 10000)")
    ap.add_argument("--batch-passes", type=positive_int, default=3,
                    help="interleaved passes of the batch-at-scale run (default 3)")
    ap.add_argument("--json", action="store_true", help="print JSON instead of text")
    args = ap.parse_args()

    from scipy.optimize import least_squares

    from zerocal_sym.identify.estimate import nlls_problem
    from zerocal_sym.identify.batch import identify_batch
    from zerocal_sym.model import compiled
    from zerocal_sym.identify.nlls import identify_nlls, residual_problem
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.paper.tables import table2_errors
    from zerocal_sym.report.plots import boundary_positions

    load0 = load()
    robot = paper_robot()
    noise = NoiseModel.paper()
    mode0 = compiled.mode()
    plant = VirtualPlant(robot, table2_errors(1))
    rows = []
    for K, poses in ((6, paper_poses(robot, 3)), (42, boundary_positions(robot, 42))):
        th = kin.ik(robot, poses)
        rng = np.random.default_rng(K)
        data = [Measurements(th, plant.measure(th, noise, rng)) for _ in range(args.rounds)]
        R = np.array([m.readings for m in data])
        res = {}
        key = (robot.mechanism_name, K, tuple(robot.errors.indices("paper")))
        nlls_problem._CACHE.pop(key, None)
        os.environ["ZEROCAL_COMPILE"] = "never"
        tiers = {"interpreted": nlls_problem.get_problem(robot, K, "paper")}
        os.environ["ZEROCAL_COMPILE"] = mode0
        hot = nlls_problem.NllsProblem(robot.mechanism, K, key[2])
        t0 = time.perf_counter()
        hot.hot(wait=True)
        build_s = time.perf_counter() - t0
        tiers["compiled"] = hot

        def use(tier):  # the problem of that tier; "never" keeps the interpreted one from turning hot
            os.environ["ZEROCAL_COMPILE"] = "never" if tier == "interpreted" else mode0
            nlls_problem._CACHE[key] = tiers[tier]

        def run_identify(tier="compiled"):
            use(tier)
            res["ours" if tier == "compiled" else "ours-int"] = [
                identify_nlls(robot, m, "paper", noise=noise) for m in data]
            return len(data)

        def run_batch():
            use("compiled")
            res["batch"] = identify_batch(robot, th, R, "paper", noise=noise)
            return len(data)

        def scipy_runner(zero_copy, tier="interpreted"):
            use(tier)
            probs = []
            for m in data:
                fun, jac, sc = residual_problem(robot, m, "paper", noise, callbacks="fast" if zero_copy else "plain")
                probs.append((fun, jac, sc))

            def f():
                res[("zc" if zero_copy else "lm") + ("-c" if tier == "compiled" else "")] = [
                    least_squares(fun, np.zeros(4), jac=jac, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14).x / sc
                    for fun, jac, sc in probs]
                return len(data)
            return f

        cols = {"identify": run_identify, "identify-int": lambda: run_identify("interpreted"),
                "scipy-lm": scipy_runner(False), "scipy-zc": scipy_runner(True),
                "scipy-zc-c": scipy_runner(True, "compiled"), "batch": run_batch}
        t = interleaved(cols, args.repeat)
        use("compiled")
        ours = np.array([r.estimate for r in res["ours"]])
        same = np.array([identify_nlls(robot, m, "paper", noise=noise, reweight=0).estimate for m in data])
        row = {
            "K": K,
            "compiled": bool(hot.compiled),
            "compile_s": build_s,
            "passes": args.repeat,
            "rounds": args.rounds,
            "columns": summary(t),
        }
        for col, key in (("identify", "identify_ms"), ("identify-int", "identify_interpreted_ms"),
                         ("scipy-lm", "scipy_lm_ms"), ("scipy-zc", "scipy_lm_zero_copy_ms"),
                         ("scipy-zc-c", "scipy_lm_zero_copy_compiled_ms"), ("batch", "batch_ms")):
            row[key] = 1e3 * median(t, col)
            row[key.replace("_ms", "_wall_ms")] = 1e3 * median(t, col, "wall")
        for key, num, den in (("speedup", "scipy-lm", "identify"), ("speedup_zero_copy", "scipy-zc", "identify"),
                              ("speedup_interpreted", "scipy-lm", "identify-int"),
                              ("speedup_zero_copy_compiled", "scipy-zc-c", "identify")):
            row[key] = ratio(t, num, den)
            row[key + "_spread"] = spread(t, num, den)
            row[key + "_wall"] = ratio(t, num, den, "wall")
        target = {6: (4.0, 1.2), 42: (5.0, 1.2)}.get(K)
        row.update({
            "max_diff_compiled_deg": float(np.max(np.abs(np.degrees(
                ours[:, :2] - np.array([r.estimate for r in res["ours-int"]])[:, :2])))),
            # the same problem as scipy's (weights held at the start): the answers must agree
            "max_diff_to_scipy_deg": float(np.max(np.abs(np.degrees(same[:, :2] - np.array(res["lm"])[:, :2])))),
            # the shipped answer (weights at the estimate, their fixed point) against scipy's problem
            "reweighting_effect_deg": float(np.max(np.abs(np.degrees(ours[:, :2] - same[:, :2])))),
            "max_diff_batch_deg": float(np.nanmax(np.abs(np.degrees(ours[:, :2] - res["batch"].estimate[:, :2])))),
            "failures": int(sum(not r.success for r in res["ours"])),
            "ipopt_iterations_mean": float(np.mean([r.info["iterations"] for r in res["ours"]])),
            "ipopt_solves": int(sum(r.info.get("confirmation") == "ipopt" for r in res["ours"])),
        })
        if target:
            row["target"] = {"speedup": target[0], "speedup_zero_copy": target[1], "answers_deg": 1e-6}
            row["met"] = {"speedup": row["speedup"] >= target[0],
                          "speedup_zero_copy": row["speedup_zero_copy"] >= target[1],
                          "answers": row["max_diff_to_scipy_deg"] <= 1e-6}
        rows.append(row)
    # batch at scale: N identifications of K = 6 in one call sequence, one process, on each tier
    th = kin.ik(robot, paper_poses(robot, 3))
    rng = np.random.default_rng(0)
    R = np.array([plant.measure(th, noise, rng) for _ in range(args.batch)])
    key = (robot.mechanism_name, 6, tuple(robot.errors.indices("paper")))
    scale_run = {"K": 6, "batch_n": args.batch}
    probs = {}
    for tier in ("interpreted", "compiled"):
        os.environ["ZEROCAL_COMPILE"] = "never" if tier == "interpreted" else mode0
        probs[tier] = nlls_problem.NllsProblem(robot.mechanism, 6, key[2])
        if tier == "compiled":
            probs[tier].hot(wait=True)
    out_b = {}

    def scale_runner(tier):
        def run():
            os.environ["ZEROCAL_COMPILE"] = "never" if tier == "interpreted" else mode0
            nlls_problem._CACHE[key] = probs[tier]
            out_b[tier] = identify_batch(robot, th, R, "paper", noise=noise)
            return 1
        return run

    tb = interleaved({"compiled": scale_runner("compiled"), "interpreted": scale_runner("interpreted")},
                     args.batch_passes)
    for tier in ("compiled", "interpreted"):
        sfx = "" if tier == "compiled" else "_interpreted"
        b = out_b[tier]
        scale_run.update({f"batch_total{sfx}_s": median(tb, tier), f"batch_total{sfx}_wall_s": median(tb, tier, "wall"),
                          f"batch_confirmed{sfx}": int(b.confirmed.sum()), f"batch_success{sfx}": int(b.success.sum())})
    scale_run["compiled"] = bool(probs["compiled"].compiled)
    scale_run["passes"] = args.batch_passes
    os.environ["ZEROCAL_COMPILE"] = mode0
    load1 = load()
    if emit({"load_before": load0, "load_after": load1, "rows": rows, "batch_at_scale": scale_run}, args.json):
        return
    mode = "compiled" if all(r["compiled"] for r in rows) else f"NOT compiled ({compiled.status()[-1][2]})"
    print(f"identify and batch on the {mode} tier; identify-int and scipy on the interpreted Functions "
          f"(scipy-zc-c: zero-copy callbacks of the compiled ones)")
    print(f"columns interleaved, {args.repeat} passes of {args.rounds} rounds; ms per identification, median over "
          "the passes, CPU time (wall time in brackets); ratios = scipy's CPU time / ours in the same pass "
          "(> 1: ours faster), see --help")
    print(f"{'K':>3s} {'identify':>15s} {'identify-int':>15s} {'scipy-lm':>15s} {'scipy-zc':>15s} "
          f"{'scipy-zc-c':>15s} {'batch':>13s} {'x lm':>6s} {'x zc':>6s} {'int x lm':>8s} {'x zc-c':>6s}")
    for r in rows:
        def c(k):
            return f"{r[k]:6.3f} ({r[k.replace('_ms', '_wall_ms')]:6.3f})"
        print(f"{r['K']:3d} {c('identify_ms'):>15s} {c('identify_interpreted_ms'):>15s} {c('scipy_lm_ms'):>15s} "
              f"{c('scipy_lm_zero_copy_ms'):>15s} {c('scipy_lm_zero_copy_compiled_ms'):>15s} {c('batch_ms'):>13s} "
              f"{r['speedup']:6.2f} {r['speedup_zero_copy']:6.2f} {r['speedup_interpreted']:8.2f} "
              f"{r['speedup_zero_copy_compiled']:6.2f}")
    for r in rows:
        lo, hi = r["speedup_spread"]
        zlo, zhi = r["speedup_zero_copy_spread"]
        met = r.get("met", {})
        tg = r.get("target", {})
        print(f"K = {r['K']}: x lm {r['speedup']:.2f} (passes {lo:.2f}-{hi:.2f}; target {tg.get('speedup')}: "
              f"{'met' if met.get('speedup') else 'NOT met'}), x zc {r['speedup_zero_copy']:.2f} (passes "
              f"{zlo:.2f}-{zhi:.2f}; target {tg.get('speedup_zero_copy')}: "
              f"{'met' if met.get('speedup_zero_copy') else 'NOT met'}); wall ratios x lm "
              f"{r['speedup_wall']:.2f}, x zc {r['speedup_zero_copy_wall']:.2f}")
        print(f"  same problem: max |ours - scipy| {r['max_diff_to_scipy_deg']:.1e} deg (reweighting moves the answer "
              f"{r['reweighting_effect_deg']:.1e} deg), |batch - single| {r['max_diff_batch_deg']:.1e} deg, "
              f"|compiled - interpreted| {r['max_diff_compiled_deg']:.1e} deg, failures {r['failures']}, Ipopt "
              f"solves {r['ipopt_solves']} of {r['rounds']} (iterations {r['ipopt_iterations_mean']:.1f} on "
              f"average), build {r['compile_s']:.1f} s")
    print(f"batch at scale: {scale_run['batch_n']} identifications at K = 6 (one process, {scale_run['passes']} "
          f"interleaved passes): {scale_run['batch_total_s']:.2f} s CPU ({scale_run['batch_total_wall_s']:.2f} s wall) "
          f"compiled (confirmed {scale_run['batch_confirmed']}, succeeded {scale_run['batch_success']}), "
          f"{scale_run['batch_total_interpreted_s']:.2f} s CPU ({scale_run['batch_total_interpreted_wall_s']:.2f} s "
          f"wall) interpreted (confirmed {scale_run['batch_confirmed_interpreted']})")
    print(load_line(load0, load1))


if __name__ == "__main__":
    main()
