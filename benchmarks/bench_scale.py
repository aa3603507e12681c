"""Scale: loading and identifying K poses, time and peak memory per K, against a small K in the same run.

For each K a measurement file of K random poses in the paper robot's
workspace is simulated (paper noise, fixed seed), then

* ``load``: :func:`zerocal_sym.io.measurements.load_measurements` (with the robot's checks);
* ``identify``: the identification itself (``tsvd``: :func:`identify_tsvd` with the
  paper noise; ``nlls``: :func:`identify_nlls`);
* ``report``: the identifiability report ``zerocal identify`` adds;
* ``cli``: the whole ``zerocal identify FILE --method M --json`` as a process
  (wall time, peak resident memory from ``os.wait4``).

The stages run in a fresh child process per (K, method): times from
``time.perf_counter`` (load and report untraced, then once more under
``tracemalloc`` for their peak; the identification once, traced), the peak of
numpy/Python allocations per stage from ``tracemalloc`` (CasADi's own
allocations are not seen there), and the child's peak resident memory
(``ru_maxrss``).  The baseline is the smallest K
of the same run; ``x base`` is time(K) / time(K0) beside K / K0 (linear time
keeps the two close).

    .venv/bin/python benchmarks/bench_scale.py                       # tsvd 100..100000, nlls 100..10000
    .venv/bin/python benchmarks/bench_scale.py --tsvd 100 100000 --nlls 100 10000 --json
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


def simulate(path, K, seed=1):
    """K random poses in the paper robot's workspace, measured with the paper's noise, written to ``path``."""
    import numpy as np

    from zerocal_sym.identify.loop import simulate_round
    from zerocal_sym.io.measurements import write_measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.model.robot import paper_robot

    robot = paper_robot()
    lo, hi = robot.workspace.bounds()
    rng = np.random.default_rng(seed)
    P = lo + (hi - lo) * rng.random((K, len(lo)))
    err = robot.errors.from_user({"theta1": 0.5, "theta2": -0.3, "rMx": 0.5, "rMy": -0.2})
    meas = simulate_round(robot, VirtualPlant(robot, err), P, None, NoiseModel.paper(), rng)
    meas.meta = {"robot_sha256": robot.sha256, "generator": "benchmarks/bench_scale.py"}
    write_measurements(path, meas, mechanism=robot)


def child(path, method):
    """The stages in this process; prints one JSON line."""
    import resource
    import tracemalloc

    from zerocal_sym.identify.identifiability import identifiability_report
    from zerocal_sym.io.measurements import load_measurements
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.robot import paper_robot

    robot = paper_robot()
    noise = NoiseModel.paper()
    out = {}

    def stage(name, fn, again=True):
        """Timed without tracemalloc (it slows Python-heavy code), then (``again``) run traced for the peak."""
        t = time.perf_counter()
        value = fn()
        out[name] = {"s": time.perf_counter() - t}
        if again:
            tracemalloc.start()
            fn()
            out[name]["peak_mb"] = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
        return value

    meas = stage("load", lambda: load_measurements(path, robot))
    if method == "tsvd":
        from zerocal_sym.identify.tsvd import identify_tsvd

        ident = lambda: identify_tsvd(robot, meas, noise=noise)  # noqa: E731
    else:
        from zerocal_sym.identify.nlls import identify_nlls

        ident = lambda: identify_nlls(robot, meas, "paper", noise=noise)  # noqa: E731
    tracemalloc.start()  # the identification once, traced (numpy-heavy: tracemalloc costs little there)
    t = time.perf_counter()
    res = ident()
    out["identify"] = {"s": time.perf_counter() - t, "peak_mb": tracemalloc.get_traced_memory()[1] / 2**20}
    tracemalloc.stop()
    stage("report", lambda: identifiability_report(robot, meas.theta_cmd, res.params, noise,
                                                   err0=res.full_vector()))
    out["K"] = int(meas.K)
    out["status"] = str(res.status)[:120]
    out["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out))


def run_process(cmd, timeout):
    """(wall s, peak RSS MB, returncode, stdout, stderr) of a command; killed after ``timeout`` s."""
    t = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    timer = threading.Timer(timeout, lambda: p.send_signal(signal.SIGKILL))
    timer.start()
    out, err = [], []
    readers = [threading.Thread(target=lambda: out.append(p.stdout.read())),
               threading.Thread(target=lambda: err.append(p.stderr.read()))]
    for r in readers:
        r.start()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    timer.cancel()
    for r in readers:
        r.join()
    p.returncode = os.waitstatus_to_exitcode(status)
    return wall, ru.ru_maxrss / 1024, p.returncode, "".join(out), "".join(err)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tsvd", nargs="*", type=int, default=[100, 1000, 10000, 100000], metavar="K")
    ap.add_argument("--nlls", nargs="*", type=int, default=[100, 1000, 10000], metavar="K")
    ap.add_argument("--timeout", type=float, default=900, help="per process, s (default 900)")
    ap.add_argument("--no-cli", action="store_true", help="skip the whole-command runs")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", nargs=2, metavar=("FILE", "METHOD"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(*args.child)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_scale.") as tmp:
        for method, Ks in (("tsvd", args.tsvd), ("nlls", args.nlls)):
            base = None
            for K in sorted(Ks):
                path = os.path.join(tmp, f"k{K}.csv")
                if not os.path.exists(path):
                    simulate(path, K)
                row = {"method": method, "K": K}
                wall, rss, rc, out, err = run_process([sys.executable, __file__, "--child", path, method],
                                                      args.timeout)
                if rc == 0:
                    row.update(json.loads(out.strip().splitlines()[-1]))
                    row["stages_maxrss_mb"] = row.pop("maxrss_mb")
                else:
                    row["stages_error"] = f"exit {rc} after {wall:.0f} s (peak {rss:.0f} MB): " + (
                        err.strip().splitlines()[-1][:160] if err.strip() else "killed")
                if not args.no_cli:
                    cmd = [sys.executable, "-m", "zerocal_sym", "identify", path, "--method", method, "--json"]
                    wall, rss, rc, out, err = run_process(cmd, args.timeout)
                    row["cli"] = {"s": wall, "maxrss_mb": rss, "exit": rc}
                    if rc not in (0, 1):
                        row["cli"]["error"] = (err.strip().splitlines()[-1][:160] if err.strip() else "killed")
                base = base or row
                rows.append(row)
                if not args.json:
                    print(_line(row, base), flush=True)
    if args.json:
        print(json.dumps(rows, indent=1))


def _line(row, base):
    def t(r, k):
        return r[k]["s"] if k in r else None

    def f(v, spec=".2f"):
        return "-" if v is None else format(v, spec)

    ratio = row["K"] / base["K"]
    parts = [f"{row['method']:4s} K={row['K']:>7d}"]
    for k in ("load", "identify", "report"):
        v, b = t(row, k), t(base, k)
        x = f"{v / b:.0f}x" if v is not None and b else "-"
        peak = f", {row[k]['peak_mb']:.0f} MB" if k in row else ""
        parts.append(f"{k} {f(v)} s ({x} base{peak})")
    if "stages_maxrss_mb" in row:
        parts.append(f"RSS {row['stages_maxrss_mb']:.0f} MB")
    if "stages_error" in row:
        parts.append(row["stages_error"])
    if "cli" in row:
        c = row["cli"]
        parts.append(f"| zerocal identify: {c['s']:.2f} s, {c['maxrss_mb']:.0f} MB, exit {c['exit']}"
                     + (f" ({c['error']})" if "error" in c else ""))
    return "  ".join(parts) + f"   [K/K0 = {ratio:.0f}]"


if __name__ == "__main__":
    sys.path.insert(0, ROOT)
    main()
