"""The measurement file format (CSV), its loader, and the files around it.

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

Pose file
---------
A list of target positions (``pose`` optional, ``x_mm``, ``y_mm``), read by
:func:`load_poses` (for ``zerocal compensate --poses``).

Results JSON and compensation table
-----------------------------------
:func:`load_result` reads what ``zerocal identify --json`` writes;
:func:`format_compensation` and :func:`format_commands` write what
``zerocal compensate`` gives to a controller.  Sign convention: the actual
joint angle is the commanded one plus the zero offset, so the controller
*subtracts* the offset: ``theta_cmd = IK(P) - offset``.
"""
from __future__ import annotations

import csv
import difflib
import io
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.files import atomic_write_text

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
#: plausibility limits of the cells (anything beyond is a unit or typing error)
ANGLE_LIMIT_DEG = 3600.0
LENGTH_LIMIT_MM = 1e6
#: two poses whose commanded angles agree to this (deg) are the same pose
DUPLICATE_TOL_DEG = 1e-9

POSE_COLUMNS = ("x_mm", "y_mm")
COMPENSATION_LINE = "# zerocal compensation v1"
SIGN_CONVENTION = "theta_cmd = IK(P) - offset_deg (actual joint angle = commanded + offset)"


@dataclass
class Measurements:
    """One identification round of measurements.

    Attributes
    ----------
    theta_cmd : ndarray, shape (K, 2)
        Commanded joint angles, rad.
    readings : ndarray, shape (K,)
        Scale readings, mm; ``readings[0] == 0``.
    target : ndarray, shape (K, 2) or None
        Nominal target positions, mm.
    meta : dict
        ``# key: value`` header lines.
    source : str
    lines : list of int
        File line of each pose (for messages).
    meta_lines : dict
        File line of each metadata key.
    """

    theta_cmd: np.ndarray
    readings: np.ndarray
    target: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    source: str = "<memory>"
    lines: list = field(default_factory=list)
    meta_lines: dict = field(default_factory=dict)

    @property
    def K(self) -> int:
        return self.theta_cmd.shape[0]

    @property
    def changes(self) -> np.ndarray:
        """The K-1 measured changes ``s_k``, shape (K-1,)."""
        return self.readings[1:]

    def where(self, k: int) -> str:
        """``file:line`` of pose k."""
        line = self.lines[k] if k < len(self.lines) else None
        return f"{self.source}:{line}" if line else f"{self.source}: pose {k}"


# --------------------------------------------------------------------------- writing

def _check_arrays(theta_cmd, readings, target):
    theta_cmd = np.asarray(theta_cmd, float)
    if theta_cmd.ndim != 2 or theta_cmd.shape[1] != 2:
        raise ValueError(f"theta_cmd must have shape (K, 2), got {theta_cmd.shape}")
    K = theta_cmd.shape[0]
    if readings is not None:
        readings = np.asarray(readings, float)
        if readings.shape != (K,):
            raise ValueError(f"readings must have shape ({K},), got {readings.shape}")
    if target is not None:
        target = np.asarray(target, float)
        if target.shape != (K, 2):
            raise ValueError(f"target must have shape ({K}, 2), got {target.shape}")
    for name, a in (("theta_cmd", theta_cmd), ("readings", readings), ("target", target)):
        if a is not None and not np.all(np.isfinite(a)):
            raise ValueError(f"{name} has non-finite values")
    return theta_cmd, readings, target


def _format_meta(meta: dict) -> str:
    out = []
    for k, v in meta.items():
        k, v = str(k).strip(), str(v).strip()
        if not k or ":" in k or "\n" in k + v or "\r" in k + v:
            raise ValueError(f"metadata key {k!r} / value {v!r} cannot be written on one '# key: value' line")
        out.append(f"# {k}: {v}\n")
    return "".join(out)


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

