"""What the calibration report shows, as numbers: read from a results file, its robot and (optionally) its data.

:func:`report_contents` gathers every section of the page
(:mod:`zerocal_sym.report.html` draws it) into a dict of plain values and
numpy arrays, so that tests compare numbers, not markup.  The numbers are the
results file's own (the offsets, their 1 sigma, the fit check, the error
budget) or computed from them (the accuracy maps,
:mod:`zerocal_sym.report.accuracy`).

The results file's optional ``error_budget`` (one entry per zero offset in
joint order: ``name``, ``noise_std`` and ``robot_file_bias`` in the offset's
unit, ``dominant_entries``: the robot-file entries dominating the bias) and
``limited_by`` (``"data"`` or ``"robot file"``) are checked by the results
file's loader (:mod:`zerocal_sym.io.result_budget`); a file without them
(written before them) says so on the page.
"""
from __future__ import annotations

import json
import math

import numpy as np

from zerocal_sym.errors import DataFileError
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units

#: a covariance's diagonal and the file's 1 sigma of the offsets: two copies of one number (relative)
SAME_STD_RTOL = 1e-6
#: the residuals of the data a result was identified from, recomputed at its estimate, agree with the file's to
#: round-off: a nanometre is far below any scale's resolution (mm)
SAME_DATA_TOL_MM = 1e-6


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def offsets_covariance(robot, rf):
    """The zero offsets' covariance, internal units (rad, mm), shape (m, m), and where it comes from.

    From the file's ``covariance`` (over ``params``) when present; else, from
    the offsets' 1 sigma, a diagonal one (their correlations unknown); else
    None.  A covariance whose diagonal disagrees with the 1 sigma the file
    states is an error (one copy was edited).

    Returns
    -------
    (ndarray or None, str)
    """
    raw, src, names = rf.raw, rf.source, list(robot.errors.zero_offsets)
    std = units.from_user(np.asarray(rf.std_zero_offsets_user, float), robot.errors.offset_unit)
    cov, params = raw.get("covariance"), raw.get("params")
    if cov is not None:
        p = len(params) if isinstance(params, list) else -1
        ok = (p > 0 and isinstance(cov, list) and len(cov) == p
              and all(isinstance(r, list) and len(r) == p and all(_number(v) for v in r) for r in cov))
        if not ok or not set(names) <= set(params):
            raise DataFileError("key 'covariance' must be a p x p matrix of finite numbers over 'params' (which "
                                f"hold the zero offsets {', '.join(names)})", where=src)
        idx = [params.index(n) for n in names]
        C = np.array(cov, float)[np.ix_(idx, idx)]
        s = np.sqrt(np.maximum(np.diag(C), 0.0))
        bad = [n for n, a, b in zip(names, s, std) if np.isfinite(b) and not math.isclose(a, b, rel_tol=SAME_STD_RTOL,
                                                                                           abs_tol=1e-15)]
        if bad:
            raise DataFileError(f"key 'covariance': the 1 sigma of {bad[0]} from it disagrees with the file's "
                                f"std of the zero offsets: one copy was edited", where=src)
        return C, "the results file's covariance"
    if np.all(np.isfinite(std)):
        return np.diag(std**2), "the offsets' 1 sigma (no covariance in the file: their correlations unknown)"
    return None, "not in this result file"


def error_budget(robot, rf):
    """The file's ``error_budget`` and ``limited_by`` (already checked against the rest of the file by
    :func:`zerocal_sym.io.results.load_result`: :mod:`zerocal_sym.io.result_budget`), or None when absent.

    Returns
    -------
    dict or None
        ``entries``: [{``name``, ``noise_std`` (float or None), ``robot_file_bias`` (floats, the offsets' unit),
        ``dominant_entries`` (list of str: each entry's name, tolerance and contribution)}], ``limited_by``
        (str or None), ``unit``.
    """
    raw = rf.raw
    budget, limited = raw.get("error_budget"), raw.get("limited_by")
    if budget is None and limited is None:
        return None
    u = rf.offset_unit

    def entry(d):
        if isinstance(d, str):
            return d
        return (f"{d['name']} (+-{d['tolerance']:.3g} {d.get('unit', '')}: {d['contribution']:.3g} {u})"
                .replace(" :", ":"))

    entries = [{"name": e["name"],
                "noise_std": None if e.get("noise_std") is None else float(e["noise_std"]),
                "robot_file_bias": float(e["robot_file_bias"]),
                "dominant_entries": [entry(d) for d in e.get("dominant_entries") or []]} for e in budget or []]
    return {"entries": entries, "limited_by": limited, "unit": u}


