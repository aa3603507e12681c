"""Robot geometry: the paper's Table 1 built in, other robots from TOML files.

A robot file (mm, degrees) has the keys of Table 1::

    ex = 80      # A1 = (ex, ey), A2 = (-ex, ey)
    ey = 0
    L = 375      # proximal links (or L1, L2)
    l = 825      # distal links   (or l1, l2)
    H = 632      # workspace: x in [-b/2, b/2], y in [H, H + h]
    b = 480
    h = 150
    cx = 0       # O -> O1, base joint of the measuring mechanism
    cy = 79
    dx = 0       # O2 -> P, platform joint of the measuring mechanism
    dy = 51

and optionally ``name``, ``mechanism = "planar_2dof"``, ``units = "mm"`` and
``singularity_margin`` (default 0.2: every ``|sin|`` of a transmission angle in
the workspace must be at least this, i.e. angles kept >= 11.5 deg from a
singular configuration).
"""
from __future__ import annotations

import hashlib
import json
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from zerocal_sym.errors import RobotFileError
from zerocal_sym.model.mechanism import get_mechanism

#: Paper Table 1 (with the OCR-dropped ``ey = 0`` restored), mm.
PAPER_TABLE1 = dict(ex=80.0, ey=0.0, L=375.0, l=825.0, H=632.0, b=480.0, h=150.0,
                    cx=0.0, cy=79.0, dx=0.0, dy=51.0)

DEFAULT_SINGULARITY_MARGIN = 0.2
REQUIRED = ("ex", "ey", "H", "b", "h", "cx", "cy", "dx", "dy")
OPTIONAL = ("L", "l", "L1", "L2", "l1", "l2", "name", "mechanism", "units", "singularity_margin")


@dataclass(frozen=True)
class Robot:
    """A robot of the paper's kind with its workspace.

    Attributes
    ----------
    geometry : ndarray, shape (12,)
        ``e1x e1y e2x e2y L1 L2 l1 l2 cx cy dx dy`` (mm).
    H, b, h : float
        Workspace rectangle ``x in [-b/2, b/2]``, ``y in [H, H + h]`` (mm).
    """

    geometry: np.ndarray
    H: float
    b: float
    h: float
    name: str = "paper"
    mechanism_name: str = "planar_2dof"
    source: str = "built-in (Mei et al. 2017, Table 1)"
    singularity_margin: float = DEFAULT_SINGULARITY_MARGIN
    keys: dict = field(default_factory=dict, compare=False)

    @property
    def mechanism(self):
        return get_mechanism(self.mechanism_name)

    def param(self, name: str) -> float:
        """A geometric parameter by name (``L1``, ``cy``, ...)."""
        return float(self.geometry[self.mechanism.geometry_names.index(name)])

    @property
    def link_lengths(self):
        """``(L1, L2)``, mm."""
        return np.array([self.param("L1"), self.param("L2")])

    def workspace_bounds(self):
        """``(lo, hi)``: ndarray, shape (2,) each."""
        return np.array([-self.b / 2, self.H]), np.array([self.b / 2, self.H + self.h])

    def workspace_corners(self):
        """Dict corner label -> (x, y) in mm."""
        x0, x1, y0, y1 = -self.b / 2, self.b / 2, self.H, self.H + self.h
        return {"(-b/2, H)": (x0, y0), "(b/2, H)": (x1, y0),
                "(-b/2, H+h)": (x0, y1), "(b/2, H+h)": (x1, y1)}

    def workspace_grid(self, nx=25, ny=9):
        """Grid over the workspace rectangle, ndarray shape (nx*ny, 2)."""
        lo, hi = self.workspace_bounds()
        X, Y = np.meshgrid(np.linspace(lo[0], hi[0], nx), np.linspace(lo[1], hi[1], ny))
        return np.column_stack([X.ravel(), Y.ravel()])

    def home_joints(self):
        """Home: ``theta1 = 0``, ``theta2 = pi`` (rad), ndarray shape (2,)."""
        return np.array([0.0, np.pi])

    def home_pose(self):
        """Home position P0, mm, ndarray shape (2,)."""
        from zerocal_sym.model.kinematics import fk

        return fk(self, self.home_joints()[None, :])[0]

    def to_dict(self):
        d = {k: float(v) for k, v in zip(self.mechanism.geometry_names, self.geometry)}
        d.update(H=self.H, b=self.b, h=self.h, mechanism=self.mechanism_name,
                 singularity_margin=self.singularity_margin)
        return d

    @property
    def sha256(self) -> str:
        """Hash of the geometry (not of the file's formatting)."""
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _from_keys(keys: dict, name: str, source: str, where) -> Robot:
    def get(k):
        return float(keys[k])

    L1 = get("L1") if "L1" in keys else get("L")
    L2 = get("L2") if "L2" in keys else get("L")
    l1 = get("l1") if "l1" in keys else get("l")
    l2 = get("l2") if "l2" in keys else get("l")
    ex, ey = get("ex"), get("ey")
    geometry = np.array([ex, ey, -ex, ey, L1, L2, l1, l2,
                         get("cx"), get("cy"), get("dx"), get("dy")])
    return Robot(geometry=geometry, H=get("H"), b=get("b"), h=get("h"), name=name,
                 mechanism_name=str(keys.get("mechanism", "planar_2dof")), source=source,
                 singularity_margin=float(keys.get("singularity_margin", DEFAULT_SINGULARITY_MARGIN)),
                 keys=dict(keys))


