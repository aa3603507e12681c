"""The results JSON (what ``zerocal identify --json`` writes) and its reader.

Results JSON
------------
:func:`load_result` reads what ``zerocal identify --json`` writes.  The
compensation table made from it is :mod:`zerocal_sym.io.compensation`.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import _json_line, _load_json, _read_text


@dataclass
class ResultFile:
    """The parts of a results JSON that a compensation needs.

    Attributes
    ----------
    zero_offsets_deg : ndarray, shape (2,)
    std_zero_offsets_deg : ndarray, shape (2,)
        NaN where unknown.
    maemm_mm : ndarray, shape (2,)
        NaN where unknown.
    method, status : str
    success : bool
    robot_sha256 : str or None
    raw : dict
        The whole JSON object.
    source : str
    """

    zero_offsets_deg: np.ndarray
    std_zero_offsets_deg: np.ndarray
    maemm_mm: np.ndarray
    method: str
    status: str
    success: bool
    robot_sha256: str | None
    raw: dict
    source: str


def _vec2(obj, key, text, src, required=True):
    where = f"{src}:{_json_line(text, key)}" if _json_line(text, key) else src
    if key not in obj:
        if required:
            raise DataFileError(f"missing key '{key}' (a results file from 'zerocal identify --json')", where=src)
        return np.full(2, np.nan)
    v = obj[key]
    if not isinstance(v, list) or len(v) != 2:
        raise DataFileError(f"key '{key}' must be a list of 2 numbers, got {json.dumps(v)[:60]}", where=where)
    out = []
    for x in v:
        if x is None and not required:
            out.append(np.nan)
            continue
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise DataFileError(f"key '{key}' must be a list of 2 finite numbers, got {json.dumps(v)[:60]}",
                                where=where)
        out.append(float(x))
    return np.array(out)


def _find_sha(obj):
    for k in ("robot_sha256", "robot_hash"):
        if isinstance(obj.get(k), str):
            return obj[k]
    r = obj.get("robot")
    if isinstance(r, dict) and isinstance(r.get("sha256"), str):
        return r["sha256"]
    return None


def load_result(path, allow_failed: bool = False) -> ResultFile:
    """Read a results JSON (``zerocal identify --json``).

    Parameters
    ----------
    path : str or Path
    allow_failed : bool
        Accept a result whose ``success`` is false (otherwise an error: a
        failed identification must not be used as a calibration).

    Returns
    -------
    ResultFile

    Raises
    ------
    DataFileError
        Naming the file and the line of the offending key.
    """
    text, src = _read_text(path, "results file")
    if not text.strip():
        raise DataFileError("empty results file", where=src)
    obj = _load_json(text, src)
    if not isinstance(obj, dict):
        raise DataFileError("a results file is a JSON object {...}", where=src)
    off = _vec2(obj, "zero_offsets_deg", text, src)
    std = _vec2(obj, "std_zero_offsets_deg", text, src, required=False)
    maemm = _vec2(obj, "maemm_mm", text, src, required=False)
    success = obj.get("success", True)
    status = str(obj.get("status", ""))
    if not isinstance(success, bool):
        raise DataFileError("key 'success' must be true or false", where=f"{src}:{_json_line(text, 'success')}")
    if not success and not allow_failed:
        raise DataFileError(f"the identification failed (status: {status or '?'}); it must not be used as a "
                            "calibration", where=f"{src}:{_json_line(text, 'success')}")
    return ResultFile(off, std, maemm, str(obj.get("method", "?")), status, success, _find_sha(obj), obj, src)
