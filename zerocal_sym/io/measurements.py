"""The measurement file format (CSV): writing, the template, the loader.

Measurement file
----------------
One row per measurement pose, in the order the robot visited them::

    # zerocal measurements v1
    # robot_sha256: 2eaac3c7...          (optional "# key: value" metadata)
    pose,theta1_deg,theta2_deg,reading_mm,x_mm,y_mm
    0,22.7339158,207.8070466,0,-240,632
    1,-2.6520186,182.6520186,-0.3517829,0,632
    ...

* ``pose``: 0, 1, ..., K-1 (the order matters: the scale measures changes).
* ``theta1_deg, theta2_deg``: the joint angles the controller *commanded*
  (nominal inverse kinematics minus any compensation already applied), deg.
* ``reading_mm``: the linear scale's reading at this pose; the reading head is
  reset after each reading, so it is the change of the measuring-mechanism
  length since the previous pose; 0 at pose 0.
* ``x_mm, y_mm`` (optional, both or neither): the nominal target position.

Columns may come in any order; the separator is a comma; ``#`` starts a
comment line; blank lines are ignored; a UTF-8 byte-order mark is accepted.
Every error is a :class:`~zerocal_sym.errors.DataFileError` naming the file,
the line and, where there is one, the column (by name and field number).
The full specification, with the results JSON and the compensation table, is
``docs/data-format.md``.

The arrays themselves are :class:`zerocal_sym.model.measurements.Measurements`;
the pose file is :mod:`zerocal_sym.io.poses`, the results JSON
:mod:`zerocal_sym.io.results`, the compensation table
:mod:`zerocal_sym.io.compensation`.
"""
from __future__ import annotations

import csv
import io

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (_check_header, _check_pose_numbers, _format_meta, _read_text,
                                    _rows_to_records, _split_csv)
from zerocal_sym.io.files import atomic_write_text
from zerocal_sym.model.measurements import Measurements, _check_arrays

REQUIRED_COLUMNS = ("pose", "theta1_deg", "theta2_deg", "reading_mm")
OPTIONAL_COLUMNS = ("x_mm", "y_mm")
FORMAT_LINE = "# zerocal measurements v1"
FORMAT_VERSION = 1
#: commanded poses farther than this outside the workspace are rejected (mm);
#: compensation moves commanded angles by a few degrees, i.e. a few mm.
WORKSPACE_TOL_MM = 25.0
#: the commanded joint angles must reach within this of the target (x_mm, y_mm)
#: (catches radians written as degrees and swapped columns; a compensation of
#: a few degrees moves the platform by some 10 mm).
TARGET_TOL_MM = 50.0
MIN_POSES = 5
#: two poses whose commanded angles agree to this (deg) are the same pose
DUPLICATE_TOL_DEG = 1e-9


# --------------------------------------------------------------------------- writing

def format_measurements(meas: Measurements) -> str:
    """CSV text of ``meas`` in the documented format (floats written exactly)."""
    theta, readings, target = _check_arrays(meas.theta_cmd, meas.readings, meas.target)
    buf = io.StringIO()
    buf.write(FORMAT_LINE + "\n")
    buf.write(_format_meta(meas.meta))
    cols = list(REQUIRED_COLUMNS) + (list(OPTIONAL_COLUMNS) if target is not None else [])
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    deg = np.degrees(theta)
    for k in range(theta.shape[0]):
        row = [k, repr(float(deg[k, 0])), repr(float(deg[k, 1])), repr(float(readings[k]))]
        if target is not None:
            row += [repr(float(target[k, 0])), repr(float(target[k, 1]))]
        w.writerow(row)
    return buf.getvalue()


def write_measurements(path, meas: Measurements) -> None:
    """Write ``meas`` to ``path`` atomically."""
    atomic_write_text(path, format_measurements(meas))


def format_template(theta_cmd, target=None, meta=None) -> str:
    """A measurement file to fill in: the poses to visit, ``reading_mm`` blank.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, 2)
        Joint angles to command, rad.
    target : ndarray, shape (K, 2), optional
        Nominal target positions, mm.
    meta : dict, optional

    Returns
    -------
    str
        The file; ``reading_mm`` is 0 at pose 0 and empty elsewhere (the
        loader refuses the file until every reading is filled in).
    """
    theta_cmd, _, target = _check_arrays(theta_cmd, None, target)
    buf = io.StringIO()
    buf.write(FORMAT_LINE + "\n")
    buf.write(_format_meta({"note": "fill in reading_mm: the scale reading at each pose (head reset after each)",
                           **(meta or {})}))
    cols = list(REQUIRED_COLUMNS) + (list(OPTIONAL_COLUMNS) if target is not None else [])
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    deg = np.degrees(theta_cmd)
    for k in range(theta_cmd.shape[0]):
        row = [k, repr(float(deg[k, 0])), repr(float(deg[k, 1])), "0" if k == 0 else ""]
        if target is not None:
            row += [repr(float(target[k, 0])), repr(float(target[k, 1]))]
        w.writerow(row)
    return buf.getvalue()


# --------------------------------------------------------------------------- reading

