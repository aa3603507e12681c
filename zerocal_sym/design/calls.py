"""The design's per-pose Functions over many poses: zero-copy, in chunks, on the compiled tier.

A design evaluates the same few per-pose Functions -- the design terms
(:func:`zerocal_sym.design.terms._pose_terms_fn`), the inverse and the forward
kinematics -- thousands of times, on anything from one pose to thousands
(the candidate grids, the certificate's pattern searches, the exchange's and
the checked design's trials).  Called with numpy arrays, a CasADi Function
converts every argument and result (about 0.1 ms a call) and maps itself over
the columns anew at each call; here each runs through
:class:`~zerocal_sym.model.fastcall.Columns` (mapped Functions of a few chunk
sizes, built once, called through their buffers) and, once hot, their
compiled twins (:class:`~zerocal_sym.model.compiled.Tier`: ``ZEROCAL_COMPILE``
decides; the compiled Functions return the interpreted ones' numbers, bit for
bit, so a design does not depend on which ran).  Every column is evaluated on
its own, as before: the numbers are those of a call on all the poses.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

#: the Functions of a mechanism are compiled when their instructions add up to at most this many (the planar
#: robot's about 900, the rotary Delta's about 4000; the hexapod's forward kinematics alone has 8947 and its
#: design terms 58588: a build of minutes, left interpreted)
COMPILE_MAX_INSTRUCTIONS = 10000


class _Calls:
    """The per-pose Functions of one mechanism and identified set, each callable over N poses."""

    #: name -> which inputs are per pose (the others, the geometry, shared)
    PER_POSE = {"design_pose_terms": (True, False), "design_pose_terms_fk": (True, False), "ik": (True, False),
                "fk": (True, False)}

    def __init__(self, mech_name: str, params: tuple):
        from zerocal_sym.design.terms import _pose_terms_fn
        from zerocal_sym.model.compiled import Tier
        from zerocal_sym.model.mechanism import get_mechanism

        mech = get_mechanism(mech_name)
        terms = _pose_terms_fn(mech_name, params)
        funcs = {"design_pose_terms": terms, "design_pose_terms_fk": _with_fk(terms, mech["fk"]), "ik": mech["ik"],
                 "fk": mech["fk"]}
        self.tier = None
        if (len({f.name() for f in funcs.values()}) == len(funcs)
                and sum(f.n_instructions() for f in funcs.values()) <= COMPILE_MAX_INSTRUCTIONS):
            self.tier = Tier(funcs, f"design-{mech_name}-" + "_".join(params))
        self._funcs, self._cols, self._version = funcs, {}, None

    def __call__(self, name: str, *args):
        """The outputs of Function ``name`` over the columns of its per-pose inputs (rows, N): arrays (rows, N)."""
        if self.tier is not None:
            self.tier.touch()
            if self._version != self.tier.version:
                self._funcs, self._cols, self._version = self.tier.get(), {}, self.tier.version
        cols = self._cols.get(name)
        if cols is None:
            from zerocal_sym.model.fastcall import Columns

            f = self._funcs[name]
            try:
                cols = Columns(f, self.PER_POSE[name])
            except ValueError:  # an output that is not a dense column (a mechanism of one's own): the plain call
                def cols(*a, f=f):
                    return [o.full() for o in f.call(list(a))]
            self._cols[name] = cols
        return cols(*args)


def _with_fk(terms, fk):
    """The design terms and, last, the forward kinematics of their joints (the reachable set's check that the
    model's assembly mode returns the pose) in one Function: the same expressions, the same numbers."""
    import casadi as ca

    P, g = ca.SX.sym("P", terms.size1_in(0)), ca.SX.sym("g", terms.size1_in(1))
    out = terms(P, g)
    return ca.Function("design_pose_terms_fk", [P, g], list(out) + [fk(out[0], g)], ["P", "g"],
                       [terms.name_out(i) for i in range(terms.n_out())] + ["fk"])


@lru_cache(maxsize=None)
def _calls(mech_name: str, params: tuple) -> _Calls:
    return _Calls(mech_name, params)


def calls(robot) -> _Calls:
    """The :class:`_Calls` of the robot's mechanism and identified set."""
    from zerocal_sym.design.terms import design_params

    return _calls(robot.mechanism_name, tuple(design_params(robot)))


def ik(robot, P):
    """Inverse kinematics and reach ratios without checks at poses ``P`` (K, n): shapes (K, m) each."""
    P = np.atleast_2d(np.asarray(P, float))
    theta, ratio = calls(robot)("ik", P.T, robot.geometry)
    return theta.T.reshape(len(P), -1), ratio.T.reshape(len(P), -1)


def fk(robot, theta):
    """Forward kinematics at joints ``theta`` (K, m): poses (K, n) (NaN where the limbs do not close)."""
    theta = np.atleast_2d(np.asarray(theta, float))
    return np.ascontiguousarray(calls(robot)("fk", theta.T, robot.geometry)[0].T)
