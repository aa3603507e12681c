"""The pose file: a list of target positions.

Pose file
---------
A list of target positions, one coordinate column per pose coordinate of the
robot's mechanism (``pose`` optional, ``x_mm``, ``y_mm``[, ``z_mm``]), or a
JSON object whose ``poses`` is a list of ``[x, y(, z)]``; read by
:func:`load_poses` (for ``zerocal compensate --poses``).  The columns (the length of each JSON
pose) are those of the robot's mechanism, or without a robot those of the
default mechanism: a pose file names no mechanism, and is not matched to one
by its columns.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (LENGTH_LIMIT_MM, ColumnMismatch, _check_header, _check_pose_numbers, _json_line,
                                    _load_json, _read_text, _rows_to_array, _split_csv, pose_columns, read_as,
                                    with_reading_hint)


def __getattr__(name):
    # the default (planar) mechanism's columns, for code written before the mechanisms
    if name == "POSE_COLUMNS":
        return pose_columns(None)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _is_number(x) -> bool:
    if not isinstance(x, (int, float)) or isinstance(x, bool):
        return False
    try:
        return math.isfinite(x) and abs(x) <= LENGTH_LIMIT_MM
    except OverflowError:  # an integer beyond any float
        return False


def load_poses(path, robot=None) -> np.ndarray:
    """Read a list of target positions.

    Either a CSV ``[pose,]x_mm,y_mm[,z_mm]`` (the columns of the robot's
    mechanism) or a JSON object with a key ``poses`` (a list of ``[x, y(, z)]``
    in mm: what ``zerocal design --json`` prints).

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given: the columns (and the length of each JSON pose) are its
        mechanism's, and every pose must lie in its workspace (1e-6 mm);
        without: the default mechanism's.

    Returns
    -------
    ndarray, shape (K, n)
        mm, in file order.

    Raises
    ------
    DataFileError
    """
    text, src = _read_text(path, "pose file")
    from zerocal_sym.model.kinematics import fmt_pose

    mech, reason = read_as(robot)
    cols = pose_columns(mech)
    if text.lstrip().startswith("{"):
        obj = _load_json(text, src)
        v = obj.get("poses") if isinstance(obj, dict) else None
        example = "[" + ", ".join(cols) + "]"
        if not isinstance(obj, dict) or "poses" not in obj:
            raise DataFileError(f"a JSON pose file needs a key 'poses' (list of {example})", where=src)
        where = f"{src}:{_json_line(text, 'poses')}"
        ok = isinstance(v, list) and len(v) > 0 and all(
            isinstance(p, list) and len(p) == len(cols) and all(_is_number(x) for x in p) for p in v)
        if not ok:
            exc = DataFileError(f"key 'poses' must be a non-empty list of {example} finite numbers", where=where)
            if isinstance(v, list) and any(isinstance(p, list) and len(p) != len(cols) for p in v):
                raise with_reading_hint(exc, mech, reason)  # poses of another size: another mechanism's?
            raise exc
        P = np.array(v, float)
        lines = None
    else:
        _, _, rows = _split_csv(text, src)
        example = "[pose,]" + ",".join(cols)
        if not rows:
            raise DataFileError(f"empty file: no header line and no data (expected the header {example})",
                                where=src)
        header_line, header = rows[0]
        try:
            _check_header(header, header_line, src, ("pose",) + cols, cols, example)
        except ColumnMismatch as exc:
            raise with_reading_hint(exc, mech, reason) from None  # another mechanism's columns?
        if len(rows) == 1:
            raise DataFileError("no data rows after the header", where=f"{src}:{header_line}")
        V, lines = _rows_to_array(rows[1:], header, src)
        if "pose" in header:
            _check_pose_numbers(V[:, header.index("pose")], lines, src, header.index("pose") + 1)
        P = V[:, [header.index(c) for c in cols]]
    if robot is not None:
        inside = robot.workspace.contains(P, 1e-6)
        for k in np.flatnonzero(~inside)[:1]:
            raise DataFileError(f"pose {k} {fmt_pose(P[k])} mm is outside the workspace "
                                f"{robot.workspace.describe()}", where=f"{src}:{lines[k]}" if lines else src)
    return P
