"""Registry of mechanisms: a name -> its generated CasADi builders, checked on load.

A mechanism is a derivation module whose generated module exports its names,
roles, units and shapes beside the CasADi builders.  :class:`Mechanism` loads
that module and checks the contract (:data:`CONTRACT`): every function the
numeric layers use is there with the sizes the names imply.

Where a mechanism comes from (:func:`mechanism_module`):

* the built-in ones (:data:`REGISTRY`, ``zerocal_sym/generated/<name>.py``);
* an installed package's entry point in the group :data:`ENTRY_POINT_GROUP`
  (``name = "package.generated_module"``);
* a robot file's ``mechanism_module`` line (a ``.py`` file beside the robot
  file, or a dotted module name), registered by :func:`register_mechanism`.

Glossary of sizes: n pose coordinates, m actuated joints, G geometry entries,
q source errors (r of them on the robot, u on the measuring mechanism),
l the measuring vector's dimension, s singularity indicators, z gauge motions.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
from functools import lru_cache
from pathlib import Path

from zerocal_sym.model.source_errors import SourceErrors
from zerocal_sym.model.units import JOINT_KINDS, UNIT_OF_KIND

REGISTRY = {
    "planar_2dof": "zerocal_sym.generated.planar_2dof",
    "delta_rotary": "zerocal_sym.generated.delta_rotary",
    "delta_linear": "zerocal_sym.generated.delta_linear",
    "hexapod": "zerocal_sym.generated.hexapod",
}
DEFAULT_MECHANISM = "planar_2dof"
#: the entry-point group of installed packages' mechanisms (name -> generated module)
ENTRY_POINT_GROUP = "zerocal_sym.mechanisms"
#: mechanisms registered at run time (:func:`register_mechanism`): name -> module name or .py path
_EXTERNAL = {}


class MechanismContractError(Exception):
    """A generated module that does not fulfil the mechanism contract (a developer error)."""


def _contract(n, m, G, q, r, z, l=None, u=None):
    """Function name -> (input sizes, output shapes) implied by the sizes."""
    l = n if l is None else l
    u = n if u is None else u
    return {
        "ik": ([n, G], [(m, 1), (m, 1)]),
        "fk": ([m, G], [(n, 1)]),
        "transmission": ([n, m, G], None),
        "pose_error_jacobian": ([n, m, G], [(n, r)]),
        "error_jacobian": ([n, m, G], [(n, m)]),
        "measuring": ([n, G], [(1, 1), (l, 1)]),
        "g_row": ([n, m, G], [(1, m + u)]),
        "distance": ([m, G, q], [(1, 1)]),
        "gauge": ([G], [(q, z)]),
    }


#: The function names every mechanism provides.
CONTRACT = tuple(_contract(0, 0, 0, 0, 0, 0))


def _entry_points() -> dict:
    """Installed packages' mechanisms: name -> module (the :data:`ENTRY_POINT_GROUP` entry points)."""
    from importlib.metadata import entry_points

    return {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}


def known_mechanisms() -> dict:
    """Every mechanism that can be loaded now: name -> its generated module (name or path).

    The built-in ones first (a name of theirs is theirs), then those registered by robot files, then the
    installed packages' (a registered name wins over an entry point's).
    """
    known = dict(REGISTRY)
    for source in (_EXTERNAL, _entry_points()):
        for name, module in source.items():
            known.setdefault(name, module)
    return known


def is_known(name: str) -> bool:
    """Whether :func:`known_mechanisms` has ``name`` (the installed packages' entry points read only when it is
    neither built in nor registered: reading them takes milliseconds)."""
    return name in REGISTRY or name in _EXTERNAL or name in _entry_points()


def register_mechanism(name: str, module) -> None:
    """Make the generated module ``module`` (a dotted name, or a path to a ``.py`` file) mechanism ``name``.

    Raises
    ------
    ValueError
        ``name`` is a built-in mechanism, or already registered from another module.
    """
    module = str(Path(module).resolve()) if str(module).endswith(".py") else str(module)
    if name in REGISTRY and REGISTRY[name] != module:
        raise ValueError(f"mechanism {name!r} is built in; name yours otherwise")
    if _EXTERNAL.get(name, module) != module:
        raise ValueError(f"mechanism {name!r} is registered already (from {_EXTERNAL[name]})")
    _EXTERNAL[name] = module


def _import(module: str):
    """The generated module: a dotted name, or a ``.py`` file (imported under a private name)."""
    if not module.endswith(".py"):
        return importlib.import_module(module)
    key = "zerocal_sym._external." + Path(module).stem
    if key in sys.modules and getattr(sys.modules[key], "__file__", None) == module:
        return sys.modules[key]
    spec = importlib.util.spec_from_file_location(key, module)
    if spec is None:
        raise MechanismContractError(f"cannot import a mechanism from {module}")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[key] = mod
    spec.loader.exec_module(mod)
    return mod


class Mechanism:
    """The generated CasADi functions and the names of one mechanism, built once.

    Attributes
    ----------
    name, description : str
    pose_names, joint_names, geometry_names : list of str
    geometry_units : dict of str -> str
    errors : SourceErrors
    n, m : int
        Pose coordinates and actuated joints.
    home_joints : ndarray, shape (m,)
    measuring_base, measuring_offset : list of str
        Geometry names of ``c`` and ``d``.
    gauge_names : list of str
    gauge_fix : list of str
        Source errors held at zero to fix the gauge (the rest of ``all`` is
        identifiable from enough poses).
    workspace : str
        ``rectangle`` | ``cylinder``.
    aliases, defaults : dict
        What a robot file may write for the geometry.
    functions : dict of str -> casadi.Function
    """

    def __init__(self, name: str):
        known = known_mechanisms()
        if name not in known:
            raise KeyError(name)
        import numpy as np

        mod = _import(known[name])
        if getattr(mod, "NAME", name) != name:
            raise MechanismContractError(f"mechanism {name!r}: its module {known[name]} is mechanism {mod.NAME!r}")
        self.name = name
        self.module = mod
        self.description = mod.DESCRIPTION
        self.pose_names = list(mod.POSE_NAMES)
        self.joint_names = list(mod.JOINT_NAMES)
        self.geometry_names = list(mod.GEOMETRY_NAMES)
        self.geometry_units = dict(mod.GEOMETRY_UNITS)
        names = [row[0] for row in mod.SOURCE_ERRORS]
        # "gauge_fixed": every source error but those that fix the gauge (identifiable from enough poses)
        default_set = tuple(getattr(mod, "DEFAULT_SET", ())) or tuple(
            row[0] for row in mod.SOURCE_ERRORS if row[1] in ("zero_offset", "measuring"))
        self.errors = SourceErrors(mod.SOURCE_ERRORS, {
            **mod.PARAM_SETS, "gauge_fixed": tuple(n for n in names if n not in mod.GAUGE_FIX),
            "default": default_set})
        self.source_error_names = list(self.errors.names)
        self.joint_kinds = list(getattr(mod, "JOINT_KINDS", ["revolute"] * len(self.joint_names)))
        self.pose_units = dict(getattr(mod, "POSE_UNITS", {p: "mm" for p in self.pose_names}))
        home = getattr(mod, "HOME_JOINTS", None)
        self.home_joints = None if home is None else np.array(home, float)
        self.home_pose_rule = getattr(mod, "HOME_POSE", None)
        self.default_set = default_set
        self.workspace_defaults = dict(getattr(mod, "WORKSPACE_DEFAULTS", {}))
        self.noise_defaults = dict(getattr(mod, "NOISE", {}))
        self.measuring_base = list(mod.MEASURING_BASE)
        self.measuring_offset = list(mod.MEASURING_OFFSET)
        self.gauge_names = list(mod.GAUGE_NAMES)
        self.gauge_fix = list(mod.GAUGE_FIX)
        self.workspace = mod.WORKSPACE
        self.aliases = dict(mod.ALIASES)
        self.list_aliases = dict(getattr(mod, "LIST_ALIASES", {}))
        self.defaults = dict(mod.DEFAULTS)
        self.positive = list(mod.POSITIVE)
        self.n, self.m = len(self.pose_names), len(self.joint_names)
        self.functions = mod.build_functions()
        self.check()

    # ------------------------------------------------------------------ units
    @property
    def joint_kind(self) -> str:
        """The kind of every actuated joint (``revolute`` | ``prismatic``)."""
        return self.joint_kinds[0]

    @property
    def joint_unit(self) -> str:
        """Internal unit of the joints and their zero offsets: ``rad`` | ``mm``."""
        return JOINT_KINDS[self.joint_kind]

    @property
    def joint_user_unit(self) -> str:
        """The joints' unit in files and on the command line: ``deg`` | ``mm``."""
        return UNIT_OF_KIND[self.joint_kind]

    @property
    def measuring_dim(self) -> int:
        """l: the dimension of the measuring vector (2 or 3)."""
        return len(self.measuring_base)

    def check(self) -> None:
        """Check the generated module against the contract.

        Raises
        ------
        MechanismContractError
            Naming the mechanism and what is wrong.
        """
        def fail(msg):
            raise MechanismContractError(f"mechanism {self.name!r}: {msg}")

        e = self.errors
        n, m, G, q = self.n, self.m, len(self.geometry_names), len(e)
        r = q - len(e.measuring)
        if len(e.zero_offsets) != m or [e[x].target for x in e.zero_offsets] != self.joint_names:
            fail("one zero offset per actuated joint, in joint order")
        if len(self.joint_kinds) != m or not set(self.joint_kinds) <= set(JOINT_KINDS) or len(set(self.joint_kinds)) > 1:
            fail(f"JOINT_KINDS must give one kind ({', '.join(JOINT_KINDS)}) shared by the {m} joints")
        if any(e[x].unit != JOINT_KINDS[k] for x, k in zip(e.zero_offsets, self.joint_kinds)):
            fail("a zero offset has its joint kind's unit (rad for revolute, mm for prismatic)")
        if not set(e[x].target for x in e.measuring) <= set(self.measuring_base) | set(self.measuring_offset):
            fail("measuring-mechanism errors are carried on the base point c or the platform point d")
        if len(self.measuring_offset) != len(self.measuring_base) or len(self.measuring_base) not in (2, 3):
            fail("the measuring points c and d have 2 or 3 coordinates each")
        if not set(self.default_set) <= set(e.zero_offsets) | set(e.measuring) or not set(e.zero_offsets) <= set(
                self.default_set):
            fail("DEFAULT_SET: every zero offset, and measuring errors only")
        for err in e:
            if err.role == "geometry" and err.target not in self.geometry_names:
                fail(f"source error {err.name!r} targets unknown geometry {err.target!r}")
            if (err.unit == "rad") != (err.lever is not None) or (err.lever and err.lever not in self.geometry_names):
                fail(f"source error {err.name!r}: an angle needs a lever arm in the geometry, a length none")
        if (self.home_joints is None) == (self.home_pose_rule is None):
            fail("HOME_JOINTS or HOME_POSE, one of them")
        if self.home_joints is not None and self.home_joints.shape != (m,):
            fail("HOME_JOINTS must have one entry per joint")
        if self.home_pose_rule not in (None, "workspace centre") and self.home_pose_rule not in self.functions:
            fail(f"HOME_POSE names a function {self.home_pose_rule!r} the module lacks")
        contract = _contract(n, m, G, q, r, len(self.gauge_names), len(self.measuring_base), len(e.measuring))
        for fname, (ins, outs) in contract.items():
            f = self.functions.get(fname)
            if f is None:
                fail(f"missing function {fname!r}")
            got_in = [f.size1_in(k) for k in range(f.n_in())]
            got_out = [f.size_out(k) for k in range(f.n_out())]
            if got_in != ins or (outs is not None and got_out != outs):
                fail(f"function {fname!r} has inputs {got_in} and outputs {got_out}, the contract says "
                     f"{ins} and {outs}")

    def __getitem__(self, fname):
        if fname not in self.functions and fname in _DERIVED:
            self.functions[fname] = _DERIVED[fname](self)
        return self.functions[fname]


def _distance_jacobians(mech: Mechanism):
    """``rho`` and its exact derivatives w.r.t. the source errors and the joints."""
    import casadi as ca

    f = mech.functions["distance"]
    th = ca.SX.sym("theta_cmd", f.size1_in(0))
    g = ca.SX.sym("g", f.size1_in(1))
    err = ca.SX.sym("err", f.size1_in(2))
    rho = f(th, g, err)
    return ca.Function("distance_jacobians", [th, g, err],
                       [rho, ca.jacobian(rho, err), ca.jacobian(rho, th)],
                       ["theta_cmd", "g", "err"], ["rho", "drho_derr", "drho_dtheta"])


#: Functions built from the generated ones by CasADi (derivatives, compositions).
_DERIVED = {"distance_jacobians": _distance_jacobians}


@lru_cache(maxsize=None)
def get_mechanism(name: str = DEFAULT_MECHANISM) -> Mechanism:
    """The (cached) :class:`Mechanism` called ``name``."""
    return Mechanism(name)
