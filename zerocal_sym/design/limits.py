"""What a design request may ask, and the error raised when it cannot be met.

:class:`DesignError`; the bounds on the number of poses K (:data:`MIN_K`,
:func:`min_k`, :data:`MAX_K`, :data:`MAX_K_EXACT`, checked by
:func:`_check_k`); the paper's scale range :data:`SCALE_RANGE_MM` and the
travel modes; the feasibility tolerance; the check of a number given for a
constraint (:func:`_finite`).
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.design.terms import design_params

#: smallest K for the planar robot (p = 4 parameters; in general p + 1, see :func:`min_k`)
MIN_K = 5
#: largest K accepted (the approximate design; K = 1000 takes seconds)
MAX_K = 5000
#: largest K of the exact method (exchange + Ipopt: time grows roughly as K^2, ~15 s at K = 40 with 3 starts,
#: 1207 s at K = 100 with the default 8 + 8 starts)
MAX_K_EXACT = 100
#: the paper's scale range l0, mm
SCALE_RANGE_MM = 350.0
TRAVEL_MODES = ("range", "consecutive")
_FEAS_TOL = 1e-6


class DesignError(ZerocalError):
    """A design request that cannot be met (bad K, region, criterion, constraints)."""


def _finite(name, v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise DesignError(f"{name} must be a number, got {v!r}") from None
    if not math.isfinite(v):
        raise DesignError(f"{name} must be finite, got {v!r}")
    return v


def min_k(robot=None) -> int:
    """Smallest K: ``p + 1`` poses for the p = m + n parameters (K - 1 >= p changes); :data:`MIN_K` without a robot."""
    return MIN_K if robot is None else max(MIN_K, len(design_params(robot)) + 1)


def _check_k(K, robot=None):
    """Raise :class:`DesignError` unless K is an integer in [:func:`min_k`, :data:`MAX_K`]."""
    if isinstance(K, bool) or not isinstance(K, (int, np.integer)):
        raise DesignError(f"K must be an integer number of poses, got {K!r}")
    kmin = min_k(robot)
    p = kmin - 1 if robot is not None else 4
    if K < kmin:
        raise DesignError(f"K = {K} is too small: at least {kmin} poses are needed to identify the {p} "
                          f"parameters (K - 1 >= {p} measured changes)")
    if K > MAX_K:
        raise DesignError(f"K = {K} is too large (at most {MAX_K})")
