"""The result of one identification, whatever the method.

Estimates are always of the *total* source errors (rad, mm) in the
parameters' order, not of increments: an identification linearised at a prior
(the current compensation and MAEMM estimate) returns prior + increment.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.model.noise import SOURCE_ERROR_NAMES


@dataclass
class IdentificationResult:
    """One identification.

    Attributes
    ----------
    method : str
        ``"tsvd"`` or ``"nlls"`` (or another registered method).
    params : tuple of str
        Names (from :data:`~zerocal_sym.model.noise.SOURCE_ERROR_NAMES`) of the
        identified parameters.
    estimate : ndarray, shape (p,)
        Total source errors, rad for zero offsets, mm otherwise.
    covariance : ndarray, shape (p, p) or None
        Estimated covariance of ``estimate`` (same units).
    success : bool
        False for anything that must not be used as a calibration.
    status : str
        Human-readable status (solver message, rank deficiency, ...).
    residuals : ndarray, shape (K-1,)
        Measured minus predicted changes at the estimate, mm.
    info : dict
        Method-specific: ``singular_values``, ``truncation``, ``filter_factors``
        (TSVD); ``iterations``, ``cost``, ``solver_status`` (Ipopt); ...
    """

    method: str
    params: tuple
    estimate: np.ndarray
    covariance: np.ndarray | None = None
    success: bool = True
    status: str = "ok"
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    info: dict = field(default_factory=dict)

    def value(self, name: str, default=0.0) -> float:
        """Estimate of one parameter by name (``default`` if not identified)."""
        return float(self.estimate[self.params.index(name)]) if name in self.params else default

    def std(self, name: str) -> float:
        """Standard deviation of one parameter (NaN without covariance)."""
        if self.covariance is None or name not in self.params:
            return float("nan")
        k = self.params.index(name)
        return float(np.sqrt(self.covariance[k, k]))

    def full_vector(self) -> np.ndarray:
        """The estimate as a 12-vector of source errors (zeros where not identified)."""
        v = np.zeros(len(SOURCE_ERROR_NAMES))
        for k, n in enumerate(self.params):
            v[SOURCE_ERROR_NAMES.index(n)] = self.estimate[k]
        return v

    @property
    def zero_offsets_deg(self) -> np.ndarray:
        return np.degrees([self.value("theta1"), self.value("theta2")])

    @property
    def std_zero_offsets_deg(self) -> np.ndarray:
        return np.degrees([self.std("theta1"), self.std("theta2")])

    @property
    def maemm_mm(self) -> np.ndarray:
        return np.array([self.value("rMx"), self.value("rMy")])

    def to_dict(self) -> dict:
        """JSON-ready summary (degrees and mm at this edge)."""
        def deg_or_mm(n, v):
            return float(np.degrees(v)) if n.startswith("theta") else float(v)

        std = [self.std(n) for n in self.params]
        return {
            "method": self.method,
            "status": self.status,
            "success": bool(self.success),
            "zero_offsets_deg": self.zero_offsets_deg.tolist(),
            "std_zero_offsets_deg": [None if not np.isfinite(s) else s for s in self.std_zero_offsets_deg.tolist()],
            "maemm_mm": self.maemm_mm.tolist(),
            "params": list(self.params),
            "estimate": {n: deg_or_mm(n, v) for n, v in zip(self.params, self.estimate)},
            "std": {n: (None if not np.isfinite(s) else deg_or_mm(n, s)) for n, s in zip(self.params, std)},
            "units": {n: ("deg" if n.startswith("theta") else "mm") for n in self.params},
            "covariance": None if self.covariance is None else self.covariance.tolist(),
            "covariance_units": "rad for theta*, mm otherwise (SI-like internal units)",
            "residuals_mm": np.asarray(self.residuals).tolist(),
        }
