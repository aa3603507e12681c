"""Monte Carlo cost: `zerocal compare` per trial, 1 vs 2 workers, and the study runner's throughput.

Every comparison is timed interleaved (each pass runs every column once, the order rotating from pass to
pass: benchmarks/_harness.py), CPU time (this process and its worker processes) beside wall time, the load
average printed:

  compare        the Monte Carlo of `zerocal compare` (paper's robot, group 1, all six methods) in this
                 process, start-up excluded, 1 worker on --n1 trials against 2 workers on --n2: CPU and wall
                 per trial.  Target: <= 5 ms of CPU per trial on one worker.
  per method     the same with one method at a time (each column runs the trial's first round and that
                 method): CPU per trial.
  start-up       the whole command `zerocal compare --trials 2` against `python -c pass` (CPU of the child).
  10,000 trials  `zerocal compare --trials 10000 --workers 2` next to `--workers 1`, whole commands, one pass
                 each, interleaved (--full; otherwise extrapolated from the in-process figures, and labelled so).
  baseline       (--baseline COMMIT) `zerocal compare --trials --n1 --group 1` of that commit's package (its
                 zerocal_sym/ extracted by `git archive`, on this environment) against this checkout's, whole
                 commands interleaved: CPU (the child's) and wall, and their ratio.
  study          the study runner (run_study, as `zerocal study`) on a generated spec (the paper's robot at
                 K = 6, p = 4; the rotary Delta at K = 12, p = 6; one cell each), one worker against two:
                 identifications per CPU second and per wall second; and identify_nlls one at a time.

Usage: python benchmarks/bench_montecarlo.py [--n1 200] [--n2 1000] [--passes 3] [--full] [--study 20000]
       [--chunk 2000] [--baseline COMMIT] [--only-baseline] [--json]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _harness import (commands, cpu_all, cpu_children, emit, interleaved, load, load_line, median, ratio, spread,
                      summary)

ROOT = Path(__file__).resolve().parents[1]
ZEROCAL = [sys.executable, "-m", "zerocal_sym"]
METHODS = ("tsvd-loop", "tsvd", "nlls", "nlls-loop", "nlls-seq", "scipy")
TARGET_MS = 5.0


def compare_column(trials, workers, methods=METHODS, out=None):
    """A column: the Monte Carlo of `zerocal compare --group 1` in this process (start-up excluded)."""
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.compare import compare as run

    robot = paper_robot()

    def col():
        rep = run(robot, trials=trials, workers=workers, methods=methods)
        if out is not None:
            out[(workers, methods)] = rep
        return trials
    return col


SPEC = """name = "bench-{label}"
seed = 0
trials = {trials}
chunk = {chunk}
robots = ["{robot}"]
noise = ["paper"]
[[design]]
scheme = "auto"
[[truth]]
name = "A"
{truth}
"""
TRUTHS = {"paper": "theta1 = 2\ntheta2 = -1\nrMx = 1\nrMy = 0.5",
          "delta": "theta1 = 2\ntheta2 = -1\ntheta3 = 0.5\nrMx = 1\nrMy = 0.5\nrMz = -0.5"}


def study_column(label, robot, trials, chunk, workers, tmp):
    """A column: the study runner in this process (run_study), one cell, a fresh directory each pass."""
    from zerocal_sym.cli import study as st

    spec = Path(tmp) / f"{label}.toml"
    spec.write_text(SPEC.format(label=label, trials=trials, chunk=chunk, robot=robot, truth=TRUTHS[label]))
    runs = [0]

    def col():
        runs[0] += 1
        st.run_study(st.load_spec(spec), Path(tmp) / f"{label}-{workers}w-{runs[0]}", workers=workers)
        return trials
    return col


def single_column(label, robot_path, n=200):
    """A column: identify_nlls one data set at a time (the path of a trial without the batch)."""
    import numpy as np

    from zerocal_sym.cli._common import scheme_poses
    from zerocal_sym.identify.nlls import identify_nlls
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant
    from zerocal_sym.model.robot import load_robot, paper_robot

    robot = paper_robot() if robot_path == "paper" else load_robot(robot_path)
    P, _ = scheme_poses(robot)
    th = kin.ik(robot, P)
    truth = robot.errors.from_user({k: float(v) for k, v in (line.replace(" ", "").split("=")
                                                             for line in TRUTHS[label].split("\n"))})
    plant, noise = VirtualPlant(robot, truth), NoiseModel.paper()
    rng = np.random.default_rng(0)
    data = [Measurements(th, plant.measure(th, noise, rng)) for _ in range(n)]

    def col():
        for m in data:
            identify_nlls(robot, m, "paper", noise=noise)
        return n
    return col


def baseline(commit, trials, passes):
    """`zerocal compare` of ``commit``'s package against this checkout's, whole commands interleaved."""
    with tempfile.TemporaryDirectory(prefix="bench-mc-") as tmp:
        arc = subprocess.run(["git", "-C", str(ROOT), "archive", commit, "zerocal_sym"], capture_output=True)
        if arc.returncode != 0:
            raise SystemExit(f"git archive {commit}: {arc.stderr.decode().strip()}")
        subprocess.run(["tar", "-x", "-C", tmp], input=arc.stdout, check=True)
        argv = ZEROCAL + ["compare", "--trials", str(trials), "--group", "1", "--quiet"]

        def col(pythonpath):
            env = dict(os.environ, PYTHONPATH=pythonpath) if pythonpath else dict(os.environ)

            def run():
                subprocess.run(argv, check=True, capture_output=True, env=env, cwd=ROOT if not pythonpath else tmp)
                return trials
            return run

        t = interleaved({f"baseline {commit}": col(tmp), "current": col(None)}, passes, clock=cpu_children)
    return {"commit": commit, "trials": trials, "columns": summary(t),
            "cpu_ratio_baseline_over_current": ratio(t, f"baseline {commit}", "current"),
            "cpu_ratio_spread": spread(t, f"baseline {commit}", "current")}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n1", type=int, default=200, help="trials of the one-worker compare (default 200)")
    ap.add_argument("--n2", type=int, default=1000, help="trials of the two-worker compare (default 1000)")
    ap.add_argument("--passes", type=int, default=3, help="interleaved passes (default 3)")
    ap.add_argument("--full", action="store_true",
                    help="run `zerocal compare --trials 10000` with --workers 2 and --workers 1 (minutes)")
    ap.add_argument("--study", type=int, default=20000, help="trials of each study cell (default 20000)")
    ap.add_argument("--chunk", type=int, default=2000, help="trials per study chunk (default 2000)")
    ap.add_argument("--baseline", metavar="COMMIT", default=None,
                    help="also time `zerocal compare` of COMMIT's package against this checkout's (interleaved)")
    ap.add_argument("--only-baseline", action="store_true", help="only the --baseline comparison")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args()

    # the compiled tier as a long run uses it; ZEROCAL_COMPILE=always builds the libraries in the warm-ups
    # (cached afterwards), so no build runs inside a timing; ZEROCAL_COMPILE=never measures the interpreted tier
    os.environ.setdefault("ZEROCAL_COMPILE", "always")
    res = {"load_before": load(), "compile_mode": os.environ["ZEROCAL_COMPILE"], "passes": args.passes}
    if args.baseline:
        res["baseline"] = b = baseline(args.baseline, args.n1, args.passes)
        if args.only_baseline:
            res["load_after"] = load()
            if emit(res, args.json):
                return
            print_baseline(b)
            print(load_line(res["load_before"], res["load_after"]))
            return
    reps = {}
    t = interleaved({"1 worker": compare_column(args.n1, 1, out=reps), "2 workers": compare_column(args.n2, 2)},
                    args.passes, clock=cpu_all)
    c1, c2 = median(t, "1 worker"), median(t, "2 workers")
    res["compare"] = {"n1": args.n1, "n2": args.n2, "columns": summary(t),
                      "cpu_per_trial_ms_1w": 1e3 * c1, "wall_per_trial_ms_1w": 1e3 * median(t, "1 worker", "wall"),
                      "cpu_per_trial_ms_2w": 1e3 * c2, "wall_per_trial_ms_2w": 1e3 * median(t, "2 workers", "wall"),
                      "wall_speedup_2w": ratio(t, "1 worker", "2 workers", "wall"),
                      "wall_speedup_2w_spread": spread(t, "1 worker", "2 workers", "wall"),
                      "cpu_ratio_2w_to_1w": ratio(t, "2 workers", "1 worker"),
                      "target_cpu_ms": TARGET_MS, "met": 1e3 * c1 <= TARGET_MS}
    rep = reps[(1, METHODS)]["groups"]["1"]["methods"]
    res["compare"]["identifications_per_trial"] = {m: rep[m]["identifications"] for m in METHODS}
    tm = interleaved({m: compare_column(args.n1, 1, (m,)) for m in METHODS}, args.passes)
    res["per_method"] = {m: {"cpu_per_trial_ms": 1e3 * median(tm, m), "wall_per_trial_ms": 1e3 * median(tm, m, "wall")}
                         for m in METHODS}
    ts = commands({"zerocal compare --trials 2": ZEROCAL + ["compare", "--trials", "2", "--group", "1", "--quiet"],
                   "python -c pass": [sys.executable, "-c", "pass"]}, args.passes, cwd=ROOT)
    res["startup"] = summary(ts, "s")
    if args.full:
        cmd = ZEROCAL + ["compare", "--trials", "10000", "--group", "1", "--quiet", "--workers"]
        tf = commands({"--workers 2": cmd + ["2"], "--workers 1": cmd + ["1"]}, 1, cwd=ROOT)
        res["compare_10000"] = {"measured": True, **summary(tf, "s")}
    else:
        st = res["startup"]["zerocal compare --trials 2"]["wall_s"]
        res["compare_10000"] = {"measured": False, "how": "extrapolated: start-up + 10,000 x the in-process wall "
                                                          "per trial",
                                "--workers 2": {"wall_s": st + 10 * res["compare"]["wall_per_trial_ms_2w"]},
                                "--workers 1": {"wall_s": st + 10 * res["compare"]["wall_per_trial_ms_1w"]}}
    res["study"] = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, robot in (("paper", "paper"), ("delta", str(ROOT / "examples" / "delta.toml"))):
            cols = {"1 worker": study_column(label, robot, args.study, args.chunk, 1, tmp),
                    "2 workers": study_column(label, robot, args.study, args.chunk, 2, tmp),
                    "identify_nlls one at a time": single_column(label, robot)}
            t = interleaved(cols, args.passes, clock=cpu_all)
            one, two, single = (median(t, c) for c in cols)
            res["study"].append({
                "label": label, "trials": args.study, "chunk": args.chunk, "columns": summary(t),
                "identifications_per_cpu_s_1w": 1 / one, "identifications_per_cpu_s_2w": 1 / two,
                "identifications_per_wall_s_1w": 1 / median(t, "1 worker", "wall"),
                "identifications_per_wall_s_2w": 1 / median(t, "2 workers", "wall"),
                "single_per_cpu_s": 1 / single,
                "wall_speedup_2w": ratio(t, "1 worker", "2 workers", "wall"),
                "cpu_ratio_2w_to_1w": ratio(t, "2 workers", "1 worker"),
                "batch_over_single_cpu": ratio(t, "identify_nlls one at a time", "1 worker")})
    res["load_after"] = load()
    if emit(res, args.json):
        return
    c = res["compare"]
    print(f"ZEROCAL_COMPILE={res['compile_mode']}; columns interleaved, {args.passes} passes; CPU time (this "
          "process and its workers) and wall time")
    print(f"compare, all six methods: 1 worker ({args.n1} trials) {c['cpu_per_trial_ms_1w']:.2f} ms CPU per trial "
          f"({c['wall_per_trial_ms_1w']:.2f} ms wall; target <= {TARGET_MS} ms CPU: "
          f"{'met' if c['met'] else 'NOT met'}); 2 workers ({args.n2} trials) {c['cpu_per_trial_ms_2w']:.2f} ms CPU "
          f"per trial ({c['cpu_ratio_2w_to_1w']:.2f} x one worker's), {c['wall_per_trial_ms_2w']:.2f} ms wall "
          f"(wall speed-up {c['wall_speedup_2w']:.2f} x)")
    print("  per method, ms CPU per trial (the first round's simulation included): "
          + ", ".join(f"{m} {v['cpu_per_trial_ms']:.2f}" for m, v in res["per_method"].items()))
    print("  identifications per trial: " + ", ".join(f"{m} {v:.2f}" for m, v in c["identifications_per_trial"].items()))
    s = res["startup"]
    print(f"start-up: `zerocal compare --trials 2` {s['zerocal compare --trials 2']['cpu_s']:.2f} s CPU "
          f"({s['zerocal compare --trials 2']['wall_s']:.2f} s wall); python -c pass "
          f"{s['python -c pass']['cpu_s']:.2f} s CPU")
    f = res["compare_10000"]
    how = "measured, whole commands" if f["measured"] else f["how"]
    print(f"compare --trials 10000: --workers 2 {f['--workers 2']['wall_s']:.0f} s wall"
          + (f" ({f['--workers 2']['cpu_s']:.0f} s CPU)" if f["measured"] else "")
          + f", --workers 1 {f['--workers 1']['wall_s']:.0f} s wall"
          + (f" ({f['--workers 1']['cpu_s']:.0f} s CPU)" if f["measured"] else "") + f" ({how})")
    for r in res["study"]:
        print(f"study {r['label']} ({r['trials']} trials, chunks of {r['chunk']}): 1 worker "
              f"{r['identifications_per_cpu_s_1w']:.0f} identifications per CPU second "
              f"({r['identifications_per_wall_s_1w']:.0f} per wall second); 2 workers "
              f"{r['identifications_per_cpu_s_2w']:.0f} per CPU second ({r['identifications_per_wall_s_2w']:.0f} per "
              f"wall second, speed-up {r['wall_speedup_2w']:.2f} x; CPU {r['cpu_ratio_2w_to_1w']:.2f} x one "
              f"worker's); identify_nlls one at a time {r['single_per_cpu_s']:.0f} per CPU second (batch "
              f"{r['batch_over_single_cpu']:.1f} x)")
    if "baseline" in res:
        print_baseline(res["baseline"])
    print(load_line(res["load_before"], res["load_after"]))


def print_baseline(b):
    cols = b["columns"]
    lo, hi = b["cpu_ratio_spread"]
    print(f"`zerocal compare --trials {b['trials']} --group 1`, whole commands interleaved: "
          + ", ".join(f"{n} {c['cpu_ms']:.2f} ms CPU per trial ({c['wall_ms']:.1f} ms wall)" for n, c in cols.items())
          + f"; the baseline's CPU / this checkout's {b['cpu_ratio_baseline_over_current']:.2f} x (passes {lo:.2f}-{hi:.2f}; "
          "start-up included)")


if __name__ == "__main__":
    main()
