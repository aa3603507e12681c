"""Checks of a measurement file beyond its syntax: its mechanism, repeated poses, the robot.

* :func:`_declared_mechanism` -- the ``# mechanism:`` line: a known
  mechanism, the robot's;
* :func:`_check_metadata` -- the ``# robot_sha256:`` line is a SHA-256 (64
  hexadecimal digits), the ``# compensation_deg:`` line one finite angle per
  joint;
* :func:`_check_duplicates` -- no pose repeats the one before it (a zero
  change); no pose repeats an earlier one unless revisits are intended (the
  file's ``# revisits: allowed`` line, or ``allow_revisits``: the CLI's
  ``--allow-revisits``);
* :func:`check_against_robot` -- every commanded pose reachable and inside
  the workspace (within :data:`WORKSPACE_TOL_MM`; a compensated round's
  commands with its ``# compensation_deg:`` undone), the targets within
  :data:`TARGET_TOL_MM` of where the commanded angles lead, the
  ``robot_sha256`` line.

Each failure is a :class:`~zerocal_sym.errors.DataFileError` naming the file
and the line; called by :func:`zerocal_sym.io.measurements.load_measurements`.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import (ALLOW_REVISITS_OPTION, MECHANISM_KEY, REVISITS_ALLOWED, REVISITS_KEY,
                                    unknown_mechanism_message)
from zerocal_sym.io.duplicates import REVISIT_TOL, consecutive_repeat, first_duplicate
from zerocal_sym.io.measurement_columns import MeasurementColumns, measurement_columns
from zerocal_sym.model import units
from zerocal_sym.model.measurements import Measurements

#: commanded poses farther than this outside the workspace are rejected (mm);
#: compensation moves commanded angles by a few degrees, i.e. a few mm.
WORKSPACE_TOL_MM = 25.0
#: the commanded joint angles must reach within this of the target (x_mm, y_mm, ...)
#: (catches radians written as degrees and swapped columns; a compensation of
#: a few degrees moves the platform by some 10 mm).
TARGET_TOL_MM = 50.0
#: two poses whose commanded angles agree to this (deg) are the same pose
DUPLICATE_TOL_DEG = REVISIT_TOL


#: the metadata of a round on a design's own region (``zerocal design --region``): its poses may leave the
#: workspace; they are checked for reachability, the assembly mode and this singularity margin instead
REGION_KEYS = ("region", "region_singularity_margin")


def region_of(meta) -> dict | None:
    """``{"region": ..., "region_singularity_margin": float}`` of a round on a design's region, or None."""
    if meta.get("region") is None:
        return None
    return {"region": meta["region"], "region_singularity_margin": float(meta["region_singularity_margin"])}


def check_region_poses(robot, P, region: dict, where) -> np.ndarray:
    """Poses of a design's region: reachable, in the home assembly mode (FK returns them, 1e-6 mm), at least the
    region's singularity margin from a singular configuration.  ``where(k)``: the place of pose k in messages.

    Returns the joints IK(P), shape (K, m); DataFileError naming the first pose that is not.
    """
    from zerocal_sym.errors import PoseError
    from zerocal_sym.model import kinematics as kin

    margin = region["region_singularity_margin"]
    try:
        theta = kin.check_poses(robot, P, margin=margin)
    except PoseError as exc:
        k = int(exc.where.split()[-1]) if exc.where and exc.where.startswith("pose ") else 0
        raise DataFileError(f"pose {k} of the design's region ({region['region']}): {exc.message}",
                            where=where(k)) from None
    with np.errstate(all="ignore"):
        back = kin.fk(robot, theta)
    bad = np.flatnonzero(~(np.linalg.norm(back - P, axis=1) <= 1e-6))
    if bad.size:
        k = int(bad[0])
        raise DataFileError(f"pose {k} {kin.fmt_user_pose(robot, P[k])} of the design's region ({region['region']}) "
                            "is in another assembly mode: the forward kinematics do not return it", where=where(k))
    return theta


def _check_metadata(meta, meta_lines, src, mech) -> None:
    """The values of the metadata lines zerocal reads, each of the right form (DataFileError naming the line)."""
    from zerocal_sym.io.compensation import parse_offsets
    from zerocal_sym.io.results import SHA256_RE

    sha = meta.get("robot_sha256")
    if sha is not None and not SHA256_RE.fullmatch(sha):
        raise DataFileError(f"'# robot_sha256:' must be the robot's SHA-256, 64 hexadecimal digits ('zerocal robot' "
                            f"prints it), got {sha[:80]!r}", where=f"{src}:{meta_lines['robot_sha256']}")
    rv = meta.get(REVISITS_KEY)
    if rv is not None and rv != REVISITS_ALLOWED:
        raise DataFileError(f"'# {REVISITS_KEY}:' can only be '{REVISITS_ALLOWED}' (the file revisits poses on "
                            f"purpose), got {rv[:80]!r}", where=f"{src}:{meta_lines[REVISITS_KEY]}")
    if (meta.get("region") is None) != (meta.get("region_singularity_margin") is None):
        given = "region" if meta.get("region") is not None else "region_singularity_margin"
        raise DataFileError("'# region:' and '# region_singularity_margin:' go together (a round on a design's "
                            "region names both)", where=f"{src}:{meta_lines[given]}")
    margin = meta.get("region_singularity_margin")
    if margin is not None:
        try:
            ok = 0 <= float(margin) < 1
        except ValueError:
            ok = False
        if not ok:
            raise DataFileError(f"'# region_singularity_margin:' must be a number in [0, 1), got {margin[:80]!r}",
                                where=f"{src}:{meta_lines['region_singularity_margin']}")
    key = units.joint_key(mech, "compensation")
    comp = meta.get(key)
    if comp is not None and parse_offsets(comp, mech.m) is None:
        raise DataFileError(f"'# {key}:' must be {mech.m} finite {units.joint_noun(mech).split()[1]} in "
                            f"{mech.joint_user_unit}, one per "
                            f"joint ({', '.join(mech.joint_names)}), got {comp[:80]!r}",
                            where=f"{src}:{meta_lines[key]}")


def _declared_mechanism(meta, meta_lines, src, robot):
    """The file's ``# mechanism:`` (None without); unknown or not the robot's: DataFileError."""
    from zerocal_sym.model.mechanism import is_known

    declared = meta.get(MECHANISM_KEY)
    if declared is None:
        return None
    where = f"{src}:{meta_lines[MECHANISM_KEY]}"
    if not is_known(declared):
        raise DataFileError(unknown_mechanism_message(declared), where=where)
    if robot is not None and declared != robot.mechanism_name:
        raise DataFileError(f"measured with mechanism {declared}, the robot file is {robot.mechanism_name} "
                            f"({robot.source}): pass the robot file of the measured robot", where=where)
    return declared


def _joint_unit(meas) -> str:
    """Internal unit of the measured joints (the file's mechanism's; rad when it names none)."""
    from zerocal_sym.model.mechanism import get_mechanism, is_known

    name = meas.mechanism
    return get_mechanism(name).joint_unit if name is not None and is_known(name) else "rad"


def revisit_hint(what: str = "file", json: bool = False) -> str:
    """How to allow revisits (the end of a refusal)."""
    line = (f'the key "{REVISITS_KEY}": "{REVISITS_ALLOWED}"' if json
            else f"the line '# {REVISITS_KEY}: {REVISITS_ALLOWED}'")
    return (f"a revisit: if the {what} revisits poses on purpose (a design's replicates), add {line} to it or pass "
            f"{ALLOW_REVISITS_OPTION}")


def check_repeats(X, tol, allow: bool, where, what: str, lines=None, file_what: str = "file",
                  json: bool = False) -> None:
    """Refuse a row that repeats the row before it (a zero change), and, unless ``allow``, one that repeats an
    earlier row (a revisit).  ``X`` (K, d) in file units; ``where(k)`` names row k; ``what`` names the
    coordinates ("commanded joint angles", "target (x_mm, y_mm)"); ``lines`` the file line of each row."""
    at = (lambda j: f" (line {lines[j]})") if lines is not None else (lambda j: "")
    k = consecutive_repeat(X, tol)
    if k is not None:
        raise DataFileError(f"pose {k} repeats the {what} of the pose before it, pose {k - 1}{at(k - 1)}: a zero "
                            "change carries no information (a row entered twice?); a revisit needs another pose "
                            "between", where=where(k))
    if allow:
        return
    dup = first_duplicate(X, tol)
    if dup is not None:
        k, j = dup
        raise DataFileError(f"duplicated pose: pose {k} repeats the {what} of pose {j}{at(j)}; "
                            f"{revisit_hint(file_what, json)}", where=where(k))


def revisits_allowed(meta, allow: bool = False) -> bool:
    """Whether revisits are intended: ``allow`` (``--allow-revisits``) or the file's metadata says so."""
    return bool(allow) or meta.get(REVISITS_KEY) == REVISITS_ALLOWED


