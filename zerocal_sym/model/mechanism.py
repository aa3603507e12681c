"""Registry of mechanisms: a name -> its generated CasADi builders.

A mechanism is described by the constants and the ``build_functions()`` of its
generated module (``zerocal_sym/generated/<name>.py``, written by
``derivations/<name>.py``).  Adding a mechanism = a derivation module, a line in
``derivations.codegen.MECHANISMS``, a line in :data:`REGISTRY`, and robot files
that name it.  The numeric layers above (kinematics, measurement, fisher,
identification, design) only use the function names listed in
``FUNCTION_SIGNATURES``.
"""
from __future__ import annotations

import importlib
from functools import lru_cache

REGISTRY = {"planar_2dof": "zerocal_sym.generated.planar_2dof"}


class Mechanism:
    """The generated CasADi functions of one mechanism, built once.

    Attributes
    ----------
    name : str
    geometry_names, source_error_names, joint_names, pose_names : list of str
    functions : dict of str -> casadi.Function
    """

    def __init__(self, name: str):
        if name not in REGISTRY:
            raise KeyError(name)
        mod = importlib.import_module(REGISTRY[name])
        self.name = name
        self.module = mod
        self.geometry_names = list(mod.GEOMETRY_NAMES)
        self.source_error_names = list(mod.SOURCE_ERROR_NAMES)
        self.joint_names = list(mod.JOINT_NAMES)
        self.pose_names = list(mod.POSE_NAMES)
        self.functions = mod.build_functions()

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
def get_mechanism(name: str = "planar_2dof") -> Mechanism:
    """The (cached) :class:`Mechanism` called ``name``."""
    return Mechanism(name)