def paper_robot() -> Robot:
    """The paper's robot (Table 1), validated."""
    return _from_keys(PAPER_TABLE1, "paper", "built-in (Mei et al. 2017, Table 1)", None)


def _line_of(text: str, key: str):
    for i, line in enumerate(text.splitlines(), 1):
        if re.match(rf"\s*({re.escape(key)}\s*=|\[\s*{re.escape(key)}\s*\])", line):
            return i
    return None


def load_robot(path) -> Robot:
    """Read and validate a robot TOML file.

    Raises
    ------
    RobotFileError
        Naming the file, the line and the key (or workspace corner) at fault.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise RobotFileError("robot file not found", where=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise RobotFileError(f"cannot read robot file: {exc}", where=str(path)) from None
    try:
        keys = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise RobotFileError(f"not valid TOML: {exc}", where=str(path)) from None

    def where(key):
        line = _line_of(text, key)
        return f"{path}:{line}" if line else str(path)

    for k, v in keys.items():
        if k not in REQUIRED + OPTIONAL:
            raise RobotFileError(f"unknown key '{k}' (allowed: {', '.join(REQUIRED + OPTIONAL)})", where=where(k))
        if k in ("name", "mechanism", "units"):
            if not isinstance(v, str):
                raise RobotFileError(f"key '{k}' must be a string", where=where(k))
        elif isinstance(v, bool) or not isinstance(v, (int, float)):
            raise RobotFileError(f"key '{k}' must be a number (mm), got {v!r}", where=where(k))
        elif not np.isfinite(v):
            raise RobotFileError(f"key '{k}' must be finite, got {v!r}", where=where(k))
    missing = [k for k in REQUIRED if k not in keys]
    for limb in ("L", "l"):
        if limb not in keys and not all(f"{limb}{i}" in keys for i in (1, 2)):
            missing.append(f"{limb} (or {limb}1 and {limb}2)")
    if missing:
        raise RobotFileError(f"missing key(s): {', '.join(missing)}", where=str(path))
    if keys.get("units", "mm") != "mm":
        raise RobotFileError(f"units = {keys['units']!r} is not supported: robot files are in mm",
                             where=where("units"))
    mech = keys.get("mechanism", "planar_2dof")
    from zerocal_sym.model.mechanism import REGISTRY

    if mech not in REGISTRY:
        raise RobotFileError(f"unknown mechanism {mech!r} (known: {', '.join(REGISTRY)})", where=where("mechanism"))
    robot = _from_keys(keys, str(keys.get("name", path.stem)), str(path), where)
    validate(robot, where=where)
    return robot


def validate(robot: Robot, where=None) -> dict:
    """Check that the robot is usable over its whole workspace.

    Checks: positive link lengths and workspace sizes; lengths that look like mm;
    every workspace corner (and a 25 x 9 grid) reachable; forward and inverse
    kinematics consistent there (same branch and assembly mode); every
    ``|sin|`` of the transmission angles at least ``robot.singularity_margin``.

    Returns
    -------
    dict
        Summary: home pose, joint angles at the corners (deg), the smallest
        transmission sine found and where.

    Raises
    ------
    RobotFileError
    """
    from zerocal_sym.errors import PoseError
    from zerocal_sym.model.kinematics import fk, ik, transmission

    where = where or (lambda key: robot.source)
    for key in ("L1", "L2", "l1", "l2"):
        if robot.param(key) <= 0:
            k = key if key in robot.keys else key[0]
            raise RobotFileError(f"link length {key} must be positive, got {robot.param(key):g}", where=where(k))
    for key in ("b", "h"):
        if getattr(robot, key) <= 0:
            raise RobotFileError(f"workspace size {key} must be positive, got {getattr(robot, key):g}",
                                 where=where(key))
    if robot.param("L1") + robot.param("l1") < 10:
        raise RobotFileError("link lengths look like metres: robot files are in mm", where=where("L"))
    if not 0 < robot.singularity_margin < 1:
        raise RobotFileError("singularity_margin must be in (0, 1)", where=where("singularity_margin"))
    corners = robot.workspace_corners()
    summary = {"home_pose_mm": None, "corners": {}}
    for label, xy in corners.items():
        try:
            th = ik(robot, np.array([xy]))
        except PoseError:
            raise RobotFileError(f"workspace corner {label} = ({xy[0]:g}, {xy[1]:g}) mm is unreachable",
                                 where=robot.source) from None
        summary["corners"][label] = {"pose_mm": list(xy), "joints_deg": np.degrees(th[0]).tolist()}
    grid = robot.workspace_grid()
    try:
        th = ik(robot, grid)
    except PoseError as exc:
        raise RobotFileError(f"part of the workspace is unreachable: {exc}", where=robot.source) from None
    back = fk(robot, th)
    bad = np.flatnonzero(~(np.linalg.norm(back - grid, axis=1) < 1e-6))
    if bad.size:
        x, y = grid[bad[0]]
        raise RobotFileError(f"forward and inverse kinematics disagree at ({x:g}, {y:g}) mm: "
                             "the workspace crosses an assembly-mode change", where=robot.source)
    s = np.abs(transmission(robot, grid, th))
    k = int(np.argmin(np.min(s, axis=1)))
    smin = float(np.min(s[k]))
    if smin < robot.singularity_margin:
        raise RobotFileError(
            f"configuration near-singular at ({grid[k, 0]:g}, {grid[k, 1]:g}) mm: min |sin transmission angle| "
            f"= {smin:.3g} < singularity_margin {robot.singularity_margin:g}", where=robot.source)
    home = robot.home_pose()
    summary.update(
        name=robot.name, source=robot.source, mechanism=robot.mechanism_name,
        home_pose_mm=home.tolist(),
        geometry_mm=robot.to_dict(),
        workspace_mm={"x": [-robot.b / 2, robot.b / 2], "y": [robot.H, robot.H + robot.h]},
        singularity_margin=robot.singularity_margin,
        min_transmission_sine=smin,
        min_transmission_sine_at_mm=grid[k].tolist(),
        sha256=robot.sha256,
    )
    return summary
