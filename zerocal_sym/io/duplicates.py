"""Repeated poses of a measurement or pose file: the helpers of :mod:`zerocal_sym.model.revisits`.

Kept importable from here (:func:`first_duplicate`, used by
:mod:`zerocal_sym.io.measurement_checks` and the pose checks).
"""
from zerocal_sym.model.revisits import (REVISIT_TOL, _first_duplicate_scan, consecutive_repeat,  # noqa: F401
                                        first_duplicate, pose_groups)
