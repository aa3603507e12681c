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
  default mechanism -- never guessed from its columns -- and columns that do
  not fit are an error saying so; a file naming another mechanism than the
  robot's is refused.

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

This module holds the writer and the loader; the columns are
:mod:`zerocal_sym.io.measurement_columns`, the checks of a loaded file (its
mechanism, repeated poses, the robot) :mod:`zerocal_sym.io.measurement_checks`.
"""
from __future__ import annotations

import csv
import io

import numpy as np

from zerocal_sym.model import units

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (MECHANISM_KEY, ColumnMismatch, _check_header, _check_pose_numbers, _format_meta,
                                    _go_together, _read_text, _rows_to_array, _split_csv, get_mechanism_of, read_as,
                                    with_reading_hint)
from zerocal_sym.io.files import atomic_write_text
from zerocal_sym.io.measurement_checks import (_check_duplicates, _check_metadata, _declared_mechanism,
                                               check_against_robot)
from zerocal_sym.io.measurement_columns import measurement_columns
from zerocal_sym.model.measurements import Measurements, _check_arrays

FORMAT_LINE = "# zerocal measurements v1"
FORMAT_VERSION = 1
MIN_POSES = 5


def __getattr__(name):
    # the default (planar) mechanism's columns, for code written before the mechanisms
    if name == "REQUIRED_COLUMNS":
        return measurement_columns().required
    if name == "OPTIONAL_COLUMNS":
        return measurement_columns().optional
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# --------------------------------------------------------------------------- writing

def resolve_mechanism(theta_cmd, target=None, meta=None, mechanism=None, declared=None):
    """The mechanism a writer names: given, declared, or the default one (never guessed from the shapes).

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
        Conflicting names, an unknown one, or shapes that do not fit the
        mechanism (none named: the default one).
    """
    theta_cmd, _, target = _check_arrays(theta_cmd, None, target)
    named = [get_mechanism_of(x).name for x in (mechanism, declared, (meta or {}).get(MECHANISM_KEY))
             if x is not None]
    if len(set(named)) > 1:
        raise ValueError(f"conflicting mechanisms: {', '.join(dict.fromkeys(named))}")
    mech = get_mechanism_of(named[0] if named else None)
    m, n = theta_cmd.shape[1], None if target is None else target.shape[1]
    if not named and (m != mech.m or n not in (None, mech.n)):
        raise ValueError(f"no mechanism named, and the default one, {mech.name}, has {mech.m} joints and {mech.n} "
                         f"pose coordinates, not {m}" + ("" if n is None else f" and {n}") + ": pass mechanism=")
    _check_arrays(theta_cmd, None, target, mech.m, mech.n)
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
    user = units.joints_to_user(mech, theta_cmd)
    target = None if target is None else units.pose_to_user(mech, target)
    for k in range(theta_cmd.shape[0]):
        row = [k] + [repr(float(v)) for v in user[k]]
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
        ``meas.mechanism``, ``meas.meta["mechanism"]``, or the default
        mechanism (see :func:`resolve_mechanism`).

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
        Default: the default mechanism (:func:`resolve_mechanism`).

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

def load_measurements(path, robot=None, min_poses: int = MIN_POSES, allow_revisits: bool = False) -> Measurements:
    """Read and validate a measurement CSV.

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given: the file must be of the robot's mechanism (its
        ``# mechanism:`` line, if any, and its columns); every commanded pose
        must be reachable and (within
        :data:`~zerocal_sym.io.measurement_checks.WORKSPACE_TOL_MM`) inside the
        robot's workspace; the targets (if any) inside the workspace and
        within :data:`~zerocal_sym.io.measurement_checks.TARGET_TOL_MM` of
        where the commanded angles lead; a
        ``robot_sha256`` metadata line must match the robot.  Without a
        robot, the columns are those of the mechanism the file names, or
        (none named) of the default mechanism.
    min_poses : int
        At least this many poses (5 for the paper's 4 parameters).
    allow_revisits : bool
        Accept a pose visited again after other poses (a design's
        replicates) without the file's ``# revisits: allowed`` line.  A pose
        right after itself (a zero change) is refused either way.

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
    mech, reason = read_as(robot, declared)

    def fits(check, *args, errors=DataFileError):
        """``check(*args)``; a file naming no mechanism is told what it was read as when it does not fit (its
        columns or its per-joint metadata may be another mechanism's)."""
        try:
            check(*args)
        except errors as exc:
            if declared is None:
                raise with_reading_hint(exc, mech, reason) from None
            raise

    fits(_check_metadata, meta, meta_lines, src, mech)
    cols = measurement_columns(mech)
    if not rows:
        raise DataFileError(f"empty file: no header line and no data (expected the header {cols.example})",
                            where=src)
    header_line, header = rows[0]
    fits(_check_header, header, header_line, src, cols.allowed, cols.required, cols.example, errors=ColumnMismatch)
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
    theta = units.joints_from_user(mech, V[:, [col[c] for c in cols.joints]])
    readings = V[:, col["reading_mm"]].copy()
    target = units.pose_from_user(mech, V[:, [col[c] for c in cols.pose]]) if all(has_pose) else None
    meas = Measurements(theta, readings, target, meta, src, lines, meta_lines, mech.name)
    if K < min_poses:
        raise DataFileError(f"too few poses: {K} (at least {min_poses} are needed to identify the parameters)",
                            where=src)
    _check_duplicates(meas, cols, allow_revisits)
    if robot is not None:
        check_against_robot(meas, robot)
    return meas


def read_metadata(path) -> dict:
    """The ``# key: value`` lines of a measurement file, without reading its rows (e.g. its ``robot_sha256``
    before the file is checked against a robot)."""
    text, src = _read_text(path)
    return _split_csv(text, src, "# zerocal measurements", FORMAT_VERSION)[0]
