"""What the fit check of a K = 6 design sees: the crlb-optimal design against the checked one (the default).

For the paper's robot (paper noise, seed 0, default settings): both designs, their CRLB and the fit check's
power per scenario (``design.detection``), then wrong-data identifications of each -- a robot file with
every length 2 % short, and the poses visited in reverse -- simulated at the truth 0.156 / -1.859 deg,
MAEMM (1, 0.5) mm, seeds 0..N-1: whether the identification is refused (the fit check rejects), its chi²,
and how far its offsets are from the truth in their reported standard deviations.  The same simulation as
``tests/test_design_detection.py``.  Then what the single robot-file entries at their tolerances do: the
largest non-centrality and harm of an entry for the paper's scheme at K = 6, 20, 100; and the linear
Delta's and the rotary Delta's K = 12 crlb designs, and their checked designs when the entries are required
too (``Requirement(entries=True)``, ``--require-entries``; not the default).

Usage: python benchmarks/design_detection.py [--seeds 5] [--no-entries | --only-entries]
"""
import argparse
import math

import numpy as np

from zerocal_sym import design
from zerocal_sym.design.power import lengths_scaled
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import VirtualPlant
from zerocal_sym.model.robot import paper_robot

TRUTH = {"theta1": math.radians(0.156), "theta2": math.radians(-1.859), "rMx": 1.0, "rMy": 0.5}


def rounds(robot, P, seed):
    plant = VirtualPlant(robot, TRUTH)
    short = lengths_scaled(robot, 0.98)
    th = kin.ik(short, P)
    a = identify_nlls(short, Measurements(theta_cmd=th, readings=plant.measure(th, robot.noise, seed), target=P,
                                          meta={}, source="short"), noise=robot.noise)
    th = kin.ik(robot, P)
    b = identify_nlls(robot, Measurements(theta_cmd=th, readings=plant.measure(th[::-1], robot.noise, seed),
                                          target=P, meta={}, source="reversed"), noise=robot.noise)
    return (("2 % short", a), ("reversed", b))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--no-entries", action="store_true", help="skip the single entries' part")
    ap.add_argument("--only-entries", action="store_true", help="only the single entries' part")
    a = ap.parse_args()
    robot = paper_robot()
    if a.only_entries:
        entries(robot)
        return
    truth = np.degrees([TRUTH["theta1"], TRUTH["theta2"]])
    for crit in ("crlb", "checked"):
        res = design.optimize_design(robot, 6, crit, seed=0)
        d = res.report["detection"]
        print(f"K = 6, {crit}: CRLB {res.report['crlb_rms_deg']:.4f} deg ({res.method}); spare dof {d['dof']}; "
              "power: " + ", ".join(f"{k} {_f(v)}" for k, v in d["power"].items())
              + f"; {'sees what it must' if d['meets'] else 'misses ' + ', '.join(d['unmet'])}")
        print("    poses (mm): " + "; ".join(f"({x:.2f}, {y:.2f})" for x, y in res.poses))
        for seed in range(a.seeds):
            parts = []
            for what, r in rounds(robot, res.poses, seed):
                off = r.zero_offsets_user
                z = np.abs(off - truth) / r.std_zero_offsets_user
                verdict = "refused" if not r.success else "accepted"
                parts.append(f"{what}: {verdict}, chi2 {r.info['fit']['chi2']:.4g}, offsets "
                             f"{off[0]:.3f}/{off[1]:.3f} deg ({np.max(z):.1f} sigma off)")
            print(f"  seed {seed}: " + "; ".join(parts))
    if not a.no_entries:
        entries(robot)


def entries(robot):
    from pathlib import Path

    from zerocal_sym.design.detection import Requirement, detection
    from zerocal_sym.model.robot import load_robot

    for n in (3, 10, 50):
        d = detection(robot, robot.workspace.boundary_scheme(n))
        rows = [r for r in d["scenarios"] if r["kind"] == "entry" and r["name"] != "scale"]
        print(f"paper scheme, K = {2 * n}: single entries at their tolerance: largest lambda "
              f"{max(r['noncentrality'] for r in rows):.3g}, largest power {max(r['power'] for r in rows):.4f}, "
              f"largest harm {max(r['harm_sigma'] for r in rows):.3f} sigma; seen by no design: "
              f"{', '.join(d['invisible_entries'])}")
    for name in ("linear_delta", "delta"):
        rob = load_robot(Path(__file__).resolve().parents[1] / "examples" / f"{name}.toml")
        ref = design.optimize_design(rob, 12, "crlb", seed=0)
        d = ref.report["detection"]
        rows = [r for r in d["scenarios"] if r["kind"] == "entry" and r["name"] != "scale"]
        worst = max(rows, key=lambda r: r["harm_sigma"])
        print(f"{rob.name}, K = 12, crlb design: CRLB {ref.report['criterion']['value']:.5g}; the most harmful "
              f"entry at its tolerance {worst['name']} ({worst['size']:g} {worst['unit']}): harm "
              f"{worst['harm_sigma']:.2f} sigma, power {worst['power']:.4f}")
        res = design.optimize_design(rob, 12, "checked", seed=0, requirement=Requirement(rob, entries=True))
        d = res.report["detection"]
        print(f"{rob.name}, K = 12, checked with the entries required: CRLB {res.report['criterion']['value']:.5g} "
              f"({res.checked['cost']:.2f} x); {'meets it' if d['meets'] else 'misses ' + ', '.join(d['unmet'])}")


def _f(v):
    return "-" if v is None else f"{v:.3f}"


if __name__ == "__main__":
    main()
