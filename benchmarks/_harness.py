"""Shared timing helpers of the benchmark scripts (imported from the script's own folder)."""
import statistics
import subprocess
import time


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