def load_measurements(path, robot=None, min_poses: int = MIN_POSES) -> Measurements:
    """Read and validate a measurement CSV.

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given: every commanded pose must be reachable and (within
        :data:`WORKSPACE_TOL_MM`) inside the robot's workspace; the targets
        (if any) inside the workspace and within :data:`TARGET_TOL_MM` of
        where the commanded angles lead; a ``robot_sha256`` metadata line
        must match the robot.
    min_poses : int
        At least this many poses (5 for the paper's 4 parameters).

    Returns
    -------
    Measurements
        ``theta_cmd`` shape (K, 2) rad, ``readings`` shape (K,) mm,
        ``target`` shape (K, 2) mm or None.

    Raises
    ------
    DataFileError
        With ``file:line: column 'name' (field j): ...``.
    """
    text, src = _read_text(path)
    meta, meta_lines, rows = _split_csv(text, src, "# zerocal measurements", FORMAT_VERSION)
    example = ",".join(REQUIRED_COLUMNS) + "[,x_mm,y_mm]"
    if not rows:
        raise DataFileError(f"empty file: no header line and no data (expected the header {example})", where=src)
    header_line, header = rows[0]
    _check_header(header, header_line, src, REQUIRED_COLUMNS + OPTIONAL_COLUMNS, REQUIRED_COLUMNS, example)
    has_xy = [c in header for c in OPTIONAL_COLUMNS]
    if any(has_xy) and not all(has_xy):
        raise DataFileError("columns x_mm and y_mm go together (both or neither)", where=f"{src}:{header_line}")
    data = rows[1:]
    if not data:
        raise DataFileError("no data rows after the header", where=f"{src}:{header_line}")
    values, lines = _rows_to_records(data, header, src)
    _check_pose_numbers(values, lines, src, header.index("pose") + 1)
    K = len(values)
    if values[0]["reading_mm"] != 0.0:
        raise DataFileError(f"column 'reading_mm' (field {header.index('reading_mm') + 1}): the reading at pose 0 "
                            f"must be 0 (the head is reset there), got {values[0]['reading_mm']:g}",
                            where=f"{src}:{lines[0]}")
    theta = np.radians(np.array([[r["theta1_deg"], r["theta2_deg"]] for r in values]))
    readings = np.array([r["reading_mm"] for r in values])
    target = np.array([[r["x_mm"], r["y_mm"]] for r in values]) if all(has_xy) else None
    meas = Measurements(theta, readings, target, meta, src, lines, meta_lines)
    if K < min_poses:
        raise DataFileError(f"too few poses: {K} (at least {min_poses} are needed to identify the parameters)",
                            where=src)
    _check_duplicates(meas)
    if robot is not None:
        check_against_robot(meas, robot)
    return meas


def _check_duplicates(meas: Measurements) -> None:
    deg = np.degrees(meas.theta_cmd)
    for k in range(1, meas.K):
        d = np.max(np.abs(deg[:k] - deg[k]), axis=1)
        j = int(np.argmin(d))
        if d[j] <= DUPLICATE_TOL_DEG:
            raise DataFileError(f"duplicated pose: pose {k} repeats the commanded joint angles of pose {j} "
                                f"(line {meas.lines[j]})", where=meas.where(k))
        if meas.target is not None:
            dt = np.max(np.abs(meas.target[:k] - meas.target[k]), axis=1)
            j = int(np.argmin(dt))
            if dt[j] <= 1e-9:
                raise DataFileError(f"duplicated pose: pose {k} repeats the target (x_mm, y_mm) of pose {j} "
                                    f"(line {meas.lines[j]})", where=meas.where(k))


def check_against_robot(meas: Measurements, robot) -> None:
    """Every commanded pose reachable and inside the workspace (see :func:`load_measurements`).

    Raises
    ------
    DataFileError
    """
    from zerocal_sym.model import kinematics as kin

    sha = meas.meta.get("robot_sha256")
    if sha and sha != robot.sha256:
        line = meas.meta_lines.get("robot_sha256")
        raise DataFileError(
            f"measured on another robot: robot_sha256 {sha[:12]}... in the file, {robot.sha256[:12]}... for "
            f"{robot.source} (pass the right --robot, or delete the line if the geometry is the same)",
            where=f"{meas.source}:{line}" if line else meas.source)
    with np.errstate(all="ignore"):
        P = kin.fk(robot, meas.theta_cmd)
    lo, hi = robot.workspace_bounds()
    for k in range(meas.K):
        if not np.all(np.isfinite(P[k])):
            t1, t2 = np.degrees(meas.theta_cmd[k])
            raise DataFileError(f"commanded joint angles ({t1:g}, {t2:g}) deg are not an assembly of the robot "
                                "(unreachable pose; angles in degrees?)", where=meas.where(k))
        pts = [("commanded", P[k], WORKSPACE_TOL_MM)]
        if meas.target is not None:
            pts.append(("target (x_mm, y_mm)", meas.target[k], 1e-6))
        for what, p, tol in pts:
            if np.any(p < lo - tol) or np.any(p > hi + tol):
                raise DataFileError(
                    f"{what} pose ({p[0]:.3f}, {p[1]:.3f}) mm is outside the workspace "
                    f"x in [{lo[0]:g}, {hi[0]:g}], y in [{lo[1]:g}, {hi[1]:g}] (tolerance {tol:g} mm)",
                    where=meas.where(k))
        if meas.target is not None:
            dist = float(np.linalg.norm(P[k] - meas.target[k]))
            if dist > TARGET_TOL_MM:
                raise DataFileError(
                    f"the commanded joint angles reach ({P[k, 0]:.3f}, {P[k, 1]:.3f}) mm, {dist:.1f} mm from the "
                    f"target ({meas.target[k, 0]:g}, {meas.target[k, 1]:g}) mm (more than {TARGET_TOL_MM:g} mm: "
                    "columns swapped, or angles not in degrees?)", where=meas.where(k))
