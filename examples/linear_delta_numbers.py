"""Recompute every number the linear Delta's model page (docs/linear-delta.md) reports as measured, and check it.

Run:  python examples/linear_delta_numbers.py [--trials N] [--seed S]

Each number is printed as ``ok  <what>: <ours> (page: <theirs>)  [tolerance]`` or ``BAD ...``; the exit
status is 1 if any is BAD.  The page's figures came from an implementation independent of zerocal_sym;
everything here is computed with zerocal_sym on the default robot (examples/linear_delta.toml).  The
tolerances are those of examples/_pagecheck.py: relative 1 % (or the page's last digit where coarser),
equality for ranks and counts, a factor 10 for rounding-error levels, and the page's Monte Carlo ranges
widened by three standard deviations of the difference between two Monte Carlo estimates (ours from the
trials asked for, default 300; the page's from 1000).
"""
import sys
from pathlib import Path

import numpy as np

from _pagecheck import (Page, analytic_distance_jacobian, arguments, central_differences, monte_carlo_note,
                        relative_disagreement, rms_ratio_sd, trial_rng)
from zerocal_sym.identify import fisher
from zerocal_sym.identify import identifiability as idf
from zerocal_sym.identify.linear import condition_number, identification_matrix
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot

ROBOT = Path(__file__).resolve().parent / "linear_delta.toml"
page = Page("page")


def workspace_points(robot):
    """The page's 21 x 21 x 11 grid over the bounding box, kept inside the cylinder, and the two rims (72 each)."""
    ws = robot.workspace
    xs = np.linspace(-ws.rw, ws.rw, 21)
    X, Y, Z = np.meshgrid(xs, xs, np.linspace(ws.zmin, ws.zmax, 11), indexing="ij")
    G = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    G = G[np.hypot(G[:, 0], G[:, 1]) <= ws.rw + 1e-9]
    t = np.radians(np.arange(0, 360, 5))
    rims = [np.column_stack([ws.rw * np.cos(t), ws.rw * np.sin(t), np.full(t.size, z)]) for z in (ws.zmax, ws.zmin)]
    return np.vstack([G] + rims)


def random_poses(robot, rng, N):
    lo, hi = robot.workspace_bounds()
    P = lo + rng.uniform(size=(40 * N, robot.n)) * (hi - lo)
    return P[robot.workspace.contains(P)][:N]


def page_null_directions(robot):
    """The page's four unobservable directions, built from its formulas (rad, mm; the errors' order)."""
    e, g = robot.errors, robot.param
    R_r = np.array([g(f"R{i}") - g("r") for i in (1, 2, 3)])
    phi = np.array([g(f"phi{i}") for i in (1, 2, 3)])
    ei = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(3)])
    eperp = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros(3)])
    c, d = robot.params(["cx", "cy", "cz"]), robot.params(["dx", "dy", "dz"])
    out = {"vertical translation": e.vector(s1=1, s2=1, s3=1, rMz=1)}
    for name, t in (("horizontal translation x", np.array([1.0, 0, 0])), ("horizontal translation y",
                                                                        np.array([0, 1.0, 0]))):
        kw = {f"R{i + 1}": ei[i] @ t for i in range(3)}
        kw.update({f"phi{i + 1}": eperp[i] @ t / R_r[i] for i in range(3)})
        out[name] = e.vector(kw, rMx=t[0], rMy=t[1])
    rot = np.cross([0, 0, 1.0], c - d)
    out["rotation about z"] = e.vector(phi1=1, phi2=1, phi3=1, rMx=rot[0], rMy=rot[1], rMz=rot[2])
    return out


def finite_motions(robot):
    """The same motions, finite and exact: the sphere centres (R_i - r) e_i and c moved, or turned about z."""
    e, g = robot.errors, robot.param
    r = g("r")
    R = np.array([g(f"R{i}") for i in (1, 2, 3)])
    phi = np.array([g(f"phi{i}") for i in (1, 2, 3)])
    c, d = robot.params(["cx", "cy", "cz"]), robot.params(["dx", "dy", "dz"])
    out = {"vertical translation by 1 mm": e.vector(s1=1, s2=1, s3=1, rMz=1)}
    t = np.array([1.0, -0.5])
    S = (R - r)[:, None] * np.column_stack([np.cos(phi), np.sin(phi)]) + t
    kw = {f"R{i + 1}": r + np.hypot(*S[i]) - R[i] for i in range(3)}
    kw.update({f"phi{i + 1}": np.arctan2(S[i, 1], S[i, 0]) - phi[i] for i in range(3)})
    out["horizontal translation by (1, -0.5) mm"] = e.vector(kw, rMx=t[0], rMy=t[1])
    a = 0.01
    Rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rM = (np.eye(3) - Rz) @ (d - c)
    out["rotation about z by 0.01 rad"] = e.vector(phi1=a, phi2=a, phi3=a, rMx=rM[0], rMy=rM[1], rMz=rM[2])
    return out


