"""The results JSON (what ``zerocal identify --json`` writes) and its reader.

Results JSON
------------
:func:`load_result` reads what ``zerocal identify --json`` writes, for any
mechanism: ``zero_offsets_deg`` (revolute joints; ``zero_offsets_mm`` for
prismatic ones: every offset key carries the joints' unit; joint order, m
values), ``std_zero_offsets_deg`` (m values or nulls), ``maemm_mm`` (the
measuring errors' order, u values), the
parameters by name (``estimate``, ``std``, ``units``) and, when present, the
``mechanism``.  The compensation table made from it is
:mod:`zerocal_sym.io.compensation`.

Only ``zero_offsets_deg`` is required; every other key is optional, and
``null`` for an optional key is the same as leaving it out.  Every key that
is read is checked against the others, so a hand edit of one copy of a value
is an error, not silently ignored: ``estimate`` and ``std`` against
``zero_offsets_deg``, ``std_zero_offsets_deg`` and ``maemm_mm``; the
``compensation`` block (``offset_deg``, ``std_deg``, ``joints``,
``sign_convention``) against the same; ``units`` against the mechanism;
``joint_names`` and ``pose_names`` against the mechanism; ``mechanism``
against ``robot.mechanism``; the robot hashes (``robot_sha256``,
``robot.sha256``, ``robot_hash``: 64 hexadecimal digits each) against each
other.  Standard deviations are >= 0 or null.

The error budget (``error_budget``, ``limited_by``; optional: files written
before it keep loading) is checked against the offsets' standard deviations
and itself: :mod:`zerocal_sym.io.result_budget`.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.model.units import DegreeViews
from zerocal_sym.io.csvtext import (_finite_number, _load_json, _read_text, _where, get_mechanism_of, read_as,
                                    unknown_mechanism_message, with_reading_hint)
from zerocal_sym.io.result_budget import check_error_budget

#: the unit of the zero offsets at the file edge of a revolute mechanism (a prismatic one's: mm); every key that
#: names them is made from the unit here (:func:`offset_keys`)
OFFSET_UNIT = "deg"


def sign_convention(unit: str = OFFSET_UNIT) -> str:
    """The sign convention of every file that carries offsets (a results file's ``compensation.sign_convention``)."""
    what = "angle" if unit == "deg" else "position"
    return f"theta_cmd = IK(P) - offset_{unit} (actual joint {what} = commanded + offset)"


#: the revolute mechanisms' sign convention (the files written before prismatic joints)
SIGN_CONVENTION = sign_convention()


def offset_keys(unit: str = OFFSET_UNIT) -> tuple:
    """``(zero_offsets_<u>, std_zero_offsets_<u>, (offset_<u>, std_<u>))``: the keys of the offsets in the unit."""
    return f"zero_offsets_{unit}", f"std_zero_offsets_{unit}", (f"offset_{unit}", f"std_{unit}")


OFFSETS_KEY, STD_OFFSETS_KEY, COMPENSATION_KEYS = offset_keys()
MAEMM_KEY = "maemm_mm"
#: two copies of one value (a key and ``estimate``, ``compensation``) agree within this (relative and absolute)
SAME_VALUE_TOL = 1e-9
#: a robot hash: what ``zerocal robot`` prints (SHA-256, hexadecimal)
SHA256_RE = re.compile(r"[0-9a-fA-F]{64}")


@dataclass
class ResultFile(DegreeViews):
    """The parts of a results JSON that a compensation needs.

    Attributes
    ----------
    zero_offsets_user : ndarray, shape (m,)
        Joint order, in the file's unit (:attr:`offset_unit`: deg for revolute joints, mm for prismatic ones).
    std_zero_offsets_user : ndarray, shape (m,)
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
        The mechanism: the robot's it was loaded for, else the file's
        ``mechanism`` key, else the default mechanism (None only for a
        ResultFile made otherwise than by :func:`load_result`).
    estimate, std : dict of str -> float
        Every identified parameter by name, user units (``units``); NaN for
        an unknown standard deviation.  Empty if the file has none.
    units : dict of str -> str
    """

    zero_offsets_user: np.ndarray
    std_zero_offsets_user: np.ndarray
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
    offset_unit: str = OFFSET_UNIT

    @property
    def zero_offsets(self) -> np.ndarray:
        """The zero offsets in internal units (rad, mm), shape (m,)."""
        from zerocal_sym.model.units import from_user

        return from_user(self.zero_offsets_user, "rad" if self.offset_unit == "deg" else "mm")

    @property
    def m(self) -> int:
        return len(self.zero_offsets_user)

    @property
    def n(self) -> int:
        return len(self.maemm_mm)

    @property
    def joint_names(self) -> list:
        """The mechanism's joint names (``theta1`` ... by position if the mechanism is unknown)."""
        if self.mechanism is not None:
            return list(get_mechanism_of(self.mechanism).joint_names)
        return [f"theta{j + 1}" for j in range(self.m)]


def _vector(obj, key, names, text, src, required=True, std=False):
    """The list ``obj[key]`` of ``len(names)`` numbers (nulls allowed unless required; ``std``: >= 0), ndarray.

    An optional key that is missing or ``null`` is all NaN.
    """
    where = _where(text, key, src)
    k = len(names)
    if obj.get(key) is None:
        if required:
            raise DataFileError(f"missing key '{key}' (a results file from 'zerocal identify --json')",
                                where=where if key in obj else src)
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
        if std and x < 0:
            raise DataFileError(f"key '{key}': a standard deviation must be >= 0 (or null if unknown), got "
                                f"{json.dumps(v)[:60]}", where=where)
        out.append(float(x))
    return np.array(out)


def _robot_block(obj, text, src) -> dict:
    """The ``robot`` object ({} if missing or null)."""
    r = obj.get("robot")
    if r is None:
        return {}
    if not isinstance(r, dict):
        raise DataFileError("key 'robot' must be an object {name, source, sha256, mechanism}",
                            where=_where(text, "robot", src))
    return r


def _find_sha(obj, text, src):
    """The robot hash: ``robot_sha256``, ``robot.sha256``, ``robot_hash``, each 64 hex digits, all the same; or None."""
    found = []
    for key, v in (("robot_sha256", obj.get("robot_sha256")), ("sha256", _robot_block(obj, text, src).get("sha256")),
                   ("robot_hash", obj.get("robot_hash"))):
        if v is None:
            continue
        label = "robot.sha256" if key == "sha256" else key
        if not isinstance(v, str) or not SHA256_RE.fullmatch(v):
            raise DataFileError(f"key '{label}' must be the robot's SHA-256, 64 hexadecimal digits ('zerocal robot' "
                                f"prints it), got {json.dumps(v)[:80]}", where=_where(text, key, src))
        found.append((label, v.lower(), key))
    for label, v, key in found[1:]:
        if v != found[0][1]:
            raise DataFileError(f"key '{label}' ({v[:12]}...) and '{found[0][0]}' ({found[0][1][:12]}...) name "
                                "different robots: one result is of one robot", where=_where(text, key, src))
    return found[0][1] if found else None


def _find_mechanism(obj, text, src):
    """The ``mechanism`` key (and ``robot.mechanism``, which must agree), checked; None without."""
    from zerocal_sym.model.mechanism import is_known

    named = [(k, v) for k, v in (("mechanism", obj.get("mechanism")),
                                 ("robot.mechanism", _robot_block(obj, text, src).get("mechanism"))) if v is not None]
    for k, v in named:
        if not isinstance(v, str) or not is_known(v):
            raise DataFileError(f"key '{k}': " + unknown_mechanism_message(v if isinstance(v, str) else
                                                                         json.dumps(v)[:60]),
                                where=_where(text, "mechanism", src))
    if len(named) == 2 and named[0][1] != named[1][1]:
        raise DataFileError(f"key 'mechanism' is {named[0][1]}, 'robot.mechanism' is {named[1][1]}: one result is of "
                            "one mechanism", where=_where(text, "mechanism", src))
    return named[0][1] if named else None


def _by_name(obj, key, mech, text, src, kind):
    """``obj[key]``: {name: number (or null for std, >= 0) | unit string}, names of ``mech`` if known ({} if null)."""
    v = obj.get(key)
    if v is None:
        return {}
    where = _where(text, key, src)
    if not isinstance(v, dict):
        raise DataFileError(f"key '{key}' must be an object {{parameter name: value}}", where=where)
    out = {}
    for name, x in v.items():
        if mech is not None and name not in mech.errors.names:
            raise DataFileError(f"key '{key}': unknown parameter {name!r} of mechanism {mech.name} (known: "
                                f"{', '.join(mech.errors.names)})", where=where)
        if kind == "unit":
            want = (mech.errors[name].user_unit,) if mech is not None else ("deg", "mm")
            if x not in want:
                raise DataFileError(f"key '{key}': the unit of {name!r} must be "
                                    f"{' or '.join(json.dumps(w) for w in want)}, got {json.dumps(x)[:30]}",
                                    where=where)
            out[name] = x
            continue
        if x is None and kind == "std":
            out[name] = float("nan")
            continue
        if not _finite_number(x):
            raise DataFileError(f"key '{key}': {name!r} must be a finite number, got {json.dumps(x)[:30]}",
                                where=where)
        if kind == "std" and x < 0:
            raise DataFileError(f"key '{key}': the standard deviation of {name!r} must be >= 0 (or null if "
                                f"unknown), got {json.dumps(x)[:30]}", where=where)
        out[name] = float(x)
    return out


def _merge(copy_key, copy: dict, key, names, values, text, src) -> np.ndarray:
    """``values`` (for ``names``) with the other copy ``copy`` ({name: value}) merged in.

    Where both copies give a number they must agree (within
    :data:`SAME_VALUE_TOL`): the error names both keys.  Where only one does
    (the other missing or null), that number is the value.
    """
    out = np.array(values, float)
    for j, name in enumerate(names):
        c = copy.get(name, math.nan)
        if math.isnan(c):
            continue
        if math.isnan(out[j]):
            out[j] = c
        elif not math.isclose(c, out[j], rel_tol=SAME_VALUE_TOL, abs_tol=SAME_VALUE_TOL):
            raise DataFileError(f"key '{copy_key}': {name} = {float(c)!r} disagrees with '{key}' ({float(out[j])!r}): "
                                "one of the two copies was edited; make them the same",
                                where=_where(text, copy_key, src))
    return out


def _check_names(obj, key, want, text, src) -> None:
    v = obj.get(key)
    if v is not None and v != list(want):
        raise DataFileError(f"key '{key}' must be {json.dumps(list(want))} (the mechanism's), got {json.dumps(v)[:80]}",
                            where=_where(text, key, src))


def _compensation(obj, names, off, std, joints, text, src, unit=OFFSET_UNIT) -> np.ndarray:
    """The ``compensation`` block, if any: the same offsets, std, joints and sign convention as the rest.

    Returns ``std`` with the block's ``std_deg`` merged in (:func:`_merge`).
    """
    c = obj.get("compensation")
    if c is None:
        return std
    where = _where(text, "compensation", src)
    if not isinstance(c, dict):
        raise DataFileError(f"key 'compensation' must be an object {{sign_convention, joints, offset_{unit}, "
                            f"std_{unit}}}", where=where)
    sign = c.get("sign_convention")
    if sign is not None and sign != sign_convention(unit):
        raise DataFileError(f"key 'compensation': sign_convention {json.dumps(sign)[:80]} is not zerocal's "
                            f"({sign_convention(unit)!r}): the offsets would be applied with the wrong sign",
                            where=_where(text, "sign_convention", src))
    if joints is not None:
        _check_names(c, "joints", joints, text, src)
    offsets_key, std_offsets_key, (off_key, std_key) = offset_keys(unit)
    comp_off = _vector(c, off_key, names, text, src, required=False)
    comp_std = _vector(c, std_key, names, text, src, required=False, std=True)
    _merge(off_key, dict(zip(names, comp_off)), offsets_key, names, off, text, src)
    return _merge(std_key, dict(zip(names, comp_std)), std_offsets_key, names, std, text, src)


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
        the mechanism is the file's ``mechanism``, or (none named) the
        default mechanism: never guessed from the sizes, and sizes that do
        not fit are an error saying what the file was read as.

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
    if robot is not None and declared is not None and declared != robot.mechanism_name:
        raise DataFileError(f"identified with mechanism {declared}, the robot file is {robot.mechanism_name} "
                            f"({robot.source}): pass the robot file of the identified robot",
                            where=_where(text, "mechanism", src))
    mech, reason = read_as(robot, declared)

    def fits(read, *args, **kw):
        """``read(*args)``; a file naming no mechanism is told what it was read as when it does not fit."""
        try:
            return read(*args, **kw)
        except DataFileError as exc:
            if declared is None:
                raise with_reading_hint(exc, mech, reason) from None
            raise

    names, measuring = mech.errors.zero_offsets, mech.errors.measuring
    unit = mech.errors.offset_user_unit
    offsets_key, std_offsets_key, _ = offset_keys(unit)
    off = fits(_vector, obj, offsets_key, names, text, src)
    std = fits(_vector, obj, std_offsets_key, names, text, src, required=False, std=True)
    maemm = fits(_vector, obj, MAEMM_KEY, measuring, text, src, required=False)
    success = obj.get("success", True)
    for key in ("status", "method"):
        if obj.get(key) is not None and not isinstance(obj[key], str):
            raise DataFileError(f"key '{key}' must be a string, got {json.dumps(obj[key])[:60]}",
                                where=_where(text, key, src))
    status = obj.get("status") or ""
    if not isinstance(success, bool):
        raise DataFileError("key 'success' must be true or false", where=_where(text, "success", src))
    if not success and not allow_failed:
        raise DataFileError(f"the identification failed (status: {status or '?'}); it must not be used as a "
                            "calibration", where=_where(text, "success", src))
    estimate = fits(_by_name, obj, "estimate", mech, text, src, "value")
    stds = fits(_by_name, obj, "std", mech, text, src, "std")
    units = fits(_by_name, obj, "units", mech, text, src, "unit")
    off = _merge("estimate", estimate, offsets_key, names, off, text, src)
    std = _merge("std", stds, std_offsets_key, names, std, text, src)
    maemm = _merge("estimate", estimate, MAEMM_KEY, measuring, maemm, text, src)
    fits(_check_names, obj, "joint_names", mech.joint_names, text, src)
    fits(_check_names, obj, "pose_names", mech.pose_names, text, src)
    std = _compensation(obj, names, off, std, mech.joint_names, text, src, unit)
    fits(check_error_budget, obj, mech, std, unit, text, src, SAME_VALUE_TOL)
    return ResultFile(off, std, maemm, obj.get("method") or "?", status, success, _find_sha(obj, text, src), obj, src,
                      mechanism=mech.name, estimate=estimate, std=stds, units=units, offset_unit=unit)

