"""The files of a study's results: one per chunk of trials of a cell, and the cell's settings.

Each chunk is written atomically (temporary file + ``os.replace``) to
``OUT/<cell-id>/chunk-<k>.npz``, one array per column:

``cell`` (the cell id, 0-d string) and ``cell_sha256`` (the hash of the
cell's settings, :meth:`~zerocal_sym.cli.study_spec.Cell.digest`), ``trial``
(int64), ``est_<param>`` and ``std_<param>`` per identified parameter
(rad / mm), ``chi2``, ``success``, ``confirmed`` (bool) and ``time_s`` (the
identification time of the chunk, 0-d).

A chunk is read back (:func:`read_chunk`) only if it is one of this cell's
chunks (its ``cell`` and ``cell_sha256``) and holds exactly the expected
trials.  A chunk of the cell whose trials run from the expected first one
but end elsewhere (``trials`` changed: the last chunk is shorter or longer)
is recomputed; any other file is refused (:class:`ChunkError`, naming the
file): one that cannot be read as a chunk (truncated, empty, not an npz),
one that lacks a column or whose columns differ in length, one of another
cell or of other settings, one that holds other trials of the cell (a file
moved or copied).  The runner writes every chunk atomically, so such a file
was made by something else: it is not overwritten; deleting it has it
recomputed by the next run.  Chunks written before the ``cell`` record
existed are checked by their columns and trials only.

``OUT/<cell-id>/cell.json`` records the cell's settings
(:meth:`~zerocal_sym.cli.study_spec.Cell.settings`) and the study's name; a
rerun whose settings differ (other than ``trials``) is refused
(:func:`_cell_json`); a directory that holds another study is refused
(:func:`check_directory`).
"""
from __future__ import annotations

import io
import json
import pickle
import re
import zipfile
import zlib
from pathlib import Path

import numpy as np

from zerocal_sym.errors import ZerocalError

_CHUNK_RE = re.compile(r"^chunk-(\d+)\.npz$")

#: what ``np.load`` and reading a member of a damaged npz raise
_UNREADABLE = (OSError, ValueError, EOFError, KeyError, TypeError, AttributeError, zipfile.BadZipFile,
               zlib.error, pickle.UnpicklingError)


class ChunkError(ZerocalError):
    """A chunk file that is not one of this cell's chunks (names the file)."""


def chunk_path(out, cell, k) -> Path:
    return Path(out) / cell.id / f"chunk-{k}.npz"


def write_chunk(path, cols: dict, params, cell_id: str, digest: str) -> None:
    """One chunk's columns to ``path`` (npz, one array per column, with the cell's record), atomically."""
    from zerocal_sym.io.files import atomic_write_bytes

    arrays = {"cell": np.array(cell_id), "cell_sha256": np.array(digest), "trial": cols["trial"]}
    for j, n in enumerate(params):
        arrays[f"est_{n}"] = cols["estimate"][:, j]
    for j, n in enumerate(params):
        arrays[f"std_{n}"] = cols["std"][:, j]
    arrays.update(chi2=cols["chi2"], success=cols["success"], confirmed=cols["confirmed"],
                  time_s=np.asarray(cols.get("time_s", 0.0)))
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())


_DELETE = "delete it and run the study with --out to recompute it"


def read_chunk(path, cell_id: str, digest: str, params, start, stop, columns: bool = True):
    """The columns of chunk file ``path`` of cell ``cell_id`` if it holds exactly trials ``start .. stop-1``.

    Returns None if it is a chunk of this cell whose trials start at ``start``
    but stop elsewhere (``trials`` changed: recompute it); ``columns=False``:
    True instead of the columns (every column is read all the same, so a
    damaged one shows).

    Raises
    ------
    ChunkError
        Naming the file: unreadable, a column missing or of another length,
        another cell's (or other settings'), other trials of this cell.
    """
    need = ["trial", "chi2", "success", "confirmed"] + [f"est_{n}" for n in params] + [f"std_{n}" for n in params]
    where = str(path)
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head[:2] != b"PK":  # np.load would try a pickle (its allow_pickle advice) or an .npy
        what = "an empty file" if not head else "not an npz archive (a chunk file is a zip of arrays)"
        raise ChunkError(f"not a readable chunk file ({what}): {_DELETE}", where=where)
    try:  # our handle: np.load leaks its own when the zip is unreadable
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as z:
            files = set(z.files)
            missing = [k for k in need if k not in files]
            if missing:
                raise ChunkError(f"not a complete chunk file (no column {missing[0]}): {_DELETE}", where=where)
            cols = {k: z[k] for k in z.files}
    except ChunkError:
        raise
    except _UNREADABLE as exc:
        why = str(exc).strip() or type(exc).__name__
        raise ChunkError(f"not a readable chunk file ({why}): {_DELETE}", where=where) from None
    if "cell" in cols or "cell_sha256" in cols:
        have_id = str(cols["cell"]) if "cell" in cols and cols["cell"].ndim == 0 else None
        have_digest = str(cols["cell_sha256"]) if "cell_sha256" in cols and cols["cell_sha256"].ndim == 0 else None
        if have_id != cell_id:
            raise ChunkError(f"holds results of cell {have_id!r}, not of {cell_id!r} (a file copied or moved from "
                             f"another cell): {_DELETE}", where=where)
        if have_digest != digest:
            raise ChunkError(f"holds results of cell {cell_id!r} under other settings than its cell.json (a file "
                             f"copied from another run): {_DELETE}", where=where)
    trial = cols["trial"]
    if not np.issubdtype(trial.dtype, np.integer):
        raise ChunkError(f"not a valid chunk file (its trial column holds {trial.dtype} values, not integers): "
                         f"{_DELETE}", where=where)
    for k in need[1:]:
        kind = "b" if k in ("success", "confirmed") else "f"
        if cols[k].dtype.kind != kind:
            raise ChunkError(f"not a valid chunk file (its column {k} holds {cols[k].dtype} values, not "
                             f"{'booleans' if kind == 'b' else 'floating-point numbers'}): {_DELETE}", where=where)
    n = trial.shape[0] if trial.ndim == 1 else -1
    if n < 1 or any(cols[k].shape != (n,) for k in need):
        raise ChunkError(f"not a valid chunk file (its columns are not {max(n, 0)} values each): {_DELETE}",
                         where=where)
    if not np.array_equal(trial, np.arange(trial[0], trial[0] + n)):
        raise ChunkError(f"not a valid chunk file (its trial column is not consecutive trials): {_DELETE}",
                         where=where)
    if int(trial[0]) != start:
        raise ChunkError(f"holds trials {int(trial[0])}..{int(trial[-1])}, this chunk is trials {start}..{stop - 1} "
                         f"(a file copied or renamed): {_DELETE}", where=where)
    ok = cols["success"]
    for k in [f"est_{p}" for p in params]:
        bad = np.flatnonzero(ok & ~np.isfinite(cols[k]))
        if bad.size:  # the runner marks a trial without a finite estimate failed: this file was altered
            raise ChunkError(f"not a valid chunk file (row {int(bad[0])}, trial {int(trial[bad[0]])}, is marked "
                             f"successful with {k} = {cols[k][bad[0]]}): {_DELETE}", where=where)
    if n != stop - start:
        return None  # trials changed: this (last) chunk is recomputed
    return cols if columns else True


