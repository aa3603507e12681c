"""One-shot Monte Carlo trials: simulate a chunk's scale readings at fixed commanded joints, identify them at once.

:func:`one_shot_chunk` simulates a chunk of trials (:class:`OneShotTask`,
trial ``t`` drawing from :func:`~zerocal_sym.identify.parallel.trial_rng`)
and identifies them in one :func:`~zerocal_sym.identify.batch.identify_batch`
call; :func:`one_shot_monte_carlo` runs the chunks
(:func:`~zerocal_sym.identify.parallel.run_chunks`) and concatenates them in
trial order.  Used by the design verification and the study runner.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from zerocal_sym.identify.parallel import chunk_ranges, default_chunk, run_chunks, trial_rng


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
    b = identify_batch(task.robot, task.theta, R, task.params, noise=task.noise, nonfinite="fail")
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

    noise = NoiseModel.coerce(noise, robot=robot)
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
