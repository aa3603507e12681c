"""The predicted accuracy over the workspace before and after compensating the zero offsets.

The numbers of the calibration report's maps, for any mechanism (m zero
offsets, n pose coordinates):

before
    the position error of the robot commanded without compensation when its
    zero offsets are the identified ones: ``|FK_actual(IK(P)) - P|`` over the
    position coordinates (mm), exact forward kinematics; its 1 sigma
    propagated from the offsets' covariance ``C`` (m, m) to first order,
    ``sqrt(u^T J C J^T u)`` with ``J`` (3, m) = dP/d(offsets) where the robot
    then stands (the joints ``IK(P) + offsets``) and ``u`` the error's
    direction;
after
    what the offsets' uncertainty leaves once they are compensated: the
    error ``J (offsets_true - offsets_estimated)`` is ``N(0, J C J^T)``, whose
    RMS length ``sqrt(trace(J C J^T))`` (mm) is the map.  Source errors
    outside the identified model are in neither.

A pose's orientation coordinates (unit ``rad`` inside, deg outside) are held
at the workspace's centre in the maps; their own errors (deg) are summed up
beside the positions' (:func:`accuracy_map`'s ``orientation``).

The maps are drawn on a grid of the first two position coordinates (x, y),
masked to the workspace and to reachable poses, at one level of the third
(2-D poses: the plane itself; 3-D: its bottom, middle and top).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units

#: cells along the longer side of a map
MAP_CELLS = 41


def position_axes(robot) -> tuple:
    """``(position, orientation)``: the indices of the pose coordinates in mm and those in rad."""
    mech = robot.mechanism
    kinds = [units.pose_unit(mech, name) for name in mech.pose_names]
    return ([k for k, u in enumerate(kinds) if u == "mm"], [k for k, u in enumerate(kinds) if u != "mm"])


def offset_jacobian(robot, P, theta=None) -> np.ndarray:
    """dP/d(zero offsets), per rad (revolute) or per mm (prismatic), shape (K, n, m)."""
    errors = robot.errors
    cols = [name for name in errors.names if name not in errors.measuring]  # pose_error_jacobian's columns
    J = kin.pose_error_jacobian(robot, P, theta)
    return J[:, :, [cols.index(name) for name in errors.zero_offsets]]


def grid(robot, cells: int = MAP_CELLS) -> dict:
    """The maps' grid: ``x`` (nx,), ``y`` (ny,), ``levels`` [(name, value in mm)] and ``P`` (L, ny, nx, n)."""
    pos, _ = position_axes(robot)
    lo, hi = robot.workspace.bounds()
    centre = robot.workspace.centre()
    ix, iy = pos[0], pos[1]
    span = max(hi[ix] - lo[ix], hi[iy] - lo[iy])
    nx = max(9, int(round(cells * (hi[ix] - lo[ix]) / span)))
    ny = max(9, int(round(cells * (hi[iy] - lo[iy]) / span)))
    x, y = np.linspace(lo[ix], hi[ix], nx), np.linspace(lo[iy], hi[iy], ny)
    names = robot.mechanism.pose_names
    if len(pos) > 2:
        iz = pos[2]
        levels = [(names[iz], float(v)) for v in (lo[iz], centre[iz], hi[iz])]
    else:
        levels = [(None, None)]
    P = np.empty((len(levels), ny, nx, robot.n))
    P[...] = centre
    P[..., ix] = x[None, None, :]
    P[..., iy] = y[None, :, None]
    for k, (_, v) in enumerate(levels):
        if v is not None:
            P[k, ..., pos[2]] = v
    return {"x": x, "y": y, "levels": levels, "P": P, "axes": (names[ix], names[iy])}


def _reachable(robot, P) -> np.ndarray:
    """Poses in the workspace where every limb closes, shape (K,) bool."""
    ok = robot.workspace.contains(P)
    with np.errstate(all="ignore"):
        theta, ratio = kin.ik_ratio(robot, P)
    return ok & np.all(np.abs(ratio) <= 1.0, axis=1) & np.all(np.isfinite(theta), axis=1)


