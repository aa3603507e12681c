"""Checks of a measurement file beyond its syntax: its mechanism, repeated poses, the robot.

* :func:`_declared_mechanism`, :func:`_check_columns_fit_robot` -- the
  ``# mechanism:`` line and the columns against the robot's mechanism;
* :func:`_check_metadata` -- the ``# robot_sha256:`` line is a SHA-256 (64
  hexadecimal digits), the ``# compensation_deg:`` line one finite angle per
  joint;
* :func:`_check_duplicates` -- no pose repeats an earlier one;
* :func:`check_against_robot` -- every commanded pose reachable and inside
  the workspace (within :data:`WORKSPACE_TOL_MM`), the targets within
  :data:`TARGET_TOL_MM` of where the commanded angles lead, the
  ``robot_sha256`` line.

Each failure is a :class:`~zerocal_sym.errors.DataFileError` naming the file
and the line; called by :func:`zerocal_sym.io.measurements.load_measurements`.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import MECHANISM_KEY, infer_mechanism
from zerocal_sym.io.duplicates import first_duplicate
from zerocal_sym.io.measurement_columns import MeasurementColumns, measurement_columns
from zerocal_sym.model.measurements import Measurements

#: commanded poses farther than this outside the workspace are rejected (mm);
#: compensation moves commanded angles by a few degrees, i.e. a few mm.
WORKSPACE_TOL_MM = 25.0
#: the commanded joint angles must reach within this of the target (x_mm, y_mm, ...)
#: (catches radians written as degrees and swapped columns; a compensation of
#: a few degrees moves the platform by some 10 mm).
TARGET_TOL_MM = 50.0
#: two poses whose commanded angles agree to this (deg) are the same pose
DUPLICATE_TOL_DEG = 1e-9


def _check_metadata(meta, meta_lines, src, mech) -> None:
    """The values of the metadata lines zerocal reads, each of the right form (DataFileError naming the line)."""
    from zerocal_sym.io.compensation import parse_offsets
    from zerocal_sym.io.results import SHA256_RE

    sha = meta.get("robot_sha256")
    if sha is not None and not SHA256_RE.fullmatch(sha):
        raise DataFileError(f"'# robot_sha256:' must be the robot's SHA-256, 64 hexadecimal digits ('zerocal robot' "
                            f"prints it), got {sha[:80]!r}", where=f"{src}:{meta_lines['robot_sha256']}")
    comp = meta.get("compensation_deg")
    if comp is not None and parse_offsets(comp, mech.m) is None:
        raise DataFileError(f"'# compensation_deg:' must be {mech.m} finite angles in deg, one per joint "
                            f"({', '.join(mech.joint_names)}), got {comp[:80]!r}",
                            where=f"{src}:{meta_lines['compensation_deg']}")


def _declared_mechanism(meta, meta_lines, src, robot):
    """The file's ``# mechanism:`` (None without); unknown or not the robot's: DataFileError."""
    from zerocal_sym.model.mechanism import REGISTRY

    declared = meta.get(MECHANISM_KEY)
    if declared is None:
        return None
    where = f"{src}:{meta_lines[MECHANISM_KEY]}"
    if declared not in REGISTRY:
        raise DataFileError(f"unknown mechanism {declared!r} (known: {', '.join(REGISTRY)})", where=where)
    if robot is not None and declared != robot.mechanism_name:
        raise DataFileError(f"measured with mechanism {declared}, the robot file is {robot.mechanism_name} "
                            f"({robot.source}): pass the robot file of the measured robot", where=where)
    return declared


def _check_columns_fit_robot(header, where, robot) -> None:
    """A file without ``# mechanism:`` whose columns are exactly another mechanism's: DataFileError."""
    other = infer_mechanism(header)
    if other.name == robot.mechanism_name:
        return
    cols = measurement_columns(other)
    h = set(header)
    if set(cols.required) <= h and h - set(cols.required) in (set(), set(cols.pose)):
        raise DataFileError(f"the columns are those of mechanism {other.name} ({', '.join(cols.joints)}), "
                            f"the robot file is {robot.mechanism_name} ({robot.source}): pass the robot file of "
                            "the measured robot", where=where)


