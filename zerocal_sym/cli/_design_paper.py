"""``zerocal design --scheme paper``: the paper's pose scheme (Section 5).

Prints the 2n poses, ``kappa_1`` (first identification, no MAEMM prior),
``kappa_m`` (with the MAEMM prior, Eq. 30), ``eps = (kappa_1 - kappa_m) /
kappa_1``, what the eps rule (Eq. 31) selects, the condition numbers for the
other readings of the paper's prior, and the Cramér-Rao bound of each zero
offset under the paper's noise model (and under the scale error alone).

Default ``--maemm-prior``: ``(1, -0.5)`` mm, the paper's ``(1, 0.5)`` read in the
paper's frame, which is ours mirrored about the x axis (docs/reproduction.md).
"""
from __future__ import annotations


def run(args, robot):
    import numpy as np

    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.errors import PoseError, ZerocalError
    from zerocal_sym.design.terms import describe_noise, noise_dict, okey
    from zerocal_sym.identify.fisher import crlb_zero_offsets_user
    from zerocal_sym.model import units
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.paper.reproduction import kappas, select_n
    from zerocal_sym.paper.tables import DEFAULT_MAEMM_PRIOR, MAEMM_PRIOR_READINGS, PAPER_KAPPA_1, PAPER_KAPPA_M
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.identify.linear import identification_matrix

    from zerocal_sym.cli._common import vector_arg, write_out

    errors = robot.errors
    prior = (tuple(vector_arg(args.maemm_prior, len(errors.measuring), "--maemm-prior", errors.measuring, "mm"))
             if args.maemm_prior else DEFAULT_MAEMM_PRIOR)
    if args.eps0 is None:
        args.eps0 = 0.01
    if args.n is not None and args.n < 3:
        raise PoseError(f"--n {args.n} gives K = {2 * args.n} < 5 poses: the 4 parameters are not identifiable "
                        "(n >= 3 needed)")
    rule_error = None
    try:
        sel = select_n(robot, args.eps0, prior)
    except ZerocalError as exc:
        if args.n is None:
            raise
        sel, rule_error = None, str(exc)
    n = args.n if args.n is not None else sel.n
    P = paper_poses(robot, n)
    theta = kin.check_poses(robot, P, in_workspace=True)
    k1, km = kappas(robot, n, prior)
    eps = (k1 - km) / k1
    s = np.linalg.svd(identification_matrix(robot, P, prior)[0], compute_uv=False)
    noise = robot.noise
    crlb = crlb_zero_offsets_user(robot, theta, "default", noise)
    crlb_scale = crlb_zero_offsets_user(robot, theta, "default", NoiseModel.named("scale-only", robot))
    k = lambda stem: okey(robot, stem)  # noqa: E731
    readings = {label: kappas(robot, n, pr)[1] for label, pr in MAEMM_PRIOR_READINGS.items()}
    out = {
        "scheme": "paper",
        "robot": robot.name,
        "n": n,
        "K": 2 * n,
        "poses": P.tolist(),
        k("joints"): units.joints_to_user(robot, theta).tolist(),
        "kappa_1": k1,
        "kappa_m": km,
        "eps": eps,
        "eps0": args.eps0,
        "selected_by": "--n" if args.n is not None else "eps0 rule",
        "eps_rule_n": None if sel is None else sel.n,
        "eps_rule_error": rule_error,
        "eps_table": None if sel is None else sel.table,
        "maemm_prior_mm": list(prior),
        "kappa_m_readings": {label: {"maemm_prior_mm": list(pr), "kappa_m": readings[label]}
                             for label, pr in MAEMM_PRIOR_READINGS.items()},
        "singular_values_with_prior": s.tolist(),
        k("crlb_zero_offsets"): crlb.tolist(),
        "crlb_noise": describe_noise(robot, noise),
        "noise": noise_dict(robot, noise),
        k("crlb_zero_offsets") + "_scale_only": crlb_scale.tolist(),
    }
    if robot.name == "paper":
        out["paper"] = {"n": 3, "kappa_1": PAPER_KAPPA_1, "kappa_m": PAPER_KAPPA_M}
    from zerocal_sym.design.detection import detection
    from zerocal_sym.io.files import json_safe

    out["detection"] = json_safe(detection(robot, P, noise))  # what this scheme's fit check sees
    write_out(args, out)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    if args.json:
        print(to_json(out))
        return 0
    print(f"paper scheme on robot {robot.name}: n = {n} poses per boundary, K = {2 * n} "
          f"({out['selected_by']}; eps0 rule selects n = {out['eps_rule_n']} with eps0 = {args.eps0:g})")
    for k, ((x, y), (t1, t2)) in enumerate(zip(P, np.degrees(theta)), 1):
        print(f"  P{k:<2d} ({x:8.3f}, {y:8.3f}) mm   theta = ({t1:9.4f}, {t2:9.4f}) deg")
    pk = "  (paper: 475.34, 472.54)" if robot.name == "paper" and n == 3 else ""
    print(f"kappa_1 = {k1:.3f}, kappa_m = {km:.3f} with MAEMM prior {prior} mm, eps = {eps:.5f}{pk}")
    print("kappa_m for the readings of the paper's prior (1, 0.5) mm:")
    for label, pr in MAEMM_PRIOR_READINGS.items():
        print(f"  {label:40s} prior {pr} mm in our frame: kappa_m = {readings[label]:.3f}")
    ju = units.joint_unit(robot)
    print("CRLB of the zero offsets: " + " / ".join(f"{v:.4f}" for v in crlb) + f" {ju} (noise: "
          f"{out['crlb_noise']}), " + " / ".join(f"{v:.4f}" for v in crlb_scale) + f" {ju} (scale error alone)")
    return 0
