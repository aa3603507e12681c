"""Monte Carlo verification of a design's CRLB with the Ipopt estimator (:func:`verify_design`)."""
from __future__ import annotations

import math
import time

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.model.noise import NoiseModel
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.terms import design_params, offsets_to_user, okey

#: default true zero offsets (deg), the first m of them: joint 1, 2, 3 (planar: Table 2 group 1)
DEFAULT_OFFSETS_DEG = (2.0, -1.0, 0.5)
#: default true zero offsets of prismatic joints (mm), the first m of them
DEFAULT_OFFSETS_MM = (0.3, -0.2, 0.1, 0.25, -0.15, 0.05)
#: default true MAEMM (mm), the first n of them: x, y, z (planar: Table 2 group 1), then further measuring errors
DEFAULT_MAEMM_MM = (1.0, 0.5, -0.5, 0.05, 0.0, -0.05)


def default_true_errors(robot) -> np.ndarray:
    """Default truth of :func:`verify_design`: zero offsets and the identified measuring errors, nothing else.

    The zero offsets (joint order) are ``(2, -1, 0.5)[:m]`` deg for revolute joints,
    ``(0.3, -0.2, 0.1, 0.25, -0.15, 0.05)[:m]`` mm for prismatic ones; the
    measuring errors of the identified set (:func:`zerocal_sym.design.terms.design_params`, in their order)
    ``(1, 0.5, -0.5, 0.05, 0, -0.05)[:u]`` mm, set by name -- for the planar robot exactly Table 2 group 1
    without its geometric errors.  A measuring error outside the identified set (the linear Delta's ``rMz``)
    stays zero: the estimator holds it there.

    Returns
    -------
    ndarray, shape (q,)
        rad, mm.

    Raises
    ------
    DesignError
        A mechanism with more joints or identified measuring errors than these lists (give ``err_true``).
    """
    errors = robot.errors
    z = errors.zero_offsets
    keep = set(design_params(robot))
    mm = tuple(n for n in errors.measuring if n in keep)
    offs = DEFAULT_OFFSETS_DEG if errors.offset_unit == "rad" else DEFAULT_OFFSETS_MM
    if len(z) > len(offs) or len(mm) > len(DEFAULT_MAEMM_MM):
        raise DesignError(f"no default true errors for mechanism {robot.mechanism_name!r} "
                          f"({len(z)} zero offsets, {len(mm)} MAEMM components): give err_true")
    values = {name: errors.from_user_value(name, v) for name, v in zip(z, offs)}
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
        Default the robot's (:attr:`Robot.noise`).
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
        Keys of offsets in their file unit (``_deg``; ``_mm`` for prismatic joints, ``unit`` says which):
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
    mc = one_shot_monte_carlo(robot, theta, err, int(n_trials), noise, design_params(robot), seed=seed, workers=workers,
                              scheduler=scheduler, progress=progress)
    ok = mc["success"]
    failed = int(np.sum(~ok))
    m = len(offsets)
    E = offsets_to_user(robot, mc["estimate"][ok][:, [mc["params"].index(n) for n in offsets]]
                        - true_off).reshape(-1, m)
    crlb = fisher.crlb_zero_offsets_user(robot, theta, design_params(robot), noise, err0=err)
    k = lambda stem: okey(robot, stem)  # noqa: E731
    return {"n_trials": int(n_trials), "n_failed": failed, "offset_names": list(offsets),
            "unit": units.joint_unit(robot),
            k("rms_error"): np.sqrt(np.mean(E ** 2, axis=0)).tolist() if len(E) else [math.nan] * m,
            k("rms_error_rms"): float(np.sqrt(np.mean(E ** 2))) if len(E) else math.nan,
            k("mean_error"): E.mean(axis=0).tolist() if len(E) else [math.nan] * m,
            k("crlb_at_truth"): crlb.tolist(), k("crlb_at_truth_rms"): float(np.sqrt(np.mean(crlb ** 2))),
            "true_errors": {"by_name": errors.to_dict(err, user=True),
                            "units": {e.name: e.user_unit for e in errors},
                            k("zero_offsets"): offsets_to_user(robot, true_off).tolist(),
                            "maemm_mm": errors.take(err, errors.measuring).tolist(),
                            "geometric": errors.to_dict(err, errors.geometry, user=True)},
            "time_s": time.perf_counter() - t0}
