"""The pose file: a list of target positions.

Pose file
---------
A list of target positions, one coordinate column per pose coordinate of the
robot's mechanism (``pose`` optional, ``x_mm``, ``y_mm``[, ``z_mm``]), or a
JSON object whose ``poses`` is a list of ``[x, y(, z)]``; read by
:func:`load_poses` (for ``zerocal compensate --poses``).  Without a robot, the
columns are those of the registered mechanism they fit (the default
mechanism's if none), and a JSON list is taken as it comes (every pose with
the same number of coordinates, that of a registered mechanism).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (LENGTH_LIMIT_MM, _check_header, _check_pose_numbers, _json_line, _load_json,
                                    _read_text, _rows_to_array, _split_csv, get_mechanism_of, infer_mechanism,
                                    mechanism_for_shape, pose_columns)


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
        mechanism's, and every pose must lie in its workspace (1e-6 mm).

    Returns
    -------
    ndarray, shape (K, n)
        mm, in file order.

    Raises
    ------
    DataFileError
    """
    from zerocal_sym.model.kinematics import fmt_pose

    text, src = _read_text(path, "pose file")
    if text.lstrip().startswith("{"):
        obj = _load_json(text, src)
        v = obj.get("poses") if isinstance(obj, dict) else None
        if robot is not None:
            mech = robot.mechanism
        else:
            first = len(v[0]) if isinstance(v, list) and v and isinstance(v[0], list) else None
            mech = mechanism_for_shape(n=first) or get_mechanism_of(None)
        cols = pose_columns(mech)
        example = "[" + ", ".join(cols) + "]"
        if not isinstance(obj, dict) or "poses" not in obj:
            raise DataFileError(f"a JSON pose file needs a key 'poses' (list of {example})", where=src)
        where = f"{src}:{_json_line(text, 'poses')}"
        ok = isinstance(v, list) and len(v) > 0 and all(
            isinstance(p, list) and len(p) == len(cols) and all(_is_number(x) for x in p) for p in v)
        if not ok:
            raise DataFileError(f"key 'poses' must be a non-empty list of {example} finite numbers", where=where)
        P = np.array(v, float)
        lines = None
    else:
        _, _, rows = _split_csv(text, src)
        mech = robot.mechanism if robot is not None else infer_mechanism(rows[0][1] if rows else (), joints=False)
        cols = pose_columns(mech)
        example = "[pose,]" + ",".join(cols)
        if not rows:
            raise DataFileError(f"empty file: no header line and no data (expected the header {example})",
                                where=src)
        header_line, header = rows[0]
        _check_header(header, header_line, src, ("pose",) + cols, cols, example)
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
