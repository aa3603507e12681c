"""The compensation table and the compensated joint commands.

Compensation table
------------------
:func:`format_compensation` and :func:`format_commands` write what
``zerocal compensate`` gives to a controller.  Sign convention: the actual
joint angle is the commanded one plus the zero offset, so the controller
*subtracts* the offset: ``theta_cmd = IK(P) - offset``.
"""
from __future__ import annotations

import csv
import io

import numpy as np

from zerocal_sym.io.csvtext import _format_meta
from zerocal_sym.io.results import ResultFile

COMPENSATION_LINE = "# zerocal compensation v1"
SIGN_CONVENTION = "theta_cmd = IK(P) - offset_deg (actual joint angle = commanded + offset)"


def compensated_commands(robot, P, offsets_deg) -> tuple[np.ndarray, np.ndarray]:
    """Nominal and compensated joint commands for target positions.

    Parameters
    ----------
    robot : Robot
    P : ndarray, shape (K, 2)
        Target positions, mm.
    offsets_deg : array_like, shape (2,)
        Identified zero offsets, deg.

    Returns
    -------
    theta_nominal : ndarray, shape (K, 2)
        ``IK(P)``, rad.
    theta_cmd : ndarray, shape (K, 2)
        ``IK(P) - offset``, rad (what to command).

    Raises
    ------
    PoseError
        For an unreachable pose.
    """
    from zerocal_sym.model import kinematics as kin

    nominal = kin.ik(robot, np.atleast_2d(np.asarray(P, float)))
    return nominal, nominal - np.radians(np.asarray(offsets_deg, float))


def format_compensation(result: ResultFile, meta: dict | None = None) -> str:
    """The compensation table a controller takes (offsets in degrees).

    Returns
    -------
    str
        CSV ``joint,offset_deg,std_deg`` with comment lines stating the sign
        convention.
    """
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION, "method": result.method, "status": result.status,
                           **({"robot_sha256": result.robot_sha256} if result.robot_sha256 else {}),
                           **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["joint", "offset_deg", "std_deg"])
    for j in range(2):
        s = result.std_zero_offsets_deg[j]
        w.writerow([f"theta{j + 1}", repr(float(result.zero_offsets_deg[j])), "" if not np.isfinite(s) else
                    repr(float(s))])
    return buf.getvalue()


def format_commands(P, theta_nominal, theta_cmd, offsets_deg, meta: dict | None = None) -> str:
    """Compensated joint commands for a pose list, as CSV.

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        mm.
    theta_nominal, theta_cmd : ndarray, shape (K, 2)
        rad.
    offsets_deg : (2,)

    Returns
    -------
    str
        ``pose,x_mm,y_mm,theta1_nominal_deg,theta2_nominal_deg,theta1_cmd_deg,theta2_cmd_deg``.
    """
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION,
                           "offset_deg": f"{float(offsets_deg[0])!r}, {float(offsets_deg[1])!r}", **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["pose", "x_mm", "y_mm", "theta1_nominal_deg", "theta2_nominal_deg", "theta1_cmd_deg",
                "theta2_cmd_deg"])
    n, c = np.degrees(theta_nominal), np.degrees(theta_cmd)
    for k in range(len(P)):
        w.writerow([k] + [repr(float(v)) for v in (P[k, 0], P[k, 1], n[k, 0], n[k, 1], c[k, 0], c[k, 1])])
    return buf.getvalue()
