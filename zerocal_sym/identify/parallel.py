"""Monte Carlo beyond one process: chunks of trials, local processes or a Dask cluster.

A Monte Carlo run is a list of *chunks* (consecutive trials of one study
cell); each chunk is a picklable task that a worker turns into a picklable
result.  The random stream of a trial is ``SeedSequence([seed, stream,
trial])``: it depends on the trial's index, never on which chunk or worker
ran it.  Chunk boundaries depend only on the number of trials and the chunk
size (never on the number of workers), and results are merged in chunk
order, so a run gives bit-identical numbers on 1 process, N processes or a
cluster.

Execution (:func:`run_chunks`)
    ``workers=1`` (default): in this process, one chunk after the other;
    ``workers=N``: N local processes (``concurrent.futures`` with the
    ``spawn`` start method: no fork of a threaded process); ``scheduler``: a
    Dask cluster (``"tcp://host:8786"`` or a ``dask.distributed.Client``;
    ``pip install 'zerocal_sym[cluster]'``).  Results come back to this
    process, which merges them (and the study runner writes them): workers
    need the package, not a shared file system.

Interruption
    Ctrl-C (``KeyboardInterrupt``, also raised by a progress callback) stops
    within a second: pending chunks are cancelled, local worker processes
    (which ignore SIGINT) are terminated, a Dask client we opened is closed,
    and the exception propagates.  Nothing is merged or written after it.
    Local workers are started with SIGINT blocked (inherited from this
    process) and a Ctrl-C is held while they are started, so one to the
    process group then does not kill them half-initialised; it is raised
    right after (:func:`_sigint_deferred`).

This module holds the chunks (:func:`chunk_ranges`, :func:`trial_rng`) and
their execution (a Dask cluster's side in :mod:`zerocal_sym.identify.dask_cluster`).  The mergeable statistics of the results are in
:mod:`zerocal_sym.identify.stats`, the progress display in
:mod:`zerocal_sym.identify.progress`, the one-shot trials (the design
verification and the study runner) in :mod:`zerocal_sym.identify.one_shot`.
"""
from __future__ import annotations

import contextlib
import math
import pickle
import signal
import threading
import time

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.identify.dask_cluster import run_dask, scheduler_timeout
# kept importable from here (zerocal_sym/identify/montecarlo.py imports them from this module)
from zerocal_sym.identify.progress import Progress  # noqa: F401
from zerocal_sym.identify.stats import Stats  # noqa: F401



# --------------------------------------------------------------------------- options

def check_execution(workers=1, scheduler=None) -> int:
    """Validate ``workers``/``scheduler``; returns the number of local workers.

    Raises
    ------
    ZerocalError
        ``workers`` < 1 or not an integer, or ``workers`` > 1 together with a scheduler, or a
        scheduler address with a bad ``$ZEROCAL_SCHEDULER_TIMEOUT``.
    """
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ZerocalError(f"--workers must be a positive integer, got {workers!r}")
    if scheduler is not None and workers != 1:
        raise ZerocalError("give --workers N (local processes) or --scheduler ADDRESS (a Dask cluster), not both")
    if isinstance(scheduler, str):
        scheduler_timeout()  # a bad $ZEROCAL_SCHEDULER_TIMEOUT before any work
    return int(workers)


def default_chunk(trials: int, cap: int = 25) -> int:
    """Trials per chunk when none is given: at most ``cap``, about 8 chunks for small runs.

    Depends only on ``trials`` (never on the workers), so results do not depend on how they are run.
    """
    return max(1, min(int(cap), math.ceil(int(trials) / 8)))


def chunk_ranges(trials: int, chunk: int):
    """``[(a, b), ...]``: consecutive trial ranges of at most ``chunk`` trials."""
    if chunk < 1:
        raise ZerocalError(f"the chunk size must be >= 1, got {chunk}")
    return [(a, min(a + chunk, trials)) for a in range(0, trials, chunk)]


