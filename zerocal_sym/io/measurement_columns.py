"""The columns of a measurement file, from the robot's mechanism (:func:`measurement_columns`).

``pose``, the joint angles ``<joint>_deg`` (required), ``reading_mm``
(required), the target ``<coordinate>_mm`` (optional, all or none); the file
format itself is :mod:`zerocal_sym.io.measurements`.
"""
from __future__ import annotations

from dataclasses import dataclass

from zerocal_sym.io.csvtext import get_mechanism_of, joint_columns, pose_columns


@dataclass(frozen=True)
class MeasurementColumns:
    """The columns of a measurement file of one mechanism.

    Attributes
    ----------
    mechanism : str
    joints : tuple of str
        ``theta1_deg, ...``, joint order.
    pose : tuple of str
        ``x_mm, y_mm[, z_mm]``, pose-coordinate order (the optional targets).
    """

    mechanism: str
    joints: tuple
    pose: tuple

    @property
    def required(self) -> tuple:
        return ("pose",) + self.joints + ("reading_mm",)

    @property
    def optional(self) -> tuple:
        return self.pose

    @property
    def allowed(self) -> tuple:
        return self.required + self.optional

    @property
    def example(self) -> str:
        """``pose,theta1_deg,theta2_deg,reading_mm[,x_mm,y_mm]``."""
        return ",".join(self.required) + "[," + ",".join(self.pose) + "]"

    def header(self, targets: bool) -> list:
        return list(self.required) + (list(self.optional) if targets else [])


def measurement_columns(mechanism=None) -> MeasurementColumns:
    """The columns of the measurement file of ``mechanism`` (name, Mechanism or Robot; None: the default)."""
    mech = get_mechanism_of(mechanism)
    return MeasurementColumns(mech.name, joint_columns(mech), pose_columns(mech))
