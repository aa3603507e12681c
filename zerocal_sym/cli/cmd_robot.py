"""Validate a robot file and print its summary.

Checks positive lengths, units (mm), a reachable workspace (its corners or
rims and a grid), consistent kinematics (forward of inverse) and the
singularity margin; prints the mechanism, the home position, the joint
angles at the workspace's corners (rims), the range of the joint angles and
the largest ``|FK(IK(P)) - P|`` over the grid, and the smallest
transmission-angle sine found.  Any mechanism: the planar robot of the paper
(``examples/paper_robot.toml``), the rotary Delta (``examples/delta.toml``),
the linear Delta (``examples/linear_delta.toml``), the hexapod
(``examples/hexapod.toml``).

``--json`` keys (units in the names, after the joints' and the pose's kinds):
``home_pose_mm`` (``home_pose`` with ``pose_units`` for a pose with
orientations), ``home_joints_deg`` / ``home_joints_mm``, ``mechanism``,
``joint_kind``, ``joint_unit``, ``joint_range_deg`` / ``joint_range_mm``,
``fk_ik_max_error_mm``, ``corners``, ``geometry_mm``, ``workspace``,
``workspace_mm``, ``min_transmission_sine``, ``sha256``, ...
"""
NAME = "robot"
HELP = "validate a robot file and print its summary"


def add_arguments(p):
    p.add_argument("--json", action="store_true", help="print JSON")


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model import units
    from zerocal_sym.model.kinematics import fmt_pose as _fmt
    from zerocal_sym.model.kinematics import fmt_user_pose
    from zerocal_sym.model.robot import validate

    def fmt_pose(p, spec="g"):  # no "-0.000" from round-off
        return _fmt([round(float(v), 9) + 0.0 for v in p], spec)

    robot = load_robot_arg(args)
    s = validate(robot)
    s["pose_names"] = list(robot.mechanism.pose_names)
    s["joint_names"] = list(robot.mechanism.joint_names)
    if args.json:
        print(to_json(s))
        return 0
    mech = robot.mechanism
    ju = mech.joint_user_unit
    pk = "_mm" if units.pose_key(robot, "pose") == "pose_mm" else ""

    def pose_text(p, spec="g"):
        return fmt_user_pose(robot, units.pose_from_user(robot, [round(float(v), 9) + 0.0 for v in p]), spec)

    print(f"robot {s['name']} ({s['mechanism']}: {s['description']}) from {s['source']}")
    g = s["geometry_mm"]
    geo_units = mech.geometry_units
    print("geometry [mm, deg]: " + ", ".join(f"{k}={g[k]:g}{' deg' if geo_units.get(k) == 'rad' else ''}"
                                             for k in mech.geometry_names))
    print(f"workspace [mm, deg]: {s['workspace']} {robot.workspace.describe()}")
    joints = ", ".join(mech.joint_names)
    home = fmt_pose(s[units.joint_key(robot, "home_joints")])
    print(f"home P0 (({joints}) = {home} {ju}): {pose_text(s['home_pose' + pk], '.3f')}")
    w = max(len(label) for label in s["corners"])
    for label, c in s["corners"].items():
        print(f"corner {label:{w}s} {pose_text(c['pose' + pk], '8.3f')} -> ({joints}) = "
              f"{fmt_pose(c[units.joint_key(robot, 'joints')], '9.4f')} {ju}")
    lo, hi = s[units.joint_key(robot, "joint_range")]
    print(f"{units.joint_noun(robot)} over the workspace: [{lo:.3f}, {hi:.3f}] {ju}; max |FK(IK(P)) - P| = "
          f"{s['fk_ik_max_error_mm']:.3g} mm")
    print(f"singularity margin: min |singularity indicator| = {s['min_transmission_sine']:.4f} at "
          f"{pose_text(s['min_transmission_sine_at' + pk], '.6g')} (required >= {s['singularity_margin']:g})")
    noise = robot.noise
    print(f"noise: scale {noise.sigma_scale_mm:g} mm per change, joints "
          f"{float(units.joints_to_user(robot, noise.sigma_joint)):.4g} {ju} per joint per pose"
          + (f", {noise.sigma_revisit_mm:g} mm per pose shared by its revisits" if noise.has_shared else ""))
    print(f"sha256: {s['sha256']}")
    return 0
