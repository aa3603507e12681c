"""Shared timing of the benchmark scripts (imported from the script's own folder).

The machines these run on are shared: a wall-clock time measures the other
processes as much as the code, and two columns timed one after the other see
different loads.  So every benchmark

* **interleaves** the columns it compares (:func:`interleaved`,
  :func:`commands`): each pass runs every column once, in an order that
  rotates from pass to pass, so a change of load hits all columns alike;
* reports **CPU time** (this process's, ``time.process_time``; a command's
  or a worker's from ``getrusage(RUSAGE_CHILDREN)``) beside wall time, and
  takes its ratios from the CPU times of the same pass (:func:`ratio`: the
  median over the passes of the per-pass ratio);
* prints the **load average** (:func:`load`) with the figures, and takes
  ``--json`` (:func:`emit`).

CPU time is not free of the load either (a process that shares a core with
others runs slower per instruction: caches, hyper-threads), which is why the
ratios, not the absolute times, carry the targets.
"""
from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import time


def load() -> dict:
    """The load average (1, 5, 15 min) and the number of CPUs."""
    one, five, fifteen = os.getloadavg()
    return {"load_1min": one, "load_5min": five, "load_15min": fifteen, "cpus": os.cpu_count()}


def load_line(before=None, after=None) -> str:
    """``load average 2.31 (before) -> 2.95 (after) on 2 CPUs`` (or the load now)."""
    now = load()
    if before is None:
        return f"load average {now['load_1min']:.2f} {now['load_5min']:.2f} {now['load_15min']:.2f} on {now['cpus']} CPUs"
    after = after or now
    return (f"load average {before['load_1min']:.2f} before, {after['load_1min']:.2f} after "
            f"(5 min: {after['load_5min']:.2f}) on {now['cpus']} CPUs")


def cpu_self() -> float:
    """CPU seconds (user + system) of this process."""
    return time.process_time()


def cpu_children() -> float:
    """CPU seconds (user + system) of this process's waited-for children (commands, worker processes)."""
    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ch.ru_utime + ch.ru_stime


def cpu_all() -> float:
    """CPU seconds of this process and of its waited-for children."""
    return cpu_self() + cpu_children()


def interleaved(columns: dict, passes: int, warmup: bool = True, clock=cpu_self) -> dict:
    """Time the columns interleaved: each pass runs every column once, the order rotating from pass to pass.

    Parameters
    ----------
    columns : dict name -> callable
        ``fn()`` does the column's work once and returns how many items it did (identifications, trials);
        times are per item.
    passes : int
    warmup : bool
        Run every column once before timing (builds, caches).
    clock : callable
        The CPU clock (default this process's; :func:`cpu_all` when the work runs in child processes).

    Returns
    -------
    dict name -> {"cpu": [s per item, one per pass], "wall": [...], "items": n}
    """
    names = list(columns)
    out = {n: {"cpu": [], "wall": [], "items": 0} for n in names}
    if warmup:
        for n in names:
            columns[n]()
    for k in range(passes):
        order = names[k % len(names):] + names[:k % len(names)]
        for n in order:
            c, w = clock(), time.perf_counter()
            items = columns[n]()
            w, c = time.perf_counter() - w, clock() - c
            out[n]["cpu"].append(c / items)
            out[n]["wall"].append(w / items)
            out[n]["items"] = items
    return out


def commands(cmds: dict, passes: int, warmup: bool = False, **run_kw) -> dict:
    """Whole commands, interleaved as :func:`interleaved`: wall and CPU (the child's, user + system) per run.

    ``cmds``: name -> argv.  Each must succeed (``check=True``).
    """
    def runner(argv):
        def run():
            subprocess.run(argv, check=True, capture_output=True, **run_kw)
            return 1
        return run

    return interleaved({n: runner(a) for n, a in cmds.items()}, passes, warmup, clock=cpu_children)


def median(times: dict, name: str, kind: str = "cpu") -> float:
    """The median over the passes of a column's time per item (s)."""
    return statistics.median(times[name][kind])


def ratio(times: dict, num: str, den: str, kind: str = "cpu") -> float:
    """``num / den``: the median over the passes of the ratio of the two columns' times in the same pass."""
    return statistics.median(a / b for a, b in zip(times[num][kind], times[den][kind]))


def spread(times: dict, num: str, den: str, kind: str = "cpu") -> tuple:
    """The smallest and largest per-pass ratio ``num / den`` (how much the load moved it)."""
    r = [a / b for a, b in zip(times[num][kind], times[den][kind])]
    return min(r), max(r)


def summary(times: dict, unit: str = "ms") -> dict:
    """Per column the medians of CPU and wall time per item (``cpu_ms``, ``wall_ms``; or ``unit`` "s") and the
    passes: JSON-ready."""
    k = {"ms": 1e3, "s": 1.0}[unit]
    return {n: {f"cpu_{unit}": k * median(times, n, "cpu"), f"wall_{unit}": k * median(times, n, "wall"),
                "passes": len(t["cpu"]), "items_per_pass": t["items"]} for n, t in times.items()}


def wall(cmd, repeat):
    """Wall time of a whole command, run ``repeat`` times.

    Returns
    -------
    (median, min) : tuple of float, seconds
    """
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return statistics.median(times), min(times)


def emit(result: dict, as_json: bool) -> bool:
    """Print ``result`` as JSON when asked (returns True: the caller prints nothing else)."""
    if as_json:
        print(json.dumps(result, indent=2, default=float))
    return as_json
