"""A reference set of identifications, and what of each is compared (tests/test_linear_cost.py).

Both methods, both mechanisms, noisy and noise-free data, rounds with a bad
reading (rejected, diagnosed, deletion diagnostics), robust losses, a
Gaussian prior and a truncated TSVD; K on both sides of the size where the
CasADi functions turn from expanded SX to MX graphs (``EXPAND_MAX_K``).

``python tests/reference_cases.py`` writes ``tests/data/reference_identifications.json``: the results
as the implementation at that commit computes them.  The file was written before the fit check, the
per-reading statistics, the robust loss and the deletion diagnostics were rewritten in banded, linear-time
form; the test recomputes every case and compares.

``python tests/reference_cases.py --tsvd-std`` rewrites only TSVD's std in the file (``covariance``,
``std_kind``, ``info`` ``covariance_noise`` and ``linearisation_bias``: the noise at the estimate, the bias of
TSVD's own operator, a bound where that bias is not known well enough), everything else as it was.

Each case records, besides the results, the conditioning the comparison's tolerances are derived from:
``kappa_J`` (condition number of the whitened, scaled Jacobian at the fit check's point), ``kappa_C``
(of the covariance of the changes there) and ``K``.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).resolve().parent / "data" / "reference_identifications.json"

#: (case id, robot, K, data noise, bad reading (pose, mm) or None, what is run)
CASES = [
    ("planar-clean-24", "planar", 24, "paper", None, ("nlls", "tsvd")),
    ("delta-clean-24", "delta", 24, "paper", None, ("nlls", "tsvd")),
    ("planar-clean-200", "planar", 200, "paper", None, ("nlls", "tsvd")),
    ("delta-clean-200", "delta", 200, "paper", None, ("nlls", "tsvd")),
    ("planar-noisefree-24", "planar", 24, "none", None, ("nlls", "tsvd")),
    ("delta-noisefree-24", "delta", 24, "none", None, ("nlls", "tsvd")),
    ("planar-scale-24", "planar", 24, "scale-only", None, ("nlls", "tsvd")),
    ("planar-prior-24", "planar", 24, "paper", None, ("nlls-prior", "tsvd-t3")),
    ("delta-prior-24", "delta", 24, "paper", None, ("nlls-prior", "tsvd-t5")),
    ("planar-bad-24", "planar", 24, "scale-only", (8, 0.5), ("nlls", "tsvd", "deletion", "huber", "soft_l1")),
    ("delta-bad-24", "delta", 24, "scale-only", (8, 0.5), ("nlls", "tsvd", "deletion", "huber", "soft_l1")),
    ("planar-badpaper-24", "planar", 24, "paper", (8, 0.5), ("nlls", "tsvd", "deletion", "huber")),
    ("delta-badpaper-24", "delta", 24, "paper", (8, 0.5), ("nlls", "tsvd", "deletion", "huber")),
    ("planar-bad-126", "planar", 126, "paper", (40, 0.5), ("nlls", "tsvd", "deletion", "huber")),
    ("delta-bad-126", "delta", 126, "paper", (40, 0.5), ("nlls", "tsvd", "deletion", "huber")),
]


def robot_of(which):
    from zerocal_sym.model.robot import load_robot, paper_robot

    return paper_robot() if which == "planar" else load_robot(ROOT / "examples" / "delta.toml")


def measurements(robot, K, noise_name, bad, seed=7):
    """K random poses inside the workspace (seeded), measured with ``noise_name``; ``bad`` added to one reading."""
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant

    e = robot.errors
    truth = e.assemble((0.5, -0.3, 0.2)[: robot.m], None, (0.5, -0.2, 0.1)[: robot.n])
    rng = np.random.default_rng(seed)
    lo, hi = robot.workspace.bounds()
    P = lo + (hi - lo) * rng.random((8 * K, len(lo)))
    P = P[robot.workspace.contains(P, -1.0)][:K]
    th = kin.ik(robot, P)
    rd = VirtualPlant(robot, truth).measure(th, NoiseModel.named(noise_name), rng)
    if bad is not None:
        rd[bad[0]] += bad[1]
    return Measurements(th, rd)


def _f(x):
    """JSON-ready copy of nested numbers (non-finite floats as strings)."""
    if isinstance(x, dict):
        return {str(k): _f(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_f(v) for v in x]
    if isinstance(x, np.ndarray):
        return _f(x.tolist())
    if isinstance(x, (bool, np.bool_)) or x is None or isinstance(x, str):
        return bool(x) if isinstance(x, np.bool_) else x
    if isinstance(x, (int, np.integer)):
        return int(x)
    v = float(x)
    return v if np.isfinite(v) else repr(v)


FIT_KEYS = ("checked", "rejected", "chi2", "dof", "p_value", "p_value_lower", "rms_whitened", "chi2_at_estimate")
READING_KEYS = ("pose", "residual_mm", "whitened", "leverage", "standardised", "estimated_error_mm")
CAUSE_KEYS = ("cause", "detected", "pose", "estimated_error_mm", "also_possible", "evidence")
INFO_KEYS = ("chi2", "dof", "rank", "singular_values", "truncation", "covariance_noise", "linearisation_bias",
             "truncation_bias_bound", "fit_point", "linear_residuals", "increment")
ROBUST_KEYS = ("weights", "standardised", "excluded_readings", "excluded_errors_mm", "converged",
               "refit_without_outliers")


def summary(res) -> dict:
    """What is compared of an identification."""
    fit = res.info.get("fit") or {}
    out = {"success": res.success, "status": res.status, "std_kind": res.std_kind,
           "estimate": res.estimate, "covariance": res.covariance,
           "info": {k: res.info[k] for k in INFO_KEYS if k in res.info},
           "fit": {k: fit.get(k) for k in FIT_KEYS},
           "readings": [{k: r.get(k) for k in READING_KEYS} for r in fit.get("readings", [])],
           "worst": fit.get("worst"),
           "causes": [{k: c.get(k) for k in CAUSE_KEYS} for c in fit.get("causes", [])]}
    if "robust" in res.info:
        out["robust"] = {k: res.info["robust"].get(k) for k in ROBUST_KEYS}
    return _f(out)


def deletion_summary(d) -> dict:
    return _f({"flagged": d["flagged"], "most_influential": d["most_influential"], "dof": d["dof"],
               "readings": [{k: r.get(k) for k in ("pose", "leverage", "standardised", "estimated_error_mm",
                                                  "chi2_without", "change", "flag", "refit_converged")}
                            for r in d["readings"]]})


def conditioning(robot, meas, res, noise) -> dict:
    """``kappa_J``, ``kappa_C`` at the fit check's point of ``res`` (dense: small K only, reference use)."""
    from zerocal_sym.identify import fisher
    from zerocal_sym.identify.fitcheck import _exact_for

    exact, z, basis = _exact_for(robot, meas, res, noise)
    r, rp, J, pred, l, b = exact.evaluate(z)
    s = np.linalg.svd(J[: exact.K - 1], compute_uv=False)
    C = fisher.ChangeCovariance(l**2 + np.r_[0.0, b**2], l[:-1] * b).dense()
    ev = np.linalg.eigvalsh(C)
    return {"kappa_J": float(s[0] / s[-1]), "kappa_C": float(ev[-1] / ev[0])}


