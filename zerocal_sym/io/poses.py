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

Read as the poses of a measurement round (``measured``: ``simulate``,
``compensate --template``, ``compare``, ``study``), a pose may come again
after other poses (a *revisit*: a design's replicates) when the file says so
(a CSV's ``# revisits: allowed`` line, a JSON's ``"revisits": "allowed"``, as
``zerocal design`` writes) or the reader is told (``allow_revisits``, the
CLI's ``--allow-revisits``); a pose right after itself (a zero change) is
refused either way.  Other pose lists (a command table) may repeat poses.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (LENGTH_LIMIT_MM, REVISITS_ALLOWED, REVISITS_KEY, ColumnMismatch, _check_header,
                                    _check_pose_numbers, _json_line, _load_json, _read_text, _rows_to_array,
                                    _split_csv, pose_columns, read_as, with_reading_hint)


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


def load_poses(path, robot=None, allow_revisits: bool = False, measured: bool = False) -> np.ndarray:
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
    allow_revisits : bool
        Accept revisits without the file saying so (module docstring).
    measured : bool
        The poses of a measurement round: repeated poses checked (module docstring).

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
        meta = {}
        if REVISITS_KEY in obj:
            if obj[REVISITS_KEY] != REVISITS_ALLOWED:
                raise DataFileError(f"key '{REVISITS_KEY}' can only be '{REVISITS_ALLOWED}' (the poses revisit on "
                                    f"purpose), got {str(obj[REVISITS_KEY])[:80]!r}",
                                    where=f"{src}:{_json_line(text, REVISITS_KEY)}")
            meta[REVISITS_KEY] = REVISITS_ALLOWED
    else:
        meta, meta_lines, rows = _split_csv(text, src)
        if meta.get(REVISITS_KEY, REVISITS_ALLOWED) != REVISITS_ALLOWED:
            raise DataFileError(f"'# {REVISITS_KEY}:' can only be '{REVISITS_ALLOWED}' (the file revisits poses on "
                                f"purpose), got {meta[REVISITS_KEY][:80]!r}", where=f"{src}:{meta_lines[REVISITS_KEY]}")
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
    from zerocal_sym.io.measurement_checks import check_repeats, revisits_allowed
    from zerocal_sym.model.revisits import REVISIT_TOL

    if measured:
        check_repeats(P, REVISIT_TOL, revisits_allowed(meta, allow_revisits),
                      lambda k: f"{src}:{lines[k]}" if lines else src, "target", lines, "pose file", json=lines is None)
    if robot is not None:
        inside = robot.workspace.contains(P, 1e-6)
        for k in np.flatnonzero(~inside)[:1]:
            raise DataFileError(f"pose {k} {fmt_pose(P[k])} mm is outside the workspace "
                                f"{robot.workspace.describe()}", where=f"{src}:{lines[k]}" if lines else src)
    return P
