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
    """The poses of :func:`load_design_poses` (without the region they carry)."""
    return load_design_poses(path, robot, allow_revisits, measured)[0]


def load_design_poses(path, robot=None, allow_revisits: bool = False, measured: bool = False) -> tuple:
    """Read a list of target positions, and the design region they carry if they leave the workspace.

    Either a CSV ``[pose,]x_mm,y_mm[,z_mm]`` (the columns of the robot's
    mechanism) or a JSON object with a key ``poses`` (a list of ``[x, y(, z)]``
    in mm: what ``zerocal design --json`` prints).

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given: the columns (and the length of each JSON pose) are its
        mechanism's, and every pose must lie in its workspace (1e-6 mm), or,
        for the poses of a design made on another region (``zerocal design
        --region ...``: its ``constraints``), be reachable, in the home
        assembly mode (FK returns the pose) and at least the design's
        singularity margin from a singular configuration; without: the
        default mechanism's.
    allow_revisits : bool
        Accept revisits without the file saying so (module docstring).
    measured : bool
        The poses of a measurement round: repeated poses checked (module docstring).

    Returns
    -------
    P : ndarray, shape (K, n)
        Internal units (mm, orientations in rad; the file's are in deg), in file order.
    region : dict or None
        For poses outside the workspace (a design's region):
        ``{"region": description, "region_singularity_margin": margin}``, the
        metadata a measurement file of these poses carries
        (:func:`zerocal_sym.io.measurement_checks.region_of`).

    Raises
    ------
    DataFileError
    """
    text, src = _read_text(path, "pose file")
    from zerocal_sym.model.kinematics import fmt_user_pose
    from zerocal_sym.model.units import pose_from_user

    mech, reason = read_as(robot)
    cols = pose_columns(mech)
    if text.lstrip().startswith("{"):
        obj = _load_json(text, src)
        v = obj.get("poses") if isinstance(obj, dict) else None
        example = "[" + ", ".join(cols) + "]"
        if not isinstance(obj, dict) or "poses" not in obj:
            raise DataFileError(f"a JSON pose file needs a key 'poses' (list of {example})", where=src)
        _check_json_claims(obj, text, src, mech, reason)
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
        cons = obj.get("constraints")
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
        cons = None
    from zerocal_sym.io.measurement_checks import check_repeats, revisits_allowed
    from zerocal_sym.model.revisits import REVISIT_TOL

    if measured:
        check_repeats(P, REVISIT_TOL, revisits_allowed(meta, allow_revisits),
                      lambda k: f"{src}:{lines[k]}" if lines else src, "target", lines, "pose file", json=lines is None)
    P = pose_from_user(mech, P)  # orientations are in degrees in the file (roll_deg, ...), radians inside
    region = None
    if robot is not None:
        inside = robot.workspace.contains(P, 1e-6)
        if not inside.all() and isinstance(cons, dict) and isinstance(cons.get("region"), str):
            region = _design_region(robot, P, cons, f"{src}:{_json_line(text, 'constraints')}")
        for k in np.flatnonzero(~inside)[:1] if region is None else ():
            raise DataFileError(f"pose {k} {fmt_user_pose(robot, P[k])} is outside the workspace "
                                f"{robot.workspace.describe()}", where=f"{src}:{lines[k]}" if lines else src)
    return P, region


def _design_region(robot, P, cons: dict, where: str) -> dict:
    """The region of a design whose poses leave the workspace, its poses checked as the design made them."""
    from zerocal_sym.io.measurement_checks import check_region_poses

    margin = cons.get("singularity_margin", robot.singularity_margin)
    if not (isinstance(margin, (int, float)) and not isinstance(margin, bool) and 0 <= margin < 1):
        raise DataFileError(f"constraints.singularity_margin must be a number in [0, 1), got {margin!r}", where=where)
    region = {"region": " ".join(cons["region"].split())[:300], "region_singularity_margin": float(margin)}
    check_region_poses(robot, P, region, lambda k: where)
    return region


def _check_json_claims(obj: dict, text: str, src: str, mech, reason: str) -> None:
    """A design JSON names its mechanism and its poses' units: they must be those the poses are read with."""
    from zerocal_sym.model.units import pose_unit

    named = obj.get("mechanism")
    if isinstance(named, str) and named != mech.name:
        raise DataFileError(f"the poses were made for mechanism {named!r} and are read as mechanism {mech.name!r}, "
                            f"{reason}: pass the robot file of the robot they were made for (--robot)",
                            where=f"{src}:{_json_line(text, 'mechanism')}")
    given = obj.get("pose_units")
    expected = [pose_unit(mech, name) for name in mech.pose_names]
    if given is not None and given != expected:
        raise DataFileError(f"key 'pose_units' is {given!r}; the poses are read in {expected!r}",
                            where=f"{src}:{_json_line(text, 'pose_units')}")
