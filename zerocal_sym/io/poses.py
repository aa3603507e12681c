"""The pose file: a list of target positions.

Pose file
---------
A list of target positions (``pose`` optional, ``x_mm``, ``y_mm``), read by
:func:`load_poses` (for ``zerocal compensate --poses``).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (LENGTH_LIMIT_MM, _check_header, _check_pose_numbers, _json_line, _load_json,
                                    _read_text, _rows_to_records, _split_csv)

POSE_COLUMNS = ("x_mm", "y_mm")


def load_poses(path, robot=None) -> np.ndarray:
    """Read a list of target positions.

    Either a CSV ``[pose,]x_mm,y_mm`` or a JSON object with a ``poses`` key
    (a list of ``[x, y]`` in mm: what ``zerocal design --json`` prints).

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given, every pose must lie in the workspace (1e-6 mm).

    Returns
    -------
    ndarray, shape (K, 2)
        mm, in file order.

    Raises
    ------
    DataFileError
    """
    text, src = _read_text(path, "pose file")
    if text.lstrip().startswith("{"):
        obj = _load_json(text, src)
        if not isinstance(obj, dict) or "poses" not in obj:
            raise DataFileError("a JSON pose file needs a key 'poses' (list of [x_mm, y_mm])", where=src)
        where = f"{src}:{_json_line(text, 'poses')}"
        v = obj["poses"]
        ok = isinstance(v, list) and len(v) > 0 and all(
            isinstance(p, list) and len(p) == 2 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                          and math.isfinite(x) and abs(x) <= LENGTH_LIMIT_MM
                                                          for x in p) for p in v)
        if not ok:
            raise DataFileError("key 'poses' must be a non-empty list of [x_mm, y_mm] finite numbers", where=where)
        P = np.array(v, float)
        lines = None
    else:
        _, _, rows = _split_csv(text, src)
        example = "[pose,]x_mm,y_mm"
        if not rows:
            raise DataFileError(f"empty file: no header line and no data (expected the header {example})",
                                where=src)
        header_line, header = rows[0]
        _check_header(header, header_line, src, ("pose",) + POSE_COLUMNS, POSE_COLUMNS, example)
        if len(rows) == 1:
            raise DataFileError("no data rows after the header", where=f"{src}:{header_line}")
        values, lines = _rows_to_records(rows[1:], header, src)
        if "pose" in header:
            _check_pose_numbers(values, lines, src, header.index("pose") + 1)
        P = np.array([[r["x_mm"], r["y_mm"]] for r in values])
    if robot is not None:
        lo, hi = robot.workspace_bounds()
        for k in range(len(P)):
            if np.any(P[k] < lo - 1e-6) or np.any(P[k] > hi + 1e-6):
                raise DataFileError(f"pose {k} ({P[k, 0]:g}, {P[k, 1]:g}) mm is outside the workspace x in "
                                    f"[{lo[0]:g}, {hi[0]:g}], y in [{lo[1]:g}, {hi[1]:g}]",
                                    where=f"{src}:{lines[k]}" if lines else src)
    return P
