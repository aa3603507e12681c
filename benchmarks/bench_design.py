"""Design time of `zerocal design --optimize`: the full design against its parts, and the reachable-region case.

Every comparison is timed interleaved (each pass runs every column once, the order rotating from pass to
pass: benchmarks/_harness.py), CPU time (this process) beside wall time, the load average printed.

* table (``--K``, ``--criteria``; the paper's robot, its workspace): the full design
  (:func:`zerocal_sym.design.optimize_design`: the approximate design's certificate, the discrete exchange,
  Ipopt multi-start, order search, polish) against one Ipopt start (NLP build + one solve from the paper's
  scheme) and the discrete exchange alone, with the stage breakdown of the design and what it achieved;
* reachable (the case of the target): ``zerocal design --optimize --K 6 --criterion crlb --region reachable
  --bounds -2000 2000 450 2000`` in this process (the region built once, outside the timing), against one
  Ipopt start of the same NLP; the CPU seconds of each stage (the certificate's approximate design, the
  exchange, the Ipopt starts and polish) and Ipopt's own split (its function evaluations against the rest).
  Target: under 1 s of CPU;
* default (the default criterion): ``zerocal design --optimize --K 6`` (``checked``: the least CRLB among
  designs whose fit check sees what they assume; the paper's robot, its workspace) in this process, against
  the crlb design of the same region (the first half of it);
* commands (``--no-commands`` skips them): the two commands above as the CLI runs them, each a fresh process
  (imports, the region, the design, the report), interleaved with the same commands run by the package of an
  earlier commit (``--baseline``, default :data:`DESIGN_BASELINE`, before the design's time was cut; the
  same interpreter and libraries); CPU of the process (user + system) and the ratio in the same pass;
* extras (``--no-extras`` skips them): K = 100 designs (the approximate method) on the paper's robot and the
  Delta, and ``--target-crlb 0.04`` (the fewest poses): one run each, CPU and wall.

The design's per-pose Functions run on the compiled tier once hot (``ZEROCAL_COMPILE``, default ``auto``: a
library in the cache loads at once, else one is built in the background and used when ready); the load and the
tier's state are printed with the figures.

Usage: python benchmarks/bench_design.py [--passes 3] [--K 6 20] [--criteria crlb cond] [--starts 8]
                                         [--only-extras] [--no-extras] [--no-commands] [--baseline REV] [--json]
"""
import argparse
import time

from _harness import commands, emit, interleaved, load, load_line, median, ratio, summary

TARGET_CPU_S = 1.0


def stage_clock(mods):
    """Wrap the stages of optimize_design to add up their CPU seconds (and Ipopt's evaluation times)."""
    import numpy as np  # noqa: F401

    from zerocal_sym.design import nlp as nlp_mod
    from zerocal_sym.design import optimize as opt

    acc = {}

    def wrap(mod, name, key):
        f = getattr(mod, name)

        def g(*a, **k):
            t = time.process_time()
            try:
                return f(*a, **k)
            finally:
                acc[key] = acc.get(key, 0.0) + time.process_time() - t
        setattr(mod, name, g)

    for name, key in (("approximate_design", "certificate (approximate design)"), ("exchange_design", "exchange"),
                      ("continuous_design", "Ipopt multi-start"), ("best_order", "order search"),
                      ("evaluate", "report")):
        if hasattr(opt, name):
            wrap(opt, name, key)
    import zerocal_sym.design.approx as approx_mod
    wrap(approx_mod, "approximate_design", "certificate (approximate design)")
    solve = nlp_mod._NLP.solve

    def counted(self, P0):
        t = time.process_time()
        try:
            return solve(self, P0)
        finally:
            acc["Ipopt solves"] = acc.get("Ipopt solves", 0.0) + time.process_time() - t
            acc["Ipopt starts"] = acc.get("Ipopt starts", 0) + 1
            st = self.solver.stats()
            acc["Ipopt evaluations"] = acc.get("Ipopt evaluations", 0.0) + sum(
                v for k, v in st.items() if k.startswith("t_proc_nlp"))
            acc["Ipopt iterations"] = acc.get("Ipopt iterations", 0) + int(st.get("iter_count", 0))
    nlp_mod._NLP.solve = counted
    return acc


