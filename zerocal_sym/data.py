"""The measurement file format (CSV) and its loader.

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

Every error names the file, the line and, where there is one, the column.
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io import atomic_write_text

REQUIRED_COLUMNS = ("pose", "theta1_deg", "theta2_deg", "reading_mm")
OPTIONAL_COLUMNS = ("x_mm", "y_mm")
FORMAT_LINE = "# zerocal measurements v1"
#: commanded poses farther than this outside the workspace are rejected (mm);
#: compensation moves commanded angles by a few degrees, i.e. a few mm.
WORKSPACE_TOL_MM = 25.0
MIN_POSES = 5


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
    """

    theta_cmd: np.ndarray
    readings: np.ndarray
    target: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    source: str = "<memory>"
    lines: list = field(default_factory=list)

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


def format_measurements(meas: Measurements) -> str:
    """CSV text of ``meas`` in the documented format."""
    buf = io.StringIO()
    buf.write(FORMAT_LINE + "\n")
    for k, v in meas.meta.items():
        buf.write(f"# {k}: {v}\n")
    cols = list(REQUIRED_COLUMNS) + (list(OPTIONAL_COLUMNS) if meas.target is not None else [])
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    deg = np.degrees(meas.theta_cmd)
    for k in range(meas.K):
        row = [k, repr(float(deg[k, 0])), repr(float(deg[k, 1])), repr(float(meas.readings[k]))]
        if meas.target is not None:
            row += [repr(float(meas.target[k, 0])), repr(float(meas.target[k, 1]))]
        w.writerow(row)
    return buf.getvalue()


def write_measurements(path, meas: Measurements) -> None:
    """Write ``meas`` to ``path`` atomically."""
    atomic_write_text(path, format_measurements(meas))


def _number(text: str, where: str, col: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise DataFileError(f"column '{col}': {text.strip()!r} is not a number", where=where) from None
    if not math.isfinite(v):
        raise DataFileError(f"column '{col}': {text.strip()} is not a finite number", where=where)
    return v


def load_measurements(path, robot=None, min_poses: int = MIN_POSES) -> Measurements:
    """Read and validate a measurement CSV.

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        If given, every commanded pose must be reachable and (within
        :data:`WORKSPACE_TOL_MM`) inside the robot's workspace.
    min_poses : int
        At least this many poses (5 for the paper's 4 parameters).

    Raises
    ------
    DataFileError
        With ``file:line: column 'name': ...``.
    """
    path = Path(path)
    src = str(path)
    try:
        raw = path.read_text()
    except FileNotFoundError:
        raise DataFileError("file not found", where=src) from None
    except UnicodeDecodeError:
        raise DataFileError("not a text (UTF-8) file", where=src) from None
    except OSError as exc:
        raise DataFileError(f"cannot read: {exc.strerror}", where=src) from None
    meta, rows = {}, []
    header = header_line = None
    for lineno, line in enumerate(raw.splitlines(), 1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            if header is None and ":" in stripped:
                k, _, v = stripped[1:].partition(":")
                meta[k.strip()] = v.strip()
            continue
        cells = next(csv.reader([line]))
        if header is None:
            header, header_line = [c.strip() for c in cells], lineno
            continue
        rows.append((lineno, cells))
    if header is None:
        raise DataFileError("empty file: no header line and no data", where=src)
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise DataFileError(f"missing column(s): {', '.join(missing)} (header must be "
                            f"{','.join(REQUIRED_COLUMNS)}[,x_mm,y_mm])", where=f"{src}:{header_line}")
    extra = [c for c in header if c not in REQUIRED_COLUMNS + OPTIONAL_COLUMNS]
    if extra:
        raise DataFileError(f"unexpected column(s): {', '.join(extra)}", where=f"{src}:{header_line}")
    dup = {c for c in header if header.count(c) > 1}
    if dup:
        raise DataFileError(f"duplicated column(s): {', '.join(sorted(dup))}", where=f"{src}:{header_line}")
    has_xy = [c in header for c in OPTIONAL_COLUMNS]
    if any(has_xy) and not all(has_xy):
        raise DataFileError("columns x_mm and y_mm go together", where=f"{src}:{header_line}")
    if not rows:
        raise DataFileError("no data rows after the header", where=src)
    cols = header
    values, lines = [], []
    for lineno, cells in rows:
        where = f"{src}:{lineno}"
        if len(cells) != len(cols):
            raise DataFileError(f"{len(cells)} cells, expected {len(cols)} ({','.join(cols)})", where=where)
        rec = {}
        for c, cell in zip(cols, cells):
            if cell.strip() == "":
                raise DataFileError(f"column '{c}': empty cell", where=where)
            rec[c] = _number(cell, where, c)
        values.append(rec)
        lines.append(lineno)
    K = len(values)
    for k, rec in enumerate(values):
        if rec["pose"] != k:
            raise DataFileError(f"column 'pose': expected {k} (poses are numbered 0, 1, ... in visiting order), "
                                f"got {rec['pose']:g}", where=f"{src}:{lines[k]}")
    if values[0]["reading_mm"] != 0.0:
        raise DataFileError("column 'reading_mm': the reading at pose 0 must be 0 (the head is reset there)",
                            where=f"{src}:{lines[0]}")
    theta = np.radians(np.array([[r["theta1_deg"], r["theta2_deg"]] for r in values]))
    readings = np.array([r["reading_mm"] for r in values])
    target = np.array([[r["x_mm"], r["y_mm"]] for r in values]) if all(has_xy) else None
    meas = Measurements(theta, readings, target, meta, src, lines)
    if K < min_poses:
        raise DataFileError(f"too few poses: {K} (at least {min_poses} are needed to identify the parameters)",
                            where=src)
    seen = {}
    for k in range(K):
        key = tuple(np.round(np.degrees(theta[k]), 9))
        if key in seen:
            raise DataFileError(f"pose {k} repeats the commanded joint angles of pose {seen[key]} "
                                f"(line {lines[seen[key]]})", where=meas.where(k))
        seen[key] = k
    if robot is not None:
        check_against_robot(meas, robot)
    return meas


def check_against_robot(meas: Measurements, robot) -> None:
    """Every commanded pose reachable and inside the workspace (see module doc)."""
    from zerocal_sym import kinematics as kin

    P = kin.fk(robot, meas.theta_cmd)
    lo, hi = robot.workspace_bounds()
    for k in range(meas.K):
        if not np.all(np.isfinite(P[k])):
            raise DataFileError("commanded joint angles are not an assembly of the robot (unreachable pose)",
                                where=meas.where(k))
        pts = [("commanded", P[k], WORKSPACE_TOL_MM)]
        if meas.target is not None:
            pts.append(("target (x_mm, y_mm)", meas.target[k], 1e-6))
        for what, p, tol in pts:
            if np.any(p < lo - tol) or np.any(p > hi + tol):
                raise DataFileError(
                    f"{what} pose ({p[0]:.3f}, {p[1]:.3f}) mm is outside the workspace "
                    f"x in [{lo[0]:g}, {hi[0]:g}], y in [{lo[1]:g}, {hi[1]:g}] (tolerance {tol:g} mm)",
                    where=meas.where(k))
