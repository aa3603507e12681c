"""Units: the one place that turns internal values into file and command-line values and back.

Inside, every angle is in rad and every length in mm.  Files, tables and the
command line carry angles in degrees and lengths in mm, and every key, column
or option that carries a value names its unit (``theta1_deg``, ``s1_mm``,
``zero_offsets_deg``, ``zero_offsets_mm``).  The unit comes from the kind of
the quantity -- a joint's kind (:data:`JOINT_KINDS`), a source error's or a
pose coordinate's unit -- never from its name.

Joint kinds
-----------
``revolute``
    the joint variable is an angle: rad inside, degrees outside;
``prismatic``
    the joint variable is a length: mm inside and outside.
"""
from __future__ import annotations

import numpy as np

#: joint kind -> internal unit of the joint variable (and of its zero offset)
JOINT_KINDS = {"revolute": "rad", "prismatic": "mm"}
#: internal unit -> the unit files and the command line use
USER_UNIT = {"rad": "deg", "mm": "mm"}
#: joint kind -> the unit files and the command line use
UNIT_OF_KIND = {kind: USER_UNIT[unit] for kind, unit in JOINT_KINDS.items()}


def to_user(value, unit: str):
    """``value`` (internal ``unit``: rad or mm) in file units (deg or mm); arrays kept as arrays."""
    if unit == "rad":
        return np.degrees(value)
    if unit == "mm":
        return value
    raise ValueError(f"unknown unit {unit!r}")


def from_user(value, unit: str):
    """``value`` in file units (deg or mm) in the internal ``unit`` (rad or mm)."""
    if unit == "rad":
        return np.radians(value)
    if unit == "mm":
        return value
    raise ValueError(f"unknown unit {unit!r}")


def user_unit(unit: str) -> str:
    """The file unit of an internal unit: ``deg`` for ``rad``, ``mm`` for ``mm``."""
    return USER_UNIT[unit]


def key(stem: str, unit: str) -> str:
    """``<stem>_<file unit>`` of a value in the internal ``unit``: ``key("zero_offsets", "rad")`` is
    ``zero_offsets_deg``."""
    return f"{stem}_{USER_UNIT[unit]}"


def joint_key(mech, stem: str) -> str:
    """``<stem>_deg`` or ``<stem>_mm`` after the mechanism's joint kind (``mech``: a Mechanism or Robot)."""
    mech = getattr(mech, "mechanism", mech)
    return key(stem, mech.joint_unit)


def joints_to_user(mech, values):
    """Joint values (or zero offsets) in file units, shape kept."""
    return to_user(np.asarray(values, float), getattr(mech, "mechanism", mech).joint_unit)


def joints_from_user(mech, values):
    """Joint values (or zero offsets) from file units to internal units, shape kept."""
    return from_user(np.asarray(values, float), getattr(mech, "mechanism", mech).joint_unit)


def joint_unit(mech) -> str:
    """The joints' file unit (``deg`` | ``mm``)."""
    return getattr(mech, "mechanism", mech).joint_user_unit


def _convert_orientations(mech, P, fn):
    """A copy of the poses ``P`` (shape (..., n)) with ``fn`` applied to the orientation coordinates."""
    mech = getattr(mech, "mechanism", mech)
    P = np.array(P, float)
    for i, name in enumerate(mech.pose_names):
        if mech.pose_units.get(name, "mm") == "rad":
            P[..., i] = fn(P[..., i])
    return P


def pose_to_user(mech, P):
    """Poses (shape (..., n)) in file units: orientation coordinates in degrees."""
    return _convert_orientations(mech, P, np.degrees)


def pose_from_user(mech, P):
    """Poses (shape (..., n)) from file units (degrees for orientations) to internal units."""
    return _convert_orientations(mech, P, np.radians)


def pose_unit(mech, name: str) -> str:
    """File unit of the pose coordinate ``name`` (``mm`` | ``deg``)."""
    mech = getattr(mech, "mechanism", mech)
    return USER_UNIT[mech.pose_units.get(name, "mm")]


def pose_key(mech, stem: str) -> str:
    """``<stem>_mm`` for a pose of lengths only; ``<stem>`` for one with orientations (its units listed beside
    it as ``pose_units``)."""
    mech = getattr(mech, "mechanism", mech)
    return f"{stem}_mm" if all(mech.pose_units.get(p, "mm") == "mm" for p in mech.pose_names) else stem


#: what the joint variables of a kind are called in messages
JOINT_NOUN = {"revolute": "joint angles", "prismatic": "joint positions"}


def joint_noun(mech) -> str:
    """``joint angles`` (revolute) or ``joint positions`` (prismatic), for messages."""
    return JOINT_NOUN[getattr(mech, "mechanism", mech).joint_kind]


def unit_hint(mech) -> str:
    """``angles in degrees?`` or ``positions in mm?``: what to check when joints look wrong."""
    mech = getattr(mech, "mechanism", mech)
    return "angles in degrees?" if mech.joint_kind == "revolute" else "positions in mm?"


def rename_unit_keys(obj, unit: str, stem: str = "_deg"):
    """A report (nested dicts and lists) with every key ending in ``_deg`` renamed to end in ``_<unit>``: a report
    of offsets written with the revolute spelling, for a mechanism whose offsets are in ``unit`` (``deg``: as is)."""
    if unit == stem[1:]:
        return obj
    if isinstance(obj, dict):
        return {(k[:-len(stem)] + "_" + unit if isinstance(k, str) and k.endswith(stem) else k):
                rename_unit_keys(v, unit, stem) for k, v in obj.items()}
    if isinstance(obj, list):
        return [rename_unit_keys(v, unit, stem) for v in obj]
    return obj


class DegreeViews:
    """The ``_deg`` views of zero offsets kept for revolute joints (the names files and code had before prismatic
    joints): a class with ``offset_unit`` (file unit), ``zero_offsets_user`` and ``std_zero_offsets_user`` gets
    ``zero_offsets_deg`` and ``std_zero_offsets_deg``, which raise AttributeError for offsets in mm."""

    def _degrees(self, what, values):
        if self.offset_unit != "deg":
            raise AttributeError(f"{what}: these zero offsets are in {self.offset_unit}; use "
                                 f"{what.replace('_deg', '_user').replace('_rad', '')}")
        return values

    @property
    def zero_offsets_deg(self):
        """The zero offsets in deg (revolute joints; ``zero_offsets_user`` for any)."""
        return self._degrees("zero_offsets_deg", self.zero_offsets_user)

    @property
    def std_zero_offsets_deg(self):
        """Their standard deviations in deg (revolute joints; ``std_zero_offsets_user`` for any)."""
        return self._degrees("std_zero_offsets_deg", self.std_zero_offsets_user)
