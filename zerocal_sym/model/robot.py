"""Robots: a mechanism, its nominal geometry and its workspace; robot files.

A robot file (TOML, mm and degrees) names its mechanism and gives the
geometry and the workspace, in tables or (the paper's flat files) at the top::

    name = "my delta"
    mechanism = "delta_rotary"        # default "planar_2dof"
    mechanism_module = "my_mech.py"   # optional: a mechanism of your own (a generated module beside this file,
                                      # or a dotted module name)
    singularity_margin = 0.2          # optional
    home = [0, 0, 0]                  # optional, the joints' unit (deg, mm) (default: the mechanism's)

    [geometry]                        # the mechanism's geometry names, or aliases
    R = 200                           # alias: R1 = R2 = R3 = 200
    L = 350
    l = 800
    r = 50
    cx = 0
    ...

    [workspace]                       # the mechanism's workspace shape
    rw = 200
    H = 700
    h = 200

    [noise]                           # optional: the measurement noise (default: the mechanism's, else the paper's)
    scale = 0.002                     # mm per measured change of the scale
    joint = 0.005                     # per joint per pose, in the joints' unit (deg for revolute, mm for prismatic)
    revisit_std_mm = 0.0              # a pose's systematic error of the measured length, shared by its revisits

    [tolerances]                      # optional: how well each entry is known (mm; deg for angles), for the
    L = 1.0                           # error budget; an entry (L1), a group (L: L1 L2 L3) or a set (lengths);
    phi2 = 0.2                        # default a robot measured by hand (zerocal_sym.model.tolerances)

An alias (``L`` for ``L1 = L2``, the planar ``ex`` for ``e1x = ex, e2x = -ex``)
sets several entries; an entry named explicitly wins over its alias (``L = 375``
with ``L2 = 380``).  Entries the mechanism gives defaults for may be left out
(the Delta's azimuths 0/120/240 deg).  Angles (the Delta's ``phi_i``) are
given in degrees.  A list key gives one value per entry (the hexapod's
``base_angles = [345, 15, 105, 135, 225, 255]``).

The paper's flat files (``ex = 80``, ``L = 375``, ``H = 632``, ...) keep
working with the same :attr:`Robot.sha256`.  The paper's robot (Table 1) is
built in (:func:`paper_robot`); ``examples/`` holds a file for each mechanism.
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
from zerocal_sym.model import units
from zerocal_sym.model.mechanism import DEFAULT_MECHANISM, get_mechanism, known_mechanisms, register_mechanism
from zerocal_sym.model.workspace import SHAPES

#: Paper Table 1 (with the OCR-dropped ``ey = 0`` restored), mm.
PAPER_TABLE1 = dict(ex=80.0, ey=0.0, L=375.0, l=825.0, H=632.0, b=480.0, h=150.0,
                    cx=0.0, cy=79.0, dx=0.0, dy=51.0)

DEFAULT_SINGULARITY_MARGIN = 0.2
#: home joint values beyond this are a unit or typing error (file units; the data files' limits)
HOME_LIMIT = {"deg": 3600.0, "mm": 1e5}
HOME_LIMIT_DEG = HOME_LIMIT["deg"]
#: a length (mm) in a robot file beyond this is no robot's (1 km, the data files' limit too; the distances'
#: arithmetic overflows far beyond)
LENGTH_LIMIT_MM = 1e6
#: a geometric angle (deg) in a robot file beyond this is a unit or typing error
ANGLE_LIMIT_DEG = 360.0
TOP_KEYS = ("name", "mechanism", "mechanism_module", "units", "singularity_margin", "home")
TABLES = ("geometry", "workspace", "noise", "tolerances")
NOISE_KEYS = ("scale", "joint", "revisit_std_mm")


@dataclass(frozen=True)
class Robot:
    """A robot: a mechanism with its nominal geometry and its workspace.

    Attributes
    ----------
    geometry : ndarray, shape (G,)
        In the mechanism's ``geometry_names`` order (mm; rad for angles).
    workspace : Rectangle or Cylinder
    home : ndarray, shape (m,) or None
        Home joints (internal units: rad, mm) if the file overrides the mechanism's.
    noise_values : tuple of (str, float)
        The robot file's ``[noise]`` (``scale`` mm, ``joint`` in the joints' file unit).
    tolerance_values : tuple of (str, float)
        The robot file's ``[tolerances]`` in table order (user units; keys as
        :mod:`zerocal_sym.model.tolerances`): :meth:`tolerances` resolves them.
    identified_set : str
        The parameters a calibration of this robot estimates (a set as
        :meth:`SourceErrors.resolve <zerocal_sym.model.source_errors.SourceErrors.resolve>`
        takes: ``"paper"``, the default, or ``"paper+L1,L2,L3"``); what the
        designs are made for (:meth:`identifying`).  Not in :attr:`sha256`.
    """

    geometry: np.ndarray
    workspace: object
    name: str = "paper"
    mechanism_name: str = DEFAULT_MECHANISM
    source: str = "built-in (Mei et al. 2017, Table 1)"
    singularity_margin: float = DEFAULT_SINGULARITY_MARGIN
    home: np.ndarray | None = None
    keys: dict = field(default_factory=dict, compare=False)
    noise_values: tuple = ()
    tolerance_values: tuple = ()
    identified_set: str = "paper"

    @property
    def mechanism(self):
        return get_mechanism(self.mechanism_name)

    @property
    def errors(self):
        """The mechanism's :class:`~zerocal_sym.model.source_errors.SourceErrors`."""
        return self.mechanism.errors

    @property
    def n(self) -> int:
        return self.mechanism.n

    @property
    def m(self) -> int:
        return self.mechanism.m

    def param(self, name: str) -> float:
        """A geometric parameter by name (``L1``, ``cy``, ...), internal units."""
        return float(self.geometry[self.mechanism.geometry_names.index(name)])

    def params(self, names) -> np.ndarray:
        return np.array([self.param(n) for n in names])

    def error_scale(self, names) -> np.ndarray:
        """mm per unit of each source error: lever arm for angles, 1 for lengths, shape (p,)."""
        return self.errors.scale(names, self.param)

    @property
    def noise(self):
        """The robot's measurement noise (:class:`~zerocal_sym.model.noise.NoiseModel`): the robot file's
        ``[noise]``, else the mechanism's default, else the paper's (Eqs. 34, 35)."""
        from zerocal_sym.model.noise import NoiseModel

        return NoiseModel.of_robot(self)

    def identifying(self, params) -> "Robot":
        """This robot with :attr:`identified_set` = ``params`` (a set name, names joined by ``+`` or ``,``, or a
        sequence of names); ValueError for an unknown name."""
        import dataclasses

        spec = params if isinstance(params, str) else ",".join(params)
        self.errors.resolve(spec)  # (raises for an unknown name)
        return dataclasses.replace(self, identified_set=spec)

    def tolerances(self) -> dict:
        """How well each entry held at the file's value is known: name -> tolerance, internal units (mm, rad),
        for every source error but the zero offsets: the file's ``[tolerances]``, else the defaults of a robot
        measured by hand (:mod:`zerocal_sym.model.tolerances`)."""
        from zerocal_sym.model import tolerances as tl

        errors = self.errors
        return {n: errors.from_user_value(n, v) for n, v in tl.resolve(errors, self.tolerance_values).items()}

    def workspace_bounds(self):
        """Bounding box of the workspace, ``(lo, hi)`` ndarray shape (n,) each."""
        return self.workspace.bounds()

    def workspace_corners(self) -> dict:
        return self.workspace.corners()

    def workspace_grid(self, *args):
        return self.workspace.grid(*args)

    def home_joints(self) -> np.ndarray:
        """Home joints (internal units: rad, mm), shape (m,): the file's, the mechanism's, or the IK of its
        home pose."""
        if self.home is not None:
            return np.array(self.home, float)
        mech = self.mechanism
        if mech.home_joints is not None:
            return mech.home_joints.copy()
        from zerocal_sym.model.kinematics import ik

        return ik(self, self.nominal_home_pose()[None, :], check=False)[0]

    def nominal_home_pose(self) -> np.ndarray:
        """The mechanism's home pose (a home-pose mechanism only), shape (n,)."""
        rule = self.mechanism.home_pose_rule
        if rule == "workspace centre":
            return self.workspace.centre()
        return np.array(self.mechanism[rule](self.geometry).full(), float).ravel()

    def home_pose(self) -> np.ndarray:
        """Home pose P0 (mm, rad), shape (n,): the forward kinematics of the home joints."""
        from zerocal_sym.model.kinematics import fk

        return fk(self, self.home_joints()[None, :])[0]

    def to_dict(self) -> dict:
        """Geometry (file units: mm, deg), workspace, mechanism and margin: what :attr:`sha256` hashes."""
        geo_units = self.mechanism.geometry_units
        d = {k: float(units.to_user(v, geo_units.get(k, "mm")))
             for k, v in zip(self.mechanism.geometry_names, self.geometry)}
        d.update(self.workspace.to_dict())
        d.update(mechanism=self.mechanism_name, singularity_margin=self.singularity_margin)
        if self.home is not None:
            d[units.joint_key(self, "home")] = units.joints_to_user(self, self.home).tolist()
        if self.noise_values:
            d["noise"] = dict(self.noise_values)
        return d

    @property
    def sha256(self) -> str:
        """Hash of the geometry (not of the file's formatting)."""
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _geometry(mech, values: dict, where) -> np.ndarray:
    """Geometry vector from explicit entries, aliases and defaults (file units)."""
    out, missing = [], []
    listed = {part: (alias, k) for alias, parts in mech.list_aliases.items() for k, part in enumerate(parts)}
    for name in mech.geometry_names:
        if name in values:
            v = values[name]
        elif name in listed and listed[name][0] in values:
            v = values[listed[name][0]][listed[name][1]]
        else:
            v = None
            for alias, parts in mech.aliases.items():
                if name in parts and alias in values:
                    v = parts[name] * values[alias]
            if v is None:
                v = mech.defaults.get(name)
        if v is None:
            alias = [a for a, parts in mech.aliases.items() if name in parts]
            missing.append(f"{alias[0]} (or {' and '.join(mech.aliases[alias[0]])})" if alias else name)
            continue
        out.append(float(units.from_user(float(v), mech.geometry_units.get(name, "mm"))))
    if missing:
        raise RobotFileError(f"missing key(s): {', '.join(dict.fromkeys(missing))}", where=where(None))
    return np.array(out, float)


