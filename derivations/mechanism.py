"""Mechanism-independent symbolic machinery.

A closed-loop mechanism is described by

* its loop-closure equations ``f(P, theta, g) = 0`` (one per limb),
* its actuated joints ``theta`` (the commanded coordinates),
* its geometric parameters ``g`` (nominal values come from a robot file),
* its source-error parameters (each an additive error on one actuated joint or
  one geometric parameter),
* its measuring mechanism (a distance between a base point and a platform point).

:class:`SymbolicMechanism` holds that description; the functions here derive
what every mechanism needs from it: the first-order error model by implicit
differentiation of the loop closure.  A new mechanism (a five-bar, a Delta with
a spherical-joint measuring mechanism) is a new module that fills in a
``SymbolicMechanism``; the code generator and the runtime stay as they are.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass
class SymbolicMechanism:
    """Symbolic description of a closed-loop mechanism.

    Attributes
    ----------
    name : str
        Module name of the generated code (``zerocal_sym/generated/<name>.py``).
    pose : list of Symbol, length n
        Platform coordinates (mm).
    joints : list of Symbol, length m
        Actuated joint coordinates (rad).
    geometry : list of Symbol
        Geometric parameters in the order of the runtime geometry vector.
    loop_closure : list of Expr, length m
        ``f_i(pose, joints, geometry)``; zero on the mechanism.
    source_errors : list of (str, Symbol)
        Each source error by name with the joint or geometric symbol it is
        added to.
    base_point, platform_offset : Matrix
        Measuring mechanism: base joint ``O1 = base_point`` and
        ``P - O2 = platform_offset``; ``lambda = P - base_point - platform_offset``.
    outputs : dict
        Filled by the mechanism module: name -> (inputs, expressions, doc).
    """

    name: str
    pose: list
    joints: list
    geometry: list
    loop_closure: list
    source_errors: list
    base_point: sp.Matrix
    platform_offset: sp.Matrix
    outputs: dict = field(default_factory=dict)

    def error_symbols(self):
        """Symbols standing for the source errors, in order."""
        return [sp.Symbol("d_" + name, real=True) for name, _ in self.source_errors]


def implicit_pose_jacobian(mech: SymbolicMechanism, wrt):
    """dP/dq from the loop closure by implicit differentiation.

    ``f(P(q), q) = 0``  =>  ``dP/dq = -(df/dP)^-1 df/dq``.

    Parameters
    ----------
    mech : SymbolicMechanism
    wrt : list of Symbol
        The joint or geometric symbols to differentiate with respect to.

    Returns
    -------
    Matrix, shape (n, len(wrt))
        In terms of the pose, the joints and the geometry (no solved kinematics
        inside, so it is valid on every branch).
    """
    f = sp.Matrix(mech.loop_closure)
    fP = f.jacobian(sp.Matrix(mech.pose))
    fq = f.jacobian(sp.Matrix(wrt))
    # adjugate / determinant: the only division is by det(df/dP), which vanishes
    # exactly at the parallel singularities. (LU pivoting would divide by a
    # pivot entry too and put a spurious singularity where that entry is zero.)
    return -(fP.adjugate() * fq) / fP.det()


def measuring_vector(mech: SymbolicMechanism):
    """The nominal measuring-mechanism vector ``lambda = P - c - d``."""
    return sp.Matrix(mech.pose) - mech.base_point - mech.platform_offset
