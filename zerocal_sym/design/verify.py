"""Monte Carlo verification of a design's CRLB with the Ipopt estimator (:func:`verify_design`)."""
from __future__ import annotations

import math
import time

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.limits import DesignError

#: default true zero offsets (deg), the first m of them: joint 1, 2, 3 (planar: Table 2 group 1)
DEFAULT_OFFSETS_DEG = (2.0, -1.0, 0.5)
#: default true MAEMM (mm), the first n of them: x, y, z (planar: Table 2 group 1)
DEFAULT_MAEMM_MM = (1.0, 0.5, -0.5)


def default_true_errors(robot) -> np.ndarray:
    """Default truth of :func:`verify_design`: zero offsets and MAEMM only, no geometric errors.

    The zero offsets (joint order) are ``(2, -1, 0.5)[:m]`` deg and the MAEMM
    (pose-coordinate order) ``(1, 0.5, -0.5)[:n]`` mm, set by name -- for the
    planar robot exactly Table 2 group 1 without its geometric errors.

    Returns
    -------
    ndarray, shape (q,)
        rad, mm.

    Raises
    ------
    DesignError
        A mechanism with more than three joints or pose coordinates (give
        ``err_true``).
    """
    errors = robot.errors
    z, mm = errors.zero_offsets, errors.measuring
    if len(z) > len(DEFAULT_OFFSETS_DEG) or len(mm) > len(DEFAULT_MAEMM_MM):
        raise DesignError(f"no default true errors for mechanism {robot.mechanism_name!r} "
                          f"({len(z)} zero offsets, {len(mm)} MAEMM components): give err_true")
    values = {name: math.radians(v) for name, v in zip(z, DEFAULT_OFFSETS_DEG)}
    values.update({name: v for name, v in zip(mm, DEFAULT_MAEMM_MM)})
    return errors.vector(values)


# --------------------------------------------------------------------------- verification
def verify_design(robot, P, n_trials: int, noise: NoiseModel | None = None, err_true=None, seed: int = 0,
                  workers: int = 1, scheduler=None, progress=None) -> dict:
    """Monte Carlo check of a design's CRLB with the Ipopt estimator.

    Each trial simulates the K scale readings of the virtual plant
    (:class:`~zerocal_sym.model.noise.VirtualPlant`) with fresh noise and
    identifies the paper's p = m + n parameters (zero offsets and MAEMM) with
    :func:`zerocal_sym.identify.nlls.identify_nlls` (same noise model for
    weighting), in batches (:func:`zerocal_sym.identify.one_shot.one_shot_monte_carlo`:
    trial t draws from ``SeedSequence([seed, 0, t])``, so the result does not
    depend on ``workers`` or ``scheduler``).

    Parameters
    ----------
    P : ndarray, shape (K, n)
        Poses in visiting order, mm (commanded by nominal inverse kinematics).
    n_trials : int
    noise : NoiseModel, optional
        Default the paper's.
    err_true : ndarray, shape (q,) or dict name -> value, optional
        True source errors (rad, mm; a dict by name as for
        :class:`~zerocal_sym.model.noise.VirtualPlant`).  Default
        :func:`default_true_errors` (no geometric errors, so that the
        identified parameters are the whole truth and the CRLB applies;
        geometric errors given here are held at zero by the estimator and
        bias it).
    seed : int
    workers, scheduler, progress
        Local processes, or a Dask cluster; ``progress(done)``
        (:func:`zerocal_sym.identify.parallel.run_chunks`).

    Returns
    -------
    dict
        ``offset_names`` (m,), ``rms_error_deg`` (m,) per offset and
        ``rms_error_rms_deg`` (over all), ``mean_error_deg`` (m,),
        ``crlb_at_truth_deg`` (m,) and its RMS, ``true_errors``
        (``by_name`` in deg / mm, ``zero_offsets_deg`` (m,), ``maemm_mm``
        (n,), ``geometric`` by name in deg / mm), ``n_trials``, ``n_failed``
        (Ipopt not converged, excluded), ``time_s``.
    """
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.one_shot import one_shot_monte_carlo

    if isinstance(n_trials, bool) or not isinstance(n_trials, (int, np.integer)) or n_trials < 1:
        raise DesignError(f"the number of Monte Carlo trials must be a positive integer, got {n_trials!r}")
    t0 = time.perf_counter()
    errors = robot.errors
    noise = NoiseModel.coerce(noise, robot=robot)
    if err_true is None:
        err = default_true_errors(robot)
    elif isinstance(err_true, dict):
        err = errors.vector(err_true)
    else:
        err = errors.check_vector(np.asarray(err_true, float), "err_true").copy()
    offsets = errors.zero_offsets
    true_off = errors.take(err, offsets)
    theta = kin.ik(robot, np.asarray(P, float))
    mc = one_shot_monte_carlo(robot, theta, err, int(n_trials), noise, "paper", seed=seed, workers=workers,
                              scheduler=scheduler, progress=progress)
    ok = mc["success"]
    failed = int(np.sum(~ok))
    m = len(offsets)
    E = np.degrees(mc["estimate"][ok][:, [mc["params"].index(n) for n in offsets]] - true_off).reshape(-1, m)
    crlb = fisher.crlb_zero_offsets_deg(robot, theta, "paper", noise, err0=err)
    return {"n_trials": int(n_trials), "n_failed": failed, "offset_names": list(offsets),
            "rms_error_deg": np.sqrt(np.mean(E ** 2, axis=0)).tolist() if len(E) else [math.nan] * m,
            "rms_error_rms_deg": float(np.sqrt(np.mean(E ** 2))) if len(E) else math.nan,
            "mean_error_deg": E.mean(axis=0).tolist() if len(E) else [math.nan] * m,
            "crlb_at_truth_deg": crlb.tolist(), "crlb_at_truth_rms_deg": float(np.sqrt(np.mean(crlb ** 2))),
            "true_errors": {"by_name": errors.to_dict(err, user=True),
                            "units": {e.name: e.user_unit for e in errors},
                            "zero_offsets_deg": np.degrees(true_off).tolist(),
                            "maemm_mm": errors.take(err, errors.measuring).tolist(),
                            "geometric": errors.to_dict(err, errors.geometry, user=True)},
            "time_s": time.perf_counter() - t0}
