"""``zerocal design --scheme ring`` (and any boundary scheme but the paper's): the scheme's poses and numbers.

Prints the 2n poses of the robot's boundary scheme
(``robot.workspace.boundary_scheme(n)``; the ring scheme of DELTA.md on a
cylindrical workspace) with their joint angles, ``kappa_1`` -- the condition
number of the paper's identification matrix G (Eq. 28 for m joints and n
pose coordinates, :func:`zerocal_sym.identify.linear.identification_matrix`,
no MAEMM prior) -- and the Cramér-Rao bound of each zero offset under the
paper's noise model (and under the scale error alone).  ``kappa_m`` and the
eps rule are the paper's (``--scheme paper``); here, without ``--n``, n is
the scheme's default and the table of ``kappa_1`` and the CRLB over n is
printed beside it.  With ``--maemm-prior`` (n values, mm) also the condition
number of G with the prior (Eq. 30).
"""
from __future__ import annotations

#: the largest n of the table printed without --n
N_TABLE_MAX = 12


def _numbers(robot, n, noise_paper, noise_scale):
    import numpy as np

    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.identify.fisher import crlb_zero_offsets_deg
    from zerocal_sym.identify.linear import condition_number, identification_matrix
    from zerocal_sym.model import kinematics as kin

    P = robot.workspace.boundary_scheme(n)
    theta = kin.check_poses(robot, P, in_workspace=True)
    G, lam = identification_matrix(robot, P, theta=theta)
    try:
        crlb = crlb_zero_offsets_deg(robot, theta, "paper", noise_paper)
        crlb_s = crlb_zero_offsets_deg(robot, theta, "paper", noise_scale)
    except ZerocalError:
        crlb = crlb_s = np.full(robot.m, np.inf)
    return P, theta, G, lam, condition_number(G), crlb, crlb_s


def run(args, robot):
    import numpy as np

    from zerocal_sym.cli._common import default_n, min_n, n_params, vector_arg, write_out
    from zerocal_sym.errors import PoseError, ZerocalError
    from zerocal_sym.identify.linear import condition_number, identification_matrix
    from zerocal_sym.io.files import json_safe, to_json
    from zerocal_sym.model.noise import NoiseModel

    ws = robot.workspace
    scheme = ws.scheme_name
    errors = robot.errors
    mech = robot.mechanism
    if args.eps0 is not None:
        raise ZerocalError(f"--eps0 is the paper's eps rule (--scheme paper); the {scheme} scheme has none: "
                           "give --n")
    p = n_params(robot)
    nmin = min_n(robot)
    if args.n is not None and args.n < nmin:
        raise PoseError(f"--n {args.n} gives K = {2 * args.n} poses, {2 * args.n - 1} measured changes: too few for "
                        f"the {p} parameters ({', '.join(errors.resolve('offsets+measuring'))}); n >= {nmin} needed")
    n = args.n if args.n is not None else default_n(robot)
    noise, noise_s = NoiseModel.paper(), NoiseModel.named("scale-only")
    P, theta, G, lam, k1, crlb, crlb_s = _numbers(robot, n, noise, noise_s)
    s = np.linalg.svd(G, compute_uv=False)
    out = {
        "scheme": scheme,
        "robot": robot.name,
        "mechanism": robot.mechanism_name,
        "workspace": ws.describe(),
        "n": n,
        "K": 2 * n,
        "selected_by": "--n" if args.n is not None else f"default of the {scheme} scheme",
        "pose_names": list(mech.pose_names),
        "joint_names": list(mech.joint_names),
        "poses": P.tolist(),
        "joints_deg": np.degrees(theta).tolist(),
        "params": list(errors.resolve("offsets+measuring")),
        "kappa_1": k1,
        "kappa_1_note": "condition number of the paper's G (Eq. 28; offsets as L_i dtheta_i and MAEMM in mm), "
                        "no MAEMM prior",
        "singular_values": s.tolist(),
        "rho_span_mm": float(np.ptp(lam)),
        "crlb_zero_offsets_deg": crlb.tolist(),
        "crlb_noise": "paper (Eq. 34 scale + Eq. 35 servo)",
        "crlb_zero_offsets_deg_scale_only": crlb_s.tolist(),
    }
    if args.maemm_prior is not None:
        prior = vector_arg(args.maemm_prior, len(errors.measuring), "--maemm-prior", errors.measuring, "mm")
        out["maemm_prior_mm"] = prior.tolist()
        out["kappa_with_prior"] = condition_number(identification_matrix(robot, P, prior, theta=theta)[0])
    if args.n is None:
        table = []
        for k in range(nmin, max(N_TABLE_MAX, n) + 1):
            try:
                *_, kk, c, cs = _numbers(robot, k, noise, noise_s)
            except PoseError as exc:
                table.append({"n": k, "K": 2 * k, "error": str(exc)})
                continue
            table.append({"n": k, "K": 2 * k, "kappa_1": kk, "crlb_rms_deg": float(np.sqrt(np.mean(c**2))),
                          "crlb_rms_deg_scale_only": float(np.sqrt(np.mean(cs**2)))})
        out["n_table"] = table
    out = json_safe(out)
    write_out(args, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    joints = ", ".join(mech.joint_names)
    coords = ", ".join(mech.pose_names)
    print(f"{scheme} scheme on robot {robot.name} ({robot.mechanism_name}; workspace {ws.describe()} mm): "
          f"n = {n} poses per boundary, K = {2 * n} ({out['selected_by']})")
    for k, (pk, tk) in enumerate(zip(P, np.degrees(theta)), 1):
        pos = ", ".join(f"{v:8.3f}" for v in np.round(pk, 9) + 0.0)
        ang = ", ".join(f"{v:9.4f}" for v in tk)
        print(f"  P{k:<2d} ({coords}) = ({pos}) mm   ({joints}) = ({ang}) deg")
    print(f"kappa_1 = {k1:.3f} (G of the {p} parameters {', '.join(out['params'])}, no MAEMM prior)"
          + (f"; with the MAEMM prior {out['maemm_prior_mm']} mm: {out['kappa_with_prior']:.3f}"
             if "kappa_with_prior" in out else ""))
    print("CRLB of the zero offsets: " + " / ".join(f"{v:.4f}" for v in crlb) + " deg (paper noise: scale + servo), "
          + " / ".join(f"{v:.4f}" for v in crlb_s) + " deg (scale error alone)")
    if "n_table" in out:
        print(f"other n (n >= {nmin}: K - 1 >= {p} changes):")
        print(f"  {'n':>3} {'K':>3} {'kappa_1':>10} {'CRLB rms [deg]':>15} {'scale only':>11}")
        for row in out["n_table"]:
            if "error" in row:
                print(f"  {row['n']:3d} {row['K']:3d}  {row['error']}")
                continue
            mark = "  <- default" if row["n"] == n else ""
            print(f"  {row['n']:3d} {row['K']:3d} {row['kappa_1']:10.1f} {row['crlb_rms_deg']:15.4f} "
                  f"{row['crlb_rms_deg_scale_only']:11.4f}{mark}")
    return 0
