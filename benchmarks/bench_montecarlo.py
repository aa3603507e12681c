"""Monte Carlo cost: `zerocal compare` per trial, 1 vs 2 workers, and the study runner's throughput.

Measured in one run (the machine's load average is printed: it is shared):

  compare-1w     the Monte Carlo of `zerocal compare --trials N1` (paper's robot, group 1, all six
                 methods) in one process, after a warm-up: wall and CPU time per trial, and per
                 method the time per trial (identifications x time per identification); the
                 command's start-up (imports, CasADi functions) measured apart.  Target <= 40 ms.
  compare-2w     the same with workers=2 on N2 trials (default 1000): wall per trial, the
                 speed-up over compare-1w, CPU per trial (the workers' included), and 10,000
                 trials extrapolated from it (labelled so; `--full` runs the 10,000).  Target < 5 min.
  study          the study runner (run_study, as `zerocal study`) on a generated spec (the paper's
                 robot at K = 6, p = 4; the rotary Delta at K = 12, p = 6; one cell each), one
                 and two workers: identifications per second of wall time and of CPU time.
  single         identify_nlls one data set at a time (the path a trial takes without the
                 batch), identifications per second, for the ratio batch / single.

Usage: python benchmarks/bench_montecarlo.py [--n1 200] [--n2 1000] [--full] [--study 20000]
       [--chunk 2000] [--json]
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ZEROCAL = [sys.executable, "-m", "zerocal_sym"]


def cpu_now():
    """CPU seconds of this process and of its waited-for children (the worker processes)."""
    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + ch.ru_utime + ch.ru_stime


def compare(trials, workers):
    """The Monte Carlo of `zerocal compare --group 1` (all methods) in this process (start-up excluded)."""
    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.compare import compare as run

    robot = paper_robot()
    run(robot, trials=2)  # warm-up: CasADi functions built
    c = cpu_now()
    rep = run(robot, trials=trials, workers=workers)
    cpu = cpu_now() - c
    ex = rep["execution"]
    per_method = {m: r["identifications"] * r["time_per_identification_ms"]
                  for m, r in rep["groups"]["1"]["methods"].items()}
    return {"trials": trials, "workers": workers, "run_wall_s": ex["wall_s"],
            "wall_per_trial_ms": ex["wall_per_trial_ms"], "cpu_per_trial_ms": 1e3 * cpu / trials,
            "per_method_ms_per_trial": per_method}


def compare_cli(trials, workers):
    """The whole command (start-up included): wall seconds."""
    t = time.perf_counter()
    subprocess.run(ZEROCAL + ["compare", "--trials", str(trials), "--group", "1", "--quiet", "--workers",
                              str(workers)], check=True, capture_output=True, cwd=ROOT)
    return time.perf_counter() - t


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


def study(label, robot, trials, chunk, workers, tmp):
    """The study runner in this process (run_study), one cell."""
    from zerocal_sym.cli import study as st

    spec = Path(tmp) / f"{label}.toml"
    spec.write_text(SPEC.format(label=label, trials=trials, chunk=chunk, robot=robot,
                                truth=TRUTHS[label.split("-")[0]]))
    c = cpu_now()
    run = st.run_study(st.load_spec(spec), Path(tmp) / f"{label}-{workers}w", workers=workers)["run"]
    cpu = cpu_now() - c
    return {"label": label, "workers": workers, "trials": trials, "chunk": chunk,
            "identifications_per_s": run["identifications_per_s"], "run_wall_s": run["wall_s"],
            "identifications_per_cpu_s": trials / cpu}


def single(label, robot_path, n=200):
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
    identify_nlls(robot, data[0], "paper", noise=noise)
    t = time.perf_counter()
    for m in data:
        identify_nlls(robot, m, "paper", noise=noise)
    return n / (time.perf_counter() - t)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n1", type=int, default=200, help="trials of the one-worker compare (default 200)")
    ap.add_argument("--n2", type=int, default=1000, help="trials of the two-worker compare (default 1000)")
    ap.add_argument("--full", action="store_true", help="run the 10,000-trial compare with --workers 2")
    ap.add_argument("--study", type=int, default=20000, help="trials of each study cell (default 20000)")
    ap.add_argument("--chunk", type=int, default=2000, help="trials per study chunk (default 2000)")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args()

    # the compiled tier as a long run uses it; ZEROCAL_COMPILE=always builds the libraries in the warm-ups
    # (cached afterwards), so no build runs inside a timing; ZEROCAL_COMPILE=never measures the interpreted tier
    os.environ.setdefault("ZEROCAL_COMPILE", "always")
    res = {"load_average_before": os.getloadavg(), "cpus": os.cpu_count(),
           "compile_mode": os.environ["ZEROCAL_COMPILE"]}
    res["compare_1w"] = c1 = compare(args.n1, 1)
    res["compare_cli_startup_s"] = startup = compare_cli(2, 1) - 2 * c1["wall_per_trial_ms"] / 1e3
    n2 = 10000 if args.full else args.n2
    res["compare_2w"] = c2 = compare(n2, 2)
    c2["speedup_over_1w"] = c1["wall_per_trial_ms"] / c2["wall_per_trial_ms"]
    c2["cpu_ratio_to_1w"] = c2["cpu_per_trial_ms"] / c1["cpu_per_trial_ms"]
    res["compare_10000_2w_s"] = {"value": (startup + c2["run_wall_s"] if args.full else
                                           startup + 10000 * c2["wall_per_trial_ms"] / 1e3),
                                 "measured": bool(args.full),
                                 "how": ("measured" if args.full else
                                         f"extrapolated: start-up + 10,000 x the wall per trial of {n2} trials")}
    res["study"] = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, robot in (("paper", "paper"), ("delta", str(ROOT / "examples" / "delta.toml"))):
            study(label + "-warm", robot, 200, 100, 1, tmp)  # warm-up: the problems built (and compiled)
            one = study(label, robot, args.study, args.chunk, 1, tmp)
            two = study(label, robot, args.study, args.chunk, 2, tmp)
            two["speedup_over_1w"] = two["identifications_per_s"] / one["identifications_per_s"]
            two["cpu_ratio_to_1w"] = one["identifications_per_cpu_s"] / two["identifications_per_cpu_s"]
            s1 = single(label, robot)
            one["single_path_identifications_per_s"] = s1
            one["batch_over_single"] = one["identifications_per_s"] / s1
            res["study"] += [one, two]
    res["load_average_after"] = os.getloadavg()
    if args.json:
        print(json.dumps(res, indent=2))
        return
    print(f"machine: {res['cpus']} CPUs, load average before {res['load_average_before'][0]:.2f}, "
          f"after {res['load_average_after'][0]:.2f} (shared: figures are upper bounds); "
          f"ZEROCAL_COMPILE={res['compile_mode']}")
    print(f"compare, 1 worker, {c1['trials']} trials (group 1, all methods): {c1['wall_per_trial_ms']:.1f} ms/trial "
          f"wall (target <= 40), {c1['cpu_per_trial_ms']:.1f} ms/trial CPU; the command's start-up "
          f"{res['compare_cli_startup_s']:.1f} s")
    print("  per method, ms per trial: " + ", ".join(f"{m} {v:.1f}" for m, v in c1["per_method_ms_per_trial"].items()))
    print(f"compare, 2 workers, {c2['trials']} trials: {c2['wall_per_trial_ms']:.1f} ms/trial wall, speed-up "
          f"{c2['speedup_over_1w']:.2f} x over 1 worker; CPU per trial (workers included) "
          f"{c2['cpu_per_trial_ms']:.1f} ms ({c2['cpu_ratio_to_1w']:.2f} x 1 worker's: the work is the same, "
          "the wall time is what the free cores allow)")
    t10 = res["compare_10000_2w_s"]
    print(f"compare, 2 workers, 10,000 trials: {t10['value']:.0f} s = {t10['value'] / 60:.1f} min "
          f"(target < 5 min; {t10['how']})")
    for s in res["study"]:
        extra = (f", speed-up {s['speedup_over_1w']:.2f} x, CPU per identification {s['cpu_ratio_to_1w']:.2f} x 1 "
                 "worker's" if "speedup_over_1w" in s else
                 f"; one at a time (identify_nlls) {s['single_path_identifications_per_s']:.0f}/s, "
                 f"batch/single {s['batch_over_single']:.1f} x")
        print(f"study {s['label']}, {s['workers']} worker(s), {s['trials']} trials in chunks of {s['chunk']}: "
              f"{s['identifications_per_s']:.0f} identifications/s ({s['identifications_per_cpu_s']:.0f} per CPU "
              f"second){extra}")


if __name__ == "__main__":
    main()
