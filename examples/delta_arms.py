"""Why ``zerocal design --params paper+L1,L2,L3`` uses the design measure (docs/trust.md).

Run:  python examples/delta_arms.py        (about a minute: it makes the exact-path design)

For the rotary Delta of ``examples/delta_arms.toml`` (upper arms in the file
331 mm, really 330), K = 12, the set that identifies the arms with the zero
offsets and the MAEMM: the exact path's design (``--method exact``: exchange
and Ipopt) and the default one (the design measure, rounded:
``examples/delta_arms_k12_free_L.json``).  Printed for each: the Cramér-Rao
bound of every parameter at zero errors (where the designs are made) and at
the truth of docs/trust.md's case (offsets 1.2, -0.7, 0.3 deg, arms 1 mm
short); then, for the exact design, the estimates of five simulated rounds.
"""
from pathlib import Path

import numpy as np

from zerocal_sym import design
from zerocal_sym.identify import fisher
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import VirtualPlant
from zerocal_sym.model.robot import load_robot

EX = Path(__file__).resolve().parent
SET = "paper+L1,L2,L3"


def main():
    robot = load_robot(EX / "delta_arms.toml").identifying(SET)
    errors = robot.errors
    names = errors.resolve(SET)
    truth = errors.vector({"theta1": np.radians(1.2), "theta2": np.radians(-0.7), "theta3": np.radians(0.3),
                           "L1": -1.0, "L2": -1.0, "L3": -1.0})
    user = np.array([errors.to_user_value(n, 1.0) for n in names])
    exact = design.optimize_design(robot, 12, "crlb", method="exact", seed=0).poses
    import json

    measure = np.array(json.loads((EX / "delta_arms_k12_free_L.json").read_text())["poses"])
    print("CRLB per parameter (" + ", ".join(f"{n} [{errors[n].user_unit}]" for n in names) + ")")
    for label, P in (("exact path (--method exact)", exact), ("design measure (the default)", measure)):
        th = kin.ik(robot, P)
        for where, e0 in (("at zero errors", None), ("at the truth", truth)):
            c = np.sqrt(np.diag(fisher.crlb(robot, th, names, robot.noise, err0=e0))) * user
            print(f"  {label}, {where}: " + " ".join(f"{v:.3g}" for v in c))
    th = kin.ik(robot, exact)
    print("exact path's design, five rounds (seeds 0-4): offsets [deg], L1-L3 [mm], rMz [mm], status")
    for seed in range(5):
        rd = VirtualPlant(robot, truth).measure(th, robot.noise, seed)
        res = identify_nlls(robot, Measurements(th, rd), names, noise=robot.noise)
        print(f"  {seed}: " + " ".join(f"{v:+.3f}" for v in res.zero_offsets_user) + " | "
              + " ".join(f"{res.value(n):+.2f}" for n in ("L1", "L2", "L3")) + f" | {res.value('rMz'):+.1f} | "
              + res.status[:60])


if __name__ == "__main__":
    main()
