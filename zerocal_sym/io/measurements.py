"""The measurement file format (CSV): writing, the template, the loader.

Measurement file
----------------
One row per measurement pose, in the order the robot visited them; the
columns come from the robot's mechanism (here the planar robot's)::

    # zerocal measurements v1
    # mechanism: planar_2dof             (written by zerocal; optional)
    # robot_sha256: 2eaac3c7...          (optional "# key: value" metadata)
    pose,theta1_deg,theta2_deg,reading_mm,x_mm,y_mm
    0,22.7339158,207.8070466,0,-240,632
    1,-2.6520186,182.6520186,-0.3517829,0,632
    ...

* ``pose``: 0, 1, ..., K-1 (the order matters: the scale measures changes).
* ``theta1_deg, ..., thetam_deg`` (the mechanism's joint names + ``_deg``):
  the joint angles the controller *commanded* (nominal inverse kinematics
  minus any compensation already applied), deg.
* ``reading_mm``: the linear scale's reading at this pose; the reading head is
  reset after each reading, so it is the change of the measuring-mechanism
  length since the previous pose; 0 at pose 0.
* ``x_mm, y_mm[, z_mm]`` (the mechanism's pose names + ``_mm``; optional, all
  or none): the nominal target position.
* ``# mechanism: NAME``: the mechanism measured.  A file without it is read as
  the mechanism of the robot it is checked against, or (no robot) as the
  registered mechanism whose columns it has; a file naming another mechanism
  than the robot's is refused.

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
import math
from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (MECHANISM_KEY, _check_header, _check_pose_numbers, _format_meta, _go_together,
                                    _read_text, _rows_to_array, _split_csv, get_mechanism_of, infer_mechanism,
                                    joint_columns, mechanism_for_shape, pose_columns)
from zerocal_sym.io.files import atomic_write_text
from zerocal_sym.model.measurements import Measurements, _check_arrays

FORMAT_LINE = "# zerocal measurements v1"
FORMAT_VERSION = 1
#: commanded poses farther than this outside the workspace are rejected (mm);
#: compensation moves commanded angles by a few degrees, i.e. a few mm.
WORKSPACE_TOL_MM = 25.0
#: the commanded joint angles must reach within this of the target (x_mm, y_mm, ...)
#: (catches radians written as degrees and swapped columns; a compensation of
#: a few degrees moves the platform by some 10 mm).
TARGET_TOL_MM = 50.0
MIN_POSES = 5
#: two poses whose commanded angles agree to this (deg) are the same pose
DUPLICATE_TOL_DEG = 1e-9


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


def __getattr__(name):
    # the default (planar) mechanism's columns, for code written before the mechanisms
    if name == "REQUIRED_COLUMNS":
        return measurement_columns().required
    if name == "OPTIONAL_COLUMNS":
        return measurement_columns().optional
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# --------------------------------------------------------------------------- writing

def resolve_mechanism(theta_cmd, target=None, meta=None, mechanism=None, declared=None):
    """The mechanism a writer names: given, declared, or the only one with these shapes.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
    target : ndarray, shape (K, n) or None
    meta : dict, optional
        Its ``mechanism`` entry, if any, counts as declared.
    mechanism : str, Mechanism or Robot, optional
    declared : str, optional
        :attr:`Measurements.mechanism`.

    Returns
    -------
    Mechanism

    Raises
    ------
    ValueError
        Conflicting names, an unknown one, shapes that do not fit it, or (none
        named) not exactly one registered mechanism with these shapes.
    """
    theta_cmd, _, target = _check_arrays(theta_cmd, None, target)
    named = [get_mechanism_of(x).name for x in (mechanism, declared, (meta or {}).get(MECHANISM_KEY))
             if x is not None]
    if len(set(named)) > 1:
        raise ValueError(f"conflicting mechanisms: {', '.join(dict.fromkeys(named))}")
    m, n = theta_cmd.shape[1], None if target is None else target.shape[1]
    if named:
        mech = get_mechanism_of(named[0])
        _check_arrays(theta_cmd, None, target, mech.m, mech.n)
        return mech
    mech = mechanism_for_shape(m, n)
    if mech is None:
        raise ValueError(f"no single registered mechanism has {m} joints" +
                         ("" if n is None else f" and {n} pose coordinates") + ": pass mechanism=")
    return mech


def _write(theta_cmd, readings, target, meta, mech, first_meta=None) -> str:
    cols = measurement_columns(mech)
    meta = dict(meta or {})
    meta.pop(MECHANISM_KEY, None)
    buf = io.StringIO()
    buf.write(FORMAT_LINE + "\n")
    buf.write(_format_meta({MECHANISM_KEY: mech.name, **(first_meta or {}), **meta}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols.header(target is not None))
    deg = np.degrees(theta_cmd)
    for k in range(theta_cmd.shape[0]):
        row = [k] + [repr(float(v)) for v in deg[k]]
        row.append(("0" if k == 0 else "") if readings is None else repr(float(readings[k])))
        if target is not None:
            row += [repr(float(v)) for v in target[k]]
        w.writerow(row)
    return buf.getvalue()


def format_measurements(meas: Measurements, mechanism=None) -> str:
    """CSV text of ``meas`` in the documented format (floats written exactly).

    Parameters
    ----------
    meas : Measurements
    mechanism : str, Mechanism or Robot, optional
        The mechanism to name in the ``# mechanism:`` line; default
        ``meas.mechanism``, ``meas.meta["mechanism"]``, or the registered
        mechanism with ``meas``'s shapes (see :func:`resolve_mechanism`).

    Raises
    ------
    ValueError
        Non-finite values, or shapes that fit no (or not the named) mechanism.
    """
    theta, readings, target = _check_arrays(meas.theta_cmd, meas.readings, meas.target)
    mech = resolve_mechanism(theta, target, meas.meta, mechanism, meas.mechanism)
    return _write(theta, readings, target, meas.meta, mech)


def write_measurements(path, meas: Measurements, mechanism=None) -> None:
    """Write ``meas`` to ``path`` atomically (see :func:`format_measurements`)."""
    atomic_write_text(path, format_measurements(meas, mechanism))


def format_template(theta_cmd, target=None, meta=None, mechanism=None) -> str:
    """A measurement file to fill in: the poses to visit, ``reading_mm`` blank.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Joint angles to command, rad.
    target : ndarray, shape (K, n), optional
        Nominal target positions, mm.
    meta : dict, optional
    mechanism : str, Mechanism or Robot, optional
        Default: the registered mechanism with these shapes.

    Returns
    -------
    str
        The file; ``reading_mm`` is 0 at pose 0 and empty elsewhere (the
        loader refuses the file until every reading is filled in).
    """
    theta_cmd, _, target = _check_arrays(theta_cmd, None, target)
    mech = resolve_mechanism(theta_cmd, target, meta, mechanism)
    note = {"note": "fill in reading_mm: the scale reading at each pose (head reset after each)"}
    return _write(theta_cmd, None, target, meta, mech, note)


# --------------------------------------------------------------------------- reading

def load_measurements(path, robot=None, min_poses: int = MIN_POSES) -> Measurements:
    """Read and validate a measurement CSV.

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given: the file must be of the robot's mechanism (its
        ``# mechanism:`` line, if any, and its columns); every commanded pose
        must be reachable and (within :data:`WORKSPACE_TOL_MM`) inside the
        robot's workspace; the targets (if any) inside the workspace and
        within :data:`TARGET_TOL_MM` of where the commanded angles lead; a
        ``robot_sha256`` metadata line must match the robot.  Without a
        robot, the columns are those of the mechanism the file names, or of
        the registered mechanism whose columns the header has.
    min_poses : int
        At least this many poses (5 for the paper's 4 parameters).

    Returns
    -------
    Measurements
        ``theta_cmd`` shape (K, m) rad, ``readings`` shape (K,) mm,
        ``target`` shape (K, n) mm or None; ``mechanism`` the mechanism read.

    Raises
    ------
    DataFileError
        With ``file:line: column 'name' (field j): ...``.
    """
    text, src = _read_text(path)
    meta, meta_lines, rows = _split_csv(text, src, "# zerocal measurements", FORMAT_VERSION)
    declared = _declared_mechanism(meta, meta_lines, src, robot)
    if robot is not None:
        mech = robot.mechanism
    elif declared is not None:
        mech = get_mechanism_of(declared)
    else:
        mech = infer_mechanism(rows[0][1]) if rows else get_mechanism_of(None)
    cols = measurement_columns(mech)
    if not rows:
        raise DataFileError(f"empty file: no header line and no data (expected the header {cols.example})",
                            where=src)
    header_line, header = rows[0]
    if robot is not None and declared is None:
        _check_columns_fit_robot(header, f"{src}:{header_line}", robot)
    _check_header(header, header_line, src, cols.allowed, cols.required, cols.example)
    has_pose = [c in header for c in cols.pose]
    if any(has_pose) and not all(has_pose):
        raise DataFileError(_go_together(cols.pose), where=f"{src}:{header_line}")
    data = rows[1:]
    if not data:
        raise DataFileError("no data rows after the header", where=f"{src}:{header_line}")
    V, lines = _rows_to_array(data, header, src)
    col = {c: j for j, c in enumerate(header)}
    _check_pose_numbers(V[:, col["pose"]], lines, src, col["pose"] + 1)
    K = len(V)
    if V[0, col["reading_mm"]] != 0.0:
        raise DataFileError(f"column 'reading_mm' (field {col['reading_mm'] + 1}): the reading at pose 0 "
                            f"must be 0 (the head is reset there), got {V[0, col['reading_mm']]:g}",
                            where=f"{src}:{lines[0]}")
    theta = np.radians(V[:, [col[c] for c in cols.joints]])
    readings = V[:, col["reading_mm"]].copy()
    target = V[:, [col[c] for c in cols.pose]] if all(has_pose) else None
    meas = Measurements(theta, readings, target, meta, src, lines, meta_lines, mech.name)
    if K < min_poses:
        raise DataFileError(f"too few poses: {K} (at least {min_poses} are needed to identify the parameters)",
                            where=src)
    _check_duplicates(meas, cols)
    if robot is not None:
        check_against_robot(meas, robot)
    return meas


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


#: odd multipliers of the cell hash (fixed: the result never depends on them, only the speed)
_HASH = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0xD6E8FEB86659FD93,
                  0xFF51AFD7ED558CCD, 0xC4CEB9FE1A85EC53], np.uint64)


def _first_duplicate_scan(X, tol):
    for k in range(1, X.shape[0]):
        d = np.max(np.abs(X[:k] - X[k]), axis=1)
        j = int(np.argmin(d))
        if d[j] <= tol:
            return k, j
    return None


def first_duplicate(X, tol: float):
    """The first row that repeats an earlier one: ``(k, j)`` or None.

    ``k`` is the smallest index with an earlier row ``j`` within ``tol`` in
    every column (``max |X_j - X_k| <= tol``), ``j`` the nearest such row (the
    first of equals).  O(3^d K log K) in time and O(K d) in memory: rows are
    put in cells of side ``tol`` (hashed); a repeat lies in the same or a
    neighbouring cell.

    Parameters
    ----------
    X : ndarray, shape (K, d)
        Finite values.
    tol : float
        > 0.
    """
    from itertools import product

    X = np.asarray(X, float)
    if X.ndim == 1:
        X = X[:, None]
    K, d = X.shape
    if K < 2:
        return None
    if not (np.all(np.isfinite(X)) and tol > 0) or float(np.max(np.abs(X))) / tol >= 2.0**50:
        return _first_duplicate_scan(X, tol)
    keys = np.floor(X / tol).astype(np.int64).view(np.uint64)
    if d > len(_HASH):
        return _first_duplicate_scan(X, tol)
    mult = _HASH[:d]
    with np.errstate(over="ignore"):
        code = (keys * mult).sum(axis=1, dtype=np.uint64)  # wraps: a hash, linear in the cell indices
    order = np.argsort(code, kind="stable")
    sc = code[order]
    eq = np.flatnonzero(sc[1:] == sc[:-1])
    if eq.size and np.any(keys[order[eq]] != keys[order[eq + 1]]):  # two cells with one hash: exact fallback
        return _first_duplicate_scan(X, tol)
    best = int(order[eq + 1].min()) if eq.size else K  # same cell (side tol): a repeat for certain
    # below ``best`` every cell holds one row: a neighbouring cell has at most one candidate
    n0 = best
    oR = np.argsort(code[:n0], kind="stable")
    scR = code[:n0][oR]
    for off in product((-1, 0, 1), repeat=d):
        nz = [o for o in off if o]
        if not nz or nz[0] < 0 or n0 < 2:  # each pair once: (i, j) by +off is (j, i) by -off
            continue
        with np.errstate(over="ignore"):
            shift = (np.asarray(off, np.int64).view(np.uint64) * mult).sum(dtype=np.uint64)
            q = code[:n0] + shift
        pos = np.minimum(np.searchsorted(scR, q), n0 - 1)
        hit = np.flatnonzero(scR[pos] == q)
        i, j = hit, oR[pos[hit]]
        close = np.max(np.abs(X[i] - X[j]), axis=1) <= tol
        if np.any(close):
            best = min(best, int(np.maximum(i[close], j[close]).min()))
    if best >= K:
        return None
    dist = np.max(np.abs(X[:best] - X[best]), axis=1)
    return best, int(np.argmin(dist))


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

    See :func:`load_measurements`.

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
    if sha and sha != robot.sha256:
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
