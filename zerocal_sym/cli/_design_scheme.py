"""``zerocal design --scheme ring|corners`` (any boundary scheme but the paper's): the scheme's poses and numbers.

Prints the K poses of the robot's boundary scheme
(``robot.workspace.boundary_scheme(n)``, ``K = robot.workspace.scheme_size(n)``:
the ring scheme on a cylindrical workspace, ``K = 2n``; the corner scheme on a
box, ``K = n`` corners) with their joints, ``kappa_1`` -- the condition number
of the paper's identification matrix G over the mechanism's identified set
(Eq. 28 for m joints and n pose coordinates,
:func:`zerocal_sym.identify.linear.identification_matrix`, no MAEMM prior) --
and the Cramér-Rao bound of each zero offset under the robot's noise model
(:attr:`Robot.noise`: its file's ``[noise]``, its mechanism's default, else the
paper's) and under the scale error alone.  Joint values and offsets are in the
joints' file unit, and so are the keys that carry them (``joints_deg``,
``crlb_zero_offsets_deg`` for revolute joints; ``joints_mm``,
``crlb_zero_offsets_mm`` for prismatic ones).  ``kappa_m`` and the eps rule are
the paper's (``--scheme paper``); here, without ``--n``, n is the scheme's
default and the table of ``kappa_1`` and the CRLB over n is printed beside it.
With ``--maemm-prior`` (one value per measuring error, mm) also the condition
number of G with the prior (Eq. 30).
"""
from __future__ import annotations

#: the largest n of the table printed without --n (a scheme whose n are fewer, the corner scheme's: all of them)
N_TABLE_MAX = 12


def _numbers(robot, n, noise, noise_scale):
    import numpy as np

    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.identify.fisher import crlb_zero_offsets_user
    from zerocal_sym.identify.linear import condition_number, identification_matrix
    from zerocal_sym.model import kinematics as kin

    P = robot.workspace.boundary_scheme(n)
    theta = kin.check_poses(robot, P, in_workspace=True)
    G, lam = identification_matrix(robot, P, theta=theta)
    try:
        crlb = crlb_zero_offsets_user(robot, theta, "default", noise)
        crlb_s = crlb_zero_offsets_user(robot, theta, "default", noise_scale)
    except ZerocalError:
        crlb = crlb_s = np.full(robot.m, np.inf)
    return P, theta, G, lam, condition_number(G), crlb, crlb_s


def table_parameters(robot, n, nmin):
    """The scheme parameters of the n table: from ``nmin`` up to :data:`N_TABLE_MAX` (and ``n``), those the
    scheme has (every n of the ring; 16, 32, 64 of the corner scheme)."""
    ws = robot.workspace
    top = ws.scheme_size(max(N_TABLE_MAX, n))
    return [k for k in ws.scheme_sizes(top) if k >= nmin]


