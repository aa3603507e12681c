"""False-rejection and detection rates of the fit check (zerocal_sym.identify.fitcheck), measured.

For each design (the paper's boundary scheme with n = 3 and n = 6, i.e. K = 6
and K = 12 poses) and each size of one bad reading (0 = clean rounds), N
simulated rounds with the paper's noise (Table 2 group 1's offsets and MAEMM,
no geometric errors, so the 4-parameter model is exact) are identified by the
batched Gauss-Newton (identify.batch, the same estimator, chi² and largest
standardised residual as identify_nlls), and the fit is rejected when either
test's p-value is below alpha (default 0.001); the columns ``chi2`` and ``max |t|``
are each test's own rate.
The bad reading is added to the reading at pose k, k = 1..K-1 in turn (equal
shares of the rounds).  With ``--name M`` the first M rounds of each bad-reading
case also go through identify_nlls to see whether the rejection names the bad
pose (needs at least 2 spare degrees of freedom, so K = 12 only).

    .venv/bin/python examples/fitcheck_rates.py [--rounds 4000] [--name 200] [--seed 11]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from zerocal_sym.identify.batch import identify_batch
from zerocal_sym.identify.fitcheck import DEFAULT_ALPHA
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot, paper_robot


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=4000, help="rounds per case (default 4000)")
    ap.add_argument("--name", type=int, default=200, help="rounds per bad-reading case through identify_nlls "
                                                          "to check the bad pose is named (default 200; 0: skip)")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--alpha", type=float, default=DEFAULT_ALPHA)
    ap.add_argument("--robot", default=None, help="robot file (default: the paper's robot)")
    ap.add_argument("--n", type=int, nargs="+", default=[3, 6], help="boundary-scheme n (K = 2n for the planar "
                                                                       "robot; default 3 6)")
    ap.add_argument("--bad", type=float, nargs="+", default=[0.0, 0.1, 0.5], help="bad-reading sizes, mm")
    args = ap.parse_args(argv)
    robot = paper_robot() if args.robot is None else load_robot(args.robot)
    noise = NoiseModel.paper()
    errors = robot.errors
    truth = errors.assemble((2.0, -1.0, 0.5)[: robot.m], None, (1.0, 0.5, -0.5)[: robot.n])
    plant = VirtualPlant(robot, truth)
    print(f"robot {robot.name} ({robot.mechanism_name}); paper noise; alpha = {args.alpha:g}; "
          f"{args.rounds} rounds per case; seed {args.seed}")
    print(f"{'K':>3} {'dof':>3} {'bad [mm]':>8} {'rejected':>9} {'± MC':>6} {'chi2':>7} {'max |t|':>7} "
          f"{'min..max over the bad pose':>27} {'bad pose named':>15}")
    t0 = time.perf_counter()
    for n in args.n:
        P = robot.workspace.boundary_scheme(n)
        th = kin.ik(robot, P)
        K = th.shape[0]
        rng = np.random.default_rng([args.seed, n])
        R = np.array([plant.measure(th, noise, rng) for _ in range(args.rounds)])
        where = 1 + np.arange(args.rounds) % (K - 1)  # the bad reading's pose, k = 1..K-1 in turn
        for bad in args.bad:
            Rb = R.copy()
            Rb[np.arange(args.rounds), where] += bad
            b = identify_batch(robot, th, Rb, "paper", noise=noise)
            rej = b.rejected(args.alpha)
            rate = float(np.mean(rej))
            r_chi2, r_max = float(np.mean(b.p_value < args.alpha)), float(np.mean(b.p_value_max < args.alpha))
            mc = float(np.sqrt(max(rate * (1 - rate), 1.0 / args.rounds) / args.rounds))
            per = [float(np.mean(rej[where == k])) for k in range(1, K)]
            span = f"{min(per):.3f}..{max(per):.3f}" if bad else "-"
            named = "-"
            if bad and args.name and b.dof >= 2:
                hits = tries = 0
                for i in range(min(args.name, args.rounds)):
                    res = identify_nlls(robot, Measurements(th, Rb[i]), "paper", noise=noise, fit_alpha=args.alpha)
                    if res.info["fit"]["rejected"]:
                        tries += 1
                        c = [c for c in res.info["fit"]["causes"] if c["cause"] == "bad reading"]
                        hits += bool(c and c[0]["pose"] == where[i])
                named = f"{hits}/{tries}" if tries else "0/0"
            print(f"{K:>3} {b.dof:>3} {bad:>8.3g} {rate:>9.4f} {mc:>6.4f} {r_chi2:>7.4f} {r_max:>7.4f} {span:>27} "
                  f"{named:>15}", flush=True)
    print(f"time {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
