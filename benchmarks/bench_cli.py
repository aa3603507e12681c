"""Start-up time of the CLI: `zerocal --help` against a bare Python start.

Every command runs in a fresh process, the commands interleaved (each pass runs every one once, the order
rotating: benchmarks/_harness.py); wall time and the child's CPU time (user + system), medians over the
passes, and the ratio to the baseline in the same pass; the load average printed.

Target: `zerocal --help` answers in under a second (of CPU: the wall time is the load's).
Usage: python benchmarks/bench_cli.py [--repeat N] [--json]
"""
import argparse
import sys

from _harness import commands, emit, load, load_line, median, ratio, summary

BASE = "python -c pass (baseline)"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", "--passes", dest="passes", type=int, default=7)
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    a = ap.parse_args()
    load0 = load()
    cmds = {
        BASE: [sys.executable, "-c", "pass"],
        "zerocal --help": [sys.executable, "-m", "zerocal_sym", "--help"],
        "import zerocal_sym.model.kinematics (casadi)": [sys.executable, "-c", "import zerocal_sym.model.kinematics"],
        "zerocal robot": [sys.executable, "-m", "zerocal_sym", "robot"],
    }
    t = commands(cmds, a.passes)
    help_cpu, help_wall = median(t, "zerocal --help"), median(t, "zerocal --help", "wall")
    res = {"load_before": load0, "load_after": load(), "passes": a.passes, "commands": summary(t, "s"),
           "x_baseline_cpu": {n: ratio(t, n, BASE) for n in cmds},
           "target": {"zerocal --help CPU s": 1.0, "met": help_cpu < 1.0}}
    if emit(res, a.json):
        return
    print(f"{'command':46s} {'wall [s]':>9s} {'CPU [s]':>8s} {'x baseline CPU':>15s}   (medians, {a.passes} interleaved "
          "passes)")
    for n in cmds:
        c = res["commands"][n]
        print(f"{n:46s} {c['wall_s']:9.3f} {c['cpu_s']:8.3f} {res['x_baseline_cpu'][n]:15.1f}")
    print(f"target: zerocal --help < 1 s of CPU: {'met' if help_cpu < 1.0 else 'NOT met'} ({help_cpu:.3f} s CPU, "
          f"{help_wall:.3f} s wall at this load)")
    print(load_line(res["load_before"], res["load_after"]))


if __name__ == "__main__":
    main()