def _from_keys(keys: dict, name: str, source: str, where=None) -> Robot:
    """A :class:`Robot` from checked keys (flat or in ``geometry``/``workspace`` tables)."""
    where = where or (lambda key: source)
    mech = get_mechanism(str(keys.get("mechanism", DEFAULT_MECHANISM)))
    ws_cls = SHAPES[mech.workspace]
    flat = {k: v for k, v in keys.items() if k not in TOP_KEYS + TABLES}
    geo = {**{k: v for k, v in flat.items() if k not in ws_cls.keys}, **keys.get("geometry", {})}
    ws_values = {**mech.workspace_defaults, **{k: v for k, v in flat.items() if k in ws_cls.keys},
                 **keys.get("workspace", {})}
    ws_values.pop("shape", None)
    geometry = _geometry(mech, geo, where)
    try:
        workspace = ws_cls.from_values(ws_values)
    except KeyError as exc:
        raise RobotFileError(f"missing or conflicting workspace key(s): {exc.args[0]}", where=where(None)) from None
    home = keys.get("home")
    return Robot(geometry=geometry, workspace=workspace,
                 name=name, mechanism_name=mech.name, source=source,
                 singularity_margin=float(keys.get("singularity_margin", DEFAULT_SINGULARITY_MARGIN)),
                 home=None if home is None else units.joints_from_user(mech, home), keys=dict(keys),
                 noise_values=tuple((k, float(v)) for k, v in keys.get("noise", {}).items()),
                 tolerance_values=tuple((k, float(v)) for k, v in keys.get("tolerances", {}).items()))


