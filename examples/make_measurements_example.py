"""Regenerate ``examples/measurements_example.csv`` (and the pose list ``examples/poses_example.csv``).

A simulated measurement round of the paper's robot (Table 1): Table 2 group 1
(zero offsets 2 and -1 deg, geometric errors "set A", MAEMM (1, 0.5) mm, read
in the paper's frame as ``zerocal simulate`` does -- ours mirrored about the
x axis, so the true offsets in the robot's frame are (-2, +1) deg and the
MAEMM (1, -0.5) mm; see ``zerocal_sym/paper/tables.py``), the paper's six poses
(``scheme.paper_poses(robot, 3)``, visiting order as in ``docs/model.md``), the paper's
noise (Eqs. 34-35) and the random stream ``default_rng([2017, 1])``.  The
readings are the same as those of
``zerocal simulate --group 1 --seed 2017 --noise paper --n 3`` (only the
metadata lines differ).  Run from the repository root::

    python examples/make_measurements_example.py

The output is byte-for-byte reproducible (tests/test_data.py checks it).
"""
from pathlib import Path

import numpy as np

from zerocal_sym.io import measurements as data
from zerocal_sym.model import kinematics
from zerocal_sym.paper import scheme
from zerocal_sym.io.files import atomic_write_text
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.tables import group_errors
from zerocal_sym.model.robot import paper_robot

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
    err = group_errors(GROUP, "paper")
    plant = VirtualPlant(robot, err)
    readings = plant.measure(theta, NoiseModel.paper(), np.random.default_rng([SEED, GROUP]))
    meta = {"robot_sha256": robot.sha256,
            "simulated": f"paper Table 2 group {GROUP} (paper frame), noise paper, rng [{SEED}, {GROUP}] "
                         "(examples/make_measurements_example.py)",
            "true_zero_offsets_deg": " ".join(f"{v:.10g}" for v in np.degrees(err[:2])),
            "true_maemm_mm": " ".join(f"{v:.10g}" for v in err[10:12])}
    return Measurements(theta, readings, P, meta, mechanism=robot.mechanism_name)


def main():
    meas = make_example()
    data.write_measurements(HERE / "measurements_example.csv", meas)
    text = "# target positions for 'zerocal compensate --poses' (the paper's six poses), mm\npose,x_mm,y_mm\n"
    text += "".join(f"{k}," + ",".join(f"{v:g}" for v in p) + "\n" for k, p in enumerate(meas.target))
    atomic_write_text(HERE / "poses_example.csv", text)


if __name__ == "__main__":
    main()