def tolerance_bias(rf):
    """The file's ``bias`` of the zero offsets (the errors left out, at their tolerances), or None."""
    zo = (rf.raw.get("bias") or {}).get("zero_offsets") if isinstance(rf.raw.get("bias"), dict) else None
    if not isinstance(zo, dict):
        return None
    u = zo.get("unit")
    worst, rms = zo.get(f"worst_case_{u}"), zo.get(f"rms_{u}")
    if not (isinstance(worst, list) and isinstance(rms, list) and len(worst) == len(rms) == rf.m
            and all(_number(v) for v in worst + rms)):
        return None
    return {"unit": u, "worst_case": [float(v) for v in worst], "rms": [float(v) for v in rms],
            "tolerances": (rf.raw["bias"].get("tolerances") or {})}


def _read(obj, key, kind, where, what):
    """``obj[key]`` of ``kind`` (``number``, ``bool``, ``str``) or None when missing or null; another type is an
    error naming ``what``."""
    v = obj.get(key)
    if v is None:
        return None
    ok = {"number": _number(v), "bool": isinstance(v, bool), "str": isinstance(v, str)}[kind]
    if not ok:
        raise DataFileError(f"{what}: '{key}' must be {'a finite number' if kind == 'number' else 'a ' + kind}, got "
                            f"{json.dumps(v)[:40]}", where=where)
    return float(v) if kind == "number" else v


def fit_record(rf):
    """The file's ``fit`` (the fit check's record) with the types the report reads checked, or None.

    Returns
    -------
    dict or None
        ``chi2``, ``dof``, ``p_value``, ``alpha`` (float or None); ``checked``, ``rejected``,
        ``accepted_despite_misfit`` (bool); ``reason``, ``diagnosis`` (str or None); ``warnings`` (list of str);
        ``readings`` [{``pose``, ``standardised``}]; ``worst`` ({``pose``, ``from_pose``, ``standardised``,
        ``estimated_error_mm``} or None); ``max_reading`` (the largest standardised residual's test:
        {``pose``, ``standardised``, ``readings``, ``p_value``, ``rejected``} or None).
    """
    fit, src = rf.raw.get("fit"), rf.source
    if fit is None:
        return None
    if not isinstance(fit, dict):
        raise DataFileError("key 'fit' must be an object (the fit check's record)", where=src)
    what = "key 'fit'"
    out = {k: _read(fit, k, "number", src, what) for k in ("chi2", "dof", "p_value", "alpha")}
    out.update({k: _read(fit, k, "bool", src, what) is True for k in ("checked", "rejected",
                                                                       "accepted_despite_misfit")})
    out.update({k: _read(fit, k, "str", src, what) for k in ("reason", "diagnosis")})
    warnings = fit.get("warnings") or []
    if not isinstance(warnings, list) or not all(isinstance(w, str) for w in warnings):
        raise DataFileError(f"{what}: 'warnings' must be a list of strings", where=src)
    out["warnings"] = warnings
    readings = fit.get("readings") or []
    if not isinstance(readings, list) or not all(isinstance(r, dict) for r in readings):
        raise DataFileError(f"{what}: 'readings' must be a list of objects, one per reading", where=src)
    out["readings"] = [{k: _read(r, k, "number", src, f"{what} readings") for k in ("pose", "standardised")}
                       for r in readings]
    w = fit.get("worst")
    if w is not None and not isinstance(w, dict):
        raise DataFileError(f"{what}: 'worst' must be an object (the worst reading)", where=src)
    out["worst"] = None if w is None else {k: _read(w, k, "number", src, f"{what} worst") for k in
                                           ("pose", "from_pose", "standardised", "estimated_error_mm")}
    m = fit.get("max_reading")
    if m is not None and not isinstance(m, dict):
        raise DataFileError(f"{what}: 'max_reading' must be an object (the largest standardised residual's test)",
                            where=src)
    out["max_reading"] = None if m is None else {
        **{k: _read(m, k, "number", src, f"{what} max_reading") for k in ("pose", "standardised", "readings",
                                                                           "p_value")},
        "rejected": _read(m, "rejected", "bool", src, f"{what} max_reading") is True}
    return out


def data_poses(robot, meas) -> np.ndarray:
    """The measured poses (internal units), shape (K, n): the file's targets, else where the commands lead."""
    if meas.target is not None:
        return np.asarray(meas.target, float)
    return kin.fk(robot, meas.theta_cmd)