def _check_duplicates(meas: Measurements, cols: MeasurementColumns, allow_revisits: bool = False) -> None:
    """Repeated poses (commanded joints to 1e-9 in their file unit, or the target to 1e-9): never the pose
    before (a zero change), an earlier one only when revisits are intended (:func:`revisits_allowed`)."""
    allow = revisits_allowed(meas.meta, allow_revisits)
    found = [("commanded joint angles", units.to_user(meas.theta_cmd, _joint_unit(meas)))]
    if meas.target is not None:
        found.append((f"target ({', '.join(cols.pose)})", meas.target))
    for what, X in found:  # zero changes first, in either
        k = consecutive_repeat(X, DUPLICATE_TOL_DEG)
        if k is not None:
            check_repeats(X, DUPLICATE_TOL_DEG, True, meas.where, what, meas.lines)
    if allow:
        return
    firsts = [(dup[0], what, X) for what, X in found if (dup := first_duplicate(X, DUPLICATE_TOL_DEG)) is not None]
    if firsts:
        _, what, X = min(firsts, key=lambda f: f[0])  # the first pose; the angles first (min is stable)
        check_repeats(X, DUPLICATE_TOL_DEG, False, meas.where, what, meas.lines)


def check_against_robot(meas: Measurements, robot) -> None:
    """The mechanism and the robot fit, every commanded pose reachable and inside the workspace.

    See :func:`~zerocal_sym.io.measurements.load_measurements`.

    Raises
    ------
    DataFileError
    """
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.kinematics import fmt_pose, fmt_user_pose

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
    from zerocal_sym.io.compensation import parse_offsets

    # a compensated round (its '# compensation_deg:' line): the commands are IK(target) - compensation, so the
    # pose they were meant for, the one checked, is where the commands plus the compensation lead
    comp = parse_offsets(meas.meta.get(units.joint_key(robot, "compensation")), robot.m)
    intended = meas.theta_cmd if comp is None else meas.theta_cmd + units.joints_from_user(robot, comp)
    with np.errstate(all="ignore"):
        P = kin.fk(robot, intended)
    ws = robot.workspace
    region = region_of(meas.meta)  # a design's own region: its poses may leave the workspace (checked below)
    contains = ws.contains if region is None else (lambda X, tol: np.ones(len(X), bool))
    target_what = f"target ({', '.join(cols.pose)})"
    with np.errstate(invalid="ignore"):  # all poses at once; the first bad one is reported below
        bad = ~np.all(np.isfinite(P), axis=1) | ~contains(P, WORKSPACE_TOL_MM)
        if meas.target is not None:
            bad |= ~contains(meas.target, 1e-6) | ~(np.linalg.norm(P - meas.target, axis=1) <= TARGET_TOL_MM)
    for k in map(int, np.flatnonzero(bad)[:1]):
        if not np.all(np.isfinite(P[k])):
            ju = robot.mechanism.joint_user_unit
            raise DataFileError(f"commanded {units.joint_noun(robot)} "
                                f"{fmt_pose(units.joints_to_user(robot, meas.theta_cmd[k]))} {ju} are not an "
                                f"assembly of the robot (unreachable pose; {units.unit_hint(robot)})",
                                where=meas.where(k))
        pts = [("commanded" if comp is None or not np.any(comp) else "commanded (compensation undone)", P[k],
                WORKSPACE_TOL_MM)]
        if meas.target is not None:
            pts.append((target_what, meas.target[k], 1e-6))
        for what, p, tol in pts:
            if not contains(p[None], tol)[0]:
                raise DataFileError(
                    f"{what} pose {fmt_user_pose(robot, p, '.3f')} is outside the workspace {ws.describe()} "
                    f"(tolerance {tol:g} mm)", where=meas.where(k))
        if meas.target is not None:
            dist = float(np.linalg.norm(P[k] - meas.target[k]))
            if dist > TARGET_TOL_MM:
                raise DataFileError(
                    f"the commanded {units.joint_noun(robot)} reach {fmt_user_pose(robot, P[k], '.3f')}, {dist:.1f} mm "
                    f"from the target {fmt_user_pose(robot, meas.target[k])} (more than {TARGET_TOL_MM:g} mm: "
                    f"columns swapped, or {units.joint_noun(robot).split()[1]} not in {robot.mechanism.joint_user_unit}?)", where=meas.where(k))
    if region is not None:
        check_region_poses(robot, P if meas.target is None else meas.target, region, meas.where)
