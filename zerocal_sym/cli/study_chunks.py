"""The files of a study's results: one per chunk of trials of a cell, and the cell's settings.

Each chunk is written atomically (temporary file + ``os.replace``) to
``OUT/<cell-id>/chunk-<k>.npz``, one array per column:

``trial`` (int64), ``est_<param>`` and ``std_<param>`` per identified
parameter (rad / mm), ``chi2``, ``success``, ``confirmed`` (bool) and
``time_s`` (the identification time of the chunk, 0-d).

A chunk is read back only if it holds exactly the expected trials
(:func:`read_chunk`; e.g. after ``trials`` changed it is recomputed).
``OUT/<cell-id>/cell.json`` records the cell's settings
(:meth:`~zerocal_sym.cli.study_spec.Cell.settings`); a rerun whose settings
differ (other than ``trials``) is refused (:func:`_cell_json`).
"""
from __future__ import annotations

import io
import json
import re
from pathlib import Path

import numpy as np

from zerocal_sym.errors import ZerocalError

_CHUNK_RE = re.compile(r"^chunk-(\d+)\.npz$")


def chunk_path(out, cell, k) -> Path:
    return Path(out) / cell.id / f"chunk-{k}.npz"


def write_chunk(path, cols: dict, params) -> None:
    """One chunk's columns to ``path`` (npz, one array per column), atomically."""
    from zerocal_sym.io.files import atomic_write_bytes

    arrays = {"trial": cols["trial"]}
    for j, n in enumerate(params):
        arrays[f"est_{n}"] = cols["estimate"][:, j]
    for j, n in enumerate(params):
        arrays[f"std_{n}"] = cols["std"][:, j]
    arrays.update(chi2=cols["chi2"], success=cols["success"], confirmed=cols["confirmed"],
                  time_s=np.asarray(cols.get("time_s", 0.0)))
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())


def read_chunk(path, params, start, stop, columns: bool = True):
    """The columns of a chunk file if it holds exactly trials ``start .. stop-1`` of these parameters, else None.

    ``columns=False``: only check (reads the ``trial`` column alone) and return True or None.
    """
    need = ["trial", "chi2", "success", "confirmed"] + [f"est_{n}" for n in params] + [f"std_{n}" for n in params]
    try:
        with np.load(path) as z:
            if any(k not in z.files for k in need) or not np.array_equal(z["trial"], np.arange(start, stop)):
                return None
            return {k: z[k] for k in z.files} if columns else True
    except (OSError, ValueError, EOFError, KeyError):
        return None


def _cell_json(out, cell, study, check_only=False):
    """Write (or check) ``OUT/<cell>/cell.json``; a different existing one is an error."""
    from zerocal_sym.io.files import atomic_write_text

    p = Path(out) / cell.id / "cell.json"
    want = cell.settings(study)
    if p.exists():
        try:
            have = json.loads(p.read_text())
        except (OSError, ValueError):
            have = None
        if have != json.loads(json.dumps(want)):
            diff = sorted(k for k in want if have is None or have.get(k) != json.loads(json.dumps(want[k])))
            raise ZerocalError(f"this cell was run with other settings ({', '.join(diff) or 'unreadable'}): use "
                               "another output directory or remove the cell's directory", where=str(p))
        return
    if not check_only:
        atomic_write_text(p, json.dumps(want, indent=1) + "\n")
