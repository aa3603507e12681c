"""One identification round of measurements, as arrays (the model layer).

:class:`Measurements` holds what a round measured: the commanded joint angles,
the scale readings and, optionally, the nominal target positions.  Reading and
writing the measurement file is :mod:`zerocal_sym.io.measurements`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Measurements:
    """One identification round of measurements.

    Attributes
    ----------
    theta_cmd : ndarray, shape (K, 2)
        Commanded joint angles, rad.
    readings : ndarray, shape (K,)
        Scale readings, mm; ``readings[0] == 0``.
    target : ndarray, shape (K, 2) or None
        Nominal target positions, mm.
    meta : dict
        ``# key: value`` header lines.
    source : str
    lines : list of int
        File line of each pose (for messages).
    meta_lines : dict
        File line of each metadata key.
    """

    theta_cmd: np.ndarray
    readings: np.ndarray
    target: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    source: str = "<memory>"
    lines: list = field(default_factory=list)
    meta_lines: dict = field(default_factory=dict)

    @property
    def K(self) -> int:
        return self.theta_cmd.shape[0]

    @property
    def changes(self) -> np.ndarray:
        """The K-1 measured changes ``s_k``, shape (K-1,)."""
        return self.readings[1:]

    def where(self, k: int) -> str:
        """``file:line`` of pose k."""
        line = self.lines[k] if k < len(self.lines) else None
        return f"{self.source}:{line}" if line else f"{self.source}: pose {k}"


def _check_arrays(theta_cmd, readings, target):
    theta_cmd = np.asarray(theta_cmd, float)
    if theta_cmd.ndim != 2 or theta_cmd.shape[1] != 2:
        raise ValueError(f"theta_cmd must have shape (K, 2), got {theta_cmd.shape}")
    K = theta_cmd.shape[0]
    if readings is not None:
        readings = np.asarray(readings, float)
        if readings.shape != (K,):
            raise ValueError(f"readings must have shape ({K},), got {readings.shape}")
    if target is not None:
        target = np.asarray(target, float)
        if target.shape != (K, 2):
            raise ValueError(f"target must have shape ({K}, 2), got {target.shape}")
    for name, a in (("theta_cmd", theta_cmd), ("readings", readings), ("target", target)):
        if a is not None and not np.all(np.isfinite(a)):
            raise ValueError(f"{name} has non-finite values")
    return theta_cmd, readings, target
