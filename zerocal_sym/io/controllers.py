"""Controller exports: a linear Delta's calibration as Klipper or RepRapFirmware configuration.

``zerocal compensate RESULT.json --format klipper|rrf`` writes the values a
delta printer's controller takes -- the geometry of the robot file and the
endstops corrected by the identified zero offsets -- instead of the
compensation table (:mod:`zerocal_sym.io.compensation`, ``--format csv``).

Which mechanisms a format describes
-----------------------------------
A :class:`ControllerFormat` declares what it can describe: joints of one
kind (``prismatic``: carriages on vertical towers), as many as it has towers
(3), and per joint ``i`` the geometry ``R<i>`` (tower radius), ``phi<i>``
(tower azimuth), ``l<i>`` (rod length) beside the shared effector radius
``r``.  Any other mechanism is refused with the formats it can use
(:func:`formats_for`); so is a robot whose towers the controller cannot
represent (tower radii ``R<i>`` that differ: both controllers have one
radius; azimuths that do not match the controller's towers one to one).

Towers: matched by angle, not by index
--------------------------------------
Klipper's steppers ``a, b, c`` and RRF's towers ``X, Y, Z`` stand at 210, 330
and 90 deg by default.  Each joint goes to the controller's tower whose
default angle is nearest its azimuth ``phi<i>`` (less than 60 deg away, one
joint per tower): with the robot file's defaults ``phi = 90, 210, 330`` deg,
``s1 -> c / Z``, ``s2 -> a / X``, ``s3 -> b / Y``.  Klipper takes the azimuth
itself (``angle``); RRF the difference from its default angle (``M665 X Y Z``,
positive anticlockwise: RRF places tower X at 210 + X deg, Y at 330 + Y deg,
Z at 90 + Z deg).  The x, y axes are the robot file's: it must be the
controller's frame.

Geometry
--------
``delta_radius`` (Klipper) and ``M665 R`` (RRF) are the horizontal distance
from a carriage's rod joint to the effector's when the rods are vertical,
``R - r``; ``arm_length`` / ``M665 L`` the rod length ``l<i>``.  Both are the
robot file's nominal values: the identification assumed that the controller
computes the carriage heights with them, so they must be the controller's.

Sign convention of the endstops
-------------------------------
The zero offset of joint ``i`` is ``actual carriage height = commanded +
offset`` (:data:`zerocal_sym.io.results.SIGN_CONVENTION`).  Both controllers
set a carriage, when its endstop triggers, to a height they compute from the
configuration -- Klipper ``position_endstop + sqrt(arm_length^2 -
delta_radius^2)``, RRF ``H + sqrt(L^2 - R^2) + M666 adjustment`` -- and command
every later height relative to it.  A carriage that is ``offset`` higher than
the controller believes is fixed by making the controller believe ``offset``
more at the trigger:

* Klipper: ``position_endstop (corrected) = position_endstop (current) + offset``;
* RRF: ``M666 adjustment (corrected) = M666 adjustment (current) + offset``,
  the convention of RRF's documentation ("positive endstop adjustments move
  the head closer to the bed when it is near the corresponding tower": the
  controller believes the carriage higher, so it drives it lower).

The current values are the controller's (``--endstop-mm``, in the
controller's tower order); without them the export states the correction to
add, as comments, and leaves the value lines out.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.io.results import sign_convention

#: every --format of ``zerocal compensate`` (csv: the compensation table, any mechanism)
FORMAT_NAMES = ("csv", "klipper", "rrf")
#: a tower's azimuth is within this of its controller tower's default angle (deg; half the spacing)
MAX_TOWER_DEVIATION_DEG = 60.0
#: tower radii R<i> that differ by more than this (mm) have no single controller radius
RADIUS_TOL_MM = 1e-9
#: a current endstop value beyond this (mm) is a typing error
ENDSTOP_LIMIT_MM = 1e5


@dataclass(frozen=True)
class ControllerFormat:
    """A controller's configuration format and the mechanisms it describes.

    Attributes
    ----------
    name : str
        The ``--format`` value.
    title : str
        How messages name the controller.
    tower_names : tuple of str
        The controller's towers, in its order.
    tower_angles_deg : tuple of float
        Their default angles (deg, anticlockwise from +x).
    digits : int
        Decimals written (the controller's own when it saves its calibration).
    comment : str
        The comment prefix of the format.
    joint_kind : str
        The kind of joint the format describes.
    tower_geometry : tuple of str
        Geometry names per joint ``i`` (1-based), ``{i}`` replaced.
    shared_geometry : tuple of str
        Geometry names the towers share.
    """

    name: str
    title: str
    tower_names: tuple
    tower_angles_deg: tuple
    digits: int
    comment: str
    joint_kind: str = "prismatic"
    tower_geometry: tuple = ("R{i}", "phi{i}", "l{i}")
    shared_geometry: tuple = ("r",)

    @property
    def towers(self) -> int:
        return len(self.tower_names)

    def geometry_names(self, m: int | None = None) -> list:
        m = self.towers if m is None else m
        return [g.format(i=i) for i in range(1, m + 1) for g in self.tower_geometry] + list(self.shared_geometry)

    def refusal(self, mechanism) -> str | None:
        """Why this format cannot describe ``mechanism`` (a Mechanism or Robot), or None if it can."""
        mech = getattr(mechanism, "mechanism", mechanism)
        kinds = sorted(set(mech.joint_kinds))
        if kinds != [self.joint_kind]:
            return f"its joints are {', '.join(kinds)}, not {self.joint_kind}"
        if mech.m != self.towers:
            return f"it has {mech.m} joints, not {self.towers}"
        missing = [g for g in self.geometry_names() if g not in mech.geometry_names]
        if missing:
            return f"its geometry has no {', '.join(missing)}"
        return None


KLIPPER = ControllerFormat("klipper", "Klipper (kinematics: delta)", ("a", "b", "c"), (210.0, 330.0, 90.0),
                           digits=6, comment="#")
RRF = ControllerFormat("rrf", "RepRapFirmware (linear delta: M665, M666)", ("X", "Y", "Z"), (210.0, 330.0, 90.0),
                       digits=3, comment=";")
FORMATS = {f.name: f for f in (KLIPPER, RRF)}


def formats_for(mechanism) -> list:
    """The ``--format`` values that can describe ``mechanism`` (``csv`` always)."""
    return ["csv"] + [name for name, f in FORMATS.items() if f.refusal(mechanism) is None]


def _wrap_deg(a):
    """An angle in (-180, 180] deg."""
    a = math.fmod(float(a), 360.0)
    if a > 180.0:
        a -= 360.0
    elif a <= -180.0:
        a += 360.0
    return a


@dataclass(frozen=True)
class Tower:
    """One controller tower and the joint it is."""

    name: str          # the controller's (a, b, c / X, Y, Z)
    default_deg: float  # the controller's default angle
    joint: int         # 0-based index of the joint
    joint_name: str
    azimuth_deg: float  # phi<i>, in [0, 360)
    rod_mm: float       # l<i>


@dataclass(frozen=True)
class DeltaDescription:
    """What a controller format takes from the robot: its towers in the controller's order and the radius."""

    fmt: ControllerFormat
    towers: tuple
    radius_mm: float   # R - r

    def correction(self, offsets_mm):
        """The offsets (joint order) in the controller's tower order."""
        off = np.asarray(offsets_mm, float)
        return np.array([off[t.joint] for t in self.towers])


def describe(fmt, robot) -> DeltaDescription:
    """The towers of ``robot`` as the controller format ``fmt`` (a name or ControllerFormat) sees them.

    Raises
    ------
    ZerocalError
        A mechanism the format cannot describe (naming the formats it can use), tower radii
        that differ, or azimuths that do not match the controller's towers one to one.
    """
    fmt = FORMATS[fmt] if isinstance(fmt, str) else fmt
    mech = robot.mechanism
    why = fmt.refusal(mech)
    if why is not None:
        raise ZerocalError(f"--format {fmt.name}: {fmt.title} cannot describe mechanism {mech.name} ({why}; it "
                           f"describes {fmt.towers} {fmt.joint_kind} joints with geometry "
                           f"{', '.join(fmt.geometry_names())}); the formats of {mech.name}: "
                           f"{', '.join(formats_for(mech))}")
    m = fmt.towers
    names = [[g.format(i=i) for g in fmt.tower_geometry] for i in range(1, m + 1)]
    r = sum(robot.param(g) for g in fmt.shared_geometry)
    radii = np.array([robot.param(n[0]) for n in names])
    if float(np.ptp(radii)) > RADIUS_TOL_MM:
        raise ZerocalError(f"--format {fmt.name}: {fmt.title} has one tower radius; the robot file's "
                           f"{', '.join(n[0] for n in names)} differ ({', '.join(f'{v:g}' for v in radii)} mm)")
    phis = [math.degrees(robot.param(n[1])) % 360.0 for n in names]
    towers = []
    for name, default in zip(fmt.tower_names, fmt.tower_angles_deg):
        near = [j for j in range(m) if abs(_wrap_deg(phis[j] - default)) < MAX_TOWER_DEVIATION_DEG]
        if len(near) != 1:
            raise ZerocalError(
                f"--format {fmt.name}: the tower azimuths {', '.join(n[1] for n in names)} = "
                f"{', '.join(f'{p:g}' for p in phis)} deg do not match {fmt.title}'s towers "
                f"{', '.join(fmt.tower_names)} at {', '.join(f'{a:g}' for a in fmt.tower_angles_deg)} deg one to "
                f"one (each within {MAX_TOWER_DEVIATION_DEG:g} deg)")
        j = near[0]
        towers.append(Tower(name, default, j, mech.joint_names[j], phis[j], robot.param(names[j][2])))
    return DeltaDescription(fmt, tuple(towers), float(radii[0] - r))


def parse_endstops(text, fmt=None) -> np.ndarray:
    """``--endstop-mm``: one value (every tower) or three, comma-separated, in the controller's tower order.

    Raises
    ------
    ValueError
        Not one or three finite numbers within +-:data:`ENDSTOP_LIMIT_MM`.
    """
    order = f" ({', '.join(FORMATS[fmt].tower_names)})" if fmt in FORMATS else ""
    vals = [v for v in re.split(r"[,\s]+", str(text).strip()) if v]
    try:
        out = np.array([float(v) for v in vals])
    except ValueError:
        out = None
    if out is None or out.size not in (1, 3) or not np.all(np.isfinite(out)):
        raise ValueError(f"--endstop-mm {text!r}: one number (every tower) or three, comma-separated, in the "
                         f"controller's tower order{order}")
    if np.any(np.abs(out) > ENDSTOP_LIMIT_MM):
        raise ValueError(f"--endstop-mm {text!r}: beyond +-{ENDSTOP_LIMIT_MM:g} mm")
    return np.broadcast_to(out, (3,)).copy()


def _fmt(v, digits) -> str:
    s = f"{float(v):.{digits}f}"
    return "0." + "0" * digits if re.fullmatch(r"-0\.0*", s) else s  # no "-0.000"


def _plus(v, digits) -> str:
    """``+ 0.8`` / ``- 0.5``: a correction to add."""
    return f"{'-' if round(float(v), digits) < 0 else '+'} {_fmt(abs(v), digits)}"


def _other_identified(robot, result) -> list:
    """Geometry errors the result identified too (not exported: the export corrects the endstops)."""
    errors = robot.errors
    return [(n, v, errors[n].user_unit) for n, v in result.estimate.items()
            if n in errors.geometry]


def _std(v) -> str:
    return "" if not np.isfinite(v) else f" (std {float(v):.3g})"


def _header(desc, robot, result, meta, endstops: list) -> list:
    """The comment lines every controller export starts with: what, from what, the conventions."""
    fmt, c = desc.fmt, desc.fmt.comment
    lines = [f"{c} zerocal compensation v1: {fmt.title}",
             f"{c} robot: {robot.name} ({robot.source}), mechanism {robot.mechanism_name}",
             f"{c} robot_sha256: {robot.sha256}",
             f"{c} result: {(meta or {}).get('result', result.source)} ({result.method}, {result.status})",
             f"{c} sign: {sign_convention('mm')}"]
    lines += [f"{c} {e}" for e in endstops]
    lines += [f"{c} towers by azimuth: " + ", ".join(f"{t.name} = {t.joint_name} ({t.azimuth_deg:g} deg)"
                                                     for t in desc.towers),
              f"{c} geometry: the robot file's (radius R - r, rod length l, azimuth phi): it must be the controller's"]
    other = _other_identified(robot, result)
    if other:
        lines.append(f"{c} also identified, not exported (this export corrects the endstops only): "
                     + ", ".join(f"{n} {v:+.6g} {u}" for n, v, u in other))
    return lines


def format_klipper(robot, result, endstop_mm=None, meta=None) -> str:
    """The Klipper configuration values of a delta printer, the endstops corrected by ``result``'s offsets.

    Parameters
    ----------
    robot : Robot
    result : ResultFile
        Zero offsets in mm (joint order).
    endstop_mm : array_like, shape (3,), optional
        The current ``position_endstop`` of ``stepper_a, _b, _c``.  Without
        it the corrections are written as comments (``position_endstop:
        <current> + 0.800000``) and no ``position_endstop`` line.
    meta : dict, optional
        ``result``: how the header names the result file.

    Returns
    -------
    str
        ``[printer]`` (``kinematics``, ``delta_radius``) and ``[stepper_a]``
        .. ``[stepper_c]`` (``angle``, ``arm_length``, ``position_endstop``).
    """
    desc = describe(KLIPPER, robot)
    d, c = KLIPPER.digits, KLIPPER.comment
    corr = desc.correction(result.zero_offsets_user)
    std = desc.correction(result.std_zero_offsets_user)
    lines = _header(desc, robot, result, meta, [
        "endstops: position_endstop (corrected) = position_endstop (current) + offset_mm",
        "  (Klipper sets a carriage to position_endstop + sqrt(arm_length^2 - delta_radius^2) when its endstop "
        "triggers)"])
    if endstop_mm is None:
        lines.append(f"{c} no --endstop-mm: add each offset to the current position_endstop (the commented lines)")
    lines.append(f"{c} merge into printer.cfg: these keys replace yours, the others stay (a SAVE_CONFIG block at its "
                 "end overrides the sections: edit them there)")
    lines += ["[printer]", "kinematics: delta", f"delta_radius: {_fmt(desc.radius_mm, d)}"]
    for k, t in enumerate(desc.towers):
        lines += ["", f"[stepper_{t.name}]", f"{c} tower {t.joint_name}: offset_mm {_fmt(corr[k], d)}{_std(std[k])}",
                  f"angle: {_fmt(t.azimuth_deg, d)}", f"arm_length: {_fmt(t.rod_mm, d)}"]
        if endstop_mm is None:
            lines.append(f"{c} position_endstop: <current> {_plus(corr[k], d)}")
        else:
            lines += [f"{c} position_endstop: {_fmt(endstop_mm[k], d)} (current) {_plus(corr[k], d)}",
                      f"position_endstop: {_fmt(endstop_mm[k] + corr[k], d)}"]
    return "\n".join(lines) + "\n"


def format_rrf(robot, result, endstop_mm=None, homed_height_mm=None, meta=None) -> str:
    """RepRapFirmware G-code for a linear delta: ``M665`` (geometry) and ``M666`` (endstop adjustments).

    Parameters
    ----------
    robot : Robot
    result : ResultFile
    endstop_mm : array_like, shape (3,), optional
        The current ``M666 X Y Z`` adjustments.  Without them the
        corrections are written as a comment (``M666 X<current> + 0.800``)
        and no ``M666`` line.
    homed_height_mm : float, optional
        ``M665 H``; without it H is left out (RRF keeps the current one).
    meta : dict, optional

    Returns
    -------
    str
        ``M665 L<rod>[:<rod>:<rod>] R<radius> [H<height>] X Y Z<angle corrections>`` and ``M666 X Y Z``.
    """
    desc = describe(RRF, robot)
    d, c = RRF.digits, RRF.comment
    corr = desc.correction(result.zero_offsets_user)
    std = desc.correction(result.std_zero_offsets_user)
    lines = _header(desc, robot, result, meta, [
        "endstops: M666 adjustment (corrected) = M666 adjustment (current) + offset_mm",
        "  (RRF sets a carriage to H + sqrt(L^2 - R^2) + adjustment when its endstop triggers: a positive adjustment",
        "  moves the head closer to the bed near its tower)"])
    for k, t in enumerate(desc.towers):
        lines.append(f"{c} tower {t.name} = {t.joint_name}: offset_mm {_fmt(corr[k], d)}{_std(std[k])}")
    rods = [_fmt(t.rod_mm, d) for t in desc.towers]
    L = rods[0] if len(set(rods)) == 1 else ":".join(rods)
    angles = " ".join(f"{t.name}{_fmt(_wrap_deg(t.azimuth_deg - t.default_deg), d)}" for t in desc.towers)
    H = "" if homed_height_mm is None else f" H{_fmt(homed_height_mm, d)}"
    if homed_height_mm is None:
        lines.append(f"{c} no --homed-height-mm: M665 without H keeps the current homed height")
    lines.append(f"M665 L{L} R{_fmt(desc.radius_mm, d)}{H} {angles}")
    if endstop_mm is None:
        lines.append(f"{c} no --endstop-mm: add each offset to the current M666 adjustment")
        lines.append(f"{c} M666 " + " ".join(f"{t.name}<current> {_plus(corr[k], d)}"
                                             for k, t in enumerate(desc.towers)))
    else:
        lines.append(f"{c} M666 current " + " ".join(f"{t.name}{_fmt(endstop_mm[k], d)}"
                                                     for k, t in enumerate(desc.towers)))
        lines.append("M666 " + " ".join(f"{t.name}{_fmt(endstop_mm[k] + corr[k], d)}"
                                        for k, t in enumerate(desc.towers)))
    return "\n".join(lines) + "\n"


def format_controller(fmt: str, robot, result, endstop_mm=None, homed_height_mm=None, meta=None) -> str:
    """:func:`format_klipper` or :func:`format_rrf` by ``--format`` name."""
    if fmt == "klipper":
        if homed_height_mm is not None:
            raise ZerocalError("--homed-height-mm is RRF's M665 H: for --format rrf only")
        return format_klipper(robot, result, endstop_mm, meta)
    if fmt == "rrf":
        return format_rrf(robot, result, endstop_mm, homed_height_mm, meta)
    raise ValueError(f"unknown controller format {fmt!r}: {', '.join(FORMATS)}")
