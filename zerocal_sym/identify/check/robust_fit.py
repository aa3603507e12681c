"""What the fit check makes of a robust fit: the readings it left out, and whether what is left can be checked.

A robust loss (:mod:`zerocal_sym.identify.estimate.robust`) down-weights
readings; those whose weight ends below :data:`ROBUST_EXCLUDE_WEIGHT` are its
outliers.  :func:`robust_linear` is the fit check's problem without them (both
tests see only the readings kept); :func:`limit_outliers` rejects a fit that
left out more than :func:`robust_exclusion_limit` allows,
:func:`unchecked_after_removal` one that has no spare degree of freedom left
to be checked; :func:`kept_outlier` says when the reading the largest
standardised residual rejects is one the loss down-weighted but kept.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.identify.whitened import _Linear

#: a reading whose robust weight ends below this is an outlier: named, and left out of the fit check
#: (huber: |scale error| > 4 loss scales; soft_l1: > 3.9 loss scales)
ROBUST_EXCLUDE_WEIGHT = 0.25
#: a robust fit may leave out at most this fraction of the K - 1 readings (at least one): beyond, the data
#: are not a good set with a few bad readings but a model that does not fit them, and the fit is rejected
ROBUST_MAX_EXCLUDED_FRACTION = 0.25


def robust_exclusion_limit(n_readings: int) -> int:
    """How many of ``n_readings`` readings a robust fit may leave out (:data:`ROBUST_MAX_EXCLUDED_FRACTION`)."""
    return max(1, int(ROBUST_MAX_EXCLUDED_FRACTION * n_readings))


def robust_linear(robust, e, A, Jp, rp, scale, names, K):
    """The fit check's problem of a robust fit: the readings it down-weighted removed (by marginalising C)."""
    keep = np.setdiff1d(np.arange(K - 1), np.asarray(robust["excluded_readings"], int) - 1)
    C = robust["_C"].take(keep)  # tridiagonal again
    return _Linear(np.concatenate([C.whiten(e[keep]), rp]), np.vstack([C.whiten(-A[keep]), Jp]), C.cholesky(),
                   keep + 1, e[keep], np.eye(len(names)), scale, names, len(rp))


def unchecked_after_removal(res, robust, loss, K, accept_misfit):
    """Refuse a robust fit that left no spare degree of freedom once its outliers were left out.

    Without a spare degree of freedom the fit check cannot test what is left
    (any readings fit), so nothing says the readings left out were the bad
    ones: with one reading 0.18 mm off on a Delta ring of K = 8 the Huber
    loss left out a good one and the offsets came out 2.5 deg off with a
    1 sigma of 0.07 deg.  ``accept_misfit`` keeps it, saying so.
    """
    fit = res.info["fit"]
    if not robust["excluded_readings"] or fit.get("checked") or fit.get("dof", 1) > 0 or not res.success:
        return
    poses = ", ".join(map(str, robust["excluded_readings"]))
    why = (f"the {loss} loss left out the reading(s) at pose {poses}, and the {K - 1 - len(robust['excluded_readings'])}"
           f" readings left give no spare degree of freedom: the fit cannot be checked, so nothing shows that the "
           "readings left out were the bad ones")
    fit["unchecked_after_removal"] = True
    if accept_misfit:
        res.status = f"accepted despite misfit (unchecked: {why}); {res.status}"
        fit["accepted_despite_misfit"] = True
    else:
        res.success = False
        res.status = f"rejected: {why}"
        fit["rejected"] = True
    fit["diagnosis"] = (f"The {loss} loss left out the reading(s) at pose {poses}; the readings left fit any "
                        "parameters exactly (no spare degree of freedom), so the fit is not checked. Measure more "
                        "poses (or re-measure the pose(s) left out) and identify again; --accept-misfit keeps it "
                        "unchecked.")


def limit_outliers(res, robust, loss, K, accept_misfit):
    """Reject a robust fit that left out more readings than :func:`robust_exclusion_limit` allows.

    A robust loss copes with a bad reading or a few; when it down-weights many,
    the fit of the rest is not evidence for the estimate (with a wrong robot
    file, 3 of 5 readings left out and the other 2 fitted by 1 parameter
    "passed" the check).  ``accept_misfit`` keeps it, saying so.
    """
    n_out, limit = len(robust["excluded_readings"]), robust_exclusion_limit(K - 1)
    res.info["fit"]["robust_exclusion_limit"] = limit
    if n_out <= limit or not res.success:
        return
    why = (f"the {loss} loss left out {n_out} of the {K - 1} readings (at most {limit}: a robust loss copes with "
           "a bad reading or a few, not with a model that does not fit the data: the robot file, the parameters "
           "estimated, the noise model)")
    if accept_misfit:
        res.status = f"accepted despite misfit ({why}); {res.status}"
        res.info["fit"]["accepted_despite_misfit"] = True
    else:
        res.success = False
        res.status = f"rejected: {why}"
    fit = res.info["fit"]
    fit["rejected"] = True
    kept = fit.get("diagnosis") or ""
    fit["diagnosis"] = (f"The {loss} loss left out the readings at pose "
                        f"{', '.join(map(str, robust['excluded_readings']))}: more than {limit} of {K - 1}, so the "
                        "data do not fit the model, whatever the few readings left say"
                        + (f" (of those: {kept[0].lower() + kept[1:]})" if kept else "."))


def kept_outlier(res, robust, loss):
    """Say so when the reading that the fit check's largest standardised residual rejects is one the loss
    down-weighted but kept (its weight at least :data:`ROBUST_EXCLUDE_WEIGHT`): the fit stays rejected (the
    data contradict the noise model at that reading), and the paragraph tells how to leave it out."""
    fit = res.info["fit"]
    mr = fit.get("max_reading") or {}
    if not (fit.get("rejected") and mr.get("rejected")):
        return
    w = float(robust["weights"][mr["pose"] - 1])
    if w >= 1.0:
        return
    note = (f" The {loss} loss down-weighted the reading at pose {mr['pose']} (weight {w:.2g}) but kept it: it "
            f"leaves out the readings weighted below {ROBUST_EXCLUDE_WEIGHT:g}; a smaller --loss-scale leaves this one "
            "out, or re-measure it.")
    fit["diagnosis"] = (fit.get("diagnosis") or "") + note
