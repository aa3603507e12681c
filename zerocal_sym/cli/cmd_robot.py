"""Validate a robot file and print its summary.

Checks positive lengths, units (mm), a reachable workspace (its corners or
rims and a grid), consistent kinematics (forward of inverse) and the
singularity margin; prints the mechanism, the home position, the joint
angles at the workspace's corners (rims), the range of the joint angles and
the largest ``|FK(IK(P)) - P|`` over the grid, and the smallest
transmission-angle sine found.  Any mechanism: the planar robot of the paper
(``examples/paper_robot.toml``) or the rotary Delta (``examples/delta.toml``).

``--json`` keys: ``home_pose_mm`` (n coordinates), ``mechanism``,
``joint_range_deg``, ``fk_ik_max_error_mm``, ``corners``, ``geometry_mm``,
``workspace``, ``workspace_mm``, ``min_transmission_sine``, ``sha256``, ...
"""
NAME = "robot"
HELP = "validate a robot file and print its summary"


def add_arguments(p):
    p.add_argument("--json", action="store_true", help="print JSON")


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.kinematics import fmt_pose as _fmt
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
    print(f"robot {s['name']} ({s['mechanism']}: {s['description']}) from {s['source']}")
    g = s["geometry_mm"]
    units = mech.geometry_units
    print("geometry [mm, deg]: " + ", ".join(f"{k}={g[k]:g}{' deg' if units.get(k) == 'rad' else ''}"
                                             for k in mech.geometry_names))
    print(f"workspace [mm]: {s['workspace']} {robot.workspace.describe()}")
    joints = ", ".join(mech.joint_names)
    home = fmt_pose(s["home_joints_deg"])
    print(f"home P0 (({joints}) = {home} deg): {fmt_pose(s['home_pose_mm'], '.3f')} mm")
    w = max(len(label) for label in s["corners"])
    for label, c in s["corners"].items():
        print(f"corner {label:{w}s} {fmt_pose(c['pose_mm'], '8.3f')} mm -> ({joints}) = "
              f"{fmt_pose(c['joints_deg'], '9.4f')} deg")
    lo, hi = s["joint_range_deg"]
    print(f"joint angles over the workspace: [{lo:.3f}, {hi:.3f}] deg; max |FK(IK(P)) - P| = "
          f"{s['fk_ik_max_error_mm']:.3g} mm")
    print(f"singularity margin: min |sin transmission| = {s['min_transmission_sine']:.4f} at "
          f"{fmt_pose(s['min_transmission_sine_at_mm'], '.6g')} mm (required >= {s['singularity_margin']:g})")
    print(f"sha256: {s['sha256']}")
    return 0
