"""The results JSON (what ``zerocal identify --json`` writes) and its reader.

Results JSON
------------
:func:`load_result` reads what ``zerocal identify --json`` writes, for any
mechanism: ``zero_offsets_deg`` (joint order, m values), ``std_zero_offsets_deg``
(m values or nulls), ``maemm_mm`` (pose-coordinate order, n values), the
parameters by name (``estimate``, ``std``, ``units``) and, when present, the
``mechanism``.  The compensation table made from it is
:mod:`zerocal_sym.io.compensation`.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.io.csvtext import _json_line, _load_json, _read_text, get_mechanism_of, mechanism_for_shape


@dataclass
class ResultFile:
    """The parts of a results JSON that a compensation needs.

    Attributes
    ----------
    zero_offsets_deg : ndarray, shape (m,)
        Joint order.
    std_zero_offsets_deg : ndarray, shape (m,)
        NaN where unknown.
    maemm_mm : ndarray, shape (n,)
        Pose-coordinate order; NaN where unknown.
    method, status : str
    success : bool
    robot_sha256 : str or None
    raw : dict
        The whole JSON object.
    source : str
    mechanism : str or None
        The mechanism: the file's ``mechanism`` key, else the robot's it was
        loaded for, else the registered mechanism with m joints (None if
        that is not unique).
    estimate, std : dict of str -> float
        Every identified parameter by name, user units (``units``); NaN for
        an unknown standard deviation.  Empty if the file has none.
    units : dict of str -> str
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
    mechanism: str | None = None
    estimate: dict = field(default_factory=dict)
    std: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)

    @property
    def m(self) -> int:
        return len(self.zero_offsets_deg)

    @property
    def n(self) -> int:
        return len(self.maemm_mm)

    @property
    def joint_names(self) -> list:
        """The mechanism's joint names (``theta1`` ... by position if the mechanism is unknown)."""
        if self.mechanism is not None:
            return list(get_mechanism_of(self.mechanism).joint_names)
        return [f"theta{j + 1}" for j in range(self.m)]


def _finite_number(x) -> bool:
    """A JSON number that is a finite float (not a bool; an integer of 400 digits is not)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return False
    try:
        return math.isfinite(x)
    except OverflowError:  # an integer beyond any float
        return False


def _where(text, key, src):
    line = _json_line(text, key)
    return f"{src}:{line}" if line else src


def _vector(obj, key, names, text, src, required=True):
    """The list ``obj[key]`` of ``len(names)`` numbers (nulls allowed unless required), ndarray."""
    where = _where(text, key, src)
    k = len(names)
    if key not in obj:
        if required:
            raise DataFileError(f"missing key '{key}' (a results file from 'zerocal identify --json')", where=src)
        return np.full(k, np.nan)
    v = obj[key]
    if not isinstance(v, list) or len(v) != k:
        raise DataFileError(f"key '{key}' must be a list of {k} numbers ({', '.join(names)}), got "
                            f"{json.dumps(v)[:60]}", where=where)
    out = []
    for x in v:
        if x is None and not required:
            out.append(np.nan)
            continue
        if not _finite_number(x):
            raise DataFileError(f"key '{key}' must be a list of {k} finite numbers, got {json.dumps(v)[:60]}",
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


def _find_mechanism(obj, text, src):
    """The ``mechanism`` key (or ``robot.mechanism``), checked; None without."""
    from zerocal_sym.model.mechanism import REGISTRY

    v = obj.get("mechanism")
    if v is None and isinstance(obj.get("robot"), dict):
        v = obj["robot"].get("mechanism")
    if v is None:
        return None
    if not isinstance(v, str) or v not in REGISTRY:
        raise DataFileError(f"unknown mechanism {json.dumps(v)[:60]} (known: {', '.join(REGISTRY)})",
                            where=_where(text, "mechanism", src))
    return v


def _by_name(obj, key, mech, text, src, kind):
    """``obj[key]``: {name: number (or null for std) | unit string}, names of ``mech`` if known."""
    v = obj.get(key, {})
    where = _where(text, key, src)
    if not isinstance(v, dict):
        raise DataFileError(f"key '{key}' must be an object {{parameter name: value}}", where=where)
    out = {}
    for name, x in v.items():
        if mech is not None and name not in mech.errors.names:
            raise DataFileError(f"key '{key}': unknown parameter {name!r} of mechanism {mech.name} (known: "
                                f"{', '.join(mech.errors.names)})", where=where)
        if kind == "unit":
            if x not in ("deg", "mm"):
                raise DataFileError(f"key '{key}': the unit of {name!r} must be \"deg\" or \"mm\", got "
                                    f"{json.dumps(x)[:30]}", where=where)
            out[name] = x
            continue
        if x is None and kind == "std":
            out[name] = float("nan")
            continue
        if not _finite_number(x):
            raise DataFileError(f"key '{key}': {name!r} must be a finite number, got {json.dumps(x)[:30]}",
                                where=where)
        out[name] = float(x)
    return out


def load_result(path, allow_failed: bool = False, robot=None) -> ResultFile:
    """Read a results JSON (``zerocal identify --json``).

    Parameters
    ----------
    path : str or Path
    allow_failed : bool
        Accept a result whose ``success`` is false (otherwise an error: a
        failed identification must not be used as a calibration).
    robot : Robot, optional
        If given: a ``mechanism`` key must name the robot's mechanism, and
        the vectors have its m joints and n pose coordinates.  Without one,
        the mechanism is the file's ``mechanism``, or the registered one with
        ``len(zero_offsets_deg)`` joints (the default mechanism's sizes are
        expected if there is none).

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
    declared = _find_mechanism(obj, text, src)
    if robot is not None:
        if declared is not None and declared != robot.mechanism_name:
            raise DataFileError(f"identified with mechanism {declared}, the robot file is {robot.mechanism_name} "
                                f"({robot.source}): pass the robot file of the identified robot",
                                where=_where(text, "mechanism", src))
        mech = robot.mechanism
    elif declared is not None:
        mech = get_mechanism_of(declared)
    else:
        off = obj.get("zero_offsets_deg")
        mech = mechanism_for_shape(m=len(off)) if isinstance(off, list) else None
    shape_of = mech or get_mechanism_of(None)  # the sizes expected when the mechanism is unknown
    off = _vector(obj, "zero_offsets_deg", shape_of.errors.zero_offsets, text, src)
    std = _vector(obj, "std_zero_offsets_deg", shape_of.errors.zero_offsets, text, src, required=False)
    maemm = _vector(obj, "maemm_mm", shape_of.errors.measuring, text, src, required=False)
    success = obj.get("success", True)
    status = str(obj.get("status", ""))
    if not isinstance(success, bool):
        raise DataFileError("key 'success' must be true or false", where=_where(text, "success", src))
    if not success and not allow_failed:
        raise DataFileError(f"the identification failed (status: {status or '?'}); it must not be used as a "
                            "calibration", where=_where(text, "success", src))
    estimate = _by_name(obj, "estimate", mech, text, src, "value")
    stds = _by_name(obj, "std", mech, text, src, "std")
    units = _by_name(obj, "units", mech, text, src, "unit")
    return ResultFile(off, std, maemm, str(obj.get("method", "?")), status, success, _find_sha(obj), obj, src,
                      mechanism=None if mech is None else mech.name, estimate=estimate, std=stds, units=units)