def residuals(rf, meas=None, robot=None):
    """The residuals per reading: the file's at the estimate, and with the data the nominal model's.

    With the data, the file's residuals are recomputed from them at the file's estimate (the exact model): data
    they do not reproduce are not the data the result was identified from (a DataFileError naming both).

    Returns
    -------
    dict or None
        ``pose`` (K-1,) 1..K-1, ``after_mm`` (K-1,), ``before_mm`` (K-1,) or None, ``method``; None when the
        file holds no residuals.
    """
    r = rf.raw.get("residuals_mm")
    if not isinstance(r, list) or not r or not all(_number(v) for v in r):
        return None
    after = np.array(r, float)
    before = None
    if meas is not None:
        if meas.K - 1 != after.size:
            raise DataFileError(f"the data have {meas.K} poses ({meas.K - 1} readings), the result {after.size} "
                                f"residuals ({rf.source}): not the data this result was identified from",
                                where=meas.source)
        readings = np.asarray(meas.readings, float)[1:]
        before = readings - np.diff(kin.distance(robot, meas.theta_cmd))
        if rf.estimate:  # the same data at the same estimate: the same residuals, to round-off
            errors = robot.errors
            err = errors.vector({n: errors.from_user_value(n, v) for n, v in rf.estimate.items()})
            with np.errstate(all="ignore"):
                again = readings - np.diff(kin.distance(robot, meas.theta_cmd, err))
            worst = float(np.max(np.abs(again - after))) if np.all(np.isfinite(again)) else math.inf
            if not worst <= SAME_DATA_TOL_MM:
                raise DataFileError(f"not the data the result {rf.source} was identified from: its residuals at the "
                                    f"estimate differ from these data's by up to {worst:.3g} mm", where=meas.source)
    return {"pose": np.arange(1, after.size + 1), "after_mm": after, "before_mm": before, "method": rf.method,
            "rms_after_mm": float(np.sqrt(np.mean(after**2))),
            "rms_before_mm": None if before is None else float(np.sqrt(np.mean(before**2)))}


def report_contents(robot, rf, meas=None, verdict: str = "", accepted: bool = True, cells=None) -> dict:
    """Every section of the report as numbers (module docstring).

    Parameters
    ----------
    robot : Robot
    rf : ResultFile
        :func:`zerocal_sym.io.results.load_result` (``allow_failed=True``).
    meas : Measurements, optional
        The data the result was identified from: the poses and the nominal model's residuals.
    verdict : str
        The verdict line (the CLI's).
    accepted : bool
        False: a rejected result; its offsets and accuracy are not reported.
    cells : int, optional
        The accuracy maps' cells along the longer side.
    """
    from zerocal_sym.report.accuracy import MAP_CELLS, accuracy_map

    errors = robot.errors
    cov, cov_source = offsets_covariance(robot, rf)
    maemm = [{"name": n, "value": float(v), "std": float(rf.std.get(n, math.nan))}
             for n, v in zip(errors.measuring, rf.maemm_mm)]
    data = rf.raw.get("data") if isinstance(rf.raw.get("data"), dict) else {}
    data = {"file": _read(data, "file", "str", rf.source, "key 'data'"), "K": _read(data, "K", "number", rf.source,
                                                                                     "key 'data'")}
    std_kind = _read(rf.raw, "std_kind", "str", rf.source, "the results file")
    out = {
        "robot": {"name": robot.name, "mechanism": robot.mechanism_name, "source": robot.source,
                  "sha256": robot.sha256, "description": robot.mechanism.description},
        "result": {"source": rf.source, "method": rf.method, "status": rf.status, "success": rf.success,
                   "std_kind": std_kind, "data_file": data["file"],
                   "K": None if data["K"] is None else int(data["K"])},
        "verdict": verdict, "accepted": bool(accepted), "unit": rf.offset_unit,
        "offsets": [{"name": n, "value": float(v), "std": float(s)}
                    for n, v, s in zip(errors.zero_offsets, rf.zero_offsets_user, rf.std_zero_offsets_user)],
        "maemm": maemm, "covariance": cov, "covariance_source": cov_source,
        "error_budget": error_budget(robot, rf), "bias": tolerance_bias(rf),
        "fit": fit_record(rf),
        "residuals": residuals(rf, meas, robot),
        "poses": None if meas is None else data_poses(robot, meas),
        "data_source": None if meas is None else meas.source,
        "accuracy": None,
    }
    if accepted:
        out["accuracy"] = accuracy_map(robot, rf.zero_offsets, cov, cells or MAP_CELLS)
    return out
