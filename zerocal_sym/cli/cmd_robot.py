"""Validate a robot file and print its summary.

Checks positive lengths, units (mm), a reachable workspace (corners and a
grid), consistent kinematics and the singularity margin; prints the home
position, the joint angles at the workspace corners and the smallest
transmission-angle sine found.
"""
NAME = "robot"
HELP = "validate a robot file and print its summary"


def add_arguments(p):
    p.add_argument("--json", action="store_true", help="print JSON")


def run(args):
    from zerocal_sym.cli import load_robot_arg
    from zerocal_sym.io.files import to_json
    from zerocal_sym.model.robot import validate

    robot = load_robot_arg(args)
    s = validate(robot)
    if args.json:
        print(to_json(s))
        return 0
    print(f"robot {s['name']} ({s['mechanism']}) from {s['source']}")
    g = s["geometry_mm"]
    print("geometry [mm]: " + ", ".join(f"{k}={g[k]:g}" for k in robot.mechanism.geometry_names))
    ws = s["workspace_mm"]
    print(f"workspace [mm]: x in [{ws['x'][0]:g}, {ws['x'][1]:g}], y in [{ws['y'][0]:g}, {ws['y'][1]:g}]")
    hx, hy = s["home_pose_mm"]
    print(f"home P0 (theta1=0, theta2=180 deg): ({hx:.3f}, {hy:.3f}) mm")
    for label, c in s["corners"].items():
        (x, y), (t1, t2) = c["pose_mm"], c["joints_deg"]
        print(f"corner {label:12s} ({x:8.3f}, {y:8.3f}) mm -> theta = ({t1:9.4f}, {t2:9.4f}) deg")
    mx, my = s["min_transmission_sine_at_mm"]
    print(f"singularity margin: min |sin transmission| = {s['min_transmission_sine']:.4f} at "
          f"({mx:g}, {my:g}) mm (required >= {s['singularity_margin']:g})")
    print(f"sha256: {s['sha256']}")
    return 0
