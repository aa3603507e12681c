"""Recompute every number the hexapod's model page (docs/hexapod.md) reports as measured, and check it.

Run:  python examples/hexapod_numbers.py [--trials N] [--seed S]

Each number is printed as ``ok  <what>: <ours> (page: <theirs>)  [tolerance]`` or ``BAD ...``; the exit
status is 1 if any is BAD.  The page's figures came from an implementation independent of zerocal_sym;
everything here is computed with zerocal_sym on the default robot (examples/hexapod.toml), except two
things written out here from the page's own statement, to compare with: the forward kinematics' Newton
steps with the page's rotation update (``Rot <- exp([dw]x) Rot``; zerocal_sym's steps are in roll, pitch,
yaw) and the Monte Carlo's weighted Gauss-Newton loop (on zerocal_sym's exact model and noise model: the
package's Ipopt identification takes seconds per data set on this mechanism; one data set is checked to
give the same estimate).  The tolerances are those of examples/_pagecheck.py: relative 1 % (or the page's
last digit where coarser), equality for ranks, counts and corner lists, a factor 10 for rounding-error
levels, and the page's Monte Carlo ranges widened by three standard deviations of the difference between two
Monte Carlo estimates (ours from the trials asked for, default 100; the page's from 1000).
"""
import sys
from pathlib import Path

import casadi as ca
import numpy as np

from _pagecheck import (Page, analytic_distance_jacobian, arguments, central_differences, chi2_mean_sd, fmt,
                        monte_carlo_note, relative_disagreement, rms_ratio_sd, trial_rng)
from zerocal_sym.identify import fisher
from zerocal_sym.identify import identifiability as idf
from zerocal_sym.identify.linear import condition_number, identification_matrix
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot

ROBOT = Path(__file__).resolve().parent / "hexapod.toml"
page = Page("page")
LEGS = range(1, 7)


# ---------------------------------------------------------------------- the page's geometry, in numpy
class Geometry:
    """Base and platform joints, c and d of the robot, for the page's formulas written out here."""

    def __init__(self, robot):
        g = robot.param
        beta = np.array([g(f"beta{i}") for i in LEGS])
        pis = np.array([g(f"pi{i}") for i in LEGS])
        self.B = g("Rb") * np.column_stack([np.cos(beta), np.sin(beta), np.zeros(6)])
        self.p = g("Rp") * np.column_stack([np.cos(pis), np.sin(pis), np.zeros(6)])
        self.c = robot.params(["cx", "cy", "cz"])
        self.d = robot.params(["dx", "dy", "dz"])
        self.z_home = g("z_home")


def rotation(roll, pitch, yaw):
    """``Rz(yaw) Ry(pitch) Rx(roll)``; arrays of angles give a stack of matrices, shape (..., 3, 3)."""
    cr, sr, cp, sp, cy, sy = (f(np.asarray(a, float)) for a in (roll, pitch, yaw) for f in (np.cos, np.sin))
    o, z = np.ones_like(cr), np.zeros_like(cr)
    Rx = np.stack([np.stack([o, z, z], -1), np.stack([z, cr, -sr], -1), np.stack([z, sr, cr], -1)], -2)
    Ry = np.stack([np.stack([cp, z, sp], -1), np.stack([z, o, z], -1), np.stack([-sp, z, cp], -1)], -2)
    Rz = np.stack([np.stack([cy, -sy, z], -1), np.stack([sy, cy, z], -1), np.stack([z, z, o], -1)], -2)
    return Rz @ Ry @ Rx


def rotations(poses):
    """The rotation of each pose, shape (K, 3, 3)."""
    return rotation(poses[:, 3], poses[:, 4], poses[:, 5])