def run_case(case) -> dict:
    """Every identification of one case: ``{what: summary}`` plus the conditioning."""
    from zerocal_sym.identify.fitcheck import deletion_diagnostics
    from zerocal_sym.identify.nlls import identify_nlls
    from zerocal_sym.identify.tsvd import identify_tsvd
    from zerocal_sym.model.noise import NoiseModel

    cid, which, K, noise_name, bad, runs = case
    robot = robot_of(which)
    meas = measurements(robot, K, noise_name, bad)
    noise = NoiseModel.named(noise_name)
    tnoise = None if noise.is_zero else noise
    out = {"K": K}
    first = None
    for what in runs:
        if what == "nlls":
            res = identify_nlls(robot, meas, noise=noise)
        elif what == "nlls-prior":
            res = identify_nlls(robot, meas, noise=noise, prior_std={robot.errors.measuring[0]: 0.05})
        elif what == "tsvd":
            res = identify_tsvd(robot, meas, noise=tnoise)
        elif what.startswith("tsvd-t"):
            res = identify_tsvd(robot, meas, noise=tnoise, t=int(what[6:]))
        elif what in ("huber", "soft_l1"):
            res = identify_nlls(robot, meas, noise=noise, loss=what)
        elif what == "deletion":
            acc = identify_nlls(robot, meas, noise=noise, accept_misfit=True)
            out["deletion-refit"] = deletion_summary(deletion_diagnostics(robot, meas, acc, method="refit"))
            out["deletion-one-step"] = deletion_summary(deletion_diagnostics(robot, meas, acc, method="one-step"))
            continue
        else:
            raise ValueError(what)
        out[what] = summary(res)
        first = first or res
    out.update(conditioning(robot, meas, first, noise))
    return out


TSVD_STD_KEYS = ("covariance", "std_kind")
TSVD_STD_INFO = ("covariance_noise", "linearisation_bias")


def update_tsvd_std():
    """Rewrite TSVD's std in the reference file (``--tsvd-std``), every other number as it was."""
    ref = json.loads(REFERENCE.read_text())
    for case in CASES:
        new = run_case(case)
        for what, summ in new.items():
            if what.startswith("tsvd"):
                for k in TSVD_STD_KEYS:
                    ref[case[0]][what][k] = summ[k]
                for k in TSVD_STD_INFO:
                    ref[case[0]][what]["info"][k] = summ["info"][k]
        print(f"{case[0]}: TSVD std rewritten", flush=True)
    REFERENCE.write_text(json.dumps(ref, sort_keys=True, separators=(",", ":")) + "\n")


def main():
    if "--tsvd-std" in sys.argv[1:]:
        return update_tsvd_std()
    from reference_files import write_reference

    write_reference(REFERENCE, CASES, run_case, with_versions=False)


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
