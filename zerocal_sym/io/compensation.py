"""The compensation table and the compensated joint commands.

Compensation table
------------------
:func:`format_compensation` and :func:`format_commands` write what
``zerocal compensate`` gives to a controller, one row per joint (table) or
per pose (commands), for the m joints and n pose coordinates of the robot's
mechanism.  Sign convention: the actual joint angle is the commanded one plus
the zero offset, so the controller *subtracts* the offset:
``theta_cmd = IK(P) - offset``.  The measurement sheet to fill in with the
compensated commands is :func:`zerocal_sym.io.measurements.format_template`
(its ``# compensation_deg:`` line is :func:`format_offsets`).
"""
from __future__ import annotations

import csv
import io
import re

import numpy as np

from zerocal_sym.io.csvtext import MECHANISM_KEY, _format_meta, get_mechanism_of, mechanism_for_shape
from zerocal_sym.io.results import SIGN_CONVENTION, ResultFile

COMPENSATION_LINE = "# zerocal compensation v1"


def _offsets(offsets_deg, m: int) -> np.ndarray:
    off = np.asarray(offsets_deg, float)
    if off.shape != (m,):
        raise ValueError(f"expected {m} zero offsets (one per joint, deg), got shape {off.shape}")
    return off


def format_offsets(offsets_deg) -> str:
    """``"2.0, -1.0[, 0.5]"``: offsets (deg, joint order) written exactly, for a ``# compensation_deg:`` line."""
    return ", ".join(repr(float(v)) for v in np.atleast_1d(np.asarray(offsets_deg, float)))


def parse_offsets(text, m: int | None = None) -> np.ndarray | None:
    """The offsets of a ``compensation_deg`` line (commas and/or blanks), or None if unreadable.

    Parameters
    ----------
    text : str or None
    m : int, optional
        The number of joints expected (None: any).
    """
    if text is None:
        return None
    vals = [v for v in re.split(r"[,\s]+", str(text).strip()) if v]
    try:
        out = np.array([float(v) for v in vals])
    except ValueError:
        return None
    if out.size == 0 or (m is not None and out.shape != (m,)) or not np.all(np.isfinite(out)):
        return None
    return out


def compensated_commands(robot, P, offsets_deg) -> tuple[np.ndarray, np.ndarray]:
    """Nominal and compensated joint commands for target positions.

    Parameters
    ----------
    robot : Robot
    P : ndarray, shape (K, n)
        Target positions, mm.
    offsets_deg : array_like, shape (m,)
        Identified zero offsets, deg, joint order.

    Returns
    -------
    theta_nominal : ndarray, shape (K, m)
        ``IK(P)``, rad.
    theta_cmd : ndarray, shape (K, m)
        ``IK(P) - offset``, rad (what to command).

    Raises
    ------
    PoseError
        For an unreachable pose.
    ValueError
        Offsets or poses of the wrong size.
    """
    from zerocal_sym.model import kinematics as kin

    off = _offsets(offsets_deg, robot.m)
    nominal = kin.ik(robot, np.atleast_2d(np.asarray(P, float)))
    return nominal, nominal - np.radians(off)


def _mechanism(mechanism, m, n=None, declared=None):
    """The Mechanism named (or of the robot), else the only one with these sizes, else None."""
    for spec in (mechanism, declared):
        if spec is not None:
            return get_mechanism_of(spec)
    return mechanism_for_shape(m, n)


def format_compensation(result: ResultFile, meta: dict | None = None, mechanism=None) -> str:
    """The compensation table a controller takes (offsets in degrees), one row per joint.

    Parameters
    ----------
    result : ResultFile
    meta : dict, optional
    mechanism : str, Mechanism or Robot, optional
        For the joint names; default ``result.mechanism``.

    Returns
    -------
    str
        CSV ``joint,offset_deg,std_deg`` with comment lines stating the sign
        convention (and the mechanism).
    """
    m = len(result.zero_offsets_deg)
    mech = _mechanism(mechanism, m, declared=result.mechanism)
    joints = list(mech.joint_names) if mech is not None else [f"theta{j + 1}" for j in range(m)]
    if len(joints) != m:
        raise ValueError(f"{m} zero offsets for the {len(joints)} joints of mechanism {mech.name}")
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION, **({MECHANISM_KEY: mech.name} if mech else {}),
                           "method": result.method, "status": result.status,
                           **({"robot_sha256": result.robot_sha256} if result.robot_sha256 else {}),
                           **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["joint", "offset_deg", "std_deg"])
    for j, name in enumerate(joints):
        s = result.std_zero_offsets_deg[j]
        w.writerow([name, repr(float(result.zero_offsets_deg[j])), "" if not np.isfinite(s) else repr(float(s))])
    return buf.getvalue()


def command_columns(mechanism) -> list:
    """``pose, x_mm, y_mm[, z_mm], theta1_nominal_deg, ..., theta1_cmd_deg, ...`` of ``mechanism``."""
    mech = get_mechanism_of(mechanism)
    return (["pose"] + [p + "_mm" for p in mech.pose_names] + [j + "_nominal_deg" for j in mech.joint_names]
            + [j + "_cmd_deg" for j in mech.joint_names])


def format_commands(P, theta_nominal, theta_cmd, offsets_deg, meta: dict | None = None, mechanism=None) -> str:
    """Compensated joint commands for a pose list, as CSV.

    Parameters
    ----------
    P : ndarray, shape (K, n)
        mm.
    theta_nominal, theta_cmd : ndarray, shape (K, m)
        rad.
    offsets_deg : (m,)
    meta : dict, optional
    mechanism : str, Mechanism or Robot, optional
        For the column names; default the registered mechanism with these
        sizes.

    Returns
    -------
    str
        ``pose,x_mm,y_mm[,z_mm],theta1_nominal_deg,...,theta1_cmd_deg,...``
        (:func:`command_columns`).

    Raises
    ------
    ValueError
        Sizes that do not fit each other or the mechanism.
    """
    P = np.atleast_2d(np.asarray(P, float))
    nom = np.degrees(np.atleast_2d(np.asarray(theta_nominal, float)))
    cmd = np.degrees(np.atleast_2d(np.asarray(theta_cmd, float)))
    K, n = P.shape
    m = nom.shape[1]
    if nom.shape != (K, m) or cmd.shape != (K, m):
        raise ValueError(f"theta_nominal and theta_cmd must have shape ({K}, m), got {nom.shape} and {cmd.shape}")
    off = _offsets(offsets_deg, m)
    mech = _mechanism(mechanism, m, n)
    if mech is None:
        raise ValueError(f"no single registered mechanism has {m} joints and {n} pose coordinates: pass mechanism=")
    if (mech.m, mech.n) != (m, n):
        raise ValueError(f"mechanism {mech.name} has {mech.m} joints and {mech.n} pose coordinates, got {m} and {n}")
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION, MECHANISM_KEY: mech.name, "offset_deg": format_offsets(off),
                           **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(command_columns(mech))
    for k in range(K):
        w.writerow([k] + [repr(float(v)) for v in (*P[k], *nom[k], *cmd[k])])
    return buf.getvalue()