def paper_robot() -> Robot:
    """The paper's robot (Table 1), with the magnitudes of Table 2's set A as its tolerances."""
    from zerocal_sym.model.tolerances import PAPER_SET_A_TOLERANCES_MM

    return _from_keys({**PAPER_TABLE1, "tolerances": PAPER_SET_A_TOLERANCES_MM}, "paper",
                      "built-in (Mei et al. 2017, Table 1)")


def _line_of(text: str, key: str, table: str | None = None):
    """The line (1-based) of ``key`` (in ``[table]`` when given), or None."""
    inside = table is None
    for i, line in enumerate(text.splitlines(), 1):
        if table is not None and re.match(r"\s*\[", line):
            inside = re.match(rf"\s*\[\s*{re.escape(table)}\s*\]", line) is not None
            continue
        if inside and re.match(rf"\s*({re.escape(key)}\s*=|\[\s*{re.escape(key)}\s*\])", line):
            return i
    return None


def _shown(v) -> str:
    """``v`` for a message: an integer too long to show is named by its digits."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) >= 10**30:
        return f"an integer of {len(str(abs(v)))} digits"
    return repr(v)


def _is_finite_number(v) -> bool:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    try:
        return bool(np.isfinite(float(v)))
    except OverflowError:  # an integer too large for a float (10**400 written out)
        return False


def _check_number(k, v, unit, where):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise RobotFileError(f"key '{k}' must be a number ({unit}), got {v!r}", where=where(k))
    if not _is_finite_number(v):
        raise RobotFileError(f"key '{k}' must be a finite number, got {_shown(v)}", where=where(k))
    limit = ANGLE_LIMIT_DEG if unit == "deg" else LENGTH_LIMIT_MM
    if abs(float(v)) > limit:
        raise RobotFileError(f"key '{k}' = {_shown(v)} {unit} is beyond +-{limit:g} {unit}: not a robot's "
                             f"(robot files are in mm and degrees)", where=where(k))


def _check_keys(keys: dict, where) -> None:
    """Types, names and units of every key, before anything is computed."""
    for k in ("name", "mechanism", "mechanism_module", "units"):
        if k in keys and not isinstance(keys[k], str):
            raise RobotFileError(f"key '{k}' must be a string", where=where(k))
    mech_name = keys.get("mechanism", DEFAULT_MECHANISM)
    if mech_name not in known_mechanisms():
        raise RobotFileError(f"unknown mechanism {mech_name!r} (known: {', '.join(known_mechanisms())}; a mechanism "
                             "of your own: mechanism_module = \"its_generated_module.py\")", where=where("mechanism"))
    if keys.get("units", "mm") != "mm":
        raise RobotFileError(f"units = {keys['units']!r} is not supported: robot files are in mm",
                             where=where("units"))
    mech = get_mechanism(mech_name)
    ws_cls = SHAPES[mech.workspace]
    geo_keys = tuple(mech.geometry_names) + tuple(mech.aliases) + tuple(mech.list_aliases)
    ju = mech.joint_user_unit

    def unit(k):
        if k in getattr(ws_cls, "angles", ()) or k == "ring_azimuth":
            return "deg"
        return "deg" if mech.geometry_units.get(k) == "rad" else "mm"

    def check_list(k, v):
        n = len(mech.list_aliases[k])
        if not isinstance(v, list) or len(v) != n or not all(_is_finite_number(x) for x in v):
            raise RobotFileError(f"key '{k}' must be a list of {n} finite numbers ({unit(mech.list_aliases[k][0])}), "
                                 f"got {_shown(v) if not isinstance(v, list) else 'a list of ' + str(len(v))}",
                                 where=where(k))

    allowed = TOP_KEYS + geo_keys + ws_cls.keys
    for k, v in keys.items():
        if k == "tolerances" and isinstance(v, dict):
            from zerocal_sym.model.tolerances import check_table

            check_table(mech.errors, v, lambda key: where(key, "tolerances"), _check_number, RobotFileError,
                        ANGLE_LIMIT_DEG)
            continue
        if k == "noise" and isinstance(v, dict):
            for kk, vv in v.items():
                if kk not in NOISE_KEYS:
                    raise RobotFileError(f"unknown key '{kk}' in [noise] (allowed: {', '.join(NOISE_KEYS)})",
                                         where=where(kk))
                _check_number(kk, vv, "mm" if kk in ("scale", "revisit_std_mm") else ju, where)
                if vv < 0:
                    raise RobotFileError(f"[noise] {kk} is a standard deviation: >= 0, got {vv!r}", where=where(kk))
            if v.get("revisit_std_mm", 0) > 0 and v.get("scale") == 0 and v.get("joint") == 0:
                raise RobotFileError("[noise] revisit_std_mm needs an independent term beside it (scale or joint "
                                     "> 0): revisits of a pose would measure exactly the same length",
                                     where=where("revisit_std_mm"))
            continue
        if k in TABLES and isinstance(v, dict):
            inner = geo_keys if k == "geometry" else ws_cls.keys + ("shape",)
            for kk, vv in v.items():
                if kk not in inner:
                    raise RobotFileError(f"unknown key '{kk}' in [{k}] (allowed: {', '.join(inner)})",
                                         where=where(kk))
                if kk == "shape":
                    if vv != ws_cls.kind:
                        raise RobotFileError(f"workspace shape {vv!r} does not fit mechanism {mech.name!r} "
                                             f"(its workspace is a {ws_cls.kind})", where=where(kk))
                    continue
                if kk in keys and kk not in TABLES:
                    raise RobotFileError(f"key '{kk}' given twice (top level and [{k}])", where=where(kk))
                if kk in mech.list_aliases:
                    check_list(kk, vv)
                    continue
                _check_number(kk, vv, unit(kk), where)
            continue
        if k in TABLES:
            raise RobotFileError(f"'{k}' must be a table ([{k}])", where=where(k))
        if k not in allowed:
            raise RobotFileError(f"unknown key '{k}' (allowed: {', '.join(allowed + TABLES)})", where=where(k))
        if k in ("name", "mechanism", "mechanism_module", "units"):
            continue
        if k in mech.list_aliases:
            check_list(k, v)
            continue
        if k == "home":
            lim = HOME_LIMIT[ju]
            if (not isinstance(v, list) or len(v) != mech.m
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
                raise RobotFileError(f"home must be a list of {mech.m} {units.joint_noun(mech)} ({ju}), got {v!r}",
                                     where=where(k))
            if not all(_is_finite_number(x) and abs(float(x)) <= lim for x in v):
                raise RobotFileError(f"home must be {mech.m} finite {units.joint_noun(mech)} within +-{lim:g} {ju}, "
                                     f"got [{', '.join(_shown(x) for x in v)}]", where=where(k))
            continue
        _check_number(k, v, "mm" if k in ws_cls.keys or k == "singularity_margin" else unit(k), where)


def read_toml(path, error, what: str) -> dict:
    """The TOML file at ``path`` as a dict; ``error(message, where=...)`` naming the file (and line) otherwise.

    ``what`` names the file in the messages ("robot file", "study spec").  UTF-8; a
    byte-order mark at the start is accepted (and skipped).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8").removeprefix("\ufeff")
    except FileNotFoundError:
        raise error(f"{what} not found", where=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"cannot read the {what}: {exc}", where=str(path)) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise error(f"not valid TOML: {exc}", where=f"{path}:{m.group(1)}" if m else str(path)) from None
    except RecursionError:  # arrays or tables nested thousands deep: the parser's recursion ends first
        line = _deepest_line(text)
        raise error("not valid TOML here: arrays or inline tables nested too deeply",
                    where=f"{path}:{line}" if line else str(path)) from None


