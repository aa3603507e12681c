"""Time per identification against scipy's least_squares on the same problems, same run.

Problems: simulated measurement rounds (Table 2 group 1 read literally, the
paper's noise) of the paper's robot at
  K = 6  -- the paper's six poses (n = 3), 4 parameters;
  K = 42 -- the 42 boundary positions of the paper's Fig. 11, 4 parameters.
Timed per identification (median over passes of the mean over the rounds):

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

and the ratios (scipy's time over ours, > 1: ours is faster):

  x lm           scipy-lm / identify       (the "speedup" asked for)
  x zc           scipy-zc / identify
  int x lm       scipy-lm / identify-int
  x zc-c         scipy-zc-c / identify

and the batched path at scale: N = 10,000 identifications at K = 6 in one
process (one core).  Ratios are against scipy-lm of the same run; the answers
are compared too (max |ours - scipy| over the offsets, deg).

With ZEROCAL_COMPILE=never (or no C compiler) the compiled columns are the
interpreted ones and the header says so.

Usage: python benchmarks/bench_nlls.py [--rounds N] [--repeat R] [--batch N] [--json]

--json prints a list with one entry per K (keys K, identify_ms, scipy_lm_ms,
speedup and the other columns; load_average); the batch-at-scale run is the
K = 6 entry's "batch_at_scale".
"""
import argparse
import json
import os
import statistics
import time

import numpy as np