def run(args, robot):
    import numpy as np

    from zerocal_sym.cli._common import default_n, min_n, n_params, vector_arg, write_out
    from zerocal_sym.design.terms import describe_noise, noise_dict, okey, pose_units
    from zerocal_sym.errors import PoseError, ZerocalError
    from zerocal_sym.identify.linear import condition_number, identification_matrix
    from zerocal_sym.io.files import json_safe, to_json
    from zerocal_sym.model import units
    from zerocal_sym.model.kinematics import fmt_user_pose
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
    params = list(errors.resolve("default"))
    if args.n is not None:
        K = ws.scheme_size(args.n)
        if K - 1 < p:
            raise PoseError(f"--n {args.n} gives K = {K} poses, {K - 1} measured changes: too few for the {p} "
                            f"parameters ({', '.join(params)}); n >= {nmin} needed")
    n = args.n if args.n is not None else default_n(robot)
    K = ws.scheme_size(n)
    noise, noise_s = robot.noise, NoiseModel.named("scale-only", robot)
    P, theta, G, lam, k1, crlb, crlb_s = _numbers(robot, n, noise, noise_s)
    s = np.linalg.svd(G, compute_uv=False)
    ju = units.joint_unit(robot)
    revolute = mech.joint_kind == "revolute"
    per = "poses per boundary" if K == 2 * n else "corners" if scheme == "corners" else "poses"
    out = {
        "scheme": scheme,
        "robot": robot.name,
        "mechanism": robot.mechanism_name,
        "workspace": ws.describe(),
        "n": n,
        "K": K,
        "selected_by": "--n" if args.n is not None else f"default of the {scheme} scheme",
        "pose_names": list(mech.pose_names),
        "pose_units": pose_units(robot),
        "joint_names": list(mech.joint_names),
        "joint_unit": ju,
        "poses": units.pose_to_user(robot, P).tolist(),
        okey(robot, "joints"): units.joints_to_user(robot, theta).tolist(),
        "params": params,
        "kappa_1": k1,
        "kappa_1_note": ("condition number of the paper's G (Eq. 28; offsets as L_i dtheta_i and MAEMM in mm), "
                         "no MAEMM prior") if revolute else
                        ("condition number of the paper's G (Eq. 28; offsets and measuring errors in mm), "
                         "no MAEMM prior"),
        "singular_values": s.tolist(),
        "rho_span_mm": float(np.ptp(lam)),
        okey(robot, "crlb_zero_offsets"): crlb.tolist(),
        "crlb_noise": describe_noise(robot, noise),
        "noise": noise_dict(robot, noise),
        okey(robot, "crlb_zero_offsets") + "_scale_only": crlb_s.tolist(),
    }
    if args.maemm_prior is not None:
        prior = vector_arg(args.maemm_prior, len(errors.measuring), "--maemm-prior", errors.measuring, "mm")
        out["maemm_prior_mm"] = prior.tolist()
        out["kappa_with_prior"] = condition_number(identification_matrix(robot, P, prior, theta=theta)[0])
    if args.n is None:
        table = []
        for k in table_parameters(robot, n, nmin):
            kk_ = ws.scheme_size(k)
            try:
                *_, kk, c, cs = _numbers(robot, k, noise, noise_s)
            except PoseError as exc:
                table.append({"n": k, "K": kk_, "error": str(exc)})
                continue
            table.append({"n": k, "K": kk_, "kappa_1": kk, okey(robot, "crlb_rms"): float(np.sqrt(np.mean(c**2))),
                          okey(robot, "crlb_rms") + "_scale_only": float(np.sqrt(np.mean(cs**2)))})
        out["n_table"] = table
    from zerocal_sym.design.detection import detection

    out["detection"] = detection(robot, P, noise)  # what this scheme's fit check sees
    out = json_safe(out)
    write_out(args, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    joints = ", ".join(mech.joint_names)
    print(f"{scheme} scheme on robot {robot.name} ({robot.mechanism_name}; workspace {ws.describe()}"
          f"{' mm' if set(pose_units(robot)) == {'mm'} else ''}): n = {n} {per}, K = {K} ({out['selected_by']})")
    show = K if K <= 40 else 16
    for k in range(show):
        ang = ", ".join(f"{v:9.4f}" for v in units.joints_to_user(robot, theta[k]))
        print(f"  P{k + 1:<2d} {fmt_user_pose(robot, np.round(P[k], 12) + 0.0, '8.3f')}   ({joints}) = ({ang}) {ju}")
    if show < K:
        print(f"  ... ({K - show} more poses: --json)")
    print(f"kappa_1 = {k1:.3f} (G of the {p} parameters {', '.join(out['params'])}, no MAEMM prior)"
          + (f"; with the MAEMM prior {out['maemm_prior_mm']} mm: {out['kappa_with_prior']:.3f}"
             if "kappa_with_prior" in out else ""))
    fmt = ".4f" if revolute else ".5f"
    print("CRLB of the zero offsets: " + " / ".join(format(v, fmt) for v in crlb) + f" {ju} (noise: "
          f"{out['crlb_noise']}), " + " / ".join(format(v, fmt) for v in crlb_s) + f" {ju} (scale error alone)")
    if "n_table" in out:
        kr = okey(robot, "crlb_rms")
        print(f"other n (K - 1 >= {p} changes):")
        print(f"  {'n':>3} {'K':>3} {'kappa_1':>10} {'CRLB rms [' + ju + ']':>15} {'scale only':>11}")
        for row in out["n_table"]:
            if "error" in row:
                print(f"  {row['n']:3d} {row['K']:3d}  {row['error']}")
                continue
            mark = "  <- default" if row["n"] == n else ""
            print(f"  {row['n']:3d} {row['K']:3d} {row['kappa_1']:10.1f} {format(row[kr], '15' + fmt)} "
                  f"{format(row[kr + '_scale_only'], '11' + fmt)}{mark}")
    return 0