def _deepest_line(text: str):
    """The line (1-based) where brackets/braces nest deepest, or None."""
    depth = best = 0
    line = where = 1
    for ch in text:
        if ch == "\n":
            line += 1
        elif ch in "[{":
            depth += 1
            if depth > best:
                best, where = depth, line
        elif ch in "]}":
            depth = max(depth - 1, 0)
    return where if best else None


def module_file(path) -> Path | None:
    """The ``.py`` file a robot file's ``mechanism_module`` names (an input of every command that reads the robot
    file), or None (no such line, a module name, or a file that does not parse: its loader says why)."""
    try:
        module = read_toml(path, RobotFileError, "robot file").get("mechanism_module")
    except (RobotFileError, OSError, ValueError):
        return None
    return (Path(path).parent / module) if isinstance(module, str) and module.endswith(".py") else None


def _register_module(keys: dict, path: Path, where) -> None:
    """Register the robot file's ``mechanism_module`` (a ``.py`` file relative to the file, or a module name)."""
    module = keys.get("mechanism_module")
    if module is None:
        return
    if not isinstance(module, str) or "mechanism" not in keys:
        raise RobotFileError("mechanism_module goes with mechanism = \"<its name>\" (a string each)",
                             where=where("mechanism_module"))
    if module.endswith(".py"):
        file = (path.parent / module).resolve()
        if not file.is_file():
            raise RobotFileError(f"mechanism_module {module!r}: no such file ({file})", where=where("mechanism_module"))
        module = str(file)
    try:
        register_mechanism(str(keys["mechanism"]), module)
        get_mechanism(str(keys["mechanism"]))
    except Exception as exc:  # noqa: BLE001 -- a user's module: any failure to import or check it is theirs
        raise RobotFileError(f"mechanism_module {keys['mechanism_module']!r} cannot be loaded as mechanism "
                             f"{keys['mechanism']!r}: {type(exc).__name__}: {exc}", where=where("mechanism_module"))