def reachable(passes):
    from zerocal_sym import design
    from zerocal_sym.design import nlp as design_nlp
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.robot import paper_robot

    robot, noise = paper_robot(), NoiseModel.paper()
    t = time.process_time()
    cons = design.make_constraints(robot, region="reachable", bounds=(-2000, 2000, 450, 2000))
    region_cpu = time.process_time() - t
    acc = stage_clock(None)
    out = {}

    def full():
        acc.clear()
        out["res"] = design.optimize_design(robot, 6, "crlb", cons, noise, seed=0)
        out["stages"] = dict(acc)
        return 1

    base = design.choose_baseline(robot, 6, cons)[0]

    def one_ipopt():
        fs, ms = design_nlp._scales(robot, base, noise)
        design_nlp._NLP(robot, 6, "crlb", cons, noise, fs, ms).solve(base)
        return 1

    t = interleaved({"design": full, "1 Ipopt start": one_ipopt}, passes)
    d = out["res"].to_dict()
    cpu = median(t, "design")
    return {"columns": summary(t, "s"), "design_cpu_s": cpu, "design_wall_s": median(t, "design", "wall"),
            "design_over_one_ipopt_cpu": ratio(t, "design", "1 Ipopt start"), "region_cpu_s": region_cpu,
            "stages_cpu_s": out["stages"], "target_cpu_s": TARGET_CPU_S, "met": cpu < TARGET_CPU_S,
            "crlb_rms_deg": d["crlb_rms_deg"], "crlb_zero_offsets_deg": d["crlb_zero_offsets_deg"],
            "baseline_scheme": d["baseline_scheme"], "baseline_crlb_rms_deg": d["paper"]["crlb_rms_deg"],
            "certificate_bound_deg": d["certificate"]["bound"],
            "efficiency_lower_bound": d["certificate"]["efficiency_lower_bound"],
            "bias_worst_deg": max(d["bias"]["worst_case_deg"]), "bias_rms_deg": max(d["bias"]["rms_deg"]),
            "rho_span_mm": d["rho_span_mm"], "poses_mm": [list(map(float, p)) for p in out["res"].poses],
            "method": d["method"]}


def default_checked(passes):
    """``zerocal design --optimize --K 6`` (criterion ``checked``) in this process, against the crlb design."""
    from zerocal_sym import design
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.robot import paper_robot

    robot, noise = paper_robot(), NoiseModel.paper()
    cons = design.make_constraints(robot)
    out = {}

    def run(crit):
        def go():
            out[crit] = design.optimize_design(robot, 6, crit, cons, noise, seed=0)
            return 1
        return go

    t = interleaved({"checked (default)": run("checked"), "crlb": run("crlb")}, passes)
    d = out["checked"].to_dict()
    return {"columns": summary(t, "s"), "checked_cpu_s": median(t, "checked (default)"),
            "checked_wall_s": median(t, "checked (default)", "wall"), "crlb_cpu_s": median(t, "crlb"),
            "checked_over_crlb_cpu": ratio(t, "checked (default)", "crlb"), "crlb_rms_deg": d["crlb_rms_deg"],
            "method": d["method"], "meets": (d.get("detection") or {}).get("meets"),
            "stages_wall_s": out["checked"].timing}


#: the commands of the target and of the default criterion, as the CLI runs them
COMMANDS = {"crlb, reachable": ["design", "--optimize", "--K", "6", "--criterion", "crlb", "--region", "reachable",
                                "--bounds", "-2000", "2000", "450", "2000"],
            "checked (default)": ["design", "--optimize", "--K", "6"]}


#: the baseline of ``--baseline``: the commit before the design's time was cut (its package run with this
#: interpreter and these libraries)
DESIGN_BASELINE = "e77060d"


def cli_commands(passes, baseline=None):
    """The commands of :data:`COMMANDS`, each a fresh process, interleaved: CPU (user + system) and wall; with
    ``baseline`` (a commit) each also with that commit's package (``git archive`` of ``zerocal_sym`` first on
    ``PYTHONPATH``), and the ratio of their CPU times in the same pass."""
    import os
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    # -P: the working folder not first on sys.path (the package is the installed one, or PYTHONPATH's)
    cmds = {k: [sys.executable, "-P", "-m", "zerocal_sym"] + v for k, v in COMMANDS.items()}
    with tempfile.TemporaryDirectory(prefix="bench-design-") as tmp:
        if baseline:
            arch = subprocess.run(["git", "-C", str(root), "archive", baseline, "zerocal_sym"], capture_output=True)
            if arch.returncode != 0:
                raise SystemExit(f"git archive {baseline}: {arch.stderr.decode().strip()}")
            subprocess.run(["tar", "-x", "-C", tmp], input=arch.stdout, check=True)
            for k, v in COMMANDS.items():
                cmds[f"{k} @{baseline}"] = ["env", f"PYTHONPATH={tmp}", sys.executable, "-P", "-m", "zerocal_sym"] + v
        env_py = os.environ.pop("PYTHONPATH", None)
        try:
            t = commands(cmds, passes, warmup=True, cwd=str(root))
        finally:
            if env_py is not None:
                os.environ["PYTHONPATH"] = env_py
    out = {"columns": summary(t, "s"), "argv": {k: "zerocal " + " ".join(v) for k, v in COMMANDS.items()}}
    if baseline:
        out["baseline"] = baseline
        out["over_baseline_cpu"] = {k: ratio(t, k, f"{k} @{baseline}") for k in COMMANDS}
    return out


