"""Monte Carlo verification of a design's CRLB with the Ipopt estimator (:func:`verify_design`)."""
from __future__ import annotations

import math
import time

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.constraints import DesignError


# --------------------------------------------------------------------------- verification
def verify_design(robot, P, n_trials: int, noise: NoiseModel | None = None, err_true=None, seed: int = 0) -> dict:
    """Monte Carlo check of a design's CRLB with the Ipopt estimator.

    Each trial simulates the K scale readings of the virtual plant
    (:class:`~zerocal_sym.model.noise.VirtualPlant`) with fresh noise and
    identifies the paper's four parameters with
    :func:`zerocal_sym.identify.nlls.identify_nlls` (same noise model for weighting).

    Parameters
    ----------
    P : ndarray, shape (K, 2)
        Poses in visiting order, mm (commanded by nominal inverse kinematics).
    n_trials : int
    noise : NoiseModel, optional
        Default the paper's.
    err_true : ndarray, shape (12,), optional
        True source errors; default Table 2 group 1 without geometric errors
        (zero offsets 2 and -1 deg, MAEMM (1, 0.5) mm), so that the four
        identified parameters are the whole truth and the CRLB applies.
    seed : int

    Returns
    -------
    dict
        ``rms_error_deg`` (2,) per offset and ``rms_error_rms_deg`` (over
        both), ``mean_error_deg`` (2,), ``crlb_at_truth_deg`` (2,) and its
        RMS, ``n_trials``, ``n_failed`` (Ipopt not converged, excluded),
        ``time_s``.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import VirtualPlant
    from zerocal_sym.paper.tables import table2_errors
    from zerocal_sym.identify.nlls import identify_nlls

    if isinstance(n_trials, bool) or not isinstance(n_trials, (int, np.integer)) or n_trials < 1:
        raise DesignError(f"the number of Monte Carlo trials must be a positive integer, got {n_trials!r}")
    t0 = time.perf_counter()
    noise = noise or NoiseModel.paper()
    err = table2_errors(1, geometric=False) if err_true is None else np.asarray(err_true, float)
    theta = kin.ik(robot, np.asarray(P, float))
    plant = VirtualPlant(robot, err)
    rng = np.random.default_rng(seed)
    E, failed = [], 0
    for _ in range(n_trials):
        res = identify_nlls(robot, Measurements(theta, plant.measure(theta, noise, rng)), "paper", noise=noise)
        if not res.success:
            failed += 1
            continue
        E.append([res.value("theta1") - err[0], res.value("theta2") - err[1]])
    E = np.degrees(np.array(E).reshape(-1, 2))
    crlb = fisher.crlb_zero_offsets_deg(robot, theta, "paper", noise, err0=err)
    return {"n_trials": int(n_trials), "n_failed": failed,
            "rms_error_deg": np.sqrt(np.mean(E ** 2, axis=0)).tolist() if len(E) else [math.nan] * 2,
            "rms_error_rms_deg": float(np.sqrt(np.mean(E ** 2))) if len(E) else math.nan,
            "mean_error_deg": E.mean(axis=0).tolist() if len(E) else [math.nan] * 2,
            "crlb_at_truth_deg": crlb.tolist(), "crlb_at_truth_rms_deg": float(np.sqrt(np.mean(crlb ** 2))),
            "true_errors": {"zero_offsets_deg": np.degrees(err[:2]).tolist(), "maemm_mm": err[10:12].tolist(),
                            "geometric_mm": err[2:10].tolist()},
            "time_s": time.perf_counter() - t0}
