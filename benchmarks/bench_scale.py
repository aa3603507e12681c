"""Scale: ``zerocal identify`` at K poses, wall and CPU time and peak memory per K, against K = 1000 of the same run.

For each robot (default the paper's planar robot and ``examples/delta.toml``;
any robot file with ``--robots``) and K, a measurement file of K random poses
in the workspace is simulated (the robot's noise, fixed seed); a *rejected* round has one bad reading (+0.5 mm at
pose K/2), which the fit check rejects and diagnoses.  Each
``zerocal identify FILE --method M --json`` runs in a fresh process: wall
time (``time.perf_counter``), CPU time (user + system, from ``os.wait4``) and
peak resident memory (``ru_maxrss``) are that process's alone.  The two
methods run interleaved at every K (nlls, tsvd, nlls, ... as the load
changes, it changes for both); ``x K0`` is the ratio to K = 1000 of the same
robot, kind and method, beside ``K/K0`` (linear cost keeps them close).  The
load average is printed at the start and with each row.

    .venv/bin/python benchmarks/bench_scale.py                    # K = 1000, 10000, 100000; rejected 400 .. 10000
    .venv/bin/python benchmarks/bench_scale.py --max-K 10000 --json
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASE_K = 1000
CLEAN_K = (1000, 10000, 100000)
REJECTED_K = (400, 1000, 10000)
BAD_MM = 0.5


def simulate(path, robot_file, K, bad=False, seed=1):
    """K random poses inside the robot's workspace, measured with the paper's noise, written to ``path``."""
    import numpy as np

    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.io.measurements import write_measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.model.robot import load_robot, paper_robot

    robot = paper_robot() if robot_file == "paper" else load_robot(robot_file)
    lo, hi = robot.workspace.bounds()
    rng = np.random.default_rng(seed)
    P = lo + (hi - lo) * rng.random((4 * K, len(lo)))
    inside = robot.workspace.contains(P, -1.0)  # 1 mm inside; a workspace with orientations (rad): inside
    P = P[inside if inside.sum() >= K else robot.workspace.contains(P, 0.0)][:K]
    e = robot.errors
    # offsets 0.5, -0.3, 0.2, ... (deg or mm, the joints' unit) and MAEMM 0.5, -0.2, 0.1, ... mm, by name: any mechanism
    err = e.from_user({**{n: (0.5, -0.3, 0.2)[i % 3] for i, n in enumerate(e.zero_offsets)},
                       **{n: (0.5, -0.2, 0.1)[i % 3] for i, n in enumerate(e.measuring)}})
    meas = simulate_round(robot, VirtualPlant(robot, err), P, None, NoiseModel.named("paper", robot), rng)
    if bad:
        meas.readings[K // 2] += BAD_MM
    meas.meta = {"robot_sha256": robot.sha256, "generator": "benchmarks/bench_scale.py"}
    write_measurements(path, meas, mechanism=robot)


def run_process(cmd, timeout):
    """(wall s, CPU s, peak RSS MB, returncode, stderr tail) of a command; killed after ``timeout`` s."""
    t = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    timer = threading.Timer(timeout, lambda: p.send_signal(signal.SIGKILL))
    timer.start()
    err = []
    reader = threading.Thread(target=lambda: err.append(p.stderr.read()))
    reader.start()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    timer.cancel()
    reader.join()
    tail = "".join(err).strip().splitlines()
    return wall, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024, os.waitstatus_to_exitcode(status), \
        (tail[-1][:160] if tail else "")


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-K", type=int, default=100000, help="the largest K (default 100000)")
    ap.add_argument("--robots", nargs="+", default=["paper", "examples/delta.toml"],
                    help="robot files ('paper': the built-in robot; default paper and examples/delta.toml)")
    ap.add_argument("--no-rejected", action="store_true", help="no rounds with a bad reading")
    ap.add_argument("--timeout", type=float, default=1800, help="per process, s (default 1800)")
    ap.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = ap.parse_args()
    plan = [("clean", K) for K in CLEAN_K if K <= args.max_K]
    if not args.no_rejected:
        plan += [("rejected", K) for K in REJECTED_K if K <= args.max_K]
    header = {"load_average_1_5_15": list(os.getloadavg()), "cpus": os.cpu_count(), "python": sys.version.split()[0]}
    if not args.json:
        print(f"load average {load()} on {os.cpu_count()} CPUs; each row a fresh `zerocal identify FILE --method M "
              "--json`", flush=True)
        print(f"{'robot':6s} {'kind':8s} {'K':>7s} {'method':6s} {'wall s':>8s} {'CPU s':>8s} {'peak MB':>8s} "
              f"{'x K0 wall':>9s} {'x K0 CPU':>8s} {'x K0 MB':>7s} {'K/K0':>5s}  exit  load", flush=True)
    rows, base = [], {}
    with tempfile.TemporaryDirectory(prefix="bench_scale.") as tmp:
        for kind, K in sorted(plan, key=lambda x: (x[0] != "clean", x[1] != BASE_K, x[1])):  # the base first
            for robot in args.robots:
                label = "paper" if robot == "paper" else os.path.splitext(os.path.basename(robot))[0]
                path = os.path.join(tmp, f"{label}-{kind}-{K}.csv")
                simulate(path, robot, K, bad=kind == "rejected")
                for method in ("nlls", "tsvd"):
                    cmd = [sys.executable, "-m", "zerocal_sym", "identify", path, "--method", method, "--json"]
                    if robot != "paper":
                        cmd += ["--robot", robot]
                    wall, cpu, mb, code, tail = run_process(cmd, args.timeout)
                    row = {"robot": label, "kind": kind, "K": K, "method": method, "wall_s": wall, "cpu_s": cpu,
                           "peak_mb": mb, "exit": code, "load_1min": os.getloadavg()[0]}
                    if code not in (0, 1):
                        row["error"] = tail
                    key = (label, kind, method)
                    if K == BASE_K:
                        base[key] = row
                    b = base.get(key)
                    if b is not None:
                        row.update(wall_x=wall / b["wall_s"], cpu_x=cpu / b["cpu_s"], mb_x=mb / b["peak_mb"],
                                   k_ratio=K / BASE_K)
                    rows.append(row)
                    if not args.json:
                        print(_line(row), flush=True)
    if args.json:
        print(json.dumps({"header": header, "rows": rows}, indent=1))


def _line(r) -> str:
    def x(k, spec):
        return format(r[k], spec) if k in r else "-"

    return (f"{r['robot']:6s} {r['kind']:8s} {r['K']:>7d} {r['method']:6s} {r['wall_s']:8.2f} {r['cpu_s']:8.2f} "
            f"{r['peak_mb']:8.0f} {x('wall_x', '9.2f'):>9s} {x('cpu_x', '8.2f'):>8s} {x('mb_x', '7.2f'):>7s} "
            f"{x('k_ratio', '5.1f'):>5s}  {r['exit']:4d}  {r['load_1min']:.2f}" + (f"  {r['error']}" if "error" in r
                                                                                      else ""))


if __name__ == "__main__":
    sys.path.insert(0, ROOT)
    main()