def _cell_json(out, cell, study, check_only=False):
    """Write (or check) ``OUT/<cell>/cell.json``; a different existing one is an error.

    The file is the cell's settings and the study's name (``study``, not compared
    here: :func:`check_directory` checks it).
    """
    from zerocal_sym.io.files import atomic_write_text

    p = Path(out) / cell.id / "cell.json"
    want = cell.settings(study)
    if p.exists():
        try:
            have = json.loads(p.read_text())
        except (OSError, ValueError) as exc:
            why = "an empty file" if not p.stat().st_size else f"{type(exc).__name__}: {exc}"
            raise ZerocalError(f"not a readable cell record ({why}): delete this cell.json alone (not the chunk "
                               "files beside it: each records its cell and is checked on its own) and run the study "
                               "with --out, which writes it again", where=str(p)) from None
        if not isinstance(have, dict):
            raise ZerocalError("not a cell record (not a JSON object): delete this cell.json alone and run the "
                               "study with --out, which writes it again", where=str(p))
        have = {k: v for k, v in have.items() if k != "study"}
        if have != json.loads(json.dumps(want)):
            diff = sorted(k for k in want if have.get(k) != json.loads(json.dumps(want[k])))
            raise ZerocalError(f"this cell was run with other settings ({', '.join(diff) or 'format'}): use "
                               "another output directory or remove the cell's directory", where=str(p))
        return
    if not check_only:
        atomic_write_text(p, json.dumps({"format": want["format"], "study": study.name, **want}, indent=1) + "\n")


def _study_names(out: Path) -> tuple:
    """``(cells, names)``: the cell directories of ``out`` (those with a cell.json) and the study names recorded
    in their cell.json files and in summary.json."""
    cells, names = [], {}
    for p in sorted(out.iterdir()):
        if p.name.startswith(".") or not (p / "cell.json").is_file():
            continue
        cells.append(p.name)
        name = _recorded_study(p / "cell.json")  # (an unreadable cell.json: _cell_json reports it)
        if name is not None:
            names.setdefault(name, f"{p.name}/cell.json")
    name = _recorded_study(out / "summary.json")
    if name is not None:
        names.setdefault(name, "summary.json")
    return cells, names


def _recorded_study(path):
    """The study name a cell.json or summary.json records, or None (no file, unreadable, none recorded)."""
    try:
        name = json.loads(path.read_text()).get("study")
    except (OSError, ValueError, AttributeError):
        return None
    return name if isinstance(name, str) else None


def check_directory(out, study, run: bool) -> None:
    """Refuse a study directory that holds another study.

    ``out`` holds another study if a cell.json (or summary.json) there records
    another study name, or (``run``: the directory is written) it holds cells
    the spec does not have, or it holds files and no study at all.  Nothing
    is read but the cell.json and summary.json files.

    Raises
    ------
    ZerocalError
        Naming the directory, the other study and what to do.
    """
    out = Path(out)
    if not out.exists():
        return
    if not out.is_dir():
        raise ZerocalError("the study output must be a directory", where=str(out))
    cells, names = _study_names(out)
    other = sorted(n for n in names if n != study.name)
    if other:
        todo = ("give another --out directory" if run else "give that study's spec")
        raise ZerocalError(f"holds the study {other[0]!r} ({names[other[0]]}), not {study.name!r} (the name in "
                           f"{study.path}): {todo}, or set name = {other[0]!r} in the spec if it is the same study",
                           where=str(out))
    if not run:
        return
    ids = {c.id for c in study.cells}
    extra = [c for c in cells if c not in ids]
    if extra:
        shown = ", ".join(extra[:3]) + (f" and {len(extra) - 3} more" if len(extra) > 3 else "")
        raise ZerocalError(f"holds cells that {study.path} does not have ({shown}): another study's directory, or "
                           "the spec lost those cells; give another --out directory (or move those cells' "
                           "directories away)", where=str(out))
    if not cells and not (out / "summary.json").exists() and any(not p.name.startswith(".") for p in out.iterdir()):
        raise ZerocalError("is not empty and holds no study (no <cell>/cell.json): give a new or empty --out "
                           "directory", where=str(out))
