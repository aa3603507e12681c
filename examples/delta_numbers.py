"""Reproduce the reference values docs/delta.md gives for the default rotary Delta robot, and check them.

Run:  python examples/delta_numbers.py        (prints each number beside the reference; exit 1 on a mismatch)

The reference values came from an implementation of the model independent of zerocal_sym; every number is
computed here with zerocal_sym, and the tolerance of each check is the number of digits the reference gives.
"""
import sys
from pathlib import Path

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.identify import identifiability as idf
from zerocal_sym.identify.linear import condition_number, identification_matrix
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot, validate

ROBOT = Path(__file__).resolve().parent / "delta.toml"
failures = []


def report(ok, what, ours, theirs):
    print(f"{'ok ' if ok else 'BAD'} {what}: ours {ours}  reference {theirs}")
    if not ok:
        failures.append(what)


def check(what, ours, theirs, tol):
    ours = np.asarray(ours, float)
    report(bool(np.all(np.abs(ours - np.asarray(theirs, float)) <= tol)), what, np.round(ours, 4).tolist(), theirs)


def below(what, ours, bound):
    report(bool(ours < bound), what, f"{ours:.3g}", f"< {bound:g}")


def main():
    robot = load_robot(ROBOT)
    s = validate(robot)
    check("P0 (mm)", s["home_pose_mm"], [0, 0, -624.500], 5e-4)
    below("max |FK(IK(P)) - P| over the grid and rims (mm)", s["fk_ik_max_error_mm"], 1e-12)
    check("joint range over the workspace (deg)", s["joint_range_deg"], [-7.003, 59.13], [5e-4, 5e-3])

    poses = {n: robot.workspace.boundary_scheme(n) for n in (3, 4, 6)}
    G3, _ = identification_matrix(robot, poses[3])
    check("ring n = 3: changes x unknowns", G3.shape, [5, 6], 0)
    check("ring n = 4: cond(G)", condition_number(identification_matrix(robot, poses[4])[0]), 3186, 0.5)
    check("ring n = 6: cond(G)", condition_number(identification_matrix(robot, poses[6])[0]), 233.4, 0.05)
    th6 = kin.ik(robot, poses[6])
    scale_only = fisher.crlb_zero_offsets_deg(robot, th6, "paper", NoiseModel.named("scale-only"))
    check("ring n = 6: CRLB per offset, scale error only (deg), within [0.0264, 0.0274]",
          [scale_only.min(), scale_only.max()], [0.0264, 0.0274], 5e-5)
    check("ring n = 6: CRLB per offset, paper noise (deg)",
          fisher.crlb_zero_offsets_deg(robot, th6, "paper", NoiseModel.paper()), [0.382] * 3, 5e-4)

    truth = robot.errors.assemble((2.0, -1.0, 0.5), None, (1.0, 0.5, -0.5))
    for n, one_step in ((4, 1.6), (6, 0.12)):
        th = kin.ik(robot, poses[n])
        meas = Measurements(theta_cmd=th, readings=VirtualPlant(robot, truth).measure(th))
        res = identify_nlls(robot, meas, "paper", noise=NoiseModel())
        below(f"ring n = {n}: exact model, noise-free, max error of offsets (rad) and MAEMM (mm)",
              np.max(np.abs(res.estimate - robot.errors.take(truth, res.params))), 1e-10)
        step = np.abs(identify_tsvd(robot, meas).zero_offsets_deg - np.degrees(robot.errors.take(
            truth, robot.errors.zero_offsets)))
        check(f"ring n = {n}: one linear step at zero errors, offset errors (deg) 'about {one_step}'",
              step, [one_step] * 3, 0.1 * one_step if n == 4 else 0.015)

    rng = np.random.default_rng(0)
    lo, hi = robot.workspace_bounds()
    P = lo + rng.uniform(size=(400, 3)) * (hi - lo)
    P = P[robot.workspace.contains(P)][:40]
    rep = idf.identifiability_report(robot, kin.ik(robot, P), "all")
    check("all 21 source errors, 40 random poses: rank", rep["rank"], 19, 0)
    print("    null space:", "; ".join(" + ".join(g) for g in rep["null_space_gauge"]))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