def expm_so3(w):
    """``exp([w]x)`` of rotation vectors ``w`` (3,) or (K, 3) (Rodrigues)."""
    w = np.atleast_2d(w)
    t = np.linalg.norm(w, axis=1)[:, None, None]
    K = np.zeros((w.shape[0], 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K = K - K.transpose(0, 2, 1)
    small = t < 1e-8
    a = np.where(small, 1 - t**2 / 6, np.sin(t) / np.where(small, 1, t))
    b = np.where(small, 0.5 - t**2 / 24, (1 - np.cos(t)) / np.where(small, 1, t) ** 2)
    return np.eye(3) + a * K + b * K @ K


def rotation_error(R1, R2):
    """``sin`` of the angle of ``R1 R2^T`` (accurate near zero), per pose."""
    E = R1 @ np.swapaxes(R2, -1, -2)
    return np.linalg.norm(np.stack([E[..., 2, 1] - E[..., 1, 2], E[..., 0, 2] - E[..., 2, 0],
                                    E[..., 1, 0] - E[..., 0, 1]], -1), axis=-1) / 2


def leg_matrix(geo, P, R, scale_mm=1.0):
    """Rows ``[u_i^T, ((Rot p_i) x u_i)^T / scale_mm]`` (``d|w_i| = M (dP, dw)``), shape (K, 6, 6), and the leg
    lengths ``|w_i|``, shape (K, 6), of poses ``P`` (K, 3), ``R`` (K, 3, 3)."""
    Rp = np.einsum("kab,ib->kia", R, geo.p)
    w = P[:, None, :] + Rp - geo.B
    n = np.linalg.norm(w, axis=2)
    u = w / n[..., None]
    return np.concatenate([u, np.cross(Rp, u) / scale_mm], axis=2), n


def newton_page(geo, L, iterations=8):
    """The page's forward kinematics for joints ``L`` (K, 6): Newton in ``(dP, dw)`` with ``Rot <- exp([dw]x) Rot``
    from home.  Returns the poses (P, Rot) and the largest leg-length residual of each pose before each step and
    after the last (mm), shape (K, iterations + 1)."""
    K = L.shape[0]
    P, R, res = np.tile([0.0, 0.0, geo.z_home], (K, 1)), np.tile(np.eye(3), (K, 1, 1)), []
    for _ in range(iterations):
        M, n = leg_matrix(geo, P, R)
        res.append(np.max(np.abs(n - L), axis=1))
        x = np.linalg.solve(M, (L - n)[..., None])[..., 0]
        P, R = P + x[:, :3], expm_so3(x[:, 3:]) @ R
    res.append(np.max(np.abs(leg_matrix(geo, P, R)[1] - L), axis=1))
    return P, R, np.array(res).T


def newton_ours(robot, geo, L, iterations=8):
    """zerocal_sym's forward kinematics' steps (generated ``fk_residual``: Newton on the squared leg lengths in
    x, y, z, roll, pitch, yaw from ``fk_start``) for joints ``L`` (K, 6); the largest leg-length residual of each
    pose before each step and after the last (mm), shape (K, iterations + 1)."""
    x = np.tile(np.array(robot.mechanism["fk_start"](robot.geometry).full()).ravel(), (L.shape[0], 1))
    res = []
    for _ in range(iterations):
        res.append(np.max(np.abs(leg_matrix(geo, x[:, :3], rotations(x))[1] - L), axis=1))
        f, f_P = kin.call(robot, "fk_residual", x, L, robot.geometry)
        x = x - np.linalg.solve(f_P, f)[..., 0]
    res.append(np.max(np.abs(leg_matrix(geo, x[:, :3], rotations(x))[1] - L), axis=1))
    return np.array(res).T


def iterations_to(res, tol):
    return int(np.argmax(res < tol))


# ---------------------------------------------------------------------- the unobservable directions
def rigid_directions(robot, geo):
    """The page's 12 rigid motions, first order, from its formulas (mm; the errors' order)."""
    e = robot.errors
    out = {}
    for side, pts, car, extra, enames in (("base", geo.B, "b", geo.c, ("rMx", "rMy", "rMz")),
                                          ("platform", geo.p, "q", geo.d, ("ddx", "ddy", "ddz"))):
        for kind in ("translation", "rotation"):
            for ax in range(3):
                t, w = np.zeros(3), np.zeros(3)
                (t if kind == "translation" else w)[ax] = 1.0
                kw = {f"{car}{i + 1}{'xyz'[k]}": (t + np.cross(w, pts[i]))[k] for i in range(6) for k in range(3)}
                kw.update({enames[k]: (t + np.cross(w, extra))[k] for k in range(3)})
                out[f"{side} {kind} {'xyz'[ax]}"] = e.vector(kw)
    return out


def rotations_about_c_and_d(robot, geo):
    """The six motions left free when drM and dd are known: the base turned about c, the platform about d."""
    e = robot.errors
    out = []
    for pts, car, centre in ((geo.B, "b", geo.c), (geo.p, "q", geo.d)):
        for ax in range(3):
            w = np.eye(3)[ax]
            out.append(e.vector({f"{car}{i + 1}{'xyz'[k]}": np.cross(w, pts[i] - centre)[k]
                                 for i in range(6) for k in range(3)}))
    return out


def finite_rigid(robot, geo, side, t, w):
    """A finite rigid motion (rotation vector ``w``, translation ``t``) of one side, exact."""
    R = expm_so3(np.asarray(w, float))[0]
    pts, car, extra, enames = ((geo.B, "b", geo.c, ("rMx", "rMy", "rMz")) if side == "base"
                               else (geo.p, "q", geo.d, ("ddx", "ddy", "ddz")))
    kw = {f"{car}{i + 1}{'xyz'[k]}": (R @ pts[i] + t - pts[i])[k] for i in range(6) for k in range(3)}
    kw.update({enames[k]: (R @ extra + t - extra)[k] for k in range(3)})
    return robot.errors.vector(kw)


def span_residual(null, vectors) -> float:
    """Largest residual of the null-space basis (rows) off the span of ``vectors`` (rows)."""
    Q, _ = np.linalg.qr(np.array(vectors).T)
    return float(np.max(np.abs(null.T - Q @ (Q.T @ null.T))))


def first_order(A, vectors) -> float:
    return max(float(np.max(np.abs(A @ v)) / (np.max(np.abs(A)) * np.max(np.abs(v)))) for v in vectors)


# ---------------------------------------------------------------------- weighted Gauss-Newton on the exact model
def weighted_gauss_newton(robot, th, readings, names, noise, tol=1e-11, max_iter=30):
    """Weighted Gauss-Newton on the exact model from zero: the weights ``Cov(s)^-1`` (scale and leg noise, the
    legs' propagated to first order) re-evaluated at every iterate, as zerocal_sym's identification does."""
    errors = robot.errors
    idx = errors.indices(names)
    err = errors.zeros()
    for _ in range(max_iter):
        rho, de, dt = kin.distance_jacobians(robot, th, err)
        C = fisher.ChangeCovariance.from_variances(noise.sigma_scale_mm, noise.sigma_joint**2 * np.sum(dt**2, axis=1))
        step = np.linalg.lstsq(C.whiten(np.diff(de[:, idx], axis=0)), C.whiten(readings[1:] - np.diff(rho)),
                               rcond=None)[0]
        err[idx] += step
        if np.max(np.abs(step)) < tol:
            return errors.take(err, names)
    raise RuntimeError("Gauss-Newton did not converge")


def legs_and_stroke(robot, draws):
    """Home, the legs over the corners and random poses, the local optima, the stroke."""
    ws = robot.workspace
    lo, hi = robot.workspace_bounds()
    home = robot.home_joints()
    page.value("home leg lengths (mm)", home, ["339.026"] * 6)
    corners = ws.boundary_scheme(64)
    Lc = kin.ik(robot, corners)
    page.value("legs over the 64 corners (mm)", [Lc.min(), Lc.max()], ["232.420", "461.725"])
    page.value("  against home (mm)", [Lc.min() - home[0], Lc.max() - home[0]], ["-106.61", "+122.70"])
    X = lo + draws.uniform(size=(200_000, 6)) * (hi - lo)
    LX = kin.ik(robot, X, check=False)
    page.exact("200,000 random poses in the box go no further than the corners",
               bool(LX.min() >= Lc.min() and LX.max() <= Lc.max()), True)
    Ps, gs = ca.SX.sym("P", 6), ca.SX.sym("g", len(robot.geometry))
    dL = ca.Function("dL", [Ps, gs], [ca.jacobian(robot.mechanism["ik"](Ps, gs)[0], Ps)])
    strict, below = [], []
    for i in range(6):
        for k, sign in ((int(np.argmin(Lc[:, i])), -1), (int(np.argmax(Lc[:, i])), 1)):
            grad = np.array(dL(corners[k], robot.geometry).full())[i]
            outward = np.where(np.isclose(corners[k], hi), 1.0, -1.0)
            ok = bool(np.all(sign * grad * outward > 0))
            extreme = np.isclose(Lc[k, i], Lc.max() if sign > 0 else Lc.min(), rtol=0, atol=1e-9)
            if extreme:
                strict.append(ok)
            elif not ok:  # this leg's own extreme: how far along the coordinates that point inwards
                for j in np.flatnonzero(sign * grad * outward <= 0):
                    Q = np.repeat(corners[k][None], 2001, axis=0)
                    Q[:, j] = np.linspace(lo[j], hi[j], 2001)
                    Lj = kin.ik(robot, Q, check=False)[:, i]
                    best = Lj.max() if sign > 0 else Lj.min()
                    below.append(f"leg {i + 1}'s {'max' if sign > 0 else 'min'} {Lc[k, i]:.4f} mm at corner {k} "
                                 f"goes to {best:.4f} mm along {robot.mechanism.pose_names[j]}")
    page.exact("a local search from the corners of the range's ends (legs at 232.42 and 461.73 mm) goes no "
               "further: each a strict local optimum (every partial derivative points out of the box)",
               (len(strict), all(strict)), (4, True))
    if below:
        page.note("within the range, not the page's claim: " + "; ".join(below))
    excess = np.abs(Lc - home) - 120
    over = [k for k in range(64) if np.any(excess[k] > 0)]
    page.exact("stroke +-120 mm: the corners it does not reach", over, [4, 13, 23, 39, 46, 61])
    page.exact("  all at z = 350, |x| = |y| = 60, one leg each",
               all(np.isclose(corners[k, 2], ws.z_max) and np.allclose(np.abs(corners[k, :2]), ws.a)
                   and np.sum(excess[k] > 0) == 1 for k in over), True)
    page.value("  how much more than the stroke they need (mm)",
               [excess[over].max(axis=1).min(), excess[over].max()], ["0.52", "2.70"])
    stroke = robot.param("stroke")
    page.exact(f"the robot file's stroke +-{stroke:g} mm holds the whole box (corners and the random poses)",
               bool(np.max(np.abs(Lc - home)) <= stroke and np.max(np.abs(LX - home)) <= stroke), True)


def forward_kinematics(robot, geo, draws):
    """FK(IK(pose)) over the corners, the 3^6 grid and random poses; Newton's steps; the leg Jacobian."""
    ws = robot.workspace
    lo, hi = robot.workspace_bounds()
    poses = np.vstack([ws.boundary_scheme(64), ws.grid(3), lo + draws.uniform(size=(3000, 6)) * (hi - lo)])
    th = kin.ik(robot, poses)
    back = kin.fk(robot, th)
    page.roundoff("FK(IK(pose)) over the corners, the 3^6 grid and 3000 random poses: position error (mm)",
                  float(np.max(np.linalg.norm(back[:, :3] - poses[:, :3], axis=1))), "< 3e-13")
    page.roundoff("  rotation error (sin of the angle)",
                  float(np.max(rotation_error(rotations(back), rotations(poses)))), "< 2e-15")
    tol = 1e-10
    P_page, R_page, res_page = newton_page(geo, th)
    page.roundoff("  the page's Newton steps (8), written out here: position error (mm)",
                  float(np.max(np.linalg.norm(P_page - poses[:, :3], axis=1))), "< 3e-13")
    page.roundoff("    rotation error (sin of the angle)", float(np.max(rotation_error(R_page, rotations(poses)))),
                  "< 2e-15")
    res_ours = newton_ours(robot, geo, th)
    page.note("largest leg residual (mm) before each Newton step, over those poses: the page's update "
              + fmt(res_page.max(axis=0), 2) + "; zerocal_sym's (roll, pitch, yaw) " + fmt(res_ours.max(axis=0), 2))
    page.exact(f"  Newton iterations to a leg residual below {tol:g} mm, the page's rotation update (most over "
               "the poses)", iterations_to(res_page.max(axis=0), tol), 5)
    page.exact("  the same for zerocal_sym's Newton steps in roll, pitch, yaw (the generated fk_residual)",
               iterations_to(res_ours.max(axis=0), tol), 5)
    conds = np.linalg.cond(leg_matrix(geo, poses[:, :3], rotations(poses), 100.0)[0])
    page.value("leg Jacobian (rotation columns at 100 mm): largest cond over those poses", conds.max(), "5.21")


def identifiability(robot, geo, draws):
    """Ranks and null spaces at 80 random poses and the corners; the weakest direction at the corners."""
    errors = robot.errors
    lo, hi = robot.workspace_bounds()
    Lc = kin.ik(robot, robot.workspace.boundary_scheme(64))
    th80 = kin.ik(robot, lo + draws.uniform(size=(80, 6)) * (hi - lo))
    rep = idf.identifiability_report(robot, th80, "all")
    page.exact("all 48 source errors, 80 random poses: rank", rep["rank"], 36)
    page.exact("  its null space is the declared gauge (12 rigid motions)", rep["null_space_rigid"], True)
    scale = fisher.parameter_scale(robot, "all")
    null = np.linalg.svd(idf.scaled_sensitivity(robot, th80, "all"))[2][rep["rank"]:]
    rigid = rigid_directions(robot, geo)
    A = fisher.sensitivity(robot, th80, "all")
    page.below("  the page's 12 rigid motions, first order: max |A v| / (max|A| max|v|)",
               first_order(A, rigid.values()), 1e-12, "unobservable", "below 1e-12")
    page.below("  they span the numerical null space: max residual of its basis off their span",
               span_residual(null, [v * scale for v in rigid.values()]), 1e-8, "together they span it", "below 1e-8")
    base = np.diff(kin.distance(robot, th80))
    for side in ("base", "platform"):
        v = finite_rigid(robot, geo, side, np.array([1.0, -2.0, 0.5]), np.array([0.01, -0.02, 0.015]))
        page.below(f"  finite {side} motion (1, -2, 0.5) mm, turned by (0.01, -0.02, 0.015) rad: max change of a "
                   "measured change (mm)", float(np.max(np.abs(np.diff(kin.distance(robot, th80, v)) - base))),
                   1e-10, "unobservable", "below 1e-10")
    rep42 = idf.identifiability_report(robot, th80, "offsets+geometry")
    page.exact("the 42 robot errors (drM, dd known): rank", rep42["rank"], 36)
    names42 = errors.resolve("offsets+geometry")
    null42 = np.linalg.svd(idf.scaled_sensitivity(robot, th80, names42))[2][rep42["rank"]:]
    free = [errors.take(v, names42) for v in rotations_about_c_and_d(robot, geo)]
    page.below("  its null space: the base turned about c and the platform about d (residual off their span)",
               span_residual(null42, free), 1e-8, "the six rotations stay free", "below 1e-8")
    page.exact("default set (dL, drM, dd): rank of 12 at 80 random poses and at the 64 corners",
               (idf.identifiability_report(robot, th80, "default")["rank"],
                idf.identifiability_report(robot, Lc, "default")["rank"]), (12, 12))
    G, _ = identification_matrix(robot, robot.workspace.boundary_scheme(64))
    weak = np.linalg.svd(G)[2][-1]
    weak = weak * np.sign(weak[errors.default.index("L3")])
    page.value("  weakest direction of G at the corners: dL1..6, drMz (unit vector)",
               np.append(weak[:6], weak[errors.default.index("rMz")]),
               ["0.24", "0.21", "0.59", "0.58", "-0.20", "-0.15", "-0.34"])


def corner_schemes(robot, noise_both, noise_scale):
    """The 64 corners, the first 16 of them, and the 2^(6-2) fraction: cond(G), CRLB, null directions."""
    errors = robot.errors
    ws = robot.workspace
    lo, hi = robot.workspace_bounds()
    corners = ws.boundary_scheme(64)
    Lc = kin.ik(robot, corners)
    page.value("corner scheme (64): cond(G), G in mm", condition_number(identification_matrix(robot, corners)[0]),
               "138.8")
    page.value("  CRLB of dL1..6, scale only (mm)", fisher.crlb_zero_offsets_user(robot, Lc, "default", noise_scale),
               ["0.01327", "0.01317", "0.01637", "0.01716", "0.01561", "0.01367"])
    page.value("  CRLB of dL1..6, scale + legs (mm)", fisher.crlb_zero_offsets_user(robot, Lc, "default", noise_both),
               ["0.02796", "0.02827", "0.02981", "0.03333", "0.03078", "0.02729"])
    rho = kin.measuring_vector(robot, corners)[0]
    page.value("  rho over the corners (mm)", [rho.min(), rho.max()], ["215.1", "338.6"])
    page.value("  largest single change (mm)", np.max(np.abs(np.diff(rho))), "120.7")

    first16 = Lc[:16]
    page.exact("the first 16 corners: pitch and yaw at their minima, only roll turns",
               bool(np.allclose(corners[:16, 4:], lo[4:]) and np.ptp(corners[:16, 3]) > 0), True)
    rep16 = idf.identifiability_report(robot, first16, "default")
    page.exact("  rank of 12", rep16["rank"], 11)
    v = np.linalg.svd(idf.scaled_sensitivity(robot, first16, "default"))[2][-1]
    v = v / v[errors.default.index("ddx")]
    rM = [errors.default.index(n) for n in ("rMx", "rMy", "rMz")]
    page.value("  null direction with ddx = 1: drM", v[rM], ["0.9513", "-0.2549", "0.1736"])
    page.value("  the page's Rz(-15 deg) Ry(-10 deg) e_x", rotation(0.0, lo[4], lo[5])[:, 0],
               ["0.9513", "-0.2549", "0.1736"])
    rest = np.delete(v, rM + [errors.default.index("ddx")])
    page.below("  the dL (and ddy, ddz) are not in it: largest entry", float(np.max(np.abs(rest))), 1e-9,
               "not in it", "below 1e-9")
    for label, noise, want in (("scale only", noise_scale, ["0.114", "0.291"]),
                               ("both noises", noise_both, ["0.238", "0.655"])):
        rep16 = idf.identifiability_report(robot, first16, "default", noise=noise)
        pinv = np.array([rep16["crlb_std"][f"L{i}"] for i in LEGS])
        held = fisher.crlb_zero_offsets_user(robot, first16, [n for n in errors.default if n != "ddx"], noise)
        page.value(f"  CRLB range of dL1..6 ({label}; ddx held known)", [held.min(), held.max()], want)
        page.below("    the same from the pseudo-inverse (12 parameters): max difference (mm)",
                   float(np.max(np.abs(pinv - held))), 1e-9, "estimable", "below 1e-9")
    page.exact("  holding ddx known: rank of 11",
               idf.identifiability_report(robot, first16, [n for n in errors.default if n != "ddx"])["rank"], 11)
    frac = ws.boundary_scheme(16)

    def bit(P, j):
        return np.isclose(P[:, j], hi[j]).astype(int)

    page.exact("the 2^(6-2) fraction: pitch bit = x^y^z, yaw bit = y^z^roll",
               bool(np.all(bit(frac, 4) == bit(frac, 0) ^ bit(frac, 1) ^ bit(frac, 2))
                    and np.all(bit(frac, 5) == bit(frac, 1) ^ bit(frac, 2) ^ bit(frac, 3))), True)
    thf = kin.ik(robot, frac)
    page.exact("  rank of 12", idf.identifiability_report(robot, thf, "default")["rank"], 12)
    page.value("  cond(G)", condition_number(identification_matrix(robot, frac)[0]), "366.4")
    for label, noise, want in (("scale only", noise_scale, ["0.049", "0.070"]),
                               ("both noises", noise_both, ["0.093", "0.133"])):
        c = fisher.crlb_zero_offsets_user(robot, thf, "default", noise)
        page.value(f"  CRLB range of dL1..6 ({label})", [c.min(), c.max()], want)


def identification(robot, trials, seed, noise_both, noise_scale):
    """Noise-free recovery, one linear step, the Jacobian, the Monte Carlo: all on the 64 corners."""
    errors = robot.errors
    Lc = kin.ik(robot, robot.workspace.boundary_scheme(64))
    truth = errors.assemble(zero_offsets_user=(0.3, -0.2, 0.1, 0.25, -0.15, 0.05),
                            maemm_mm=(0.1, -0.1, 0.05, 0.05, 0.0, -0.05))
    names = errors.resolve("default")
    plant = VirtualPlant(robot, truth)
    meas = Measurements(theta_cmd=Lc, readings=plant.measure(Lc))
    res = identify_nlls(robot, meas, "default", noise=NoiseModel())
    page.roundoff("noise-free: exact-model Gauss-Newton (identify_nlls), max error of the 12 (mm)",
                  float(np.max(np.abs(res.estimate - errors.take(truth, names)))), "6e-13")
    page.roundoff("  the same by the Gauss-Newton loop of this script (mm)",
                  float(np.max(np.abs(weighted_gauss_newton(robot, Lc, meas.readings, names, NoiseModel(1e-3))
                                      - errors.take(truth, names)))), "6e-13")
    step = identify_tsvd(robot, meas)
    page.value("one linear step with G at zero errors: largest error of dL (mm)",
               np.max(np.abs(step.zero_offsets_user - errors.take(truth, errors.zero_offsets))), "0.0054")

    # ---------------------------------------------------------------- the Jacobian
    err = truth + errors.embed(errors.geometry, np.random.default_rng(48).normal(0, 0.1, len(errors.geometry)))
    rel = relative_disagreement(analytic_distance_jacobian(robot, Lc, err), central_differences(robot, Lc, err))
    page.roundoff("Jacobian, all 48 errors set, 64 corners: analytic (implicit differentiation) vs central "
                  "differences (step 1e-3 mm), relative", rel, "1.4e-9")

    # ---------------------------------------------------------------- Monte Carlo
    monte_carlo_note(trials, "64 corners, the truth of the noise-free case; weighted Gauss-Newton on the exact "
                     "model (this script's loop: identify_nlls takes seconds per data set here)", chi2_dof=12)
    for case, (noise, lo_r, hi_r, chi, label) in enumerate(((noise_both, 0.97, 1.04, 12.15, "both noises"),
                                                            (noise_scale, 1.02, 1.05, 12.28, "scale only"))):
        # the linearised estimator at the truth, on the same draws: where a Monte Carlo figure sits off its
        # expectation, it says whether the draws or the estimator put it there
        C = fisher.change_covariance(robot, Lc, noise, truth)
        lin = np.linalg.pinv(C.whiten(fisher.sensitivity(robot, Lc, names, truth)))
        s0 = np.diff(kin.distance(robot, Lc, truth))
        E, E_lin = [], []
        for trial in range(trials):
            readings = plant.measure(Lc, noise, trial_rng(seed, case, trial))
            est = weighted_gauss_newton(robot, Lc, readings, names, noise)
            if case == 0 and trial == 0:
                ref = identify_nlls(robot, Measurements(theta_cmd=Lc, readings=readings), "default", noise=noise,
                                    accept_misfit=True)
                page.below("  trial 0: this loop's estimate against identify_nlls's, max difference (mm)",
                           float(np.max(np.abs(ref.estimate - est))), 1e-8, "the same estimator", "below 1e-8")
            E.append(est - errors.take(truth, names))
            E_lin.append(lin @ C.whiten(readings[1:] - s0))
        E, E_lin = np.array(E), np.array(E_lin)
        F = fisher.fisher_information(robot, Lc, names, noise, err0=truth)
        crlb = np.sqrt(np.diag(np.linalg.inv(F)))[:6]
        page.monte_carlo(f"Monte Carlo, {label}: RMS/CRLB of dL1..6", np.sqrt(np.mean(E[:, :6] ** 2, axis=0)) / crlb,
                         lo_r, hi_r, rms_ratio_sd, trials, f"{lo_r:.2f}-{hi_r:.2f}")
        page.monte_carlo(f"  mean of e^T F e ({label}; 12 if efficient)", np.mean(np.einsum("ti,ij,tj->t", E, F, E)),
                         chi, chi, chi2_mean_sd(12), trials, f"{chi:.2f}")
        page.note(f"    the same draws through the linearised estimator at the truth: mean e^T F e "
                  f"{np.mean(np.einsum('ti,ij,tj->t', E_lin, F, E_lin)):.3f}, RMS/CRLB "
                  + fmt(np.sqrt(np.mean(E_lin[:, :6] ** 2, axis=0)) / crlb, 3))


def main():
    args = arguments(__doc__, trials=100)
    robot = load_robot(ROBOT)
    geo = Geometry(robot)
    noise_both = robot.noise
    noise_scale = NoiseModel.named("scale-only", robot)
    print(f"robot: {ROBOT.name}; noise: scale {noise_both.sigma_scale_mm} mm, legs {noise_both.sigma_joint} mm")
    draws = np.random.default_rng(2017)  # the random poses
    legs_and_stroke(robot, draws)
    forward_kinematics(robot, geo, draws)
    identifiability(robot, geo, draws)
    corner_schemes(robot, noise_both, noise_scale)
    identification(robot, args.trials, args.seed, noise_both, noise_scale)
    return page.exit_code()


if __name__ == "__main__":
    sys.exit(main())