def tier_state():
    """What the compiled tier did in this process (the design's Functions: loaded, built, or interpreted)."""
    import os

    from zerocal_sym.model import compiled

    return {"ZEROCAL_COMPILE": os.environ.get("ZEROCAL_COMPILE", "auto"),
            "design_events": [e for _, k, e in compiled.status() if k.startswith("design-")]}


def table(a):
    from zerocal_sym import design
    from zerocal_sym.design import nlp as design_nlp
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.robot import paper_robot

    robot = paper_robot()
    noise = NoiseModel.paper()
    cons = design.make_constraints(robot)
    design.pose_terms(robot, robot.workspace_grid(3, 3))  # warm the CasADi function cache
    rows = []
    for K in a.K:
        base = design.paper_baseline(robot, K)
        for crit in a.criteria:
            out = {}

            def one_ipopt():
                fs, ms = design_nlp._scales(robot, base, noise)
                design_nlp._NLP(robot, K, crit, cons, noise, fs, ms).solve(base)
                return 1

            def exchange():
                design.exchange_design(robot, K, crit, cons, noise, 0, a.starts)
                return 1

            def full():
                out["res"] = design.optimize_design(robot, K, crit, cons, noise, seed=0, n_starts=a.starts,
                                                    exchange_starts=a.starts)
                return 1

            t = interleaved({"design": full, "1 Ipopt start": one_ipopt, "exchange": exchange}, a.passes)
            d = out["res"].to_dict()
            rows.append({"K": K, "criterion": crit, "columns": summary(t, "s"),
                         "design_over_one_ipopt_cpu": ratio(t, "design", "1 Ipopt start"),
                         "design_over_exchange_cpu": ratio(t, "design", "exchange"),
                         "stages_wall_s": out["res"].timing, "value": d["criterion"]["value"],
                         "paper_value": d["paper"]["criterion"]["value"],
                         "crlb_ratio": d["ratio"]["crlb_rms_design_over_paper"]})
    return rows


