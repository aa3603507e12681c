"""The result of one identification, whatever the method and the mechanism.

Estimates are always of the *total* source errors (rad, mm) of the named
parameters, not of increments: an identification linearised at a prior (the
current compensation and MAEMM estimate) returns prior + increment.  Every
parameter is read by name; the zero offsets and the MAEMM come in joint and
pose-coordinate order from the mechanism's :class:`SourceErrors`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.model import units


@dataclass
class IdentificationResult(units.DegreeViews):
    """One identification.

    Attributes
    ----------
    method : str
        ``"tsvd"`` or ``"nlls"`` (or another registered method).
    params : tuple of str
        Names of the identified parameters (a subset of the mechanism's source errors).
    estimate : ndarray, shape (p,)
        Total source errors, rad for angles, mm otherwise.
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
    errors : SourceErrors or None
        The mechanism's source errors (names, roles, units); set by the
        identification.  Needed for :meth:`full_vector` and the role views.
    std_kind : str
        What the standard deviations include: ``"total"`` (every error the
        method knows of: the noise through the model, and for TSVD its
        linearisation bias and the truncated directions' bias bound),
        ``"from residuals"`` (no noise model: the noise level estimated from
        the residuals), ``"bound"`` (TSVD: the std of at least one parameter is
        an upper bound, its linearisation bias not small or not well
        determined; ``info["std_kinds"]`` per parameter, ``to_dict()["std_kinds"]``),
        ``"lower bound"`` (a known contribution could not be
        evaluated; ``info`` says which).  Unmodelled source errors are in none
        of them: the fit check (``info["fit"]``) is the guard against those.
    """

    method: str
    params: tuple
    estimate: np.ndarray
    covariance: np.ndarray | None = None
    success: bool = True
    status: str = "ok"
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    info: dict = field(default_factory=dict)
    errors: object = field(default=None, repr=False)
    std_kind: str = "total"

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
        """The estimate as a source-error vector of the mechanism (zeros where not identified), shape (q,)."""
        return self.errors.vector(dict(zip(self.params, self.estimate)))

    @property
    def zero_offset_names(self) -> tuple:
        return self.errors.zero_offsets

    @property
    def zero_offsets(self) -> np.ndarray:
        """Zero offsets in joint order (internal units: rad, mm), shape (m,)."""
        return np.array([self.value(n) for n in self.errors.zero_offsets])

    @property
    def zero_offsets_user(self) -> np.ndarray:
        """Zero offsets in joint order in file units (:attr:`offset_unit`: deg or mm), shape (m,)."""
        return units.to_user(self.zero_offsets, self.errors.offset_unit)

    @property
    def std_zero_offsets_user(self) -> np.ndarray:
        return units.to_user(np.array([self.std(n) for n in self.errors.zero_offsets]), self.errors.offset_unit)

    @property
    def offset_unit(self) -> str:
        """File unit of the zero offsets: ``deg`` (revolute joints) or ``mm`` (prismatic)."""
        return self.errors.offset_user_unit

    @property
    def zero_offsets_rad(self) -> np.ndarray:
        """Zero offsets in joint order (rad), shape (m,): revolute joints."""
        return self._degrees("zero_offsets_rad", self.zero_offsets)

    @property
    def maemm_mm(self) -> np.ndarray:
        """The measuring errors (MAEMM) in their order (mm), shape (u,)."""
        return np.array([self.value(n) for n in self.errors.measuring])

    def user_value(self, name: str, v: float) -> float:
        return self.errors.to_user_value(name, v)

    def to_dict(self) -> dict:
        """JSON-ready summary (degrees and mm at this edge), keyed by parameter name."""
        std = [self.std(n) for n in self.params]
        return {
            "method": self.method,
            "status": self.status,
            "success": bool(self.success),
            units.key("zero_offsets", self.errors.offset_unit): self.zero_offsets_user.tolist(),
            units.key("std_zero_offsets", self.errors.offset_unit):
                [None if not np.isfinite(s) else s for s in self.std_zero_offsets_user.tolist()],
            "maemm_mm": self.maemm_mm.tolist(),
            "params": list(self.params),
            "estimate": {n: self.user_value(n, v) for n, v in zip(self.params, self.estimate)},
            "std": {n: (None if not np.isfinite(s) else self.user_value(n, s)) for n, s in zip(self.params, std)},
            "units": {n: self.errors[n].user_unit for n in self.params},
            "covariance": None if self.covariance is None else self.covariance.tolist(),
            "covariance_units": "rad for angles, mm otherwise (SI-like internal units)",
            "residuals_mm": np.asarray(self.residuals).tolist(),
            "std_kind": self.std_kind,
            "std_kinds": dict(self.info["std_kinds"]) if isinstance(self.info, dict) and "std_kinds" in self.info
            else {n: self.std_kind for n in self.params},
            "fit": _json_ready(self.info.get("fit")) if isinstance(self.info, dict) else None,
            **({"revisits": _json_ready(self.info["revisits"])}
               if isinstance(self.info, dict) and "revisits" in self.info else {}),
        }


def _noise_dict(noise) -> dict:
    """The noise model as a result records it (``info["noise"]``, ``info["fit"]["noise"]``)."""
    d = {"sigma_scale_mm": float(noise.sigma_scale_mm), "sigma_servo_rad": float(noise.sigma_servo_rad)}
    if getattr(noise, "sigma_revisit_mm", 0):
        d["sigma_revisit_mm"] = float(noise.sigma_revisit_mm)
    return d


def _json_ready(obj):
    """Plain Python (dicts, lists, floats, None for non-finite numbers) of a nested structure."""
    if isinstance(obj, dict):
        return {str(k): _json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _json_ready(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj
