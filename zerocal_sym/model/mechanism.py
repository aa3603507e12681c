"""Registry of mechanisms: a name -> its generated CasADi builders, checked on load.

A mechanism is a derivation module (``derivations/mechanisms/<name>.py``) whose
generated module ``zerocal_sym/generated/<name>.py`` exports its names, roles
and shapes beside the CasADi builders.  :class:`Mechanism` loads that module
and checks the contract (:data:`CONTRACT`): every function the numeric layers
use is there with the sizes the names imply.  Adding a mechanism = a
derivation module, a line in ``derivations.codegen.MECHANISMS`` and in
:data:`REGISTRY`, and robot files that name it (``docs/new-mechanism.md``).

Glossary of sizes: n pose coordinates, m actuated joints, G geometry entries,
q source errors (r of them on the robot, n on the measuring mechanism),
s singularity indicators, z gauge motions.
"""
from __future__ import annotations

import importlib
from functools import lru_cache

from zerocal_sym.model.source_errors import SourceErrors

REGISTRY = {
    "planar_2dof": "zerocal_sym.generated.planar_2dof",
    "delta_rotary": "zerocal_sym.generated.delta_rotary",
}
DEFAULT_MECHANISM = "planar_2dof"


class MechanismContractError(Exception):
    """A generated module that does not fulfil the mechanism contract (a developer error)."""


def _contract(n, m, G, q, r, z):
    """Function name -> (input sizes, output shapes) implied by the sizes."""
    return {
        "ik": ([n, G], [(m, 1), (m, 1)]),
        "fk": ([m, G], [(n, 1)]),
        "transmission": ([n, m, G], None),
        "pose_error_jacobian": ([n, m, G], [(n, r)]),
        "error_jacobian": ([n, m, G], [(n, m)]),
        "measuring": ([n, G], [(1, 1), (n, 1)]),
        "g_row": ([n, m, G], [(1, m + n)]),
        "distance": ([m, G, q], [(1, 1)]),
        "gauge": ([G], [(q, z)]),
    }


#: The function names every mechanism provides.
CONTRACT = tuple(_contract(0, 0, 0, 0, 0, 0))


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
        if name not in REGISTRY:
            raise KeyError(name)
        import numpy as np

        mod = importlib.import_module(REGISTRY[name])
        self.name = name
        self.module = mod
        self.description = mod.DESCRIPTION
        self.pose_names = list(mod.POSE_NAMES)
        self.joint_names = list(mod.JOINT_NAMES)
        self.geometry_names = list(mod.GEOMETRY_NAMES)
        self.geometry_units = dict(mod.GEOMETRY_UNITS)
        names = [row[0] for row in mod.SOURCE_ERRORS]
        # "gauge_fixed": every source error but those that fix the gauge (identifiable from enough poses)
        self.errors = SourceErrors(mod.SOURCE_ERRORS, {
            **mod.PARAM_SETS, "gauge_fixed": tuple(n for n in names if n not in mod.GAUGE_FIX)})
        self.source_error_names = list(self.errors.names)
        self.home_joints = np.array(mod.HOME_JOINTS, float)
        self.measuring_base = list(mod.MEASURING_BASE)
        self.measuring_offset = list(mod.MEASURING_OFFSET)
        self.gauge_names = list(mod.GAUGE_NAMES)
        self.gauge_fix = list(mod.GAUGE_FIX)
        self.workspace = mod.WORKSPACE
        self.aliases = dict(mod.ALIASES)
        self.defaults = dict(mod.DEFAULTS)
        self.positive = list(mod.POSITIVE)
        self.n, self.m = len(self.pose_names), len(self.joint_names)
        self.functions = mod.build_functions()
        self.check()

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
        if [e[x].target for x in e.measuring] != self.measuring_base or len(self.measuring_base) != n:
            fail("one measuring-mechanism error per pose coordinate, carried on the base point")
        for err in e:
            if err.role == "geometry" and err.target not in self.geometry_names:
                fail(f"source error {err.name!r} targets unknown geometry {err.target!r}")
            if (err.unit == "rad") != (err.lever is not None) or (err.lever and err.lever not in self.geometry_names):
                fail(f"source error {err.name!r}: an angle needs a lever arm in the geometry, a length none")
        if self.home_joints.shape != (m,):
            fail("HOME_JOINTS must have one entry per joint")
        for fname, (ins, outs) in _contract(n, m, G, q, r, len(self.gauge_names)).items():
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
