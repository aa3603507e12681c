"""Monte Carlo: mean squared error of the bias-aware (mse) designs against the CRLB-only design .

The paper's robot, K poses, paper noise.  For each tolerance scale s (default 1 and 10): the CRLB-only design
(criterion crlb, which ignores the omitted errors) and the bias-aware designs (criterion mse with the
tolerances s x |set A|, the planar default; bias model ``rms``: the expected squared bias of errors uniform
within the tolerances, and ``worst``: the squared worst case) are each identified ``--trials`` times with
the Ipopt estimator (:func:`zerocal_sym.design.verify_design`, the paper's 4 parameters) from data
simulated with the truth of Table 2 group 1 (offsets 2, -1 deg, MAEMM 1, 0.5 mm) and geometric errors
(which the estimator holds at zero):

* ``setA``: s x set A (Table 2's frame, :func:`zerocal_sym.paper.tables.group_errors`) -- one corner of
  the tolerance box;
* ``random``: ``--truths`` robots with errors uniform in the tolerance box, ``--trials / --truths`` trials
  each (what the ``rms`` model averages over);
* ``corner``: the design's own worst corner of the tolerance box: the corner with the largest bias of the
  offsets on the exact model, searched over all 2^r corners (noise-free data identified by the estimator
  itself; what the ``worst`` model bounds).  A closing table gives that bias beside the bias at the corner the
  first-order sensitivity at zero errors would pick.

Printed per design: the Monte Carlo RMS error of the offsets (the square root of the mean squared error,
bias included), its mean (the bias), the CRLB at the truth, the first-order bias at the truth
(:func:`zerocal_sym.identify.fisher.model_bias`) and the predicted RMS error sqrt(CRLB^2 + bias^2); and
the design's own mse criterion (the RMS error expected for errors uniform within the tolerances).

Usage: python benchmarks/mc_bias.py [--trials 1000] [--truths 50] [--K 6] [--scales 1 10]
                                    [--regions reachable workspace] [--seed 0] [--workers N]
"""
import itertools
import argparse
import math
import time

import numpy as np

from zerocal_sym import design
from zerocal_sym.identify.budget import bias
from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.model.robot import paper_robot
from zerocal_sym.paper.tables import group_errors

REGIONS = {
    "reachable": dict(region="reachable", bounds=(-math.inf, math.inf, 450, math.inf)),
    "workspace": {},
}


def truth(robot, scale):
    """Table 2 group 1 (paper frame) with the geometric errors times ``scale``."""
    err = group_errors(1, "paper")
    geo = robot.errors.indices("geometry")
    err = err.copy()
    err[geo] *= scale
    return err


def worst_corner(robot, P, tol, noise):
    """The corner of the tolerance box with the largest bias of the offsets (sum of squares) on the exact model.

    Every one of the 2^r corners: noise-free readings of the virtual plant with the corner's geometric errors
    (Table 2 group 1's offsets and MAEMM), identified by the batched estimator (the paper's 4 parameters, the
    geometry held at zero), the bias the estimate minus the truth.  Returns the corner (by name) and, for
    comparison, the corner the first-order sensitivity at zero errors picks, with both exact biases (deg).
    """
    from zerocal_sym.identify.batch import identify_batch
    from zerocal_sym.model.noise import VirtualPlant

    th = kin.ik(robot, P)
    names = bias.omitted(robot)
    t = bias.tolerance_vector(robot, tol, names)
    corners = np.array(list(itertools.product((-1.0, 1.0), repeat=len(t)))) * t
    truths = [with_geometry(robot, dict(zip(names, c))) for c in corners]
    R = np.array([VirtualPlant(robot, err).measure(th) for err in truths])
    b = identify_batch(robot, th, R, "paper", noise=noise)
    off = robot.errors.zero_offsets
    exact = np.degrees(b.values(off) - np.array([robot.errors.take(err, off) for err in truths]))
    ss = np.sum(exact ** 2, axis=1)
    S, _ = bias.bias_sensitivity(robot, th, "paper", noise)
    k_lin = int(np.argmax(np.sum((corners @ S[:2].T) ** 2, axis=1)))
    k = int(np.nanargmax(ss))
    return dict(zip(names, corners[k])), {"exact": np.sqrt(ss[k] / 2), "first_order_pick": np.sqrt(ss[k_lin] / 2),
                                          "same": k == k_lin, "corners": len(corners)}


def with_geometry(robot, geo):
    err = group_errors(1, "paper").copy()
    idx = robot.errors.indices("geometry")
    err[idx] = 0.0
    for name, v in geo.items():
        err[robot.errors.index(name)] = v
    return err


