"""The Monte Carlo comparison's report (:func:`zerocal_sym.identify.montecarlo.compare`) as text."""
from __future__ import annotations

import numpy as np


def _vec(v, fmt):
    return ",".join(format(x, fmt) for x in v)


def format_compare(rep: dict) -> str:
    """The comparison as text tables (one column group per zero offset and MAEMM component)."""
    u = rep["settings"].get("offset_unit", "deg")  # the keys of the offsets carry it (deg, mm)
    k_crlb, k_set, k_rms, k_bias, k_q, k_diff = (f"{k}_{u}" for k in (
        "crlb_zero_offsets", "set", "rms", "bias", "quantiles", "max_abs_diff_to_ipopt"))
    s = rep["settings"]
    nz = s["noise"]
    joint = (f"servo {np.degrees(nz['sigma_servo_rad']):.4g} deg" if "sigma_servo_rad" in nz
             else f"joints {nz['sigma_joint_mm'] * 1e3:.4g} um")
    lines = [f"Monte Carlo: {s['trials']} trials per group, K = {s['K']} poses, Ipopt parameters "
             f"{', '.join(s['params'])}, noise scale {nz['sigma_scale_mm'] * 1e3:.4g} um, {joint}, seed {s['seed']}"
             + (f"; geometric errors {'on' if s['geometric_errors'] else 'off'}" if "geometric_errors" in s else "")
             + f"; errors in {s['error_frame']} frame"]
    for g, go in rep["groups"].items():
        cr = go[k_crlb]
        m = len(go[k_set])
        lines.append("")
        lines.append(f"group {g}: true offsets {_vec(go[k_set], '+.3f')} {u};  CRLB "
                     + ("n/a" if cr is None else f"{_vec(cr, '.4f')} {u}"))
        joints = list(s.get("truth", {}))[:m]  # the source errors by name, the zero offsets first
        offs = ",".join(f"d{j}" for j in joints) if u != "deg" and len(joints) == m else \
            ",".join(f"dth{k + 1}" for k in range(m))  # angles: dth1, dth2, ... (prismatic joints: ds1, dL1, ...)
        w = 11 * m
        lines.append(f"  {'method':10s} {'bias ' + offs + f' [{u}]':>{w}s} {'RMS ' + offs + f' [{u}]':>{w}s} "
                     f"{'RMS/CRLB':>{6 * m + 1}s} {'RMS rM [mm]':>{8 * m}s} {'dp0 RMS':>8s} {'fail':>4s} "
                     f"{'noconv':>6s} {'ident':>5s} {'ms/ident':>8s}")
        for name, r in go["methods"].items():
            if r[k_rms] is None:
                lines.append(f"  {name:10s} all {r['failures']} trials failed")
                continue
            ratio = "n/a" if r["rms_crlb_ratio"] is None else _vec(r["rms_crlb_ratio"], ".3f")
            nc = "-" if r["not_converged"] is None else str(r["not_converged"])
            lines.append(f"  {name:10s} {_vec(r[k_bias], '+10.4f'):>{w}s} {_vec(r[k_rms], '10.4f'):>{w}s} "
                         f"{ratio:>{6 * m + 1}s} {_vec(r['rms_maemm_mm'], '7.4f'):>{8 * m}s} {r['dp0_rms_mm']:8.4f} "
                         f"{r['failures']:4d} {nc:>6s} {r['identifications']:5.1f} "
                         f"{r['time_per_identification_ms']:8.2f}")
        qs = [(name, r[k_q]) for name, r in go["methods"].items() if r.get(k_q)]
        if qs:
            lines.append(f"  {'quantiles':10s} {'5% ' + offs + f' [{u}]':>{w}s} {'median ' + offs + f' [{u}]':>{w}s} "
                         f"{'95% ' + offs + f' [{u}]':>{w}s}")
            for name, q in qs:
                lines.append(f"  {name:10s} {_vec(q['q05'], '+10.4f'):>{w}s} {_vec(q['median'], '+10.4f'):>{w}s} "
                             f"{_vec(q['q95'], '+10.4f'):>{w}s}")
        sr = go.get("scipy_reference")
        if sr:
            lines.append(f"  scipy least_squares (lm) on Ipopt's problem with the weights held at the start "
                         f"(identify_nlls reweight=0, not the nlls row): max |diff| to Ipopt "
                         f"{sr[k_diff]:.2e} {u}; time Ipopt {sr['time_ipopt_ms']:.2f} ms "
                         f"(whole identification) vs scipy {sr['time_scipy_ms']:.2f} ms (solver call): "
                         f"ratio {sr['time_ratio_ipopt_over_scipy']:.2f}")
    return "\n".join(lines)