def predicted_errors(robot, offsets, cov, P) -> dict:
    """Before/after position errors at K poses (module docstring).

    Parameters
    ----------
    offsets : ndarray, shape (m,)
        The identified zero offsets, internal units (rad, mm).
    cov : ndarray, shape (m, m) or None
        Their covariance, internal units; None: no uncertainty (NaN).
    P : ndarray, shape (K, n)
        Reachable poses.

    Returns
    -------
    dict
        ``before_mm``, ``before_std_mm``, ``after_mm`` (K,); ``before_deg``, ``after_deg`` (K,) or None (the
        orientation's, for poses with orientation coordinates).
    """
    errors = robot.errors
    pos, rot = position_axes(robot)
    theta = kin.ik(robot, P, check=False)
    err = errors.vector(dict(zip(errors.zero_offsets, np.asarray(offsets, float))))
    from zerocal_sym.model.noise import VirtualPlant

    with np.errstate(all="ignore"):
        dP = VirtualPlant(robot, err).actual_pose(theta) - P
    before = np.linalg.norm(dP[:, pos], axis=1)
    out = {"before_mm": before, "before_std_mm": np.full(len(P), np.nan), "after_mm": np.full(len(P), np.nan),
           "before_deg": np.degrees(np.linalg.norm(dP[:, rot], axis=1)) if rot else None,
           "after_deg": np.full(len(P), np.nan) if rot else None}
    if cov is None:
        return out
    # before: the uncompensated robot stands at FK(theta + offsets), where the offsets' uncertainty moves it
    Jb = offset_jacobian(robot, P + dP, theta + np.asarray(offsets, float))[:, pos]
    Cb = np.einsum("kim,mn,kjn->kij", Jb, cov, Jb)
    u = dP[:, pos] / np.where(before > 0, before, 1.0)[:, None]
    out["before_std_mm"] = np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", u, Cb, u), 0.0))
    # after: compensated, it stands at the pose up to the estimate's error
    J = offset_jacobian(robot, P, theta)
    Cp = np.einsum("kim,mn,kjn->kij", J[:, pos], cov, J[:, pos])  # (K, 3, 3): the position error's covariance
    out["after_mm"] = np.sqrt(np.maximum(np.trace(Cp, axis1=1, axis2=2), 0.0))
    if rot:
        Cr = np.einsum("kim,mn,kjn->kij", J[:, rot], cov, J[:, rot])
        out["after_deg"] = np.degrees(np.sqrt(np.maximum(np.trace(Cr, axis1=1, axis2=2), 0.0)))
    return out


def accuracy_map(robot, offsets, cov, cells: int = MAP_CELLS) -> dict:
    """The maps of :func:`predicted_errors` over :func:`grid`, and their summary.

    Returns
    -------
    dict
        :func:`grid`'s keys; ``before_mm``, ``before_std_mm``, ``after_mm`` (L, ny, nx), NaN outside the
        workspace or its reach; ``summary``: ``max_before_mm`` with ``before_std_at_max_mm`` (its 1 sigma),
        ``max_after_mm``, ``mean_before_mm``, ``mean_after_mm``, ``points``; ``orientation``: ``max_before_deg``,
        ``max_after_deg`` or None.
    """
    g = grid(robot, cells)
    shape = g["P"].shape[:-1]
    P = g["P"].reshape(-1, robot.n)
    ok = _reachable(robot, P)
    maps = {k: np.full(len(P), np.nan) for k in ("before_mm", "before_std_mm", "after_mm", "before_deg", "after_deg")}
    if ok.any():
        pred = predicted_errors(robot, offsets, cov, P[ok])
        for k, v in pred.items():
            if v is not None:
                maps[k][ok] = v
    out = dict(g)
    out.update({k: v.reshape(shape) for k, v in maps.items()})
    b, s, a = maps["before_mm"][ok], maps["before_std_mm"][ok], maps["after_mm"][ok]
    k = int(np.nanargmax(b)) if ok.any() else None
    out["summary"] = {
        "points": int(ok.sum()),
        "max_before_mm": float(b[k]) if k is not None else float("nan"),
        "before_std_at_max_mm": float(s[k]) if k is not None else float("nan"),
        "mean_before_mm": float(np.mean(b)) if ok.any() else float("nan"),
        "max_after_mm": float(np.max(a)) if ok.any() else float("nan"),
        "mean_after_mm": float(np.mean(a)) if ok.any() else float("nan"),
    }
    _, rot = position_axes(robot)
    out["orientation"] = None if not rot or not ok.any() else {
        "max_before_deg": float(np.max(maps["before_deg"][ok])), "max_after_deg": float(np.max(maps["after_deg"][ok]))}
    return out
