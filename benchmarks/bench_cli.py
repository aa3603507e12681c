"""Start-up time of the CLI: `zerocal --help` against a bare Python start.

Target: `zerocal --help` answers in under a second.
Usage: python benchmarks/bench_cli.py [--repeat N]
"""
import argparse
import sys

from _harness import wall




def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args()
    base, _ = wall([sys.executable, "-c", "pass"], a.repeat)
    rows = [
        ("python -c pass (baseline)", [sys.executable, "-c", "pass"]),
        ("zerocal --help", [sys.executable, "-m", "zerocal_sym", "--help"]),
        ("import zerocal_sym.model.kinematics (casadi)", [sys.executable, "-c", "import zerocal_sym.model.kinematics"]),
        ("zerocal robot", [sys.executable, "-m", "zerocal_sym", "robot"]),
    ]
    print(f"{'command':42s} {'median [s]':>10s} {'min [s]':>8s} {'x baseline':>10s}")
    for name, cmd in rows:
        med, mn = wall(cmd, a.repeat)
        print(f"{name:42s} {med:10.3f} {mn:8.3f} {med / base:10.1f}")
    med, _ = wall([sys.executable, "-m", "zerocal_sym", "--help"], a.repeat)
    print(f"target: zerocal --help < 1 s: {'met' if med < 1.0 else 'NOT met'} ({med:.3f} s)")


if __name__ == "__main__":
    main()
