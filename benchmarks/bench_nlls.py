"""Time per Ipopt identification against scipy's least_squares on the same problems, same run.

Problems: one simulated measurement round (Table 2 group 1 read literally, the
paper's noise) at
  K = 6  -- the paper's six poses (n = 3), 4 parameters;
  K = 42 -- the 42 boundary positions of the paper's Fig. 11, 4 parameters.
N rounds each (different noise).  Timed per identification:

  ipopt-full    identify_nlls as shipped (TSVD warm start, weights re-evaluated at
                the solution: two Ipopt solves, covariance, identifiability of the result)
  ipopt-same    identify_nlls(warm_start=None, reweight=0): exactly scipy's problem,
                whole function (weights, solve, covariance)
  ipopt-solver  the cached Ipopt solver call alone on that problem
  scipy-lm      scipy.optimize.least_squares(method="lm") on the same whitened,
                scaled residuals and Jacobian (CasADi-evaluated), solver call alone
  scipy-trf     the same with method="trf"

Ratios are against scipy-lm of the same run; the answers are compared too.
Usage: python benchmarks/bench_nlls.py [--rounds N] [--repeat R]
"""
import argparse
import statistics
import time

import numpy as np


def timed(fn, repeat):
    """Median over ``repeat`` passes of the mean time per call of fn over its data."""
    fn()  # warm-up (builds and caches the NLP)
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        n = fn()
        out.append((time.perf_counter() - t) / n)
    return statistics.median(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=50, help="simulated rounds per K (default 50)")
    ap.add_argument("--repeat", type=int, default=5, help="timing passes, median reported (default 5)")
    args = ap.parse_args()

    from scipy.optimize import least_squares

    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.identify.nlls import get_problem, identify_nlls, residual_problem
    from zerocal_sym.report.plots import boundary_positions
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.paper.tables import table2_errors

    robot = paper_robot()
    noise = NoiseModel.paper()
    plant = VirtualPlant(robot, table2_errors(1))
    print(f"{'K':>3s} {'method':13s} {'ms/ident':>9s} {'ratio to scipy-lm':>18s}")
    for K, poses in ((6, paper_poses(robot, 3)), (42, boundary_positions(robot, 42))):
        th = kin.ik(robot, poses)
        rng = np.random.default_rng(K)
        data = [Measurements(th, plant.measure(th, noise, rng)) for _ in range(args.rounds)]
        probs = [residual_problem(robot, m, "paper", noise) for m in data]
        prob = get_problem(robot, K, "paper")

        # the raw solver call, with the parameter vector identify_nlls builds
        from zerocal_sym.identify import fisher
        from zerocal_sym.identify.nlls import _weights

        scale = fisher.parameter_scale(robot, "paper")
        pars = []
        for m in data:
            W = _weights(robot, th, noise, np.zeros(12))
            par = prob.pack(th, robot.geometry, np.zeros(12), m.readings[1:], W, scale, np.zeros(4),
                            np.zeros((4, 4)))
            J0 = prob.resfun(np.zeros(4), par)[2].full()
            par[-1] = 1.0 / np.linalg.norm(J0, 2) ** 2
            pars.append(par)

        res = {}

        def run_full():
            res["full"] = [identify_nlls(robot, m, "paper", noise=noise) for m in data]
            return len(data)

        def run_same():
            res["same"] = [identify_nlls(robot, m, "paper", noise=noise, warm_start=None, reweight=0) for m in data]
            return len(data)

        def run_solver():
            res["solver"] = [prob.solver(x0=np.zeros(4), p=p)["x"].full().ravel() / scale for p in pars]
            return len(data)

        def run_scipy(method):
            def f():
                res[method] = [least_squares(fun, np.zeros(4), jac=jac, method=method, xtol=1e-14, ftol=1e-14,
                                             gtol=1e-14).x / sc for fun, jac, sc in probs]
                return len(data)
            return f

        t = {"ipopt-full": timed(run_full, args.repeat), "ipopt-same": timed(run_same, args.repeat),
             "ipopt-solver": timed(run_solver, args.repeat), "scipy-lm": timed(run_scipy("lm"), args.repeat),
             "scipy-trf": timed(run_scipy("trf"), args.repeat)}
        for name, v in t.items():
            print(f"{K:3d} {name:13s} {1e3 * v:9.3f} {v / t['scipy-lm']:18.2f}")
        same = np.array([r.estimate for r in res["same"]])
        d_lm = np.max(np.abs(np.degrees(same[:, :2] - np.array(res["lm"])[:, :2])))
        d_trf = np.max(np.abs(np.degrees(same[:, :2] - np.array(res["trf"])[:, :2])))
        d_solver = np.max(np.abs(np.degrees(same[:, :2] - np.array(res["solver"])[:, :2])))
        fails = sum(not r.success for r in res["full"]) + sum(not r.success for r in res["same"])
        print(f"    answers: max |Ipopt - scipy-lm| = {d_lm:.2e} deg, |Ipopt - scipy-trf| = {d_trf:.2e} deg, "
              f"|identify_nlls - raw solver| = {d_solver:.2e} deg; Ipopt failures {fails}; "
              f"mean Ipopt iterations {np.mean([r.info['iterations'] for r in res['same']]):.1f}")


if __name__ == "__main__":
    main()
