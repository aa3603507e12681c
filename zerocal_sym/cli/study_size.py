"""What a study needs of the machine, checked before any work.

:func:`check_spec` (called by :func:`~zerocal_sym.cli.study_spec.load_spec`
once the cells are built) refuses, naming the spec's line:

* more than :data:`MAX_CHUNKS` chunk files per cell (``ceil(trials / chunk)``);
* a study whose summary would not fit in memory: summarising a cell holds the
  errors of all its trials (``trials x p`` numbers, :data:`SUMMARY_COPIES`
  copies at the quantiles);
* a chunk whose identification would not fit in memory: the readings
  (``chunk x K`` numbers) and the batched Gauss-Newton of
  ``min(chunk, CHUNK)`` data sets of K poses (:data:`BYTES_PER_POSE` for the
  problem, :data:`BYTES_PER_POSE_TRIAL` per data set and pose;
  :mod:`zerocal_sym.identify.batch`).

"In memory": at most :data:`MEMORY_SHARE` of the machine's
(:func:`machine_memory`: physical memory, or the container's limit if lower;
not checked where neither is known).  The poses of a ``[[design]]`` are capped
where the spec is read, as ``--n`` (:data:`~zerocal_sym.cli._checks.MAX_N`).
:func:`check_disk` (the runner, before it writes anything) refuses chunk
files that would not fit in the free space of the output directory.
"""
from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

from zerocal_sym.errors import ZerocalError

#: chunk files per cell at most (a directory of more is no longer a set of files one looks after)
MAX_CHUNKS = 100_000
#: the summary of a cell holds its errors this many times over (the samples, their concatenation, the sort)
SUMMARY_COPIES = 3
#: memory of the batched Gauss-Newton problem per pose, and per data set and pose (bytes; upper bounds of the
#: growth of the peak resident memory tests/test_study_size.py measures in identify_batch)
BYTES_PER_POSE = 8192
BYTES_PER_POSE_TRIAL = 2048
#: a study may use at most this share of the machine's memory
MEMORY_SHARE = 0.5


def machine_memory():
    """Bytes of memory this process may use: the physical memory, or the cgroup's limit if lower; None if
    neither is known."""
    sizes = []
    try:
        sizes.append(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        pass
    for f in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(f).read_text().strip()
        except OSError:
            continue
        if text.isdigit():
            sizes.append(int(text))
    sizes = [s for s in sizes if s > 0]
    return min(sizes) if sizes else None


def _gb(n) -> str:
    return f"{n / 2**30:.3g} GB"


def chunk_bytes(K: int, chunk: int) -> int:
    """Memory to identify one chunk of ``chunk`` trials of K poses (bytes)."""
    from zerocal_sym.identify.batch import CHUNK

    return K * (BYTES_PER_POSE + min(chunk, CHUNK) * BYTES_PER_POSE_TRIAL + 2 * 8 * chunk)


def check_spec(study, where, error=ZerocalError, memory=None) -> None:
    """Refuse a study this machine cannot hold (module docstring); ``where(key)`` names the spec's line.

    ``memory``: bytes available (default :func:`machine_memory`).
    """
    at_chunk = where("chunk") if where("chunk") != where() else where("trials")  # chunk's default: from trials
    chunks = math.ceil(study.trials / study.chunk)
    if chunks > MAX_CHUNKS:
        raise error(f"trials = {study.trials} in chunks of {study.chunk}: {chunks} chunk files per cell, at most "
                    f"{MAX_CHUNKS} (a larger chunk, or fewer trials)", where=at_chunk)
    memory = machine_memory() if memory is None else memory
    if not memory:
        return
    budget = MEMORY_SHARE * memory
    p = max(len(c.params) for c in study.cells)
    need = SUMMARY_COPIES * 8 * p * study.trials
    if need > budget:
        most = int(budget // (SUMMARY_COPIES * 8 * p))
        raise error(f"trials = {study.trials}: the summary of a cell holds the errors of all its trials ({p} "
                    f"parameters: about {_gb(need)}), more than {MEMORY_SHARE:.0%} of this machine's "
                    f"{_gb(memory)}; at most {most} trials per cell here", where=where("trials"))
    K = max(c.poses.shape[0] for c in study.cells)
    need = chunk_bytes(K, study.chunk)
    if need > budget:
        most = (f"at most {_largest_chunk(K, budget)} trials per chunk here" if chunk_bytes(K, 1) <= budget else
                f"not even one trial of {K} poses fits")
        raise error(f"chunk = {study.chunk}: identifying a chunk of a cell of {K} poses needs about {_gb(need)}, "
                    f"more than {MEMORY_SHARE:.0%} of this machine's {_gb(memory)}; {most}", where=at_chunk)


def _largest_chunk(K: int, budget: float) -> int:
    """The largest chunk whose identification fits in ``budget`` bytes (bisection on :func:`chunk_bytes`)."""
    lo, hi = 1, 2
    while chunk_bytes(K, hi) <= budget:
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if chunk_bytes(K, mid) <= budget else (lo, mid)
    return lo


def chunk_file_bytes(p: int, trials: int) -> int:
    """Bytes of a chunk file of ``trials`` trials of ``p`` parameters (its columns; npz adds about 1 KB)."""
    return trials * (2 * p + 4) * 8 + 1024


def check_disk(todo, out) -> None:
    """Refuse chunk files ``todo`` (``[(cell, k, start, stop)]``) that would not fit in the free space of ``out``."""
    need = sum(chunk_file_bytes(len(cell.params), b - a) for cell, _, a, b in todo)
    d = Path(out).resolve()
    while not d.exists() and d != d.parent:
        d = d.parent
    try:
        free = shutil.disk_usage(d).free
    except OSError:
        return
    if need > free:
        raise ZerocalError(f"the {len(todo)} chunk files to write need about {_gb(need)}, the disk has {_gb(free)} "
                           "free", where=str(out))
