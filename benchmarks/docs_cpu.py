"""The docs checker's cost: CPU seconds of every command it runs, its fast items (per page) and its slow ones.

The checker (tests/docs_check.py, tests/test_docs_commands.py) runs every command README.md and docs/*.md show;
CI runs it twice (newest and oldest dependency versions) on 2 cores.  This script runs the same items the same
way (one scratch directory per page for the fast items, one run per slow command whichever pages show it) and
prints, per page and per slow item, the CPU seconds of the commands' processes (user + system, bash's ``times``)
beside the wall time, and whether the page agrees with what its commands print.  The load average is printed:
wall times on a shared machine are not the commands' cost, CPU times are.

Usage: python benchmarks/docs_cpu.py [--fast | --slow] [--top N] [PAGE ...]
       (PAGE: README.md or docs/NAME.md; default every page)
"""
import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import docs_check as dc  # noqa: E402


def _cpu(directory: Path) -> float:
    return sum(dc.cpu_seconds(directory)) if (directory / ".docs-check").exists() else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pages", nargs="*", metavar="PAGE", help="pages to run (default: every page)")
    group = ap.add_mutually_exclusive_group()
    group.add_argument("--fast", action="store_true", help="only the fast items")
    group.add_argument("--slow", action="store_true", help="only the slow items")
    ap.add_argument("--top", type=int, default=12, metavar="N", help="list the N costliest fast commands (default 12)")
    a = ap.parse_args()
    pages = {dc._rel(p): p for p in dc.PAGES}
    unknown = [n for n in a.pages if n not in pages]
    if unknown:
        ap.error(f"unknown page(s) {', '.join(unknown)}: the pages are {', '.join(pages)}")
    parsed = {n: dc.parse_page(pages[n]) for n in (a.pages or pages)}
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} CPUs; "
          f"ZEROCAL_COMPILE={dc.environment()['ZEROCAL_COMPILE']}", flush=True)
    problems, fast_cpu, slow_cpu, costly = [], 0.0, 0.0, []
    with tempfile.TemporaryDirectory() as tmp:
        cache = dc.SharedCache(Path(tmp))
        if not a.slow:
            print(f"\n{'fast items of':40s} {'cmds':>5s} {'CPU s':>8s} {'wall s':>8s}  result")
            for name, page in parsed.items():
                cmds = sum(len(it.commands) for it in page.items if not it.slow)
                if not cmds:
                    continue
                before = set(Path(tmp).glob("cmd-*"))
                t = time.perf_counter()
                directory, found = cache.page(page)
                new = set(Path(tmp).glob("cmd-*")) - before  # checks another page shows too: a run of their own
                wall, cpu = time.perf_counter() - t, _cpu(directory) + sum(_cpu(d) for d in new if d.is_dir())
                fast_cpu += cpu
                problems += found
                print(f"{name:40s} {cmds:5d} {cpu:8.1f} {wall:8.1f}  {'ok' if not found else f'{len(found)} differ'}",
                      flush=True)
                costly += [(s, name, text) for s, text in zip(dc.cpu_seconds(directory),
                                                             dc.fast_commands(page, cache.shared)[0])]
            print(f"{'fast items, total':40s} {'':5s} {fast_cpu:8.1f}")
        if not a.fast:
            print(f"\n{'slow item':72s} {'CPU s':>8s} {'wall s':>8s}  result")
            runs = {}
            for name, page in parsed.items():
                for k, it in enumerate(page.items):
                    if not it.slow:
                        continue
                    before = set(Path(tmp).glob("cmd-*")) | set(Path(tmp).glob("item-*"))
                    t = time.perf_counter()
                    found = dc.judge_item(it, cache.slow_results(page, k))
                    wall = time.perf_counter() - t
                    new = (set(Path(tmp).glob("cmd-*")) | set(Path(tmp).glob("item-*"))) - before
                    cpu = sum(_cpu(d) for d in new if d.is_dir())
                    slow_cpu += cpu
                    problems += found
                    label = f"{it.where} {it.commands[0].text}"[:72]
                    shared = "" if new or not it.commands else " (run before)"
                    runs[label] = cpu
                    print(f"{label:72s} {cpu:8.1f} {wall:8.1f}  {'ok' if not found else 'differs'}{shared}",
                          flush=True)
            print(f"{'slow items, total':72s} {slow_cpu:8.1f}")
    if costly:
        print(f"\nthe {a.top} costliest fast commands (CPU s, page, command):")
        for s, name, text in sorted(costly, reverse=True)[:a.top]:
            print(f"{s:7.1f}  {name:24s} {text[:100]}")
    if problems:
        print(f"\n{len(problems)} difference(s):\n" + "\n".join(problems))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
