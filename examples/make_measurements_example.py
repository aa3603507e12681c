"""Regenerate ``examples/measurements_example.csv`` (and the pose list ``examples/poses_example.csv``).

A simulated measurement round of the paper's robot (Table 1): Table 2 group 1
(zero offsets 2 and -1 deg, geometric errors "set A", MAEMM (1, 0.5) mm), the
paper's six poses (``scheme.paper_poses(robot, 3)``, visiting order as in
SPEC.md), the paper's noise (Eqs. 34-35) and seed 2017.  Run from the
repository root::

    python examples/make_measurements_example.py

The output is byte-for-byte reproducible (tests/test_data.py checks it).
"""
from pathlib import Path

import numpy as np

from zerocal_sym import data, kinematics, scheme
from zerocal_sym.io import atomic_write_text
from zerocal_sym.measurement import NoiseModel, VirtualPlant, table2_errors
from zerocal_sym.robot import paper_robot

HERE = Path(__file__).resolve().parent
SEED = 2017
GROUP = 1


def make_example():
    """The example measurements (nothing written).

    Returns
    -------
    Measurements
        K = 6 poses.
    """
    robot = paper_robot()
    P = scheme.paper_poses(robot, 3)
    theta = kinematics.ik(robot, P)
    plant = VirtualPlant(robot, table2_errors(GROUP))
    readings = plant.measure(theta, NoiseModel.paper(), np.random.default_rng(SEED))
    meta = {"robot_sha256": robot.sha256,
            "simulated": f"paper Table 2 group {GROUP}, noise paper, seed {SEED} "
                         "(examples/make_measurements_example.py)"}
    return data.Measurements(theta, readings, P, meta)


def main():
    meas = make_example()
    data.write_measurements(HERE / "measurements_example.csv", meas)
    text = "# target positions for 'zerocal compensate --poses' (the paper's six poses), mm\npose,x_mm,y_mm\n"
    text += "".join(f"{k},{x:g},{y:g}\n" for k, (x, y) in enumerate(meas.target))
    atomic_write_text(HERE / "poses_example.csv", text)


if __name__ == "__main__":
    main()
