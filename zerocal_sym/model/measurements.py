"""One identification round of measurements, as arrays (the model layer).

:class:`Measurements` holds what a round measured: the commanded joint angles
(m joints), the scale readings and, optionally, the nominal target positions
(n pose coordinates), for any mechanism.  Reading and writing the measurement
file is :mod:`zerocal_sym.io.measurements`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Measurements:
    """One identification round of measurements.

    Attributes
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joint angles, rad (joint order of the mechanism).
    readings : ndarray, shape (K,)
        Scale readings, mm; ``readings[0] == 0``.
    target : ndarray, shape (K, n) or None
        Nominal target positions, mm (pose-coordinate order).
    meta : dict
        ``# key: value`` header lines.
    source : str
    lines : list of int
        File line of each pose (for messages).
    meta_lines : dict
        File line of each metadata key.
    mechanism : str or None
        Name of the mechanism measured (``planar_2dof``, ``delta_rotary``), if
        known: the file's ``# mechanism:`` line, or the robot it was loaded
        or simulated for.

    Raises
    ------
    ValueError
        Inconsistent shapes (checked on construction; values are not).
    """

    theta_cmd: np.ndarray
    readings: np.ndarray
    target: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    source: str = "<memory>"
    lines: list = field(default_factory=list)
    meta_lines: dict = field(default_factory=dict)
    mechanism: str | None = None

    def __post_init__(self):
        self.theta_cmd, self.readings, self.target = _check_shapes(self.theta_cmd, self.readings, self.target)

    @property
    def K(self) -> int:
        return self.theta_cmd.shape[0]

    @property
    def m(self) -> int:
        """Actuated joints (columns of ``theta_cmd``)."""
        return self.theta_cmd.shape[1]

    @property
    def n(self) -> int | None:
        """Pose coordinates (columns of ``target``), None without targets."""
        return None if self.target is None else self.target.shape[1]

    @property
    def changes(self) -> np.ndarray:
        """The K-1 measured changes ``s_k``, shape (K-1,)."""
        return self.readings[1:]

    def where(self, k: int) -> str:
        """``file:line`` of pose k."""
        line = self.lines[k] if k < len(self.lines) else None
        return f"{self.source}:{line}" if line else f"{self.source}: pose {k}"

    def check_robot(self, robot) -> None:
        """Raise ValueError unless the shapes (and the mechanism, if known) fit ``robot``."""
        mech = robot.mechanism
        if self.mechanism is not None and self.mechanism != mech.name:
            raise ValueError(f"measurements of mechanism {self.mechanism!r}, the robot is {mech.name!r}")
        _check_shapes(self.theta_cmd, self.readings, self.target, mech.m, mech.n)


def _check_shapes(theta_cmd, readings, target, m=None, n=None):
    """Arrays as float; shapes (K, m), (K,), (K, n) or None (m, n from the arrays unless given)."""
    theta_cmd = np.asarray(theta_cmd, float)
    if theta_cmd.ndim != 2 or theta_cmd.shape[1] < 1 or (m is not None and theta_cmd.shape[1] != m):
        raise ValueError(f"theta_cmd must have shape (K, {'m' if m is None else m}), got {theta_cmd.shape}")
    K = theta_cmd.shape[0]
    if readings is not None:
        readings = np.asarray(readings, float)
        if readings.shape != (K,):
            raise ValueError(f"readings must have shape ({K},), got {readings.shape}")
    if target is not None:
        target = np.asarray(target, float)
        if target.ndim != 2 or target.shape[0] != K or target.shape[1] < 1 or (n is not None and target.shape[1] != n):
            raise ValueError(f"target must have shape ({K}, {'n' if n is None else n}), got {target.shape}")
    return theta_cmd, readings, target


def _check_arrays(theta_cmd, readings, target, m=None, n=None):
    """:func:`_check_shapes` and every value finite (what a file may hold)."""
    theta_cmd, readings, target = _check_shapes(theta_cmd, readings, target, m, n)
    for name, a in (("theta_cmd", theta_cmd), ("readings", readings), ("target", target)):
        if a is not None and not np.all(np.isfinite(a)):
            raise ValueError(f"{name} has non-finite values")
    return theta_cmd, readings, target
