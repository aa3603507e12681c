"""The test suite's time against the suite of an earlier commit, both run here in one session.

    python benchmarks/bench_tests.py                    # baseline: the suite before the batched Monte Carlo paths
    python benchmarks/bench_tests.py --baseline HEAD~5  # any commit
    python benchmarks/bench_tests.py --baseline-dir /tmp/old  # a checkout with its own .venv, installed

Runs the README's test command (``pytest -n 2 --nbmake tests notebooks``)
on the baseline, in a fresh copy with its own virtual environment (``git
archive`` of the commit, ``pip install -e '.[test]'``), and on this
checkout with the running interpreter, interleaved: ``--passes N`` runs of
each, alternating, the one that goes first alternating too
(benchmarks/_harness.py); the medians are reported.  Prints, for each, the
wall time, the CPU time of the whole run (pytest and its workers, from
``getrusage``), the summed test durations (``--durations=0``), and per test
file the seconds of both (the first pass); the files of both
suites are summed apart from those only one has, so that the same tests are
compared with the same tests (like with like) and the growth of the suite is
shown as what it is.  ``--json`` prints the figures as JSON.

The machine is shared: the load average is printed with the figures; the
ratio of the two suites in the same pass, not either figure alone, is what
this measures.
"""
from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

from _harness import cpu_children, emit, load, load_line

ROOT = Path(__file__).resolve().parents[1]
#: the suite before the batched Monte Carlo paths (about 60 s on 2 cores then; the goal: no slower once the
#: Monte Carlo tests use them)
BASELINE = "bbf074f"
TEST_ARGS = ["-m", "pytest", "-n", "2", "--nbmake", "tests", "notebooks", "-q", "--durations=0",
             "-p", "no:cacheprovider"]
_DURATION = re.compile(r"^(\d+(?:\.\d+)?)s (call|setup|teardown)\s+(\S+?)(?:::|\s|$)")
_PASSED = re.compile(r"(\d+) passed")


def parse(text):
    """Per-file summed durations (s) and the number of passed tests from pytest's output."""
    per_file = defaultdict(float)
    for line in text.splitlines():
        m = _DURATION.match(line.strip())
        if m:
            per_file[m.group(3)] += float(m.group(1))
    passed = _PASSED.findall(text)
    return dict(per_file), int(passed[-1]) if passed else 0


def run_suite(python, cwd):
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    t0, c0 = time.perf_counter(), cpu_children()
    proc = subprocess.run([str(python)] + TEST_ARGS, cwd=cwd, env=env, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, cpu_children() - c0
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).splitlines()[-15:])
        raise SystemExit(f"the test suite in {cwd} failed (exit {proc.returncode}):\n{tail}")
    per_file, passed = parse(proc.stdout)
    return {"wall_s": wall, "run_cpu_s": cpu, "cpu_s": sum(per_file.values()), "passed": passed,
            "per_file": per_file}


