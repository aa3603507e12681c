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

Statistics (:class:`Stats`)
    Per quantity: count, sum, sum of squares and the samples themselves (for
    quantiles); merging two is addition and concatenation.

One-shot trials (:func:`one_shot_chunk`, :func:`one_shot_monte_carlo`)
    Simulate a chunk's scale readings at fixed commanded joints and identify
    them in one :func:`~zerocal_sym.identify.batch.identify_batch` call (the
    design verification and the study runner).
"""
from __future__ import annotations

import math
import os
import pickle
import signal
import sys
import time
from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import ZerocalError

#: seconds to wait for a Dask scheduler (override: ZEROCAL_SCHEDULER_TIMEOUT)
SCHEDULER_TIMEOUT_S = 10.0
#: quantiles reported (5 %, median, 95 %)
QUANTILES = {"q05": 0.05, "median": 0.5, "q95": 0.95}


# --------------------------------------------------------------------------- options

def check_execution(workers=1, scheduler=None) -> int:
    """Validate ``workers``/``scheduler``; returns the number of local workers.

    Raises
    ------
    ZerocalError
        ``workers`` < 1 or not an integer, or ``workers`` > 1 together with a scheduler.
    """
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ZerocalError(f"--workers must be a positive integer, got {workers!r}")
    if scheduler is not None and workers != 1:
        raise ZerocalError("give --workers N (local processes) or --scheduler ADDRESS (a Dask cluster), not both")
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


# --------------------------------------------------------------------------- statistics

class Stats:
    """Mergeable statistics of row vectors of width ``w``.

    ``count``, ``sum`` (w,), ``sumsq`` (w,) and the samples (for quantiles);
    :meth:`merge` adds and concatenates, so statistics of chunks combine into
    those of the whole run.  Merged in the same order, the same chunks give
    bit-identical results.
    """

    __slots__ = ("width", "count", "sum", "sumsq", "parts", "keep")

    def __init__(self, width: int, keep: bool = True):
        self.width = int(width)
        self.count = 0
        self.sum = np.zeros(self.width)
        self.sumsq = np.zeros(self.width)
        self.parts = []
        self.keep = keep  # keep the samples (quantiles); False: moments only

    @classmethod
    def of(cls, rows, width: int | None = None, keep: bool = True) -> "Stats":
        """Statistics of the rows of ``rows`` (shape (N, w); (N,) is one column)."""
        a = np.asarray(rows, float)
        if a.ndim == 1:
            a = a.reshape(-1, 1) if width in (None, 1) else a.reshape(-1, width)
        if a.size == 0:
            a = a.reshape(0, a.shape[1] if a.ndim == 2 and a.shape[1] else (width or 1))
        st = cls(a.shape[1], keep)
        st.count = a.shape[0]
        if st.count:
            st.sum = np.sum(a, axis=0)
            st.sumsq = np.sum(a * a, axis=0)
            st.parts = [a] if keep else []
        return st

    def merge(self, other: "Stats") -> "Stats":
        """Add ``other`` to this (in place); returns self."""
        if other.count:
            if self.count and other.width != self.width:
                raise ValueError(f"cannot merge statistics of width {other.width} into width {self.width}")
            if not self.count:
                self.width = other.width
                self.sum = np.zeros(self.width)
                self.sumsq = np.zeros(self.width)
            self.count += other.count
            self.sum = self.sum + other.sum
            self.sumsq = self.sumsq + other.sumsq
            if self.keep:
                self.parts.extend(other.parts)
        return self

    def __getstate__(self):
        return {k: getattr(self, k) for k in self.__slots__}

    def __setstate__(self, st):
        for k, v in st.items():
            setattr(self, k, v)

    @property
    def samples(self) -> np.ndarray:
        """All rows, shape (count, w), in merge order."""
        return np.concatenate(self.parts, axis=0) if self.parts else np.zeros((0, self.width))

    @property
    def mean(self):
        """ndarray (w,), or None without samples."""
        return self.sum / self.count if self.count else None

    @property
    def rms(self):
        """Root mean square, ndarray (w,), or None."""
        return np.sqrt(self.sumsq / self.count) if self.count else None

    @property
    def std(self):
        """Sample standard deviation (ddof = 1), ndarray (w,), or None for fewer than 2 samples."""
        if self.count < 2:
            return None
        var = (self.sumsq - self.sum**2 / self.count) / (self.count - 1)
        return np.sqrt(np.maximum(var, 0.0))

    def quantiles(self, qs=QUANTILES) -> dict | None:
        """``{name: ndarray (w,)}`` of the quantiles ``qs`` (name -> fraction), or None."""
        if not self.count or not self.keep:
            return None
        S = self.samples
        return {k: np.quantile(S, q, axis=0) for k, q in qs.items()}

    def max(self):
        return np.max(self.samples, axis=0) if self.count and self.keep else None


# --------------------------------------------------------------------------- progress

class Progress:
    """Progress on stderr: a tqdm bar on a terminal; otherwise a line every 10 %.

    ``progress(done)`` with the number of trials done; ``enabled=False``
    (``--quiet``) prints nothing.  :meth:`close` ends the bar.
    """

    def __init__(self, total: int, label: str = "compare", stream=None, enabled: bool = True):
        self.total, self.label, self.enabled = max(1, int(total)), label, enabled
        self.stream = sys.stderr if stream is None else stream
        self.t0 = time.perf_counter()
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.next_pct = 10
        self._bar = None
        self._done = 0

    def __call__(self, done: int) -> None:
        if not self.enabled:
            return
        done = int(done)
        if self.tty:
            if self._bar is None:
                from tqdm import tqdm

                self._bar = tqdm(total=self.total, desc=self.label, file=self.stream, unit="trial",
                                 mininterval=0.2, dynamic_ncols=True, leave=True)
            self._bar.update(done - self._done)
            self._done = done
            if done >= self.total:
                self.close()
            return
        frac = done / self.total
        if 100 * frac >= self.next_pct or done == self.total:
            while self.next_pct <= 100 * frac:
                self.next_pct += 10
            el = time.perf_counter() - self.t0
            eta = el / frac - el if frac > 0 else float("nan")
            bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
            self.stream.write(f"{self.label} [{bar}] {done}/{self.total}  {el:.1f} s, eta {eta:.0f} s\n")
            self.stream.flush()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


# --------------------------------------------------------------------------- execution

def _worker_init():  # pragma: no cover - runs in the worker processes
    # Ctrl-C goes to the whole process group: the parent decides (it terminates us)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


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
        _run_dask(fn, tasks, scheduler, finished)
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
        futs = {pool.submit(fn, t): i for i, t in enumerate(tasks)}
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
    """Cancel what is pending, terminate the worker processes, shut down without waiting for work."""
    for f in futs:
        f.cancel()
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for p in procs:
        if p.is_alive():
            p.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    deadline = time.monotonic() + 0.5
    for p in procs:
        p.join(max(0.0, deadline - time.monotonic()))
    for p in procs:  # still there (stuck in a system call): SIGKILL
        if p.is_alive():
            p.kill()
            p.join(0.5)


def dask_client(scheduler):
    """``(client, owned)`` for a scheduler address or a Client (owned: we opened it and close it).

    Raises
    ------
    ZerocalError
        dask.distributed is not installed, or the scheduler cannot be reached.
    """
    try:
        from dask.distributed import Client
    except ImportError:
        raise ZerocalError("--scheduler needs dask.distributed: pip install 'zerocal_sym[cluster]'") from None
    if isinstance(scheduler, Client):
        return scheduler, False
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise ZerocalError(f"--scheduler: expected an address like tcp://host:8786, got {scheduler!r}")
    timeout = float(os.environ.get("ZEROCAL_SCHEDULER_TIMEOUT", SCHEDULER_TIMEOUT_S))
    try:
        client = Client(scheduler, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ZerocalError(f"cannot reach the Dask scheduler at {scheduler} within {timeout:g} s: {msg}") from None
    return client, True


def describe_scheduler(scheduler):
    """The address of a scheduler (a string as given, a Client's scheduler address), or None."""
    if scheduler is None or isinstance(scheduler, str):
        return scheduler
    try:
        return str(scheduler.scheduler.address)
    except AttributeError:
        return str(scheduler)


def _run_dask(fn, tasks, scheduler, finished):
    from dask.distributed import as_completed

    client, owned = dask_client(scheduler)
    futs = []
    try:
        futs = [client.submit(fn, t, pure=False) for t in tasks]
        index = {f.key: i for i, f in enumerate(futs)}
        for f in as_completed(futs):
            finished(index[f.key], f.result())
    except BaseException:
        try:
            client.cancel(futs)
        except Exception:  # noqa: BLE001 - the cluster may be gone already
            pass
        raise
    finally:
        if owned:
            client.close()


# --------------------------------------------------------------------------- one-shot trials

@dataclass
class OneShotTask:
    """A chunk of one-shot trials: simulate at ``theta`` with the truth ``err``, identify in one batch.

    Attributes
    ----------
    robot : Robot
    theta : ndarray, shape (K, m)
        Commanded joints (rad).
    err : ndarray, shape (q,)
        True source errors (rad, mm).
    noise : NoiseModel
    params : tuple of str
    seed, stream : int
        Trial ``t`` draws from ``SeedSequence([seed, stream, t])``.
    start, stop : int
        Trials ``start .. stop-1``.
    """

    robot: object
    theta: np.ndarray
    err: np.ndarray
    noise: object
    params: tuple
    seed: int
    stream: int
    start: int
    stop: int


def simulate_readings(robot, plant, theta, noise, seed, stream, start, stop) -> np.ndarray:
    """Scale readings of trials ``start .. stop-1`` at the commanded joints, shape (stop - start, K)."""
    return np.array([plant.measure(theta, noise, trial_rng(seed, stream, t)) for t in range(start, stop)]
                    ).reshape(stop - start, np.shape(theta)[0])


def one_shot_chunk(task: OneShotTask) -> dict:
    """Simulate and identify one chunk (runs in a worker).

    Returns
    -------
    dict
        Columns: ``trial`` (n,) int64, ``estimate`` (n, p), ``std`` (n, p),
        ``chi2`` (n,), ``success`` (n,) bool, ``confirmed`` (n,) bool; and
        ``time_s`` (the identification).
    """
    from zerocal_sym.identify.batch import identify_batch
    from zerocal_sym.model.noise import VirtualPlant

    plant = VirtualPlant(task.robot, task.err)
    R = simulate_readings(task.robot, plant, task.theta, task.noise, task.seed, task.stream, task.start, task.stop)
    t = time.perf_counter()
    b = identify_batch(task.robot, task.theta, R, task.params, noise=task.noise)
    return {"trial": np.arange(task.start, task.stop, dtype=np.int64), "estimate": b.estimate, "std": b.std,
            "chi2": b.chi2, "success": b.success, "confirmed": b.confirmed,
            "time_s": time.perf_counter() - t}


def concat_columns(parts) -> dict:
    """The columns of several chunk results, concatenated in order (``time_s`` summed)."""
    parts = [p for p in parts if p is not None]
    if not parts:
        return {}
    out = {k: np.concatenate([p[k] for p in parts]) for k in parts[0] if k != "time_s"}
    out["time_s"] = float(sum(p.get("time_s", 0.0) for p in parts))
    return out


def one_shot_monte_carlo(robot, theta, err, trials: int, noise=None, params="paper", seed: int = 0,
                         stream: int = 0, chunk: int | None = None, workers: int = 1, scheduler=None,
                         progress=None) -> dict:
    """``trials`` one-shot identifications at fixed commanded joints, chunked (see :func:`one_shot_chunk`).

    Returns
    -------
    dict
        The concatenated columns (trial order) and ``params``.
    """
    from zerocal_sym.model.noise import NoiseModel

    noise = NoiseModel.paper() if noise is None else noise
    names = robot.errors.resolve(params)
    theta = np.atleast_2d(np.asarray(theta, float))
    err = robot.errors.check_vector(np.asarray(err, float), "err_true")
    chunk = default_chunk(trials, 1000) if chunk is None else int(chunk)
    ranges = chunk_ranges(int(trials), chunk)
    tasks = [OneShotTask(robot, theta, err, noise, names, int(seed), int(stream), a, b) for a, b in ranges]
    res = run_chunks(one_shot_chunk, tasks, [b - a for a, b in ranges], workers, scheduler, progress)
    out = concat_columns(res)
    out["params"] = names
    return out