def timed(fn, repeat):
    """Median over ``repeat`` passes of the mean time per call of fn over its data (after a warm-up)."""
    fn()
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        n = fn()
        out.append((time.perf_counter() - t) / n)
    return statistics.median(out)


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
    ap.add_argument("--repeat", type=positive_int, default=5, help="timing passes, median reported (default 5)")
    ap.add_argument("--batch", type=positive_int, default=10000,
                    help="identifications of the batch-at-scale run (default 10000)")
    ap.add_argument("--json", action="store_true", help="print a JSON list (one entry per K) instead of text")
    args = ap.parse_args()

    from scipy.optimize import least_squares

    from zerocal_sym.identify import nlls_problem
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

        t = {"identify": timed(run_identify, args.repeat),
             "identify-int": timed(lambda: run_identify("interpreted"), args.repeat),
             "scipy-lm": timed(scipy_runner(False), args.repeat),
             "scipy-zc": timed(scipy_runner(True), args.repeat),
             "scipy-zc-c": timed(scipy_runner(True, "compiled"), args.repeat),
             "batch": timed(run_batch, args.repeat)}
        use("compiled")
        ours = np.array([r.estimate for r in res["ours"]])
        same = np.array([identify_nlls(robot, m, "paper", noise=noise, reweight=0).estimate for m in data])
        row = {
            "K": K,
            "identify_ms": 1e3 * t["identify"],
            "compiled": bool(hot.compiled),
            "compile_s": build_s,
            "identify_interpreted_ms": 1e3 * t["identify-int"],
            "scipy_lm_zero_copy_compiled_ms": 1e3 * t["scipy-zc-c"],
            "scipy_lm_ms": 1e3 * t["scipy-lm"],
            "scipy_lm_zero_copy_ms": 1e3 * t["scipy-zc"],
            "batch_ms": 1e3 * t["batch"],
            "speedup": t["scipy-lm"] / t["identify"],
            "speedup_zero_copy": t["scipy-zc"] / t["identify"],
            "speedup_interpreted": t["scipy-lm"] / t["identify-int"],
            "speedup_zero_copy_compiled": t["scipy-zc-c"] / t["identify"],
            "max_diff_compiled_deg": float(np.max(np.abs(np.degrees(
                ours[:, :2] - np.array([r.estimate for r in res["ours-int"]])[:, :2])))),
            # the same problem as scipy's (weights held at the start): the answers must agree
            "max_diff_to_scipy_deg": float(np.max(np.abs(np.degrees(same[:, :2] - np.array(res["lm"])[:, :2])))),
            # the shipped answer (weights at the estimate, their fixed point) against scipy's problem
            "reweighting_effect_deg": float(np.max(np.abs(np.degrees(ours[:, :2] - same[:, :2])))),
            "max_diff_batch_deg": float(np.nanmax(np.abs(np.degrees(ours[:, :2] - res["batch"].estimate[:, :2])))),
            "failures": int(sum(not r.success for r in res["ours"])),
            "ipopt_iterations_mean": float(np.mean([r.info["iterations"] for r in res["ours"]])),
        }
        rows.append(row)
    # batch at scale: N identifications of K = 6 in one call sequence, one process, on each tier
    th = kin.ik(robot, paper_poses(robot, 3))
    rng = np.random.default_rng(0)
    R = np.array([plant.measure(th, noise, rng) for _ in range(args.batch)])
    key = (robot.mechanism_name, 6, tuple(robot.errors.indices("paper")))
    scale_run = {"K": 6, "batch_n": args.batch}
    for tier in ("interpreted", "compiled"):
        os.environ["ZEROCAL_COMPILE"] = "never" if tier == "interpreted" else mode0
        prob = nlls_problem.NllsProblem(robot.mechanism, 6, key[2])
        if tier == "compiled":
            prob.hot(wait=True)
        nlls_problem._CACHE[key] = prob
        identify_batch(robot, th, R[:10], "paper", noise=noise)  # warm-up (builds the mapped Function)
        t0 = time.perf_counter()
        b = identify_batch(robot, th, R, "paper", noise=noise)
        sfx = "" if tier == "compiled" else "_interpreted"
        scale_run.update({f"batch_total{sfx}_s": time.perf_counter() - t0,
                          f"batch_confirmed{sfx}": int(b.confirmed.sum()),
                          f"batch_success{sfx}": int(b.success.sum())})
        if tier == "compiled":
            scale_run["compiled"] = bool(prob.compiled)
    load = os.getloadavg()[0]
    if args.json:
        for r in rows:
            r["load_average"] = load
        next(r for r in rows if r["K"] == 6)["batch_at_scale"] = scale_run
        print(json.dumps(rows, indent=2))
        return
    mode = "compiled" if all(r["compiled"] for r in rows) else f"NOT compiled ({compiled.status()[-1][2]})"
    print(f"identify and batch on the {mode} tier; identify-int and scipy on the interpreted Functions "
          f"(scipy-zc-c: zero-copy callbacks of the compiled ones)")
    print("times in ms per identification; ratios = scipy's time / ours (> 1: ours faster), see --help")
    print(f"{'K':>3s} {'identify':>12s} {'identify-int':>12s} {'scipy-lm':>12s} {'scipy-zc':>12s} "
          f"{'scipy-zc-c':>11s} {'batch':>9s} {'x lm':>8s} {'x zc':>6s} {'int x lm':>8s} {'x zc-c':>8s}  answers")
    for r in rows:
        print(f"{r['K']:3d} {r['identify_ms']:12.3f} {r['identify_interpreted_ms']:12.3f} {r['scipy_lm_ms']:12.3f} "
              f"{r['scipy_lm_zero_copy_ms']:12.3f} {r['scipy_lm_zero_copy_compiled_ms']:11.3f} {r['batch_ms']:9.3f} "
              f"{r['speedup']:8.2f} {r['speedup_zero_copy']:6.2f} {r['speedup_interpreted']:8.2f} "
              f"{r['speedup_zero_copy_compiled']:8.2f}  "
              f"same problem: max |ours - scipy| {r['max_diff_to_scipy_deg']:.1e} deg (reweighting moves the "
              f"answer {r['reweighting_effect_deg']:.1e} deg), |batch - single| "
              f"{r['max_diff_batch_deg']:.1e} deg, |compiled - interpreted| {r['max_diff_compiled_deg']:.1e} deg, "
              f"failures {r['failures']}, Ipopt iterations {r['ipopt_iterations_mean']:.1f}, "
              f"build {r['compile_s']:.1f} s")
    print(f"batch at scale: {scale_run['batch_n']} identifications at K = 6 (one process): "
          f"{scale_run['batch_total_s']:.2f} s compiled (confirmed {scale_run['batch_confirmed']}, succeeded "
          f"{scale_run['batch_success']}), {scale_run['batch_total_interpreted_s']:.2f} s interpreted (confirmed "
          f"{scale_run['batch_confirmed_interpreted']})")
    print(f"load average {load:.2f} on {os.cpu_count()} cores")

if __name__ == "__main__":
    main()
