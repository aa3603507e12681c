"""The fewest poses whose design reaches a target zero-offset CRLB, with a certified lower bound.

:func:`fewest_poses`: the crlb measure
(:func:`zerocal_sym.design.approx.approximate_design`) bounds K from below;
designs realised from it (:func:`zerocal_sym.design.rounding.realize`) are
evaluated exactly up to the smallest K that meets the target.
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

from zerocal_sym.design.constraints import Constraints, make_constraints
from zerocal_sym.design.limits import DesignError
from zerocal_sym.design.rounding import realize
from zerocal_sym.design.terms import offset_unit, offsets_from_user, okey, poses_to_user

if TYPE_CHECKING:
    from zerocal_sym.design.approx import ApproxDesign


def fewest_poses(robot, target: float, cons: Constraints | None = None, noise=None, k_max: int | None = None,
                 ad: ApproxDesign | None = None):
    """The fewest poses K whose design reaches an RMS zero-offset CRLB of ``target``, with the bound.

    ``target`` is in the zero offsets' file unit: deg for revolute joints, mm for prismatic ones
    (:func:`zerocal_sym.design.terms.offset_unit`); so are the CRLBs returned (keys ``target_crlb_deg``,
    ``crlb_rms_deg``, or ``..._mm``).

    The crlb measure (:func:`~zerocal_sym.design.approx.approximate_design`) gives a certified lower
    bound: no ordered design of fewer than ``K_lower_bound`` poses on the
    candidates can reach the target (its CRLB is at least
    ``sqrt(bound / K)``).  Designs realised from the measure
    (:func:`realize`) are evaluated exactly from there upwards (the CRLB
    falls as ``1/sqrt(K)``: a step to the predicted K, then bisection), and
    the smallest K whose design meets the target is returned with its poses.

    With a shared revisit error (``noise.sigma_revisit_mm``) the CRLB of the
    replicates levels off (:func:`zerocal_sym.design.replicates.shared_floor`):
    a target below that floor is refused at once.

    Returns
    -------
    dict
        ``K``, ``K_lower_bound``, ``unit``, ``target_crlb_deg``, ``crlb_rms_deg`` (of
        the returned design), ``poses`` (K, n), ``evaluated`` {K: crlb},
        ``approximate`` (the measure's summary), ``time_s``.

    Raises
    ------
    DesignError
        A target that needs more than ``k_max`` poses.
    """
    from zerocal_sym.design.approx import approximate_design
    from zerocal_sym.design.limits import MAX_K, min_k
    from zerocal_sym.design.criteria import criterion_values
    from zerocal_sym.model.noise import NoiseModel

    t0 = time.perf_counter()
    u = offset_unit(robot)
    what = "degrees" if u == "deg" else "mm"
    given = target
    try:
        target = float(target)
    except (TypeError, ValueError):
        raise DesignError(f"the target CRLB must be a number of {what}, got {given!r}") from None
    if not (math.isfinite(target) and target > 0):
        raise DesignError(f"the target CRLB must be positive and finite, got {given!r} {u}")
    noise = NoiseModel.coerce(noise, robot=robot)
    cons = cons or make_constraints(robot)
    k_max = MAX_K if k_max is None else int(k_max)
    ad = ad or approximate_design(robot, "crlb", cons, noise)
    tr = float(offsets_from_user(robot, target)) ** 2
    k_lb = max(min_k(robot), int(math.ceil(math.exp(ad.bound_loss) / tr * (1 - 1e-12))))
    if k_lb > k_max:
        raise DesignError(f"a CRLB of {target:g} {u} needs at least {k_lb} poses (certified), more than "
                          f"the {k_max} allowed")
    from zerocal_sym.design.replicates import shared_floor

    floor = shared_floor(robot, ad.support, noise)
    if floor >= target:  # the shared revisit error: replicates level off above the target
        raise DesignError(f"a CRLB of {target:g} {u} is out of reach of this design's replicates: the shared "
                          f"revisit error ({noise.sigma_revisit_mm:g} mm per pose) keeps their CRLB above "
                          f"{floor:.4g} {u} however many poses (more support points, or a smaller revisit_std_mm)")
    evaluated = {}
    designs = {}

    def crlb_at(K, n_orders=10):
        P, _ = realize(robot, ad, K, cons, noise, n_orders=n_orders)
        v = criterion_values(robot, P, noise)["crlb"]
        evaluated[K] = v
        designs[K] = P
        return v

    K = k_lb
    v = crlb_at(K)
    lo = None
    while v > target:
        lo = K
        K = min(k_max, max(K + 1, int(math.ceil(K * (v / target) ** 2))))
        if K == lo:
            raise DesignError(f"no design of up to {k_max} poses reaches a CRLB of {target:g} {u} "
                              f"(at {k_max}: {v:.4g} {u})")
        v = crlb_at(K)
    hi = K
    lo = k_lb - 1 if lo is None else lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if crlb_at(mid) <= target:
            hi = mid
        else:
            lo = mid
    # the final design with the full order search
    v = crlb_at(hi, n_orders=60)
    if v > target:  # the fuller order search never makes it worse than the short one; keep the short one
        v = min(x for k, x in evaluated.items() if k == hi)
    return {"K": int(hi), "K_lower_bound": int(k_lb), "unit": u, okey(robot, "target_crlb"): target,
            okey(robot, "crlb_rms"): float(v),
            "poses": designs[hi], "evaluated": {int(k): float(x) for k, x in sorted(evaluated.items())},
            "approximate": dict(ad.to_dict(hi), support=poses_to_user(robot, ad.support).tolist()),
            "time_s": time.perf_counter() - t0}
