"""Monte Carlo comparison of the identification methods on the same simulated data.

For any mechanism: given the true source errors (one or more labelled
*truths*) and the measurement poses, per trial (one seed per truth and trial)
the first measurement round is simulated once; every method sees exactly that
round first:

* ``tsvd-loop``  -- the paper's procedure: TSVD identification inside the
  compensation loop (:func:`zerocal_sym.identify.loop.calibration_loop`), stopping at
  the first ``mu < mu0``;
* ``tsvd``       -- the first TSVD identification of that loop alone;
* ``nlls``       -- Ipopt on the exact model, one shot, on the first round;
* ``nlls-loop``  -- Ipopt as the identifier of the same loop (each round's
  estimate from that round's data only);
* ``nlls-seq``   -- the loop with sequential MAP (each round's Ipopt estimate
  uses the previous round's estimate and covariance as a Gaussian prior:
  the information of all rounds is kept) -- beyond the paper;
* ``scipy``      -- ``scipy.optimize.least_squares`` (``method="lm"``) on the
  first round's whitened problem, as an outside reference for the answer
  (difference to Ipopt on the identical problem) and the speed.

The loops draw their later rounds from the same seed, so the loop methods
share the first round but not (after their compensations differ) the later
ones.  Within a chunk the TSVD loops of all trials run in lockstep, each
round's identifications in one batch
(:func:`~zerocal_sym.identify.loop.calibration_loops` with
:func:`~zerocal_sym.identify.tsvd.identify_tsvd_many`, the estimate without
TSVD's diagnostics: the same numbers as one loop per trial, bit for bit);
their time per identification is their share of the batch.  The Ipopt loops run in lockstep the same way
(:class:`~zerocal_sym.identify.nlls_rounds.LoopRounds`), and every round of a chunk's loops is simulated in one
mapped call of the distance (:func:`~zerocal_sym.identify.loop.simulate_rounds`, each loop's own draws in their
order: the same numbers).  The scipy
reference evaluates the residuals through zero-copy callbacks
(:func:`scipy_identify`).  Errors are reported in our frame, or through a
``report`` transform (the paper's Table 2 frame:
:func:`zerocal_sym.paper.compare.compare`; RMS values do not depend on the
frame).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from zerocal_sym.model import units

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import IdentificationError, ZerocalError
from zerocal_sym.identify.loop import calibration_loop, calibration_loops, simulate_rounds
from zerocal_sym.identify.dask_cluster import describe_scheduler
from zerocal_sym.identify.parallel import (Progress, Stats, check_execution, chunk_ranges, default_chunk,
                                          run_chunks)
from zerocal_sym.identify.compare_report import format_compare
from zerocal_sym.identify.scipy_reference import least_squares_or_error, scipy_identify
from zerocal_sym.model.noise import NoiseModel, VirtualPlant

__all__ = ["METHODS", "Progress", "compare", "format_compare", "scipy_identify"]

METHODS = ("tsvd-loop", "tsvd", "nlls", "nlls-loop", "nlls-seq", "scipy")


class _Timed:
    """Wrap an identifier: count the calls and the time spent in them."""

    def __init__(self, fn):
        self.fn, self.n, self.t = fn, 0, 0.0

    def __call__(self, robot, meas, prior=None):
        t = time.perf_counter()
        try:
            return self.fn(robot, meas, prior)
        finally:
            self.t += time.perf_counter() - t
            self.n += 1


def _continued(ss, state):
    """``np.random.default_rng(ss)`` moved to ``state`` (a generator's ``bit_generator.state``)."""
    bg = np.random.PCG64(ss)
    bg.state = state
    return np.random.Generator(bg)


def _record_loop(record, m, loop, n_id, t_id, methods, paper4, errors):
    """Record loop method ``m`` (a LoopResult, None if it failed) and, for ``tsvd-loop``, its first identification
    as ``tsvd``; ``n_id`` identifications took ``t_id`` seconds."""
    if m == "tsvd-loop" and "tsvd" in methods:
        res1 = loop.history[0].result if loop is not None and loop.history else None
        if res1 is None or not res1.success:
            record("tsvd", None, 0.0)
        else:
            record("tsvd", np.array([res1.value(n) for n in paper4]), t_id / max(1, n_id))
    if m not in methods:
        return
    if loop is None:
        record(m, None, t_id, n_id)
        return
    full = errors.put(errors.put(errors.zeros(), errors.zero_offsets,
                                 units.from_user(loop.compensation_deg, errors.offset_unit)),
                      errors.measuring, loop.maemm_mm)
    record(m, errors.take(full, paper4), t_id, n_id, loop.converged)


def _identity_report(values, which):
    return np.asarray(values, float)


#: run the Ipopt loops of a chunk in lockstep (:class:`~zerocal_sym.identify.nlls_rounds.LoopRounds`); False: one
#: loop after the other, each identification by ``identify_nlls`` (the same numbers: tests/test_compare_reference.py)
NLLS_LOCKSTEP = True


@dataclass
class _CompareTask:
    """A chunk of trials of one truth (picklable: sent to worker processes)."""

    robot: object
    err: np.ndarray
    stream: int
    poses: np.ndarray
    names: tuple
    noise: NoiseModel
    seed: int
    methods: tuple
    mu0_deg: float
    max_iter: int
    report: object
    start: int
    stop: int


class _Acc:
    """What one method collects over a chunk."""

    def __init__(self):
        self.E, self.M, self.comp = [], [], []
        self.fail = self.nc = self.nid = 0
        self.t = 0.0

    def done(self, robot, plant, m_, n_) -> dict:
        # dp0 of every compensation of the chunk in one forward-kinematics call (as loop.home_error each)
        comp = np.reshape(self.comp, (-1, m_))
        dp0 = (np.linalg.norm(plant.actual_pose(robot.home_joints()[None, :] - comp) - robot.home_pose(), axis=1)
               if len(comp) else np.zeros(0))
        return {"E": Stats.of(np.reshape(self.E, (-1, m_))), "M": Stats.of(np.reshape(self.M, (-1, n_))),
                "dp0": Stats.of(dp0.reshape(-1, 1)), "fail": self.fail, "nc": self.nc,
                "nid": self.nid, "t": self.t}


def _compare_chunk(task: _CompareTask) -> dict:
    """Trials ``task.start .. task.stop-1`` of one truth, every method (runs in a worker).

    Returns per method the mergeable statistics (:class:`~zerocal_sym.identify.parallel.Stats`)
    of the offset errors ``E`` (reported frame, deg), the MAEMM errors ``M`` (mm) and ``dp0``
    (mm), the counters and the time; and the scipy reference's differences and times.
    """
    from zerocal_sym.identify.batch import identify_batch
    from zerocal_sym.identify.nlls import identify_nlls, make_nlls_identifier
    from zerocal_sym.identify.nlls_rounds import LoopRounds
    from zerocal_sym.identify.tsvd import identify_tsvd_many

    robot, methods, names, noise = task.robot, task.methods, task.names, task.noise
    errors = robot.errors
    offs = errors.zero_offsets
    paper4 = errors.resolve("default")
    m_, n_ = len(offs), len(paper4) - len(offs)  # the identified measuring errors: those of the default set
    report = task.report or _identity_report
    plant = VirtualPlant(robot, task.err)
    true4 = errors.take(task.err, paper4)
    th0 = kin.ik(robot, task.poses)
    rec = {m: _Acc() for m in methods}
    sc_diff, sc_t, ip_t, first = [], [], [], []

    def record(m, est4, t, n_ident=1, converged=True):
        r = rec[m]
        r.t += t
        r.nid += n_ident
        if est4 is None:
            r.fail += 1
            return
        r.nc += 0 if converged else 1
        e = est4 - true4
        r.E.append(report(units.to_user(e[:m_], errors.offset_unit), "offsets"))
        r.M.append(report(e[m_:], "maemm"))
        r.comp.append(est4[:m_])

    # per trial: its seed, first round and the generator state after it (every loop: this first round, then its
    # own draws); the first rounds simulated together (as simulate_round each, the same numbers)
    seeds = [np.random.SeedSequence([task.seed, task.stream, trial]) for trial in range(task.start, task.stop)]
    rngs = [np.random.default_rng(ss) for ss in seeds]
    firsts = simulate_rounds(robot, plant, task.poses, [(np.zeros(robot.m), th0, g) for g in rngs], noise)
    trials = [(ss, m1, g.bit_generator.state) for ss, m1, g in zip(seeds, firsts, rngs)]
    loop_kw = dict(noise=noise, mu0_deg=task.mu0_deg, max_iter=task.max_iter, kappa=False, theta=th0)
    if "tsvd-loop" in methods or "tsvd" in methods:  # the chunk's TSVD loops in lockstep, one batch per round
        runs = calibration_loops(robot, plant, task.poses, identify_tsvd_many,
                                 [_continued(ss, st) for ss, _, st in trials], firsts=[m1 for _, m1, _ in trials],
                                 catch=(IdentificationError, ZerocalError), **loop_kw)
        for loop, n_id, t_id in runs:
            loop = None if isinstance(loop, BaseException) else loop
            _record_loop(record, "tsvd-loop", loop, n_id, t_id, methods, paper4, errors)
    for m in ("nlls-loop", "nlls-seq"):
        if m not in methods:
            continue
        if NLLS_LOCKSTEP:  # the chunk's Ipopt loops in lockstep, each round's identifications in one mapped call
            runs = calibration_loops(robot, plant, task.poses, LoopRounds(names, noise, m == "nlls-seq"),
                                     [_continued(ss, st) for ss, _, st in trials], firsts=[m1 for _, m1, _ in trials],
                                     catch=(IdentificationError, ZerocalError), pass_loops=True, **loop_kw)
            for loop, n_id, t_id in runs:
                _record_loop(record, m, None if isinstance(loop, BaseException) else loop, n_id, t_id, methods,
                             paper4, errors)
            continue
        for ss, meas1, after1 in trials:  # one loop after the other (the same numbers)
            ident = _Timed(make_nlls_identifier(params=names, noise=noise, sequential=(m == "nlls-seq")))
            try:
                loop = calibration_loop(robot, plant, task.poses, identify=ident, rng=_continued(ss, after1),
                                        first=meas1, **loop_kw)
            except (IdentificationError, ZerocalError):
                loop = None
            _record_loop(record, m, loop, ident.n, ident.t, methods, paper4, errors)
    for ss, meas1, after1 in trials:
        if "nlls" in methods:
            first.append(meas1.readings)
        if "scipy" in methods:
            ref = identify_nlls(robot, meas1, names, noise=noise, warm_start=None, reweight=0)
            p_sc, info = scipy_identify(robot, meas1, names, noise)
            ok = info["success"] and ref.success
            record("scipy", np.array([p_sc[names.index(n)] if n in names else 0.0 for n in paper4]) if ok else None,
                   info["time_s"])
            if ok:
                pos = [names.index(n) for n in offs]
                sc_diff.append(np.max(np.abs(units.to_user(p_sc[pos] - ref.estimate[pos], errors.offset_unit))))
                sc_t.append(info["time_s"])
                ip_t.append(ref.info["time_s"])
    if "nlls" in methods:  # the one-shot Ipopt of all first rounds in one batch (unconfirmed: the single path)
        t = time.perf_counter()
        b = identify_batch(robot, th0, np.array(first), names, noise=noise, nonfinite="fail")
        dt = (time.perf_counter() - t) / len(first)
        # the offsets and the MAEMM by name; one not estimated is held at its prior, zero here (as scipy's)
        est4 = np.column_stack([b.values([n])[:, 0] if n in names else np.zeros(len(first)) for n in paper4])
        for k in range(len(first)):
            record("nlls", est4[k] if b.success[k] else None, dt)
    return {"methods": {m: rec[m].done(robot, plant, m_, n_) for m in methods},
            "scipy": {"diff": sc_diff, "t_sc": sc_t, "t_ip": ip_t}}


def offsets_missing(errors, names) -> str | None:
    """Why the parameter set ``names`` cannot serve a comparison of zero offsets (they are what it compares), or
    None."""
    offs = errors.zero_offsets
    if any(n not in names for n in offs):
        return f"the parameter set must contain the zero offsets {', '.join(offs)}"
    return None


def compare(robot, truths: dict, poses, trials: int = 100, params="paper", noise: NoiseModel | None = None,
            seed: int = 0, methods=METHODS, mu0_deg: float = 0.1, max_iter: int = 20,
            progress=None, report=None, settings=None, workers: int = 1, scheduler=None,
            chunk: int | None = None) -> dict:
    """Run the Monte Carlo comparison.

    Parameters
    ----------
    robot : Robot
    truths : dict of label -> ndarray, shape (q,)
        The true source errors (rad, mm) of each study; the label keys the
        output (``rep["groups"][str(label)]``).  Seeds are ``(seed, label, trial)``
        for an integer label, ``(seed, index, trial)`` otherwise.
    poses : ndarray, shape (K, n)
        Measurement poses in visiting order.
    trials : int
        Trials per truth.
    params : str or sequence of str
        Parameters of the Ipopt methods (TSVD always has the zero offsets and the MAEMM).
    noise : NoiseModel, optional
        Simulation noise and the weights of Ipopt (default: the paper's).
    seed : int
    methods : sequence of str
        A subset of :data:`METHODS`.
    mu0_deg, max_iter : loop settings.
    progress : callable, optional
        ``progress(done)`` with the trials done (over all truths), after each chunk.
    report : callable, optional
        ``report(values, which)`` with ``which`` ``"offsets"`` (deg, m) or
        ``"maemm"`` (mm, n): how errors are reported (default: as they are);
        picklable (a module-level function or a ``functools.partial`` of one)
        for ``workers > 1`` or a scheduler.
    settings : dict, optional
        Extra entries for ``rep["settings"]``.
    workers : int
        Local worker processes (default 1: this process).
    scheduler : str or dask.distributed.Client, optional
        Run the chunks on a Dask cluster instead.
    chunk : int, optional
        Trials per chunk (default :func:`~zerocal_sym.identify.parallel.default_chunk`);
        the results depend on it (the order of the sums), never on ``workers``/``scheduler``.

    Returns
    -------
    dict
        ``settings``, ``crlb_zero_offsets_deg`` (per truth, at the truth and the
        first round's poses), and per group and method: ``bias_deg``,
        ``rms_deg``, ``rms_crlb_ratio`` (zero offsets), ``quantiles_deg``
        (``q05``, ``median``, ``q95`` of the offset errors), ``bias_maemm_mm``,
        ``rms_maemm_mm``, ``dp0_rms_mm`` / ``dp0_mean_mm`` / ``dp0_max_mm``
        (home position error after compensating with the estimate),
        ``failures`` (identification failed or raised), ``not_converged``
        (loops that did not reach ``mu < mu0``), ``identifications``
        (per trial, mean), ``time_per_identification_ms``; ``scipy``:
        ``max_abs_diff_to_ipopt_deg`` and the time ratio; ``execution``:
        workers, scheduler, chunks, wall time.
    """
    t_wall = time.perf_counter()
    errors = robot.errors
    offs = errors.zero_offsets
    workers = check_execution(workers, scheduler)
    noise = NoiseModel.coerce(noise, robot=robot)
    methods = tuple(methods)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ZerocalError(f"unknown method(s) {', '.join(unknown)} (known: {', '.join(METHODS)})")
    if "scipy" in methods:
        least_squares_or_error()
    try:
        names = errors.resolve(params)
    except ValueError as exc:
        raise ZerocalError(str(exc)) from None
    missing = offsets_missing(errors, names)
    if missing:
        raise ZerocalError(missing)
    poses = np.atleast_2d(np.asarray(poses, float))
    th0 = kin.check_poses(robot, poses)
    K = poses.shape[0]
    if K - 1 < len(names):
        raise ZerocalError(f"{K} poses give {K - 1} measured changes: fewer than the {len(names)} parameters")
    chunk = default_chunk(trials) if chunk is None else int(chunk)
    ranges = chunk_ranges(int(trials), chunk)
    out = {"settings": {"mechanism": robot.mechanism_name, "groups": [str(g) for g in truths], "trials": trials,
                        "K": K, "poses_mm": poses.tolist(),
                        "params": list(names), "noise": noise.to_dict(robot),
                        "offset_unit": errors.offset_user_unit,
                        "seed": seed, "methods": list(methods), "mu0_deg": mu0_deg,
                        "max_iter": max_iter, "chunk": chunk, "error_frame": "ours", **(settings or {})},
           "groups": {}}
    tasks, owner, prepared = [], [], []
    for gi, (g, err) in enumerate(truths.items()):
        err = errors.check_vector(err, f"truth {g!r}")
        stream = g if isinstance(g, int) else gi
        prepared.append((g, err))
        for a, b in ranges:
            tasks.append(_CompareTask(robot, err, stream, poses, names, noise, int(seed), methods, float(mu0_deg),
                                      int(max_iter), report, a, b))
            owner.append(gi)
    results = run_chunks(_compare_chunk, tasks, [t.stop - t.start for t in tasks], workers, scheduler, progress)
    report = report or _identity_report
    for gi, (g, err) in enumerate(prepared):
        try:
            crlb = fisher.crlb_zero_offsets_user(robot, th0, names, noise, err0=err) if not noise.is_zero else None
        except ZerocalError:
            crlb = None
        mine = [r for r, o in zip(results, owner) if o == gi]  # chunk order
        gout = {"crlb_zero_offsets_deg": None if crlb is None else np.asarray(crlb).tolist(),
                "set_deg": report(units.to_user(errors.take(err, offs), errors.offset_unit), "offsets").tolist(),
                "methods": {}}
        for m in methods:
            gout["methods"][m] = _method_summary(m, [r["methods"][m] for r in mine], trials, crlb)
        sc = {k: [x for r in mine for x in r["scipy"][k]] for k in ("diff", "t_sc", "t_ip")}
        if "scipy" in methods and sc["t_sc"]:
            gout["scipy_reference"] = {
                "problem": "whitened residuals, weights at zero, start at zero (Ipopt: warm_start=None, reweight=0)",
                "max_abs_diff_to_ipopt_deg": float(np.max(sc["diff"])),
                "time_scipy_ms": 1e3 * float(np.mean(sc["t_sc"])),
                "time_ipopt_ms": 1e3 * float(np.mean(sc["t_ip"])),
                "time_ratio_ipopt_over_scipy": float(np.mean(sc["t_ip"]) / np.mean(sc["t_sc"])),
            }
        out["groups"][str(g)] = gout
    out["execution"] = {"workers": workers, "scheduler": describe_scheduler(scheduler),
                        "chunks": len(tasks), "chunk_trials": chunk, "wall_s": time.perf_counter() - t_wall,
                        "wall_per_trial_ms": 1e3 * (time.perf_counter() - t_wall) / max(1, trials * len(prepared))}
    return units.rename_unit_keys(out, errors.offset_user_unit)


def _method_summary(m, parts, trials, crlb) -> dict:
    """Merge a method's chunk statistics (in chunk order) into its report entry."""
    E, M, D = Stats(0), Stats(0), Stats(1)
    fail = nc = nid = 0
    t = 0.0
    for p in parts:
        E.merge(p["E"])
        M.merge(p["M"])
        D.merge(p["dp0"])
        fail += p["fail"]
        nc += p["nc"]
        nid += p["nid"]
        t += p["t"]
    bias, rms = E.mean, E.rms
    q = E.quantiles()
    ok = E.count > 0
    return {
        "trials": trials,
        "failures": fail,
        "not_converged": nc if m.endswith(("loop", "seq")) else None,
        "bias_deg": None if bias is None else bias.tolist(),
        "rms_deg": None if rms is None else rms.tolist(),
        "rms_crlb_ratio": (None if rms is None or crlb is None else (rms / np.asarray(crlb)).tolist()),
        "quantiles_deg": None if q is None else {k: v.tolist() for k, v in q.items()},
        "bias_maemm_mm": None if M.mean is None else M.mean.tolist(),
        "rms_maemm_mm": None if M.rms is None else M.rms.tolist(),
        "dp0_rms_mm": float(D.rms[0]) if ok else None,
        "dp0_mean_mm": float(D.mean[0]) if ok else None,
        "dp0_max_mm": float(D.max()[0]) if ok else None,
        "identifications": nid / trials if trials else None,
        "time_per_identification_ms": 1e3 * t / max(1, nid),
    }