def load_robot(path) -> Robot:
    """Read and validate a robot TOML file.

    Raises
    ------
    RobotFileError
        Naming the file, the line and the key (or workspace corner) at fault.
    """
    path = Path(path)
    keys = read_toml(path, RobotFileError, "robot file")
    text = path.read_text(encoding="utf-8").removeprefix("\ufeff")  # for the line numbers of the keys

    def where(key, table=None):
        line = (_line_of(text, key, table) or _line_of(text, key)) if key else None
        return f"{path}:{line}" if line else str(path)

    _register_module(keys, path, where)
    _check_keys(keys, where)
    robot = _from_keys(keys, str(keys.get("name", path.stem)), str(path), where)
    validate(robot, where=where)
    return robot


def validate(robot: Robot, where=None) -> dict:
    """Check that the robot is usable over its whole workspace.

    Checks: positive lengths (the mechanism's ``POSITIVE`` entries) and
    workspace sizes; lengths that look like mm; every workspace corner (rim)
    and a grid over the workspace reachable; forward and inverse kinematics
    consistent there (same branch and assembly mode); every singularity
    indicator ``|s|`` at least ``robot.singularity_margin``.

    Returns
    -------
    dict
        Summary: home pose, joint angles at the corners (deg), the joint range
        over the grid, the largest ``|FK(IK(P)) - P|``, the smallest
        singularity indicator found and where.

    Raises
    ------
    RobotFileError
    """
    from zerocal_sym.errors import PoseError
    from zerocal_sym.model.kinematics import fk, fmt_user_pose, ik, ik_ratio, transmission

    where = where or (lambda key: robot.source)
    mech = robot.mechanism

    def key_of(name):
        if name in robot.keys or name in robot.keys.get("geometry", {}):
            return name
        return next((a for a, parts in mech.aliases.items() if name in parts), name)

    links = set(mech.errors.extra_sets.get("lengths", ()))
    for key in mech.positive:
        if robot.param(key) <= 0:
            what = "link length" if key in links else "length"
            raise RobotFileError(f"{what} {key} must be positive, got {robot.param(key):g}", where=where(key_of(key)))
    for key in robot.workspace.sizes:
        v = getattr(robot.workspace, key)
        if v <= 0:
            raise RobotFileError(f"workspace size {key} must be positive, got {v:g}", where=where(key))
    for key in getattr(robot.workspace, "distances", ()):
        v = getattr(robot.workspace, key)
        if v <= 0:
            raise RobotFileError(f"workspace distance {key} must be positive, got {v:g}: it is how far the workspace "
                                 f"is from the base ({robot.workspace.kind}: {robot.workspace.describe()} mm), on "
                                 "the side the mechanism works", where=where(key))
    if max(robot.param(k) for k in mech.positive) < 10:
        raise RobotFileError("link lengths look like metres: robot files are in mm", where=where(key_of(mech.positive[0])))
    if not 0 < robot.singularity_margin < 1:
        raise RobotFileError("singularity_margin must be in (0, 1)", where=where("singularity_margin"))

    def fmt(p):
        return "(" + ", ".join(f"{v:g}" for v in p) + ")"

    jkey = units.joint_key(robot, "joints")
    summary = {units.pose_key(robot, "home_pose"): None, "corners": {}}
    corners = robot.workspace_corners()
    P_c = np.array(list(corners.values()), float)
    th_c = ik(robot, P_c, check=False)
    _, ratio = ik_ratio(robot, P_c)
    for (label, p), th, ok in zip(corners.items(), th_c, np.all(np.abs(ratio) <= 1, axis=1) & np.all(
            np.isfinite(th_c), axis=1)):
        if not ok:
            raise RobotFileError(f"workspace corner {label} = {fmt_user_pose(robot, p)} is unreachable "
                                 "(a limb cannot close, or a joint is beyond its travel)", where=robot.source)
        summary["corners"][label] = {units.pose_key(robot, "pose"): units.pose_to_user(robot, p).tolist(),
                                     jkey: units.joints_to_user(robot, th).tolist()}
    grid = robot.workspace_grid()
    try:
        th = ik(robot, grid)
    except PoseError as exc:
        raise RobotFileError(f"part of the workspace is unreachable: {exc}", where=robot.source) from None
    back = fk(robot, th)
    dev = np.linalg.norm(back - grid, axis=1)
    bad = np.flatnonzero(~(dev < 1e-6))
    if bad.size:
        raise RobotFileError(f"forward and inverse kinematics disagree at {fmt_user_pose(robot, grid[bad[0]])}: "
                             "the workspace crosses an assembly-mode change (or the forward kinematics' solve "
                             "does not converge there)", where=robot.source)
    s = np.abs(transmission(robot, grid, th))
    k = int(np.argmin(np.min(s, axis=1)))
    smin = float(np.min(s[k]))
    if smin < robot.singularity_margin:
        raise RobotFileError(
            f"configuration near-singular at {fmt_user_pose(robot, grid[k])}: min |singularity indicator| "
            f"(sine of a transmission angle) = {smin:.3g} < singularity_margin {robot.singularity_margin:g}",
            where=robot.source)
    home = robot.home_pose()
    if not np.all(np.isfinite(home)):
        raise RobotFileError("the home joints are not an assembly of the robot", where=where("home"))
    jr = units.joints_to_user(robot, np.array([th.min(), th.max()]))
    summary.update(
        name=robot.name, source=robot.source, mechanism=robot.mechanism_name,
        description=mech.description,
        joint_kind=mech.joint_kind,
        joint_unit=mech.joint_user_unit,
        pose_names=list(mech.pose_names),
        pose_units=[units.pose_unit(mech, p) for p in mech.pose_names],
        **{units.pose_key(robot, "home_pose"): units.pose_to_user(robot, home).tolist()},
        **{units.joint_key(robot, "home_joints"): units.joints_to_user(robot, robot.home_joints()).tolist()},
        geometry_mm=robot.to_dict(),
        workspace=robot.workspace.kind,
        workspace_mm=robot.workspace.ranges(),
        **{units.joint_key(robot, "joint_range"): [float(jr[0]), float(jr[1])]},
        fk_ik_max_error_mm=float(dev.max()),
        singularity_margin=robot.singularity_margin,
        min_transmission_sine=smin,
        **{units.pose_key(robot, "min_transmission_sine_at"): units.pose_to_user(robot, grid[k]).tolist()},
        sha256=robot.sha256,
    )
    return summary