def main():
    args = arguments(__doc__, trials=300)
    robot = load_robot(ROBOT)
    errors = robot.errors
    noise_both = robot.noise
    noise_scale = NoiseModel.named("scale-only", robot)
    print(f"robot: {ROBOT.name}; noise: scale {noise_both.sigma_scale_mm} mm, carriage {noise_both.sigma_joint} mm")

    # ---------------------------------------------------------------- home, workspace, kinematics
    page.value("home P0 (mm)", robot.home_pose(), ["0", "0", "120"])
    page.value("carriage heights at home (mm)", robot.home_joints(), ["394.955"] * 3)
    W = workspace_points(robot)
    page.exact("workspace points (21 x 21 x 11 grid in the cylinder and the two rims)", len(W), 3631)
    th_W, ratio = kin.ik_ratio(robot, W)
    page.exact("every workspace point reachable", bool(np.all(np.abs(ratio) <= 1) and np.all(np.isfinite(th_W))),
               True)
    page.roundoff("max |FK(IK(P)) - P| over those points (mm)",
                  float(np.max(np.linalg.norm(kin.fk(robot, th_W) - W, axis=1))), "< 4e-13")
    page.value("carriage heights over the workspace (mm)", [th_W.min(), th_W.max()], ["223.961", "519.333"])
    rings = {n: robot.workspace.boundary_scheme(n) for n in (3, 4, 5, 6)}
    rho = np.concatenate([kin.measuring_vector(robot, P)[0] for P in rings.values()])
    page.value("rho over the rings (mm)", [rho.min(), rho.max()], ["100.1", "228.1"])
    page.value("largest single change on the rings (mm)",
               max(np.max(np.abs(np.diff(kin.measuring_vector(robot, P)[0]))) for P in rings.values()), "128")

    # ---------------------------------------------------------------- identifiability
    draws = np.random.default_rng(2017)  # the random poses
    th40 = kin.ik(robot, random_poses(robot, draws, 40))
    rep = idf.identifiability_report(robot, th40, "all")
    page.exact("all 15 source errors, 40 random poses: rank", rep["rank"], 11)
    page.exact("  its null space is the mechanism's declared gauge (rigid motions)", rep["null_space_rigid"], True)
    As = idf.scaled_sensitivity(robot, th40, "all")
    scale = fisher.parameter_scale(robot, "all")
    null = np.linalg.svd(As)[2][rep["rank"]:]
    mine = page_null_directions(robot)
    A = fisher.sensitivity(robot, th40, "all")
    worst = max(np.max(np.abs(A @ v)) / (np.max(np.abs(A)) * np.max(np.abs(v))) for v in mine.values())
    page.below("  the page's four directions, first order: max |A v| / (max|A| max|v|)", worst, 1e-12,
               "unobservable", "below 1e-12")
    Q, _ = np.linalg.qr(np.array([v * scale for v in mine.values()]).T)
    page.below("  they span the numerical null space: max residual of its basis off their span",
               float(np.max(np.abs(null.T - Q @ (Q.T @ null.T)))), 1e-8, "together they span it", "below 1e-8")
    base = np.diff(kin.distance(robot, th40))
    for name, v in finite_motions(robot).items():
        page.below(f"  finite {name}: max change of a measured change (mm)",
                   float(np.max(np.abs(np.diff(kin.distance(robot, th40, v)) - base))), 1e-10,
                   "unobservable", "below 1e-10")
    rep = idf.identifiability_report(robot, th40, "offsets+measuring")
    page.exact("{ds, drM}: rank of 6", rep["rank"], 5)
    page.exact("  its null direction", rep["null_space_gauge"], [["translation z"]])
    page.exact("{ds1..3, drMx, drMy} (the default set): rank of 5",
               idf.identifiability_report(robot, th40, "default")["rank"], 5)

    # ---------------------------------------------------------------- the ring scheme
    both, scale_only = {}, {}
    for n, P in rings.items():
        G, _ = identification_matrix(robot, P)
        th = kin.ik(robot, P)
        page.value(f"ring n = {n} (K = {2 * n}): cond(G), G in mm", condition_number(G),
                   {3: "16.36", 4: "14.43", 5: "10.69", 6: "9.884"}[n])
        scale_only[n] = fisher.crlb_zero_offsets_user(robot, th, "default", noise_scale)
        both[n] = fisher.crlb_zero_offsets_user(robot, th, "default", noise_both)
        page.value(f"ring n = {n}: CRLB of ds1..3, scale only (mm)", scale_only[n], {
            3: ["0.00433", "0.00394", "0.00344"], 4: ["0.00427", "0.00410", "0.00288"],
            5: ["0.00344", "0.00353", "0.00294"], 6: ["0.00307", "0.00354", "0.00306"]}[n])
        page.value(f"ring n = {n}: CRLB of ds1..3, scale + carriage (mm)", both[n], {
            3: ["0.01222", "0.01208", "0.01193"], 4: ["0.01060", "0.01031", "0.00995"],
            5: ["0.00973", "0.00962", "0.00929"], 6: ["0.00907", "0.00925", "0.00887"]}[n])
    G3, _ = identification_matrix(robot, rings[3])
    page.exact("ring n = 3: G square (changes x unknowns) and of full rank",
               (G3.shape, int(np.linalg.matrix_rank(G3))), ((5, 5), 5))
    ratios = [float(np.mean(both[n]) / np.mean(scale_only[n])) for n in rings]
    page.within("carriage noise dominates: mean CRLB both / scale only, n = 3..6", ratios, 2.5, 3.5,
                "about 3x", "'about 3': rounds to 3")

    # ---------------------------------------------------------------- noise-free identification, n = 6
    truth = errors.assemble(zero_offsets_user=(0.8, -0.5, 0.3), maemm_mm=(0.2, -0.1, 0.0))
    names = errors.resolve("default")
    th6 = kin.ik(robot, rings[6])
    meas = Measurements(theta_cmd=th6, readings=VirtualPlant(robot, truth).measure(th6))
    res = identify_nlls(robot, meas, "default", noise=NoiseModel())
    page.roundoff("noise-free, n = 6: exact-model Gauss-Newton, max error of ds, drMxy (mm)",
                  float(np.max(np.abs(res.estimate - errors.take(truth, names)))), "2e-13")
    step = identify_tsvd(robot, meas)
    off = step.estimate - errors.take(truth, step.params)
    page.value("one linear step with G at zero errors: error of ds (mm)", off[:3], ["-0.0043", "-0.0032", "0.0138"])
    page.value("  and of drMxy (mm)", off[3:], ["0.0228", "-0.0149"])
    G6, _ = identification_matrix(robot, rings[6])
    s_lin = np.diff(kin.distance(robot, th6, truth)) - np.diff(kin.distance(robot, th6))
    page.below("  the same step as a plain least-squares solve of G x = s - s(0): max difference (mm)",
               float(np.max(np.abs(np.linalg.lstsq(G6, s_lin, rcond=None)[0] - step.estimate))), 1e-12,
               "one linear step", "below 1e-12")
    crlb6 = np.sqrt(np.diag(fisher.crlb(robot, th6, "default", noise_both)))
    page.value("  |error| / CRLB (both noises) of ds3 and drMx", np.abs(off[[2, 3]]) / crlb6[[2, 3]],
               ["1.55", "1.65"])

    # ---------------------------------------------------------------- the Jacobian
    err = errors.vector(dict(zip(errors.names, (0.8, -0.5, 0.3, 0.1, -0.05, 0.08, np.radians(0.05),
                                                np.radians(-0.03), np.radians(0.02), 0.1, -0.2, 0.05,
                                                0.2, -0.1, 0.3))))
    rel = relative_disagreement(analytic_distance_jacobian(robot, th6, err), central_differences(robot, th6, err))
    page.roundoff("Jacobian, all 15 errors set, ring n = 6: analytic (implicit differentiation) vs central "
                  "differences (steps 1e-3 mm, 1e-5 rad), relative", rel, "3e-9")

    # ---------------------------------------------------------------- Monte Carlo
    monte_carlo_note(args.trials, "truth ds = (0.8, -0.5, 0.3) mm, drMxy = (0.2, -0.1) mm; weighted Gauss-Newton "
                     "on the exact model (identify_nlls)")
    for case, (n, noise, lo, hi, label) in enumerate(((6, noise_both, 0.98, 1.03, "both noises"),
                                                      (6, noise_scale, 0.95, 1.01, "scale only"),
                                                      (4, noise_both, 0.99, 1.03, "both noises"))):
        th = kin.ik(robot, rings[n])
        plant = VirtualPlant(robot, truth)
        E = []
        for trial in range(args.trials):
            m = Measurements(theta_cmd=th, readings=plant.measure(th, noise, trial_rng(args.seed, case, trial)))
            r = identify_nlls(robot, m, "default", noise=noise, accept_misfit=True)
            E.append(r.zero_offsets_user - errors.take(truth, errors.zero_offsets))
        rms = np.sqrt(np.mean(np.square(E), axis=0))
        crlb = fisher.crlb_zero_offsets_user(robot, th, "default", noise, err0=truth)
        page.monte_carlo(f"Monte Carlo n = {n}, {label}: RMS/CRLB of ds1..3", rms / crlb, lo, hi, rms_ratio_sd,
                         args.trials, f"{lo:.2f}-{hi:.2f}")
    return page.exit_code()


if __name__ == "__main__":
    sys.exit(main())
