"""Per-pose feasibility of designs' poses, and the design terms of the feasible ones from the same evaluation.

The certificate's pattern searches, the candidate grids and the checked design's polish check thousands of
poses for feasibility (region, reach, singularity margin, joint limits; on the reachable set also the
forward kinematics' assembly mode) and then need the design terms
(:func:`~zerocal_sym.design.terms.pose_terms`) of the feasible ones: both come from one evaluation
(:func:`_pointwise`), the terms laid out as ``pose_terms`` lays them out (:func:`take_terms`), so that what
is computed from them is what ``pose_terms`` of those poses would give, bit for bit.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.design.calls import calls, fk, ik
from zerocal_sym.design.terms import _reachable, pose_terms, terms_dict


def _pointwise(robot, P, cons):
    """Per-pose feasibility under the constraints ``cons`` (region, reach, margin, joint limits; on the reachable
    set :func:`reachable_terms`), bool shape (K,), and the design terms of the feasible poses (those of
    :func:`~zerocal_sym.design.terms.pose_terms` of ``P[ok]``, or None when none is), from one evaluation."""
    from zerocal_sym.design.constraints import _POINT_TOL

    P = np.atleast_2d(P)
    ok = cons.region.contains(P, _POINT_TOL)
    if not np.any(ok):
        return ok, None
    idx = np.flatnonzero(ok)
    if cons.mode_signs is not None:
        jl = cons.joint_limits_internal()
        good, t = reachable_terms(robot, P[ok], cons.singularity_margin, jl, np.asarray(cons.mode_signs))
    else:
        t = pose_terms(robot, P[ok])
        good = _reachable(t["ratio"], t["theta"], 1e-9)
        sel = np.flatnonzero(good)
        if len(sel):
            sub = np.min(np.abs(t["s"][sel]), axis=1) >= cons.singularity_margin + 1e-9
            if cons.joint_limits is not None:
                jl = cons.joint_limits_internal()
                theta = t["theta"][sel]
                sub &= np.all((theta >= jl[:, 0] + 1e-9) & (theta <= jl[:, 1] - 1e-9), axis=1)
            good[sel] = sub
            sel = sel[sub]
        t = take_terms(t, sel)
    ok[idx] = good
    return ok, (t if np.any(good) else None)


def take_terms(t: dict, keep) -> dict:
    """The design terms (:func:`~zerocal_sym.design.terms.pose_terms`) of the poses ``keep`` selects (bool or
    indices), laid out as ``pose_terms`` lays them out (each (K, r) array column-major), so that what is computed
    from them is what ``pose_terms`` of those poses would give, bit for bit."""
    return {k: (v[keep] if v.ndim == 1 else np.asfortranarray(v[keep])) for k, v in t.items()}


def reachable_terms(robot, P, margin, jl_rad, signs):
    """Per-pose feasibility of the reachable set (no clip: every limb closes, each signed singularity indicator
    at least ``margin``, the joints within ``jl_rad`` (rad or mm, (m, 2), or None), the forward kinematics
    returning the pose), bool shape (K,), and the design terms of the feasible poses (:func:`take_terms`; None
    when none is), from one evaluation of the terms."""
    P = np.atleast_2d(P)
    if len(P) <= FUSED_MAX:  # one call: the terms and the forward kinematics of every pose
        out = calls(robot)("design_pose_terms_fk", P.T, robot.geometry)
        t, back = terms_dict(out[:-1], len(P)), np.ascontiguousarray(out[-1].T)
        ok = _reachable(t["ratio"], t["theta"], 1e-9)
    else:  # a grid, many poses out of reach: the inverse kinematics first, the terms of the reachable poses
        ok = _reachable(*ik(robot, P)[::-1], 1e-9)
    idx = np.flatnonzero(ok)
    if not len(idx):
        return ok, None
    if len(P) <= FUSED_MAX:
        s, theta, back = t["s"][idx], t["theta"][idx], back[idx]
    else:
        t = pose_terms(robot, P[idx])
        s, theta = t["s"], t["theta"]
        back = fk(robot, theta)
    good = np.min(s * signs, axis=1) >= margin + 1e-9
    if jl_rad is not None:
        good &= np.all((theta >= jl_rad[:, 0] + 1e-9) & (theta <= jl_rad[:, 1] - 1e-9), axis=1)
    good &= np.linalg.norm(back - P[idx], axis=1) < 1e-6
    ok[idx] = good
    if not np.any(good):
        return ok, None
    return ok, take_terms(t, idx[good] if len(P) <= FUSED_MAX else good)


#: :func:`reachable_terms` of up to this many poses in one call (the terms and the forward kinematics of each);
#: of more (a grid over a box, many poses out of reach) the terms of the reachable ones only
FUSED_MAX = 4096