def mc(robot, P, trials, noise, err, seed, workers):
    v = design.verify_design(robot, P, trials, noise, err_true=err, seed=seed, workers=workers)
    return np.square(v["rms_error_deg"]), v["n_failed"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=1000)
    ap.add_argument("--truths", type=int, default=50)
    ap.add_argument("--K", type=int, default=6)
    ap.add_argument("--scales", type=float, nargs="+", default=[1.0, 10.0])
    ap.add_argument("--regions", nargs="+", default=["reachable", "workspace"], choices=list(REGIONS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    a = ap.parse_args()
    robot, noise = paper_robot(), NoiseModel.paper()
    rng = np.random.default_rng(a.seed)
    print(f"paper robot, K = {a.K}, paper noise, seed {a.seed}; offsets/MAEMM of Table 2 group 1; MC RMS error of "
          f"the two offsets [deg] (bias included), {a.trials} trials per design and truth "
          f"(random: {a.truths} robots x {a.trials // a.truths} trials)")
    print(f"{'region':>9} {'s':>4} {'design':>11} | {'CRLB':>8} {'mse rms':>8} {'mse wc':>8} | "
          f"{'set A':>8} {'pred':>8} | {'random':>8} {'pred':>8} | {'corner':>8} {'pred':>8} | {'fail':>4} {'time':>6}")
    searched = []
    for rname in a.regions:
        cons = design.make_constraints(robot, **REGIONS[rname])
        designs = {"crlb": design.optimize_design(robot, a.K, "crlb", cons, noise, seed=a.seed)}
        for s in a.scales:
            tol_r = bias.make_tolerances(robot, scale=s, bias_model="rms")
            tol_w = bias.make_tolerances(robot, scale=s, bias_model="worst")
            times = {}
            for label, tol in (("mse rms", tol_r), ("mse worst", tol_w)):
                t = time.perf_counter()
                designs[label] = design.optimize_design(robot, a.K, "mse", cons, noise, seed=a.seed, tolerances=tol)
                times[label] = time.perf_counter() - t
            setA = truth(robot, s)
            names = bias.omitted(robot)
            randoms = [with_geometry(robot, dict(zip(names, rng.uniform(-1, 1, len(names))
                                                     * bias.tolerance_vector(robot, tol_r, names))))
                       for _ in range(a.truths)]
            for label in ("crlb", "mse rms", "mse worst"):
                P = designs[label].poses
                th = kin.ik(robot, P)
                crlb = fisher.crlb_zero_offsets_deg(robot, th, "paper", noise)
                vals = design.criterion_values(robot, P, noise, tol_r)
                mse_r = vals["mse"]
                mse_w = design.criterion_values(robot, P, noise, tol_w)["mse"]
                fails = 0

                def pred(err):
                    c = fisher.crlb_zero_offsets_deg(robot, th, "paper", noise, err0=err)
                    b = np.degrees(fisher.model_bias(robot, th, err, "paper", noise)[:2])
                    return np.mean(c ** 2 + b ** 2)

                e2, f = mc(robot, P, a.trials, noise, setA, a.seed, a.workers)
                fails += f
                res_a, pred_a = np.sqrt(np.mean(e2)), np.sqrt(pred(setA))
                acc, pacc = [], []
                for k, err in enumerate(randoms):
                    e2, f = mc(robot, P, max(a.trials // a.truths, 2), noise, err, a.seed + 1 + k, a.workers)
                    fails += f
                    acc.append(np.mean(e2))
                    pacc.append(pred(err))
                res_r, pred_r = np.sqrt(np.mean(acc)), np.sqrt(np.mean(pacc))
                geo, found = worst_corner(robot, P, tol_r, noise)
                corner = with_geometry(robot, geo)
                searched.append((rname, s, label, found))
                e2, f = mc(robot, P, a.trials, noise, corner, a.seed, a.workers)
                fails += f
                res_c, pred_c = np.sqrt(np.mean(e2)), np.sqrt(pred(corner))
                print(f"{rname:>9} {s:4g} {label:>11} | {np.sqrt(np.mean(crlb ** 2)):8.5f} {mse_r:8.5f} {mse_w:8.5f} | "
                      f"{res_a:8.5f} {pred_a:8.5f} | {res_r:8.5f} {pred_r:8.5f} | {res_c:8.5f} {pred_c:8.5f} | "
                      f"{fails:4d} {times.get(label, 0.0):6.1f}")
            for label in ("mse rms", "mse worst"):
                print(f"    {label} design (s = {s:g}) poses (mm): "
                      + "; ".join(f"({x:.1f}, {y:.1f})" for x, y in designs[label].poses))
        print("    crlb design poses (mm): " + "; ".join(f"({x:.1f}, {y:.1f})" for x, y in designs["crlb"].poses))
    print("worst corner searched on the exact model (all corners of the tolerance box, noise-free, the estimator "
          "itself): RMS bias of the offsets there [deg], and at the corner the first-order sensitivity at zero picks")
    for rname, s, label, f in searched:
        print(f"{rname:>9} {s:4g} {label:>11} | {f['corners']} corners: worst {f['exact']:.5f}, first-order pick "
              f"{f['first_order_pick']:.5f}" + (" (the same corner)" if f["same"] else ""))
    print("columns: CRLB = RMS CRLB at zero errors; mse rms / mse wc = the design's mse criterion under the two bias "
          "models (deg); set A / random / corner = Monte Carlo RMS error, pred = first-order prediction "
          "sqrt(CRLB^2 + bias^2) at the truth (RMS over the random robots)")


if __name__ == "__main__":
    main()
