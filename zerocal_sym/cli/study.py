"""The study runner: robots x designs x noise levels x truths x trials, chunked, resumable.

A *study* (a TOML spec, :func:`~zerocal_sym.cli.study_spec.load_spec`)
crosses robot files, measurement designs, noise levels and true source
errors; each combination is a *cell*.
Every cell runs the same number of one-shot identifications (Ipopt on the
exact model, :func:`~zerocal_sym.identify.batch.identify_batch`), split in
chunks of consecutive trials, each written atomically to its own file
(:mod:`zerocal_sym.cli.study_chunks`).

A rerun skips the chunks already on disk (the last chunk of a cell whose
trials stop elsewhere, after ``trials`` changed, is recomputed), so an
interrupted study resumes where it stopped.  ``OUT/<cell-id>/cell.json``
records the cell's settings and the study's name: a rerun whose settings
differ (other than ``trials``) is refused, and so is a directory that holds
another study (another name; with ``--out``, cells the spec does not have).
Every chunk file records its cell (id and settings hash): a damaged file or
another cell's is refused, naming it, before any work (delete it to have it
recomputed).  A run that has chunks to compute first removes
``OUT/summary.json`` (it would no longer describe the directory) and writes it
again at the end.  The summary (:func:`summarize`) is merged from the chunk
files: per cell and parameter the bias, RMS, sample std, the CRLB at the
truth and RMS/CRLB, quantiles (5 %, median, 95 %) of the errors, the mean
reported std, failures.

This module holds the runner (:func:`plan`, :func:`run_study`) and the
summary (:func:`summarize`, :func:`format_summary`); the spec is read by
:mod:`zerocal_sym.cli.study_spec`, the chunk files are
:mod:`zerocal_sym.cli.study_chunks`.
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.cli.study_chunks import (_CHUNK_RE, ChunkError, _cell_json, check_directory, chunk_path, read_chunk,
                                          write_chunk)
from zerocal_sym.cli.study_size import check_disk
from zerocal_sym.cli.study_spec import Study, load_spec  # noqa: F401 - load_spec kept importable from here (benchmarks)
from zerocal_sym.identify.one_shot import OneShotTask, one_shot_chunk
from zerocal_sym.identify.dask_cluster import describe_scheduler
from zerocal_sym.identify.parallel import chunk_ranges, run_chunks
from zerocal_sym.identify.stats import QUANTILES, Stats


# --------------------------------------------------------------------------- running

def plan(study: Study, out) -> tuple:
    """``(todo, on_disk)``: the chunks to run ``[(cell, k, start, stop)]`` and how many are already done.

    Every chunk file on disk is read (:func:`~zerocal_sym.cli.study_chunks.read_chunk`).

    Raises
    ------
    ChunkError
        The first chunk file that is refused (damaged, another cell's), with the number of others.
    """
    todo, done, bad = [], 0, []
    for cell in study.cells:
        digest = cell.digest(study)
        bad += beyond_chunks(study, out, cell, digest)
        for k, (a, b) in enumerate(chunk_ranges(study.trials, study.chunk)):
            p = chunk_path(out, cell, k)
            try:
                ok = p.exists() and read_chunk(p, cell.id, digest, cell.params, a, b, columns=False) is not None
            except ChunkError as exc:
                bad.append(exc)
                continue
            if ok:
                done += 1
            else:
                todo.append((cell, k, a, b))
    _refuse(bad)
    return todo, done


def _refuse(bad) -> None:
    """Raise the first of the chunk files refused (``bad``, ChunkErrors), saying how many others there are."""
    if bad:
        n = len(bad) - 1
        more = f" ({n} other chunk file{'s are' if n > 1 else ' is'} refused too)" if n else ""
        raise ChunkError(bad[0].message + more, where=bad[0].where)


def beyond_chunks(study: Study, out, cell, digest) -> list:
    """Check the chunk files of ``cell`` whose index is beyond its chunks (``chunk-<k>.npz``, ``k >= chunks``).

    Such a file is left by a run with more trials (it is read again if
    ``trials`` grows back) or it was put there: it is checked like the others
    (its cell record, its trials ``k*chunk ..``), not summarised.

    Returns
    -------
    list of ChunkError
        The files that do not belong (damaged, another cell's, other trials).
    """
    d = Path(out) / cell.id
    if not d.is_dir():
        return []
    bad = []
    for p in sorted(d.iterdir()):
        m = _CHUNK_RE.match(p.name)
        if not m or p.name != f"chunk-{int(m.group(1))}.npz" or int(m.group(1)) < study.chunks_per_cell:
            continue
        k = int(m.group(1))
        try:
            read_chunk(p, cell.id, digest, cell.params, k * study.chunk, (k + 1) * study.chunk, columns=False)
        except ChunkError as exc:
            bad.append(exc)
    return bad


def run_study(study: Study, out, workers: int = 1, scheduler=None, progress=None, log=None,
              make_progress=None) -> dict:
    """Run the chunks not on disk yet, then summarise.

    Parameters
    ----------
    out : path
        Output directory (created).
    workers, scheduler : see :func:`~zerocal_sym.identify.parallel.run_chunks`
    progress : callable, optional
        ``progress(done)`` with the trials done in this run.  A ``KeyboardInterrupt``
        (Ctrl-C, or raised by it) stops the run: the chunks written so far stay
        (complete files), nothing partial is left, no summary is written (and the
        one of an earlier run is gone: it was removed when this run started work).
    log : callable, optional
        ``log(text)`` for the one-line account of what is on disk and what runs.
    make_progress : callable, optional
        ``make_progress(total) -> progress`` (total: the trials to run), instead of ``progress``.

    Returns
    -------
    dict
        The summary (:func:`summarize`), also written to ``OUT/summary.json``.

    Raises
    ------
    ZerocalError
        Before anything is written: ``out`` holds another study
        (:func:`~zerocal_sym.cli.study_chunks.check_directory`), a cell's
        cell.json other settings, a chunk file is refused (:func:`plan`),
        the chunk files to write do not fit on the disk
        (:func:`~zerocal_sym.cli.study_size.check_disk`).
    """
    from zerocal_sym.io.files import write_json

    from zerocal_sym.model.compiled import mode

    out = Path(out)
    mode()  # ZEROCAL_COMPILE: a bogus value is a user error before anything is written
    check_directory(out, study, run=True)
    for cell in study.cells:
        _cell_json(out, cell, study, check_only=True)
    todo, on_disk = plan(study, out)
    check_disk(todo, out)  # the chunk files to write fit on the disk: before anything is written
    total = on_disk + len(todo)
    if log:
        log(f"study {study.name}: {len(study.cells)} cells x {study.chunks_per_cell} chunks of <= {study.chunk} "
            f"trials: {on_disk} of {total} chunks already on disk, {len(todo)} to run "
            f"({sum(b - a for _, _, a, b in todo)} identifications)")
    if make_progress is not None:
        progress = make_progress(sum(b - a for *_, a, b in todo))
    t0 = time.perf_counter()
    if todo:  # the summary of an earlier run no longer describes the directory: gone before the first chunk
        (out / "summary.json").unlink(missing_ok=True)
    digests = {c.id: c.digest(study) for c, *_ in todo}  # the cells to run
    for cell in study.cells:  # and those whose (unreadable) cell.json was deleted
        if cell.id in digests or (out / cell.id).is_dir():
            _cell_json(out, cell, study)
    tasks = [OneShotTask(c.robot, c.theta, c.truth, c.noise, c.params, study.seed, c.stream, a, b)
             for c, k, a, b in todo]

    def save(i, cols):
        cell, k, a, b = todo[i]
        write_chunk(chunk_path(out, cell, k), cols, cell.params, cell.id, digests[cell.id])
        return float(cols.get("time_s", 0.0))

    times = run_chunks(one_shot_chunk, tasks, [b - a for *_, a, b in todo], workers, scheduler, progress,
                       on_result=save)
    wall = time.perf_counter() - t0
    summary = summarize(study, out)
    n_run = sum(b - a for *_, a, b in todo)
    summary["run"] = {"chunks_on_disk_before": on_disk, "chunks_run": len(todo), "identifications": n_run,
                      "wall_s": wall, "identifications_per_s": n_run / wall if n_run and wall > 0 else None,
                      "identification_time_s": float(sum(t for t in times if t is not None)),
                      "workers": workers, "scheduler": describe_scheduler(scheduler)}
    write_json(out / "summary.json", summary)
    return summary


# --------------------------------------------------------------------------- summary

def _crlb(cell):
    from zerocal_sym.identify import fisher

    if cell.noise.is_zero:
        return None
    try:
        return np.sqrt(np.diag(fisher.crlb(cell.robot, cell.theta, cell.params, cell.noise, err0=cell.truth)))
    except (ZerocalError, np.linalg.LinAlgError, ValueError):
        return None


def summarize(study: Study, out) -> dict:
    """Merge the chunk files on disk into per-cell statistics (errors in deg for angles, mm otherwise).

    Cells with missing chunks are summarised over what is there (``trials_done``); the last chunk of a
    cell whose trials stop elsewhere (``trials`` changed) is left out.

    Raises
    ------
    ZerocalError
        ``out`` holds another study (another name), a cell's cell.json other settings, a chunk file is
        refused (:func:`~zerocal_sym.cli.study_chunks.read_chunk`).
    """
    out = Path(out)
    check_directory(out, study, run=False)
    cells = []
    for cell in study.cells:
        _cell_json(out, cell, study, check_only=True)  # chunks of other settings are not merged
        digest = cell.digest(study)
        _refuse(beyond_chunks(study, out, cell, digest))  # not summarised, but refused if not the cell's
        errors = cell.robot.errors
        names = cell.params
        conv = np.array([math.degrees(1.0) if errors[n].unit == "rad" else 1.0 for n in names])
        true = errors.take(cell.truth, names)
        St, Ss = Stats(len(names)), Stats(len(names), keep=False)
        fail = unconf = chunks = n_done = 0
        chi2_sum, t_id = 0.0, 0.0
        for k, (a, b) in enumerate(chunk_ranges(study.trials, study.chunk)):
            p = chunk_path(out, cell, k)
            cols = read_chunk(p, cell.id, digest, names, a, b) if p.exists() else None
            if cols is None:
                continue
            chunks += 1
            n_done += b - a
            ok = cols["success"].astype(bool)
            fail += int(np.sum(~ok))
            unconf += int(np.sum(~cols["confirmed"].astype(bool)))
            est = np.column_stack([cols[f"est_{n}"] for n in names])[ok]
            std = np.column_stack([cols[f"std_{n}"] for n in names])[ok]
            St.merge(Stats.of((est - true) * conv))
            Ss.merge(Stats.of(std * conv, keep=False))
            chi2_sum += float(np.sum(cols["chi2"][ok]))
            t_id += float(cols.get("time_s", 0.0))
        crlb = _crlb(cell)
        crlb_u = None if crlb is None else crlb * conv
        q = St.quantiles()

        def by_name(v):
            return None if v is None else {n: float(x) for n, x in zip(names, v)}

        rms = St.rms
        cells.append({
            "id": cell.id, "robot": cell.robot_label, "mechanism": cell.robot.mechanism_name,
            "design": cell.design_label, "K": int(cell.poses.shape[0]), "noise": cell.noise_label,
            "truth": cell.truth_label, "truth_values": cell.truth_user,
            "params": list(names), "units": {n: errors[n].user_unit for n in names},
            "trials": study.trials, "trials_done": n_done, "chunks_done": chunks,
            "chunks": study.chunks_per_cell, "identified": St.count, "failures": fail,
            "unconfirmed_in_batch": unconf,
            "bias": by_name(St.mean), "rms": by_name(rms), "std": by_name(St.std),
            "crlb": by_name(crlb_u),
            "rms_crlb_ratio": by_name(None if rms is None or crlb_u is None else rms / crlb_u),
            **{k: by_name(None if q is None else q[k]) for k in QUANTILES},
            "mean_reported_std": by_name(Ss.mean),
            "chi2_per_dof": (chi2_sum / St.count / (cell.poses.shape[0] - 1 - len(names))
                             if St.count and cell.poses.shape[0] - 1 > len(names) else None),
            "identification_time_s": t_id,
        })
    return {"study": study.name, "spec": str(study.path), "seed": study.seed, "trials": study.trials,
            "chunk": study.chunk, "streams": study.streams, "cells": cells}


def format_summary(s: dict) -> str:
    """The summary as text: one block per cell, one row per parameter."""
    lines = [f"study {s['study']}: {len(s['cells'])} cells, {s['trials']} trials each (chunks of {s['chunk']}, "
             f"seed {s['seed']}, {s['streams']} random streams)"]
    for c in s["cells"]:
        lines.append("")
        lines.append(f"{c['id']}: robot {c['robot']}, design {c['design']} (K = {c['K']}), noise {c['noise']}, "
                     f"truth {c['truth']}; {c['trials_done']}/{c['trials']} trials on disk, "
                     f"{c['failures']} failed" + (f", chi2/dof {c['chi2_per_dof']:.3f}" if c["chi2_per_dof"] else ""))
        if not c["identified"]:
            lines.append("  no identification on disk")
            continue
        lines.append(f"  {'param':8s} {'unit':4s} {'bias':>10s} {'RMS':>10s} {'CRLB':>10s} {'RMS/CRLB':>8s} "
                     f"{'5%':>10s} {'median':>10s} {'95%':>10s} {'mean std':>10s}")
        for n in c["params"]:
            def f(key, spec="10.4g"):
                v = c[key]
                return format(v[n], spec) if v is not None and v.get(n) is not None else "-".rjust(10)

            ratio = c["rms_crlb_ratio"]
            lines.append(f"  {n:8s} {c['units'][n]:4s} {f('bias', '+10.4g')} {f('rms')} {f('crlb')} "
                         f"{(format(ratio[n], '8.3f') if ratio else '-'.rjust(8))} {f('q05', '+10.4g')} "
                         f"{f('median', '+10.4g')} {f('q95', '+10.4g')} {f('mean_reported_std')}")
    r = s.get("run")
    if r:
        ips = r["identifications_per_s"]
        lines.append("")
        lines.append(f"this run: {r['chunks_run']} chunks ({r['identifications']} identifications) in "
                     f"{r['wall_s']:.1f} s" + (f", {ips:.0f} identifications/s" if ips else "")
                     + f"; {r['chunks_on_disk_before']} chunks were on disk")
    return "\n".join(lines)


def log_stderr(text: str) -> None:
    sys.stderr.write(text + "\n")  # one write: a Ctrl-C cannot fall between the line and its end
    sys.stderr.flush()