def trial_rng(seed: int, stream: int, trial: int) -> np.random.Generator:
    """The random generator of one trial: ``SeedSequence([seed, stream, trial])``."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(stream), int(trial)]))


# --------------------------------------------------------------------------- execution

def _worker_init():  # pragma: no cover - runs in the worker processes
    # Ctrl-C goes to the whole process group: the parent decides (it terminates us).  SIGINT has been
    # blocked since the process started (inherited, _sigint_deferred); ignoring it discards one that is
    # pending, so it can be unblocked now.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    _die_with_parent()


#: prctl's option that has the kernel signal a process when its parent ends (Linux, <sys/prctl.h>)
PR_SET_PDEATHSIG = 1


def _die_with_parent():  # pragma: no cover - runs in the worker processes
    """End this worker when the process that started it ends, however it ends (SIGKILL included).

    A worker waits for its next chunk on a pipe that it holds both ends of
    (the ``spawn`` start method hands each worker the whole call queue), so
    it never sees the parent go: after ``kill -9`` of the command, the
    workers (and the resource tracker, which waits for everyone holding its
    pipe) lived on.  On Linux the kernel sends this process SIGKILL when the
    parent ends (``prctl(PR_SET_PDEATHSIG)``); elsewhere a thread waits on
    the parent's sentinel (a pipe that closes when the parent ends) and
    exits.  A parent that ended before this ran is noticed at once.
    """
    import multiprocessing
    import os
    import sys

    parent = multiprocessing.parent_process()
    if parent is None:
        return
    armed = False
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError, TypeError):
            armed = False
    if os.getppid() != parent.pid:  # the parent is gone already (the signal only comes for a later end)
        os._exit(1)
    if not armed and parent.sentinel is not None:
        def watch():
            multiprocessing.connection.wait([parent.sentinel])
            os._exit(1)

        threading.Thread(target=watch, name="zerocal-parent-watch", daemon=True).start()


@contextlib.contextmanager
def _sigint_deferred():
    """A Ctrl-C while the pool's worker processes are started is held until they are.

    SIGINT is blocked in this (the main) thread: a child inherits the mask
    through fork/exec, so a Ctrl-C (sent to the whole process group) while a
    worker's interpreter is still starting, before its initializer ignores
    SIGINT, stays pending instead of killing it with a ``Fatal Python error:
    init_import_site`` traceback.  Other threads of this process (OpenBLAS's,
    the CLI's) still take the signal, so the Python handler is replaced by one
    that only notes it: the spawn is not interrupted half-way (the worker
    then died on ``EOFError`` reading what it was to run).  On exit the mask
    and the handler are restored and a noted Ctrl-C is raised again, to the
    restored handler (a ``KeyboardInterrupt`` as usual).  Only in the main
    thread (the mask is per thread; Python handles signals there).
    """
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    noted = []
    handler = signal.getsignal(signal.SIGINT)  # None: not set from Python, cannot be put back
    if handler is not None:
        signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        try:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)  # one pending for this thread: noted now
        finally:
            if handler is not None:
                signal.signal(signal.SIGINT, handler)
        if noted:
            signal.raise_signal(signal.SIGINT)


def _picklable(fn, tasks):
    try:
        pickle.dumps((fn, tasks[:1]))
    except Exception as exc:  # noqa: BLE001 - a lambda report, an open file, ...
        raise ZerocalError(f"the Monte Carlo task cannot be sent to another process ({exc}); "
                           "run with workers=1") from None


def run_chunks(fn, tasks, sizes=None, workers: int = 1, scheduler=None, progress=None, on_result=None):
    """Run ``fn(task)`` for every task; results in task order.

    Parameters
    ----------
    fn : callable
        A module-level function (pickled by reference for other processes).
    tasks : sequence
        Picklable tasks.
    sizes : sequence of int, optional
        Trials per task, for ``progress`` (default 1 each).
    workers : int
        Local processes (1: in this process).
    scheduler : str or dask.distributed.Client, optional
        A Dask cluster instead of local processes.
    progress : callable, optional
        ``progress(done)`` with the trials done so far, after each chunk (in this process).
    on_result : callable, optional
        ``on_result(index, result)`` as each chunk completes (in this process,
        completion order); its return value replaces the result (e.g. None
        after writing it out, to keep memory flat).

    Returns
    -------
    list
        One entry per task, in task order.

    Raises
    ------
    KeyboardInterrupt
        After cancelling what is pending and stopping the workers.
    ZerocalError
        Bad ``workers``, dask missing, a scheduler that cannot be reached.
    """
    workers = check_execution(workers, scheduler)
    tasks = list(tasks)
    sizes = [1] * len(tasks) if sizes is None else [int(s) for s in sizes]
    out = [None] * len(tasks)
    state = {"done": 0}

    def finished(i, res):
        out[i] = on_result(i, res) if on_result is not None else res
        state["done"] += sizes[i]
        if progress is not None:
            progress(state["done"])

    if not tasks:
        return out
    if scheduler is not None:
        run_dask(fn, tasks, scheduler, finished)
    elif workers == 1 or len(tasks) == 1:
        for i, t in enumerate(tasks):
            finished(i, fn(t))
    else:
        _picklable(fn, tasks)
        _run_processes(fn, tasks, min(workers, len(tasks)), finished)
    return out


def _run_processes(fn, tasks, workers, finished):
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_init)
    futs = {}
    ok = False
    try:
        with _sigint_deferred():  # Python 3.11 starts the spawn pool's processes in submit, in this thread
            for i, t in enumerate(tasks):
                futs[pool.submit(fn, t)] = i
        pending = set(futs)
        while pending:
            done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            for f in sorted(done, key=futs.get):
                finished(futs[f], f.result())
        ok = True
    finally:
        if ok:
            pool.shutdown(wait=True)
        else:
            _stop_pool(pool, futs)


def _stop_pool(pool, futs):
    """Terminate the worker processes, then shut down without waiting for work.

    Nothing is cancelled before the pool's manager thread has seen the
    terminated workers: it then fails every pending future itself
    (``BrokenProcessPool``) and ends.  Python 3.11's manager raises
    ``InvalidStateError`` (a traceback printed from its thread) on a future
    cancelled while it does so; cancelling first hit that race in 3 of 20
    interrupts of ``compare`` (one run).
    """
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for p in procs:
        if p.is_alive():
            p.terminate()
    manager = getattr(pool, "_executor_manager_thread", None)
    if procs and manager is not None:
        _join_started(manager, 2.0)  # milliseconds when idle; bounded on a loaded machine
    for f in futs:
        f.cancel()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in list((getattr(pool, "_processes", None) or {}).values()):  # one started since the snapshot
        if p not in procs:
            procs.append(p)
            p.terminate()
    deadline = time.monotonic() + 0.5
    for p in procs:
        p.join(max(0.0, deadline - time.monotonic()))
    for p in procs:  # still there (stuck in a system call): SIGKILL
        if p.is_alive():
            p.kill()
            p.join(0.5)


def _join_started(thread, timeout):
    """``thread.join(timeout)``, also when a Ctrl-C interrupted its ``start()`` (``submit`` starts the
    manager thread and waits until it runs): the thread then comes up a moment later, and joining it
    before that raised ``RuntimeError: cannot join thread before it is started``."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            thread.join(max(0.0, deadline - time.monotonic()))
            return
        except RuntimeError:  # not started (yet)
            if time.monotonic() >= deadline:
                return
            time.sleep(0.005)