def _read_text(path, what="file") -> tuple[str, str]:
    """File text with BOM removed and newlines normalised; typed errors."""
    path = Path(path)
    src = str(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise DataFileError(f"{what} not found", where=src) from None
    except IsADirectoryError:
        raise DataFileError(f"{what} is a directory", where=src) from None
    except OSError as exc:
        raise DataFileError(f"cannot read {what}: {exc.strerror or exc}", where=src) from None
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    elif raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise DataFileError("file is UTF-16 encoded: save it as UTF-8 (plain CSV)", where=f"{src}:1")
    nul = raw.find(b"\x00")
    if nul >= 0:
        line = raw.count(b"\n", 0, nul) + 1
        raise DataFileError("binary data (NUL byte) in a text file", where=f"{src}:{line}")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        before = raw[:exc.start]
        line = before.count(b"\n") + 1
        col = exc.start - (before.rfind(b"\n") + 1) + 1
        raise DataFileError(f"not UTF-8 text: byte 0x{raw[exc.start]:02x} at column {col} "
                            "(save the file as UTF-8 CSV)", where=f"{src}:{line}") from None
    return text.replace("\r\n", "\n").replace("\r", "\n"), src


def _split_csv(text: str, src: str, format_prefix: str | None = None, version: int | None = None):
    """Metadata lines, their line numbers and CSV rows (line number, stripped cells)."""
    meta, meta_lines, rows = {}, {}, []
    header_seen = False
    for lineno, line in enumerate(text.split("\n"), 1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            if format_prefix and stripped.startswith(format_prefix):
                m = re.fullmatch(re.escape(format_prefix) + r" v(\d+)", stripped)
                if not m or int(m.group(1)) != version:
                    raise DataFileError(f"unsupported format line {stripped[:60]!r} (this version reads "
                                        f"'{format_prefix} v{version}')", where=f"{src}:{lineno}")
            elif not header_seen and ":" in stripped:
                k, _, v = stripped[1:].partition(":")
                meta[k.strip()] = v.strip()
                meta_lines[k.strip()] = lineno
            continue
        try:
            cells = next(csv.reader([line], strict=True))
        except csv.Error as exc:
            raise DataFileError(f"malformed CSV line ({exc})", where=f"{src}:{lineno}") from None
        rows.append((lineno, [c.strip() for c in cells]))
        header_seen = True
    return meta, meta_lines, rows


def _looks_numeric(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _check_header(header, header_line, src, allowed, required, example):
    where = f"{src}:{header_line}"
    if len(header) == 1 and (";" in header[0] or "\t" in header[0]):
        sep = "';'" if ";" in header[0] else "a tab"
        raise DataFileError(f"the separator must be a comma, found {sep} (header must be {example})", where=where)
    if any(_looks_numeric(c) for c in header if c):
        raise DataFileError(f"no header line: the first non-comment line must be the header {example}", where=where)
    for j, c in enumerate(header, 1):
        if c == "":
            raise DataFileError(f"column {j} of the header has no name (a trailing comma?)", where=where)
    dup = sorted({c for c in header if header.count(c) > 1})
    if dup:
        raise DataFileError(f"duplicated column(s): {', '.join(dup)}", where=where)
    extra = [c for c in header if c not in allowed]
    if extra:
        hints = []
        for c in extra:
            close = difflib.get_close_matches(c.lower(), allowed, n=1, cutoff=0.6)
            hints.append(f"'{c}' (column {header.index(c) + 1}" + (f"; did you mean '{close[0]}'?)" if close else ")"))
        missing = [c for c in required if c not in header]
        miss = f"; missing: {', '.join(missing)}" if missing else ""
        raise DataFileError(f"unexpected column(s): {', '.join(hints)}{miss}; allowed: {', '.join(allowed)}",
                            where=where)
    missing = [c for c in required if c not in header]
    if missing:
        raise DataFileError(f"missing column(s): {', '.join(missing)} (header must be {example})", where=where)


def _number(text: str, where: str, col: str, j: int) -> float:
    label = f"column '{col}' (field {j})"
    if text == "":
        hint = " (fill in the scale reading)" if col == "reading_mm" else ""
        raise DataFileError(f"{label}: empty cell{hint}", where=where)
    try:
        v = float(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise DataFileError(f"{label}: {shown!r} is not a number", where=where) from None
    if not math.isfinite(v):
        raise DataFileError(f"{label}: {text} is not a finite number", where=where)
    limit, unit = (ANGLE_LIMIT_DEG, "deg") if col.endswith("_deg") else (LENGTH_LIMIT_MM, "mm")
    if col != "pose" and abs(v) > limit:
        raise DataFileError(f"{label}: {v:g} is beyond the plausible range +-{limit:g} {unit}", where=where)
    return v


def _rows_to_records(rows, cols, src, int_cols=("pose",)):
    values, lines = [], []
    for lineno, cells in rows:
        where = f"{src}:{lineno}"
        if len(cells) != len(cols):
            more = "" if len(cells) < len(cols) else f" (field {len(cols) + 1} = {cells[len(cols)]!r} is extra)"
            raise DataFileError(f"{len(cells)} fields, expected {len(cols)} ({','.join(cols)}){more}", where=where)
        rec = {}
        for j, (c, cell) in enumerate(zip(cols, cells), 1):
            rec[c] = _number(cell, where, c, j)
            if c in int_cols and rec[c] != int(rec[c]):
                raise DataFileError(f"column '{c}' (field {j}): {cell!r} is not a whole number", where=where)
        values.append(rec)
        lines.append(lineno)
    return values, lines


def _check_pose_numbers(values, lines, src, col_index):
    """Poses numbered 0, 1, ... in file order; the first deviation is reported."""
    first = {}
    for k, rec in enumerate(values):
        p = int(rec["pose"])
        if p != k:
            if p in first:
                msg = f"pose {p} appears twice (lines {first[p]} and {lines[k]})"
            else:
                msg = f"expected {k}, got {p}" + (" (numbering starts at 0)" if k == 0 and p == 1 else "")
            raise DataFileError(f"column 'pose' (field {col_index}): {msg}; poses are numbered 0, 1, ... in "
                                "visiting order, one row each", where=f"{src}:{lines[k]}")
        first[p] = lines[k]


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


# --------------------------------------------------------------------------- pose lists

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


# --------------------------------------------------------------------------- results and compensation

@dataclass
class ResultFile:
    """The parts of a results JSON that a compensation needs.

    Attributes
    ----------
    zero_offsets_deg : ndarray, shape (2,)
    std_zero_offsets_deg : ndarray, shape (2,)
        NaN where unknown.
    maemm_mm : ndarray, shape (2,)
        NaN where unknown.
    method, status : str
    success : bool
    robot_sha256 : str or None
    raw : dict
        The whole JSON object.
    source : str
    """

    zero_offsets_deg: np.ndarray
    std_zero_offsets_deg: np.ndarray
    maemm_mm: np.ndarray
    method: str
    status: str
    success: bool
    robot_sha256: str | None
    raw: dict
    source: str


def _reject_constant(c):
    raise ValueError(f"{c} is not allowed")


def _load_json(text: str, src: str):
    try:
        return json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise DataFileError(f"not valid JSON: {exc.msg} (column {exc.colno})", where=f"{src}:{exc.lineno}") from None
    except (ValueError, RecursionError) as exc:
        raise DataFileError(f"not valid JSON: {exc}", where=src) from None


def _json_line(text: str, key: str):
    m = re.search(rf'"{re.escape(key)}"\s*:', text)
    return text.count("\n", 0, m.start()) + 1 if m else None


def _vec2(obj, key, text, src, required=True):
    where = f"{src}:{_json_line(text, key)}" if _json_line(text, key) else src
    if key not in obj:
        if required:
            raise DataFileError(f"missing key '{key}' (a results file from 'zerocal identify --json')", where=src)
        return np.full(2, np.nan)
    v = obj[key]
    if not isinstance(v, list) or len(v) != 2:
        raise DataFileError(f"key '{key}' must be a list of 2 numbers, got {json.dumps(v)[:60]}", where=where)
    out = []
    for x in v:
        if x is None and not required:
            out.append(np.nan)
            continue
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise DataFileError(f"key '{key}' must be a list of 2 finite numbers, got {json.dumps(v)[:60]}",
                                where=where)
        out.append(float(x))
    return np.array(out)


def _find_sha(obj):
    for k in ("robot_sha256", "robot_hash"):
        if isinstance(obj.get(k), str):
            return obj[k]
    r = obj.get("robot")
    if isinstance(r, dict) and isinstance(r.get("sha256"), str):
        return r["sha256"]
    return None


def load_result(path, allow_failed: bool = False) -> ResultFile:
    """Read a results JSON (``zerocal identify --json``).

    Parameters
    ----------
    path : str or Path
    allow_failed : bool
        Accept a result whose ``success`` is false (otherwise an error: a
        failed identification must not be used as a calibration).

    Returns
    -------
    ResultFile

    Raises
    ------
    DataFileError
        Naming the file and the line of the offending key.
    """
    text, src = _read_text(path, "results file")
    if not text.strip():
        raise DataFileError("empty results file", where=src)
    obj = _load_json(text, src)
    if not isinstance(obj, dict):
        raise DataFileError("a results file is a JSON object {...}", where=src)
    off = _vec2(obj, "zero_offsets_deg", text, src)
    std = _vec2(obj, "std_zero_offsets_deg", text, src, required=False)
    maemm = _vec2(obj, "maemm_mm", text, src, required=False)
    success = obj.get("success", True)
    status = str(obj.get("status", ""))
    if not isinstance(success, bool):
        raise DataFileError("key 'success' must be true or false", where=f"{src}:{_json_line(text, 'success')}")
    if not success and not allow_failed:
        raise DataFileError(f"the identification failed (status: {status or '?'}); it must not be used as a "
                            "calibration", where=f"{src}:{_json_line(text, 'success')}")
    return ResultFile(off, std, maemm, str(obj.get("method", "?")), status, success, _find_sha(obj), obj, src)


def compensated_commands(robot, P, offsets_deg) -> tuple[np.ndarray, np.ndarray]:
    """Nominal and compensated joint commands for target positions.

    Parameters
    ----------
    robot : Robot
    P : ndarray, shape (K, 2)
        Target positions, mm.
    offsets_deg : array_like, shape (2,)
        Identified zero offsets, deg.

    Returns
    -------
    theta_nominal : ndarray, shape (K, 2)
        ``IK(P)``, rad.
    theta_cmd : ndarray, shape (K, 2)
        ``IK(P) - offset``, rad (what to command).

    Raises
    ------
    PoseError
        For an unreachable pose.
    """
    from zerocal_sym.model import kinematics as kin

    nominal = kin.ik(robot, np.atleast_2d(np.asarray(P, float)))
    return nominal, nominal - np.radians(np.asarray(offsets_deg, float))


def format_compensation(result: ResultFile, meta: dict | None = None) -> str:
    """The compensation table a controller takes (offsets in degrees).

    Returns
    -------
    str
        CSV ``joint,offset_deg,std_deg`` with comment lines stating the sign
        convention.
    """
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION, "method": result.method, "status": result.status,
                           **({"robot_sha256": result.robot_sha256} if result.robot_sha256 else {}),
                           **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["joint", "offset_deg", "std_deg"])
    for j in range(2):
        s = result.std_zero_offsets_deg[j]
        w.writerow([f"theta{j + 1}", repr(float(result.zero_offsets_deg[j])), "" if not np.isfinite(s) else
                    repr(float(s))])
    return buf.getvalue()


def format_commands(P, theta_nominal, theta_cmd, offsets_deg, meta: dict | None = None) -> str:
    """Compensated joint commands for a pose list, as CSV.

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        mm.
    theta_nominal, theta_cmd : ndarray, shape (K, 2)
        rad.
    offsets_deg : (2,)

    Returns
    -------
    str
        ``pose,x_mm,y_mm,theta1_nominal_deg,theta2_nominal_deg,theta1_cmd_deg,theta2_cmd_deg``.
    """
    buf = io.StringIO()
    buf.write(COMPENSATION_LINE + "\n")
    buf.write(_format_meta({"sign": SIGN_CONVENTION,
                           "offset_deg": f"{float(offsets_deg[0])!r}, {float(offsets_deg[1])!r}", **(meta or {})}))
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["pose", "x_mm", "y_mm", "theta1_nominal_deg", "theta2_nominal_deg", "theta1_cmd_deg",
                "theta2_cmd_deg"])
    n, c = np.degrees(theta_nominal), np.degrees(theta_cmd)
    for k in range(len(P)):
        w.writerow([k] + [repr(float(v)) for v in (P[k, 0], P[k, 1], n[k, 0], n[k, 1], c[k, 0], c[k, 1])])
    return buf.getvalue()
