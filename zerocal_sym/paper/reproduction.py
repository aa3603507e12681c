"""The paper's simulation study (Sections 5-6).

* :func:`select_n` -- the number of poses per boundary by the eps rule (Eq. 31);
* :func:`run_group` / :func:`reproduce` -- Table 2's six groups through the
  loop (:func:`zerocal_sym.identify.loop.calibration_loop`), with the paper's
  Tables 3-6 (:mod:`zerocal_sym.paper.tables`) alongside.

Table 2 is read in the frame described in :mod:`zerocal_sym.paper.tables`
(``frame="paper"``, the default, or ``frame="literal"``).  Offsets and MAEMM
are *reported* in Table 2's frame so that they compare directly with the paper.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import PoseError, ZerocalError
from zerocal_sym.identify.loop import calibration_loop, home_error, position_errors, simulate_round
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.identify.linear import condition_number, identification_matrix
from zerocal_sym.paper.tables import (DEFAULT_MAEMM_PRIOR, PAPER_KAPPA_1, PAPER_KAPPA_M, PAPER_N, group_errors,
                                      paper_table, to_table_frame)
from zerocal_sym.identify.tsvd import identify_tsvd


# ---------------------------------------------------------------- pose scheme
@dataclass
class NSelection:
    """Result of the eps rule (Eq. 31).

    Attributes
    ----------
    n : int
        Selected poses per boundary.
    eps0 : float
    table : list of dict
        Per n: ``n, K, kappa_1, kappa_m, eps``.
    maemm_prior : (2,)
    """

    n: int
    eps0: float
    table: list
    maemm_prior: tuple


def kappas(robot, n: int, maemm_prior=DEFAULT_MAEMM_PRIOR):
    """``(kappa_1, kappa_m)`` of the paper's scheme with n poses per boundary.

    ``kappa_m`` is the condition number with the MAEMM prior applied
    (Eq. 30), i.e. the mean over later identifications when each uses the
    same prior.
    """
    P = paper_poses(robot, n)
    return (condition_number(identification_matrix(robot, P)[0]),
            condition_number(identification_matrix(robot, P, maemm_prior)[0]))


def select_n(robot, eps0=0.01, maemm_prior=DEFAULT_MAEMM_PRIOR, n_max=21, n_min=3) -> NSelection:
    """The smallest n with ``eps = (kappa_1 - kappa_m) / kappa_1 <= eps0`` (Eq. 31).

    ``n`` starts at 3: ``K = 2n >= 5`` poses are needed for rank 4.

    Raises
    ------
    ZerocalError
        Bad ``eps0`` or no n in ``n_min..n_max`` satisfies the rule.
    """
    if not eps0 > 0:
        raise ZerocalError(f"eps0 must be positive, got {eps0}")
    n_min = max(int(n_min), 3)
    table, chosen = [], None
    for n in range(n_min, int(n_max) + 1):
        k1, km = kappas(robot, n, maemm_prior)
        eps = (k1 - km) / k1
        table.append({"n": n, "K": 2 * n, "kappa_1": k1, "kappa_m": km, "eps": eps})
        if chosen is None and abs(eps) <= eps0:
            chosen = n
            break
    if chosen is None:
        raise ZerocalError(f"no n in {n_min}..{n_max} gives |eps| <= eps0 = {eps0:g}")
    return NSelection(chosen, eps0, table, tuple(float(v) for v in maemm_prior))


# ---------------------------------------------------------------- the study
def run_group(robot, group, noise=None, rng=None, n=PAPER_N, frame="paper", mu0_deg=0.1, max_iter=20,
              identify=identify_tsvd, run_all=True) -> dict:
    """One group of Table 2 through the loop.

    Returns
    -------
    dict
        Keys ``group, compensation_deg, delta_deg, dp0_before_mm, dp0_after_mm,
        dpmax_before_mm, dpmax_after_mm, delta_maemm_mm, kappa_mean`` plus
        ``set_deg, maemm_mm, kappa_1, kappa_m, converged, iterations,
        history`` (per identification: compensation_deg, mu_deg, kappa).
        Offsets and MAEMM in Table 2's frame; ``kappa_mean`` over all
        identifications run (``max_iter`` with ``run_all``, as the paper's
        Fig. 9 / Table 6), the rest at the first ``mu < mu0``.
    """
    err = group_errors(group, frame)
    plant = VirtualPlant(robot, err)
    poses = paper_poses(robot, n)
    loop = calibration_loop(robot, plant, poses, identify=identify, noise=noise, rng=rng, mu0_deg=mu0_deg,
                            max_iter=max_iter, run_all=run_all)
    comp = np.radians(loop.compensation_deg)
    set_deg = to_table_frame(np.degrees(err[:2]), frame, "offsets")
    comp_t = to_table_frame(loop.compensation_deg, frame, "offsets")
    maemm_t = to_table_frame(loop.maemm_mm, frame, "maemm")
    true_maemm_t = to_table_frame(err[10:12], frame, "maemm")
    return {
        "group": int(group),
        "frame": frame,
        "set_deg": set_deg.tolist(),
        "compensation_deg": comp_t.tolist(),
        "delta_deg": np.abs(comp_t - set_deg).tolist(),
        "dp0_before_mm": home_error(robot, plant),
        "dp0_after_mm": home_error(robot, plant, comp),
        "dpmax_before_mm": float(np.max(position_errors(robot, plant, poses))),
        "dpmax_after_mm": float(np.max(position_errors(robot, plant, poses, comp))),
        "maemm_mm": maemm_t.tolist(),
        "delta_maemm_mm": np.abs(maemm_t - true_maemm_t).tolist(),
        "kappa_mean": loop.kappa_mean,
        "kappa_1": loop.kappa_1,
        "kappa_m": loop.kappa_m,
        "converged": bool(loop.converged),
        "iterations": int(loop.iterations),
        "history": {
            "compensation_deg": [to_table_frame(h.compensation_deg, frame, "offsets").tolist()
                                 for h in loop.history],
            "mu_deg": [h.mu_deg for h in loop.history],
            "kappa": [h.kappa for h in loop.history],
        },
    }


SUMMARY_KEYS = ("compensation_deg", "delta_deg", "dp0_before_mm", "dp0_after_mm", "dpmax_before_mm",
                "dpmax_after_mm", "delta_maemm_mm", "kappa_mean", "kappa_1", "kappa_m", "iterations")


def _summarise(runs: list) -> dict:
    """Mean (and std over trials) of the per-trial results of one group."""
    out = {"group": runs[0]["group"], "frame": runs[0]["frame"], "set_deg": runs[0]["set_deg"],
           "trials": len(runs), "converged_fraction": float(np.mean([r["converged"] for r in runs]))}
    for k in SUMMARY_KEYS:
        v = np.array([r[k] for r in runs], float)
        out[k] = np.mean(v, axis=0).tolist()
        if len(runs) > 1:
            out[k + "_std"] = np.std(v, axis=0, ddof=1).tolist()
    out["history"] = runs[0]["history"]
    return out


def reproduce(robot=None, seed=0, trials=1, noise="paper", n=PAPER_N, frame="paper", mu0_deg=0.1,
              max_iter=20, identify=identify_tsvd, groups=(1, 2, 3, 4, 5, 6), progress=None) -> dict:
    """Table 2's groups through the loop, with the paper's values alongside.

    Parameters
    ----------
    robot : Robot, optional
        Default: the paper's.
    seed : int
        Trial ``i`` of group ``g`` uses ``numpy.random.default_rng([seed + i, g])``.
    trials : int
    noise : str or NoiseModel
        ``paper`` | ``scale-only`` | ``servo-only`` | ``none`` or a NoiseModel.
    progress : callable, optional
        Called as ``progress(done, total)`` after each loop.

    Returns
    -------
    dict
        ``settings``, ``groups`` (per group: the means over trials, ``*_std``
        with more than one trial), ``paper`` (the paper's values per group),
        ``kappa`` (``kappa_1``, ``kappa_m`` of the design), ``crlb_zero_offsets_deg``
        (per noise model), ``elapsed_s``.
    """
    from zerocal_sym.identify.fisher import crlb_zero_offsets_deg
    from zerocal_sym.model.robot import paper_robot

    robot = robot or paper_robot()
    if trials < 1:
        raise ZerocalError(f"--trials must be >= 1, got {trials}")
    if n < 3:
        raise PoseError(f"n = {n} gives K = {2 * n} < 5 poses: the 4 parameters are not identifiable")
    for g in groups:
        group_errors(g, frame)
    noise_name = noise if isinstance(noise, str) else "custom"
    try:
        nm = NoiseModel.named(noise) if isinstance(noise, str) else noise
    except ValueError as exc:
        raise ZerocalError(str(exc)) from None
    t0 = time.perf_counter()
    total, done = len(groups) * trials, 0
    per_group = []
    for g in groups:
        runs = []
        for i in range(trials):
            rng = np.random.default_rng([seed + i, g])
            runs.append(run_group(robot, g, nm, rng, n=n, frame=frame, mu0_deg=mu0_deg, max_iter=max_iter,
                                  identify=identify))
            done += 1
            if progress:
                progress(done, total)
        per_group.append(_summarise(runs))
    poses = paper_poses(robot, n)
    th = kin.ik(robot, poses)
    crlb = {}
    for name in ("scale-only", "paper"):
        crlb[name] = crlb_zero_offsets_deg(robot, th, "paper", NoiseModel.named(name)).tolist()
    k1, km = kappas(robot, n, DEFAULT_MAEMM_PRIOR)
    return {
        "settings": {"seed": seed, "trials": trials, "noise": noise_name,
                     "sigma_scale_mm": nm.sigma_scale_mm, "sigma_servo_deg": float(np.degrees(nm.sigma_servo_rad)),
                     "n": n, "K": 2 * n, "frame": frame, "mu0_deg": mu0_deg, "max_iter": max_iter,
                     "identifier": getattr(identify, "__name__", str(identify)), "robot": robot.name},
        "groups": per_group,
        "paper": [paper_table(g) for g in groups] if robot.name == "paper" else [],
        "kappa": {"kappa_1": k1, "kappa_m": km, "maemm_prior_mm": list(DEFAULT_MAEMM_PRIOR),
                  "paper_kappa_1": PAPER_KAPPA_1, "paper_kappa_m": PAPER_KAPPA_M},
        "crlb_zero_offsets_deg": crlb,
        "elapsed_s": time.perf_counter() - t0,
    }


# ---------------------------------------------------------------- text tables
def _pm(v, s, fmt):
    return fmt.format(v) if s is None else (fmt.format(v) + "±" + fmt.format(s).strip())


def format_tables(rep: dict) -> str:
    """Tables 3-6 side by side with the paper's values (text)."""
    paper = {p["group"]: p for p in rep.get("paper", [])}
    lines = []
    st = rep["settings"]
    lines.append(f"zerocal reproduce: noise {st['noise']} (sigma_scale {st['sigma_scale_mm'] * 1e3:.3g} um, "
                 f"sigma_servo {st['sigma_servo_deg']:.3g} deg), {st['trials']} trial(s), seed {st['seed']}, "
                 f"n = {st['n']} (K = {st['K']}), mu0 = {st['mu0_deg']:g} deg, {st['max_iter']} identifications, "
                 f"Table 2 read in the {st['frame']} frame")
    lines.append("values: ours" + (" (mean±std over trials)" if st["trials"] > 1 else "") + " | paper")

    def get(r, k, i=None):
        v = r[k] if i is None else r[k][i]
        s = r.get(k + "_std")
        s = None if s is None else (s if i is None else s[i])
        return v, s

    def pcol(g, k, i=None):
        if g not in paper:
            return ""
        v = paper[g][k]
        return f"{(v if i is None else v[i]):g}"

    lines.append("")
    lines.append("Table 3: compensation value, delta = |set - compensation| [deg], dp0 before/after [mm]")
    lines.append(f"{'grp':>3} {'':4} {'set':>6} {'comp':>15} {'paper':>7} {'delta':>15} {'paper':>6}"
                 f" {'dp0 before':>12} {'paper':>7} {'dp0 after':>13} {'paper':>6}")
    for r in rep["groups"]:
        g = r["group"]
        for i in range(2):
            c, cs = get(r, "compensation_deg", i)
            d, ds = get(r, "delta_deg", i)
            row = (f"{g:>3} {'dth' + str(i + 1):4} {r['set_deg'][i]:6.2f} {_pm(c, cs, '{:7.3f}'):>15} "
                   f"{pcol(g, 'compensation_deg', i):>7} {_pm(d, ds, '{:6.3f}'):>15} {pcol(g, 'delta_deg', i):>6}")
            if i == 0:
                b, bs = get(r, "dp0_before_mm")
                a, as_ = get(r, "dp0_after_mm")
                row += (f" {_pm(b, bs, '{:7.3f}'):>12} {pcol(g, 'dp0_before_mm'):>7}"
                        f" {_pm(a, as_, '{:6.3f}'):>13} {pcol(g, 'dp0_after_mm'):>6}")
            lines.append(row)
    lines.append("")
    lines.append("Table 4: dp_max over the measurement poses [mm]")
    lines.append(f"{'grp':>3} {'before':>12} {'paper':>7} {'after':>13} {'paper':>6}")
    for r in rep["groups"]:
        g = r["group"]
        b, bs = get(r, "dpmax_before_mm")
        a, as_ = get(r, "dpmax_after_mm")
        lines.append(f"{g:>3} {_pm(b, bs, '{:7.3f}'):>12} {pcol(g, 'dpmax_before_mm'):>7} "
                     f"{_pm(a, as_, '{:6.3f}'):>13} {pcol(g, 'dpmax_after_mm'):>6}")
    lines.append("")
    lines.append("Table 5: |set - identified| MAEMM [mm]")
    lines.append(f"{'grp':>3} {'d_rMx':>13} {'paper':>6} {'d_rMy':>13} {'paper':>6}")
    for r in rep["groups"]:
        g = r["group"]
        x, xs = get(r, "delta_maemm_mm", 0)
        y, ys = get(r, "delta_maemm_mm", 1)
        lines.append(f"{g:>3} {_pm(x, xs, '{:6.3f}'):>13} {pcol(g, 'delta_maemm_mm', 0):>6} "
                     f"{_pm(y, ys, '{:6.3f}'):>13} {pcol(g, 'delta_maemm_mm', 1):>6}")
    lines.append("")
    lines.append("Table 6: mean condition number over all identifications (kappa_1, mean of the later ones)")
    lines.append(f"{'grp':>3} {'kappa_mean':>10} {'paper':>7} {'kappa_1':>8} {'kappa_m':>8} {'iter':>5} {'conv':>5}")
    for r in rep["groups"]:
        g = r["group"]
        lines.append(f"{g:>3} {r['kappa_mean']:10.2f} {pcol(g, 'kappa_mean'):>7} {r['kappa_1']:8.2f} "
                     f"{r['kappa_m']:8.2f} {r['iterations']:5.1f} {r['converged_fraction']:5.2f}")
    k = rep["kappa"]
    cr = rep["crlb_zero_offsets_deg"]
    lines.append("")
    lines.append(f"design: kappa_1 = {k['kappa_1']:.2f} (paper {k['paper_kappa_1']}), kappa_m = {k['kappa_m']:.2f} "
                 f"(paper {k['paper_kappa_m']}) with MAEMM prior {tuple(k['maemm_prior_mm'])} mm")
    lines.append(f"CRLB of each zero offset at these poses: scale-only {cr['scale-only'][0]:.3f}/"
                 f"{cr['scale-only'][1]:.3f} deg, paper noise (scale + servo) {cr['paper'][0]:.3f}/"
                 f"{cr['paper'][1]:.3f} deg; see docs/reproduction.md")
    lines.append(f"elapsed {rep['elapsed_s']:.2f} s")
    return "\n".join(lines)