def _check_duplicates(meas: Measurements, cols: MeasurementColumns) -> None:
    """A pose that repeats an earlier one (commanded angles to 1e-9 deg, or the target to 1e-9 mm)."""
    found = [("angles", first_duplicate(np.degrees(meas.theta_cmd), DUPLICATE_TOL_DEG))]
    if meas.target is not None:
        found.append(("target", first_duplicate(meas.target, 1e-9)))
    found = [(kj, what) for what, kj in found if kj is not None]
    if not found:
        return
    (k, j), what = min(found, key=lambda f: f[0][0])  # the first pose; the angles first (min is stable)
    if what == "angles":
        raise DataFileError(f"duplicated pose: pose {k} repeats the commanded joint angles of pose {j} "
                            f"(line {meas.lines[j]})", where=meas.where(k))
    raise DataFileError(f"duplicated pose: pose {k} repeats the target ({', '.join(cols.pose)}) of "
                        f"pose {j} (line {meas.lines[j]})", where=meas.where(k))


def check_against_robot(meas: Measurements, robot) -> None:
    """The mechanism and the robot fit, every commanded pose reachable and inside the workspace.

    See :func:`~zerocal_sym.io.measurements.load_measurements`.

    Raises
    ------
    DataFileError
    """
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.kinematics import fmt_pose

    line = meas.meta_lines.get(MECHANISM_KEY)
    if meas.mechanism is not None and meas.mechanism != robot.mechanism_name:
        raise DataFileError(f"measured with mechanism {meas.mechanism}, the robot file is {robot.mechanism_name} "
                            f"({robot.source}): pass the robot file of the measured robot",
                            where=f"{meas.source}:{line}" if line else meas.source)
    cols = measurement_columns(robot)
    if meas.m != robot.m or meas.n not in (None, robot.n):
        raise DataFileError(f"{meas.m} joint and {meas.n or 0} target columns, the robot's mechanism "
                            f"{robot.mechanism_name} has {cols.example}", where=meas.source)
    sha = meas.meta.get("robot_sha256")
    if sha and sha.lower() != robot.sha256:
        line = meas.meta_lines.get("robot_sha256")
        raise DataFileError(
            f"measured on another robot: robot_sha256 {sha[:12]}... in the file, {robot.sha256[:12]}... for "
            f"{robot.source} (pass the right --robot, or delete the line if the geometry is the same)",
            where=f"{meas.source}:{line}" if line else meas.source)
    with np.errstate(all="ignore"):
        P = kin.fk(robot, meas.theta_cmd)
    ws = robot.workspace
    target_what = f"target ({', '.join(cols.pose)})"
    with np.errstate(invalid="ignore"):  # all poses at once; the first bad one is reported below
        bad = ~np.all(np.isfinite(P), axis=1) | ~ws.contains(P, WORKSPACE_TOL_MM)
        if meas.target is not None:
            bad |= ~ws.contains(meas.target, 1e-6) | ~(np.linalg.norm(P - meas.target, axis=1) <= TARGET_TOL_MM)
    for k in map(int, np.flatnonzero(bad)[:1]):
        if not np.all(np.isfinite(P[k])):
            raise DataFileError(f"commanded joint angles {fmt_pose(np.degrees(meas.theta_cmd[k]))} deg are not an "
                                "assembly of the robot (unreachable pose; angles in degrees?)", where=meas.where(k))
        pts = [("commanded", P[k], WORKSPACE_TOL_MM)]
        if meas.target is not None:
            pts.append((target_what, meas.target[k], 1e-6))
        for what, p, tol in pts:
            if not ws.contains(p, tol)[0]:
                raise DataFileError(
                    f"{what} pose {fmt_pose(p, '.3f')} mm is outside the workspace {ws.describe()} "
                    f"(tolerance {tol:g} mm)", where=meas.where(k))
        if meas.target is not None:
            dist = float(np.linalg.norm(P[k] - meas.target[k]))
            if dist > TARGET_TOL_MM:
                raise DataFileError(
                    f"the commanded joint angles reach {fmt_pose(P[k], '.3f')} mm, {dist:.1f} mm from the "
                    f"target {fmt_pose(meas.target[k])} mm (more than {TARGET_TOL_MM:g} mm: "
                    "columns swapped, or angles not in degrees?)", where=meas.where(k))
