"""Designs of true replicates (the paper's workspace, crlb): what rounding costs, and a shared revisit error.

Prints, for K = 20, 100, 700: the certified bound of any K-pose design on the candidates, and the CRLB and
efficiency lower bound of the design realised from the crlb measure (true replicates of its support points,
never one twice in a row); then, with a shared revisit error of 0, 1, 3 and 10 um per pose (the paper's noise
besides), the CRLB of the realised design at K = 50, 200, 800 and the floor its replicates approach
(:func:`zerocal_sym.design.replicates.shared_floor`).  No timing.

Usage: python benchmarks/replicates.py
"""

from zerocal_sym import design
from zerocal_sym.design import approx, rounding
from zerocal_sym.design.replicates import shared_floor
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.model.robot import paper_robot


def main():
    robot = paper_robot()
    cons = design.make_constraints(robot)
    ad = approx.approximate_design(robot, "crlb", cons)
    print("paper's workspace, crlb, paper noise: bound (any K-pose design on the candidates) and the realised "
          "design of true replicates")
    print(f"{'K':>6} {'bound deg':>10} {'realised deg':>13} {'efficiency >=':>14}")
    for K in (20, 100, 700):
        P, _ = rounding.realize(robot, ad, K, cons)
        v = design.criterion_values(robot, P)["crlb"]
        print(f"{K:>6} {ad.bound(K):>10.5f} {v:>13.5f} {ad.efficiency(v, K):>14.3f}")
    paper = NoiseModel.paper()
    Ks = (50, 200, 800)  # by K = 800 the rows with a shared error are near their floor; larger K costs most of the run
    print("\nshared revisit error (revisit_std_mm) besides the paper's noise: CRLB of the realised design [deg]")
    print(f"{'um':>6} " + " ".join(f"{'K = ' + str(K):>10}" for K in Ks) + f" {'floor':>10}")
    for tau_um in (0, 1, 3, 10):
        nm = NoiseModel(paper.sigma_scale_mm, paper.sigma_joint, tau_um * 1e-3)
        row = [design.criterion_values(robot, rounding.realize(robot, ad, K, cons, nm)[0], nm)["crlb"] for K in Ks]
        print(f"{tau_um:>6} " + " ".join(f"{x:>10.5f}" for x in row) + f" {shared_floor(robot, ad.support, nm):>10.5f}")


if __name__ == "__main__":
    main()
