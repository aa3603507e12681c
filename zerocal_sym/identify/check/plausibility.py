"""Reasons to refuse a result as a calibration: not a calibration, or offsets and a MAEMM no robot has.

:func:`plausibility` lists them (an empty list: plausible), against
:data:`DEFAULT_MAX_OFFSET` (per unit of the zero offsets) and
:data:`DEFAULT_MAX_MAEMM_MM`.
"""
from __future__ import annotations

import math

import numpy as np

#: a zero offset beyond this (deg) is not a zero offset but a wrong joint zero / sign / robot file
DEFAULT_MAX_OFFSET_DEG = 10.0
#: the same per file unit of the zero offsets (deg: revolute joints, mm: prismatic ones)
DEFAULT_MAX_OFFSET = {"deg": DEFAULT_MAX_OFFSET_DEG, "mm": 10.0}
#: a MAEMM (norm, mm) beyond this is not an assembly error but a wrong measuring-mechanism geometry
DEFAULT_MAX_MAEMM_MM = 50.0


def plausibility(robot, result, max_offset: float | None = None,
                 max_maemm_mm: float = DEFAULT_MAX_MAEMM_MM, max_offset_deg: float | None = None) -> list:
    """Reasons not to use ``result`` as a calibration (empty list: plausible).

    ``result``: an :class:`~zerocal_sym.identify.result.IdentificationResult`
    or a results file read by :func:`zerocal_sym.io.results.load_result`
    (``load_result(path, allow_failed=True, robot=robot)``, so that a failed
    one is reported here rather than refused there).

    * not a calibration: ``success`` is False (not converged, not
      identifiable, the fit rejected) -- a result accepted despite misfit is
      one;
    * a zero offset beyond ``max_offset`` (in the joints' unit; default 10
      deg for revolute joints: far beyond a homing error; the first-order
      model and TSVD's linearisation fail there, and it usually is a wrong
      joint zero, sign or robot file; 10 mm for prismatic joints: beyond an
      endstop's repeatability, a wrong robot file); ``max_offset_deg``, its
      former name, for revolute joints;
    * a MAEMM (norm of the measuring mechanism's assembly error) beyond
      ``max_maemm_mm`` (default 50 mm, ~7 % of the planar robot's measuring
      length: not an assembly error but a wrong ``c``/``d`` in the robot
      file);
    * a non-finite estimate or standard deviation of an offset; a MAEMM that
      is not finite (a results file without one: unknown, not a reason).
    """
    reasons = []
    if not result.success:
        reasons.append(f"the identification is not a calibration: {result.status}")
    errors = robot.errors
    unit = errors.offset_user_unit
    limit = max_offset if max_offset is not None else max_offset_deg
    limit = DEFAULT_MAX_OFFSET[unit] if limit is None else limit
    off = np.asarray(result.zero_offsets_user, float)
    for n, v in zip(errors.zero_offsets, off):
        if not np.isfinite(v):
            reasons.append(f"zero offset {n} is not a finite number")
        elif abs(v) > limit:
            reasons.append(f"zero offset {n} = {v:+.4g} {unit} is beyond the plausible {limit:g} {unit} "
                           "(a wrong joint zero, sign convention or robot file?)")
    params = getattr(result, "params", None)  # None: a results file (io.results.ResultFile)
    std = np.asarray(result.std_zero_offsets_user, float)
    for n, s in zip(errors.zero_offsets, std):
        if params is not None and n in params and not np.isfinite(s):
            reasons.append(f"the standard deviation of zero offset {n} is not finite (not identifiable)")
    mm = np.asarray(result.maemm_mm, float)
    norm = math.hypot(*mm.tolist()) if mm.size and np.all(np.isfinite(mm)) else None  # (no overflow: 1e308 mm)
    if norm is not None and norm > max_maemm_mm:
        reasons.append(f"MAEMM |rM| = {norm:.4g} mm is beyond the plausible {max_maemm_mm:g} mm "
                       "(the measuring mechanism's c / d in the robot file?)")
    elif mm.size and not np.all(np.isfinite(mm)) and params is not None:
        reasons.append("the MAEMM is not finite")
    return reasons