def prepare_baseline(commit, where):
    """A copy of ``commit`` in ``where`` with its own virtual environment; returns its python."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit], capture_output=True, check=False)
    if archive.returncode != 0:
        raise SystemExit(f"git archive {commit}: {archive.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(where)], input=archive.stdout, check=True)
    subprocess.run([sys.executable, "-m", "venv", str(where / ".venv")], check=True)
    py = where / ".venv" / "bin" / "python"
    subprocess.run([str(py), "-m", "pip", "install", "--quiet", "-e", ".[test]"], cwd=where, check=True)
    return py


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default=BASELINE, help="commit of the baseline suite")
    ap.add_argument("--baseline-dir", type=Path,
                    help="an existing checkout of the baseline with its .venv installed (skips the install)")
    ap.add_argument("--passes", type=int, default=1, help="runs of each suite, interleaved (default 1)")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args(argv)

    load0 = load()
    runs = {"baseline": [], "current": []}
    with tempfile.TemporaryDirectory(prefix="bench-tests-") as tmp:
        if args.baseline_dir:
            base_dir = args.baseline_dir.resolve()
            base_py = base_dir / ".venv" / "bin" / "python"
            if not base_py.exists():
                raise SystemExit(f"{base_py} not found: --baseline-dir needs a checkout with its .venv")
            label = str(base_dir)
        else:
            base_dir = Path(tmp)
            base_py = prepare_baseline(args.baseline, base_dir)
            label = args.baseline
        for k in range(args.passes):
            order = [("baseline", base_py, base_dir), ("current", Path(sys.executable), ROOT)]
            for name, py, where in (order if k % 2 == 0 else order[::-1]):
                runs[name].append(run_suite(py, where))

    def merged(rs):
        out = {k: statistics.median(r[k] for r in rs) for k in ("wall_s", "run_cpu_s", "cpu_s")}
        out.update(passed=rs[0]["passed"], per_file=rs[0]["per_file"])
        return out

    base, cur = merged(runs["baseline"]), merged(runs["current"])
    both = sorted(set(base["per_file"]) & set(cur["per_file"]))
    only_cur = sorted(set(cur["per_file"]) - set(base["per_file"]))
    only_base = sorted(set(base["per_file"]) - set(cur["per_file"]))
    same_base = sum(base["per_file"][f] for f in both)
    same_cur = sum(cur["per_file"][f] for f in both)
    out = {"baseline": label, "baseline_suite": {k: v for k, v in base.items() if k != "per_file"},
           "current_suite": {k: v for k, v in cur.items() if k != "per_file"},
           "same_files": {"files": len(both), "baseline_cpu_s": same_base, "current_cpu_s": same_cur,
                          "ratio": same_cur / same_base if same_base else None},
           "only_current_cpu_s": sum(cur["per_file"][f] for f in only_cur),
           "only_baseline_cpu_s": sum(base["per_file"][f] for f in only_base),
           "per_file": {f: [base["per_file"].get(f), cur["per_file"].get(f)] for f in both + only_cur + only_base},
           "passes": args.passes, "ratio_per_pass_run_cpu": [c["run_cpu_s"] / b["run_cpu_s"] for b, c in
                                                            zip(runs["baseline"], runs["current"])],
           "load_before": load0, "load_after": load()}
    if emit(out, args.json):
        return 0
    print(f"{'suite':<24}{'tests':>7}{'wall s':>9}{'run CPU s':>10}{'test CPU-s':>12}   (medians of {args.passes} "
          "interleaved pass(es))")
    for name, s in ((f"baseline {label}", base), ("current", cur)):
        print(f"{name[:24]:<24}{s['passed']:>7}{s['wall_s']:>9.1f}{s['run_cpu_s']:>10.1f}{s['cpu_s']:>12.1f}")
    print(f"\n{'test file':<44}{'baseline s':>11}{'current s':>11}")
    for f in both + only_cur + only_base:
        b, c = base["per_file"].get(f), cur["per_file"].get(f)
        print(f"{f:<44}{'-' if b is None else f'{b:.1f}':>11}{'-' if c is None else f'{c:.1f}':>11}")
    print(f"\nthe {len(both)} files of both suites: baseline {same_base:.1f} CPU-s, current {same_cur:.1f} CPU-s, "
          f"ratio {out['same_files']['ratio']:.2f}")
    print(f"files only in the current suite: {out['only_current_cpu_s']:.1f} CPU-s; "
          f"only in the baseline: {out['only_baseline_cpu_s']:.1f} CPU-s")
    print(f"whole suites: wall {cur['wall_s'] / base['wall_s']:.2f}x, run CPU {cur['run_cpu_s'] / base['run_cpu_s']:.2f}x "
          f"(per pass: {', '.join(f'{r:.2f}' for r in out['ratio_per_pass_run_cpu'])}), test CPU "
          f"{cur['cpu_s'] / base['cpu_s']:.2f}x the baseline")
    print(load_line(out["load_before"], out["load_after"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
