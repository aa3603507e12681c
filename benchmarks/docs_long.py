"""Commands the docs quote that are too long for the test suite's docs checker: run them and print what they print.

The docs checker (tests/test_docs_commands.py) runs every command a page shows, within the suite's time budget.
A few figures come from Monte Carlo runs of minutes (many groups, hundreds of trials, several variants); the page
quotes them from this script's output, with its date and load, and says so.  Each run below prints the command,
then its output (whole, or the summary a page quotes), then its CPU and wall time.

Usage: python benchmarks/docs_long.py [NAME ...]      (NAME: reproduce, rules, compare, arms, hexapod; default all)

* reproduce (README.md's results, docs/reproduction.md "What reproduces" and "What does not reproduce"):
  ``zerocal reproduce --trials 100`` with the scale error alone and with the paper's noise; per quantity the range
  over the six groups (and its standard deviation over the trials where the pages give it).
* rules (docs/reproduction.md, Decision 3): the TSVD's truncation rules over 100 trials of ``zerocal reproduce``;
  per run the range over the six groups and two offsets of the mean residual delta and of its standard deviation.
* compare (docs/nonlinear.md, "Monte Carlo against the CRLB and TSVD"): ``zerocal compare`` with 500 trials on
  every group of Table 2, and on group 1 without geometric errors, in Table 2's literal frame and with the scale
  error alone; whole output.
* arms (docs/trust.md, "Why the design measure"): ``python examples/delta_arms.py``, the exact path's design for
  the Delta's offsets and arms against the design measure's; whole output.  Run from the repository's root.
* hexapod (docs/design.md, "Results: the linear Delta and the hexapod"): the hexapod's K = 64 crlb design with
  the tolerances of a machined robot (``--tolerance-scale 0.04``); whole output.
"""
import argparse
import datetime
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path


def _delta_ranges(out: str) -> str:
    groups = json.loads(out)["groups"]
    delta = [d for g in groups for d in g["delta_deg"]]
    std = [d for g in groups for d in g["delta_deg_std"]]
    return (f"mean delta {min(delta):.3f}-{max(delta):.3f} deg, "
            f"its std over the trials {min(std):.3f}-{max(std):.3f} deg")


def _reproduce_ranges(out: str) -> str:
    groups = json.loads(out)["groups"]

    def rng(name, key, index=None, digits=3):
        vals = []
        for g in groups:  # a group's value, or its values (one per offset)
            v = g[key] if index is None else g[key][index]
            vals += v if isinstance(v, list) else [v]
        return f"{name} {min(vals):.{digits}f}-{max(vals):.{digits}f}"

    rows = [rng("delta_deg", "delta_deg"), rng("delta_deg_std", "delta_deg_std"),
            rng("dp0_after_mm", "dp0_after_mm", digits=2), rng("dp0_after_mm_std", "dp0_after_mm_std", digits=2),
            rng("dpmax_after_mm", "dpmax_after_mm", digits=2),
            rng("dpmax_after_mm_std", "dpmax_after_mm_std", digits=2),
            rng("delta_maemm_mm[0]", "delta_maemm_mm", 0), rng("delta_maemm_mm_std[0]", "delta_maemm_mm_std", 0),
            rng("delta_maemm_mm[1]", "delta_maemm_mm", 1), rng("delta_maemm_mm_std[1]", "delta_maemm_mm_std", 1),
            rng("kappa_mean", "kappa_mean", digits=2), rng("iterations", "iterations", digits=1),
            rng("converged_fraction", "converged_fraction", digits=2)]
    return "\n".join(rows)


RUNS = {
    "reproduce": [(f"zerocal reproduce --trials 100{noise} --json", _reproduce_ranges)
                  for noise in (" --noise scale-only", "")],
    "rules": [(f"zerocal reproduce --trials 100 --noise {noise} --rule {rule} --json", _delta_ranges)
              for noise, rule in (("scale-only", "threshold"), ("scale-only", "gcv"), ("scale-only", "discrepancy"),
                                  ("paper", "threshold"), ("paper", "discrepancy"))],
    "compare": [(cmd, None) for cmd in ("zerocal compare --trials 500 --all",
                                        "zerocal compare --trials 500 --group 1 --no-geometric",
                                        "zerocal compare --trials 500 --group 1 --frame literal",
                                        "zerocal compare --trials 500 --group 1 --noise scale-only")],
    "arms": [("python examples/delta_arms.py", None)],
    "hexapod": [("zerocal design --robot examples/hexapod.toml --optimize --K 64 --criterion crlb --tolerance-scale 0.04",
                 None)],
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", metavar="NAME", help=f"which runs: {', '.join(RUNS)} (default: all)")
    a = ap.parse_args()
    unknown = [n for n in a.names if n not in RUNS]
    if unknown:
        ap.error(f"unknown run(s) {', '.join(unknown)}: the runs are {', '.join(RUNS)}")
    bindir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    if not shutil.which("zerocal", path=env["PATH"]):
        sys.exit(f"docs_long.py: no zerocal beside {sys.executable}")
    for name in a.names or list(RUNS):
        for cmd, summary in RUNS[name]:
            load = " ".join(f"{x:.2f}" for x in os.getloadavg())
            print(f"$ {cmd}\n# {datetime.date.today().isoformat()}, load average {load} on {os.cpu_count()} CPUs",
                  flush=True)
            t, c = time.perf_counter(), os.times()
            r = subprocess.run(cmd, shell=True, env=env, capture_output=True, text=True, check=True)
            c2 = os.times()
            cpu = c2.children_user - c.children_user + c2.children_system - c.children_system
            print(summary(r.stdout) if summary else r.stdout.rstrip())
            print(f"# CPU {cpu:.1f} s, wall {time.perf_counter() - t:.1f} s\n", flush=True)


if __name__ == "__main__":
    main()