def extras():
    from pathlib import Path

    from zerocal_sym import design
    from zerocal_sym.design import approx
    from zerocal_sym.model.noise import NoiseModel
    from zerocal_sym.model.robot import load_robot, paper_robot

    robot, noise = paper_robot(), NoiseModel.paper()
    out = []

    def timed(label, fn):
        c, w = time.process_time(), time.perf_counter()
        info = fn()
        out.append({"case": label, "cpu_s": time.process_time() - c, "wall_s": time.perf_counter() - w, **info})

    delta = load_robot(Path(__file__).resolve().parents[1] / "examples" / "delta.toml")
    for label, rob in (("paper", robot), ("delta", delta)):
        for crit in ("crlb", "D"):
            def run(rob=rob, crit=crit):
                d = design.optimize_design(rob, 100, crit, None, noise, seed=0).to_dict()
                return {"method": d["method"], "value": d["criterion"]["value"], "bound": d["certificate"]["bound"],
                        "efficiency_lower_bound": d["certificate"]["efficiency_lower_bound"]}
            timed(f"K = 100, {label}, {crit}", run)
    timed("--target-crlb 0.04 (paper workspace)",
          lambda: {k: v for k, v in approx.fewest_poses(robot, 0.04, design.make_constraints(robot), noise).items()
                   if k in ("K", "K_lower_bound", "crlb_rms_deg")})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--passes", "--repeat", dest="passes", type=int, default=3, help="interleaved passes (default 3)")
    ap.add_argument("--K", type=int, nargs="+", default=[6, 20])
    ap.add_argument("--criteria", nargs="+", default=["crlb", "cond"])
    ap.add_argument("--starts", type=int, default=8)
    ap.add_argument("--only-extras", dest="only_extras", action="store_true",
                    help="only the reachable case and the extra cases")
    ap.add_argument("--no-extras", dest="no_extras", action="store_true",
                    help="skip the extra cases (K = 100, fewest poses)")
    ap.add_argument("--no-commands", action="store_true", help="skip the commands run as fresh processes")
    ap.add_argument("--baseline", default=DESIGN_BASELINE,
                    help=f"commit whose package runs the commands too (default {DESIGN_BASELINE}; '' for none)")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    a = ap.parse_args()
    res = {"load_before": load(), "passes": a.passes}
    res["reachable_K6"] = reachable(a.passes)
    res["default_K6"] = default_checked(a.passes)
    if not a.no_commands:
        res["commands"] = cli_commands(a.passes, a.baseline or None)
    if not a.only_extras:
        res["table"] = table(a)
    if not a.no_extras:
        res["extras"] = extras()
    res["compiled_tier"] = tier_state()
    res["load_after"] = load()
    if emit(res, a.json):
        return
    r = res["reachable_K6"]
    print(f"columns interleaved, {a.passes} passes; CPU time (this process), wall time in brackets")
    print(f"reachable region, y >= 450 mm, K = 6, crlb: design {r['design_cpu_s']:.2f} s CPU ({r['design_wall_s']:.2f} s "
          f"wall; target < {TARGET_CPU_S} s CPU: {'met' if r['met'] else 'NOT met'}), {r['design_over_one_ipopt_cpu']:.1f} "
          f"x one Ipopt start; region {r['region_cpu_s']:.2f} s CPU (outside); CRLB {r['crlb_rms_deg']:.5f} deg "
          f"per offset {[round(v, 5) for v in r['crlb_zero_offsets_deg']]}; baseline {r['baseline_scheme']} "
          f"{r['baseline_crlb_rms_deg']:.4f}; certified bound {r['certificate_bound_deg']:.5f}, efficiency >= "
          f"{r['efficiency_lower_bound']:.3f}; bias worst/RMS {r['bias_worst_deg']:.4f}/{r['bias_rms_deg']:.4f} deg; "
          f"rho span {r['rho_span_mm']:.1f} mm; {r['method']})")
    print("  poses (mm): " + "; ".join(f"({x:.1f}, {y:.1f})" for x, y in r["poses_mm"]))
    print("  stages, CPU s: " + ", ".join(f"{k} {v:.3f}" if isinstance(v, float) else f"{k} {v}"
                                          for k, v in r["stages_cpu_s"].items()))
    dft = res["default_K6"]
    print(f"workspace, K = 6, checked (the default): {dft['checked_cpu_s']:.2f} s CPU ({dft['checked_wall_s']:.2f} s "
          f"wall), {dft['checked_over_crlb_cpu']:.2f} x the crlb design ({dft['crlb_cpu_s']:.2f} s CPU); CRLB "
          f"{dft['crlb_rms_deg']:.5f} deg; {dft['method']}; fit check meets the requirement: {dft['meets']}")
    cm = res.get("commands", {})
    for name, argv in cm.get("argv", {}).items():
        c = cm["columns"][name]
        line = f"  `{argv}` (a fresh process): {c['cpu_s']:.2f} s CPU ({c['wall_s']:.2f} s wall)"
        if cm.get("baseline"):
            b = cm["columns"][f"{name} @{cm['baseline']}"]
            line += (f"; at {cm['baseline']} {b['cpu_s']:.2f} s CPU ({b['wall_s']:.2f} s wall): "
                     f"{cm['over_baseline_cpu'][name]:.2f} x in CPU")
        print(line)
    for row in res.get("table", []):
        c = row["columns"]
        print(f"K = {row['K']:3d} {row['criterion']:>5s}: design {c['design']['cpu_s']:.2f} s CPU "
              f"({c['design']['wall_s']:.2f}), 1 Ipopt start {c['1 Ipopt start']['cpu_s']:.3f} "
              f"({c['1 Ipopt start']['wall_s']:.3f}), exchange {c['exchange']['cpu_s']:.2f} "
              f"({c['exchange']['wall_s']:.2f}); design / 1 Ipopt {row['design_over_one_ipopt_cpu']:.1f} x, / exchange "
              f"{row['design_over_exchange_cpu']:.1f} x; value {row['value']:.4g} (paper {row['paper_value']:.4g}), "
              f"CRLB ratio {row['crlb_ratio']:.4f}")
    for e in res.get("extras", []):
        rest = ", ".join(f"{k} {v:.5g}" if isinstance(v, float) else f"{k} {v}"
                         for k, v in e.items() if k not in ("case", "cpu_s", "wall_s"))
        print(f"{e['case']}: {e['cpu_s']:.2f} s CPU ({e['wall_s']:.2f} s wall); {rest}")
    tier = res["compiled_tier"]
    print(f"compiled tier (ZEROCAL_COMPILE={tier['ZEROCAL_COMPILE']}): "
          + ("; ".join(tier["design_events"]) or "the design's Functions interpreted"))
    print(load_line(res["load_before"], res["load_after"]))


if __name__ == "__main__":
    main()
