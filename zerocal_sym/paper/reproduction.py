"""The paper's calibration procedure and its simulation study (Sections 5-6).

* :func:`simulate_round` -- one identification round on a virtual plant;
* :func:`calibration_loop` -- identify, compensate, re-measure, identify the
  remainder until ``mu < mu0`` (Eq. 30-33), with a pluggable identifier;
* :func:`select_n` -- the number of poses per boundary by the eps rule (Eq. 31);
* :func:`run_group` / :func:`reproduce` -- Table 2's six groups through the
  loop, with the paper's Tables 3-6 alongside.

Frame of Table 2 (see ``docs/reproduction.md``)
-----------------------------------------------
Read literally in our frame (``y`` from the base towards the workspace, angles
counter-clockwise), Table 2's set values do not give the paper's ``dp0
(before)`` (Table 3) and ``dp_max (before)`` (Table 4): differences up to
0.19 mm.  Read in the frame mirrored about the ``x`` axis (``y -> -y``: the
zero offsets, the ``e_iy`` and ``rMy`` change sign, everything else is
unchanged) they reproduce Table 3 within 0.0015 mm and Table 4 within
0.0004 mm (exact forward kinematics).  ``frame="paper"`` (the default) applies
this reading; ``frame="literal"`` does not.  Offsets and MAEMM are *reported*
in Table 2's frame so that they compare directly with the paper.

Stopping rule
-------------
``mu_j = sqrt(((c1_j - c1_{j-1})^2 + (c2_j - c2_{j-1})^2) / 2)`` with ``c_j``
the compensation value (sum of the increments) after the ``j``-th
identification, i.e. the RMS of the ``j``-th increment; defined from ``j = 2``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.errors import IdentificationError, PoseError, ZerocalError
from zerocal_sym.model.noise import NoiseModel, VirtualPlant, table2_errors
from zerocal_sym.paper.scheme import condition_number, identification_matrix, paper_poses
from zerocal_sym.identify.tsvd import identify_tsvd

#: Sign of each source error (SOURCE_ERROR_NAMES order) under the mirror y -> -y.
MIRROR_Y = np.array([-1, -1, 1, -1, 1, -1, 1, 1, 1, 1, 1, -1], dtype=float)
FRAMES = ("paper", "literal")
#: The paper's MAEMM prior (1, 0.5) mm read in the paper's (mirrored) frame, in our frame.
DEFAULT_MAEMM_PRIOR = (1.0, -0.5)
#: kappa_m readings of the paper's prior: label -> prior applied as lambda_k - rM (our frame).
MAEMM_PRIOR_READINGS = {
    "paper frame (y mirrored), lambda - rM": (1.0, -0.5),
    "literal, lambda - rM": (1.0, 0.5),
    "literal, lambda + rM": (-1.0, -0.5),
    "paper frame, lambda + rM": (-1.0, 0.5),
}

# ---------------------------------------------------------------- paper's numbers
PAPER_N = 3
PAPER_KAPPA_1 = 475.34
PAPER_KAPPA_M = 472.54
#: Table 3: group -> compensation (deg), delta (deg), dp0 before, dp0 after (mm)
PAPER_TABLE3 = {
    1: ((2.033, -0.957), (0.033, 0.043), 10.933, 0.402),
    2: ((-1.049, 0.463), (0.049, 0.037), 5.482, 0.423),
    3: ((0.536, 0.297), (0.036, 0.047), 3.796, 0.434),
    4: ((2.024, -0.978), (0.024, 0.022), 10.896, 0.228),
    5: ((-1.025, 0.474), (0.025, 0.026), 5.5195, 0.256),
    6: ((0.476, 0.225), (0.024, 0.025), 3.798, 0.239),
}
#: Table 4: group -> dp_max before, after (mm), over the six measurement poses
PAPER_TABLE4 = {1: (12.906, 0.493), 2: (6.418, 0.531), 3: (4.672, 0.533),
                4: (12.868, 0.279), 5: (6.455, 0.314), 6: (4.663, 0.293)}
#: Table 5: group -> |delta rMx|, |delta rMy| (mm)
PAPER_TABLE5 = {1: (0.069, 0.040), 2: (0.074, 0.045), 3: (0.071, 0.042),
                4: (0.044, 0.022), 5: (0.051, 0.028), 6: (0.047, 0.024)}
#: Table 6: group -> mean condition number
PAPER_TABLE6 = {1: 472.47, 2: 472.49, 3: 472.49, 4: 472.50, 5: 472.51, 6: 472.50}


def paper_table(group: int) -> dict:
    """The paper's reported values for one group, with the JSON keys of :func:`run_group`."""
    comp, delta, b, a = PAPER_TABLE3[group]
    return {"group": group, "compensation_deg": list(comp), "delta_deg": list(delta),
            "dp0_before_mm": b, "dp0_after_mm": a, "dpmax_before_mm": PAPER_TABLE4[group][0],
            "dpmax_after_mm": PAPER_TABLE4[group][1], "delta_maemm_mm": list(PAPER_TABLE5[group]),
            "kappa_mean": PAPER_TABLE6[group]}


def group_errors(group: int, frame: str = "paper") -> np.ndarray:
    """Source errors of Table 2's group in our frame, ndarray shape (12,).

    Parameters
    ----------
    group : int
        1..6.
    frame : {"paper", "literal"}
        ``paper``: Table 2 read in the frame mirrored about the x axis (module
        docstring); ``literal``: read in our frame as printed.

    Raises
    ------
    ZerocalError
        Unknown group or frame.
    """
    if group not in PAPER_TABLE3:
        raise ZerocalError(f"unknown group {group!r}: Table 2 has groups 1..6")
    if frame not in FRAMES:
        raise ZerocalError(f"unknown frame {frame!r} (known: {', '.join(FRAMES)})")
    err = table2_errors(group)
    return err * MIRROR_Y if frame == "paper" else err


def to_table_frame(vec, frame: str, which: str):
    """Offsets (``which="offsets"``) or MAEMM (``"maemm"``) from our frame to Table 2's."""
    v = np.asarray(vec, float)
    if frame == "literal":
        return v.copy()
    return v * (MIRROR_Y[[0, 1]] if which == "offsets" else MIRROR_Y[[10, 11]])


# ---------------------------------------------------------------- simulation and loop
def simulate_round(robot, plant, poses, compensation_rad=(0.0, 0.0), noise=None, rng=None) -> Measurements:
    """One identification round: command the poses, read the scale.

    Parameters
    ----------
    robot : Robot
        Nominal robot (the controller's model).
    plant : VirtualPlant
    poses : ndarray, shape (K, 2)
        Nominal target poses, mm, in visiting order.
    compensation_rad : (2,)
        Current compensation: commanded = IK(poses) - compensation.
    noise : NoiseModel, optional
    rng : numpy Generator or seed, optional

    Returns
    -------
    Measurements
        ``theta_cmd`` (K, 2) rad, ``readings`` (K,) mm, ``target`` = poses.
    """
    poses = np.atleast_2d(np.asarray(poses, float))
    theta_cmd = kin.ik(robot, poses) - np.asarray(compensation_rad, float)
    readings = plant.measure(theta_cmd, noise, rng)
    return Measurements(theta_cmd=theta_cmd, readings=readings, target=poses.copy(),
                        meta={}, source="<simulated>")


@dataclass
class IterationRecord:
    """One identification of the loop.

    Attributes
    ----------
    result : IdentificationResult
    compensation_deg : ndarray, shape (2,)
        Compensation value (sum of increments) after this identification, our frame.
    increment_deg : ndarray, shape (2,)
    mu_deg : float or None
        Compensation accuracy (None at the first identification).
    kappa : float
        Condition number of G of this identification (NaN if the identifier does not report it).
    maemm_mm : ndarray, shape (2,)
    """

    result: object
    compensation_deg: np.ndarray
    increment_deg: np.ndarray
    mu_deg: float | None
    kappa: float
    maemm_mm: np.ndarray


@dataclass
class LoopResult:
    """The whole history of a calibration loop.

    Attributes
    ----------
    history : list of IterationRecord
    compensation_deg : ndarray, shape (2,)
        Compensation value when the loop stopped (at the first ``mu < mu0``
        if it converged, else after the last identification), our frame.
    maemm_mm : ndarray, shape (2,)
        MAEMM estimate at the same identification.
    converged : bool
    iterations : int
        Identifications up to and including the stopping one.
    """

    history: list = field(default_factory=list)
    compensation_deg: np.ndarray = field(default_factory=lambda: np.zeros(2))
    maemm_mm: np.ndarray = field(default_factory=lambda: np.zeros(2))
    converged: bool = False
    iterations: int = 0

    @property
    def kappas(self) -> np.ndarray:
        """Condition number of each identification, shape (len(history),)."""
        return np.array([h.kappa for h in self.history])

    @property
    def kappa_1(self) -> float:
        return float(self.history[0].kappa)

    @property
    def kappa_mean(self) -> float:
        """Mean condition number over all identifications run (paper's Table 6)."""
        return float(np.mean(self.kappas))

    @property
    def kappa_m(self) -> float:
        """Mean condition number over the identifications after the first."""
        k = self.kappas[1:]
        return float(np.mean(k)) if k.size else float("nan")


def calibration_loop(robot, plant, poses, identify=identify_tsvd, noise=None, rng=None, mu0_deg=0.1,
                     max_iter=20, maemm_prior=None, run_all=False) -> LoopResult:
    """The paper's iterative identification and compensation (Eq. 30-33).

    Each round commands ``IK(poses) - compensation``, measures, and calls
    ``identify(robot, meas, prior)`` with ``prior`` the 12-vector of the
    current total estimates (offsets = compensation, MAEMM = previous
    estimate; from the 2nd identification on this corrects the nominal
    measuring-mechanism vector, Eq. 30).  The identifier returns totals; the
    new compensation is its offset estimate (= the sum of the increments).

    Parameters
    ----------
    robot : Robot
    plant : VirtualPlant
    poses : ndarray, shape (K, 2)
    identify : callable
        ``identify(robot, meas, prior) -> IdentificationResult`` (TSVD by default;
        an Ipopt identifier plugs in the same way).
    noise : NoiseModel, optional
    rng : numpy Generator or seed, optional
    mu0_deg : float
        Threshold of the compensation accuracy mu.
    max_iter : int
        Maximum number of identifications.
    maemm_prior : (2,), optional
        MAEMM prior of the first identification (default zero, as the paper).
    run_all : bool
        Continue to ``max_iter`` after convergence (the paper's robustness
        study, Fig. 9); the reported state is still the one at convergence.

    Returns
    -------
    LoopResult
    """
    if max_iter < 1:
        raise ValueError("max_iter must be >= 1")
    rng = np.random.default_rng(rng)
    prior = np.zeros(12)
    if maemm_prior is not None:
        prior[10:12] = np.asarray(maemm_prior, float)
    out = LoopResult()
    comp = np.zeros(2)
    for j in range(1, max_iter + 1):
        meas = simulate_round(robot, plant, poses, comp, noise, rng)
        res = identify(robot, meas, prior.copy())
        if not getattr(res, "success", True):
            raise IdentificationError(f"identification {j} failed: {res.status}")
        new = np.array([res.value("theta1"), res.value("theta2")])
        maemm = np.array([res.value("rMx", prior[10]), res.value("rMy", prior[11])])
        inc = new - comp
        mu = None if j == 1 else float(np.degrees(np.sqrt(np.mean(inc**2))))
        kappa = float(res.info.get("kappa", np.nan)) if isinstance(res.info, dict) else float("nan")
        if not np.isfinite(kappa):
            P = kin.fk(robot, meas.theta_cmd + prior[:2])
            kappa = condition_number(identification_matrix(robot, P, prior[10:12])[0])
        out.history.append(IterationRecord(res, np.degrees(new), np.degrees(inc), mu, kappa, maemm.copy()))
        comp = new
        prior[:2] = new
        prior[10:12] = maemm
        if not out.converged:
            out.compensation_deg, out.maemm_mm, out.iterations = np.degrees(new), maemm.copy(), j
            if mu is not None and mu < mu0_deg:
                out.converged = True
                if not run_all:
                    break
    return out


# ---------------------------------------------------------------- evaluation
def position_errors(robot, plant, poses, compensation_rad=(0.0, 0.0)) -> np.ndarray:
    """``|P_actual - P|`` at nominal poses commanded as ``IK(P) - compensation``.

    Exact forward kinematics of the actual robot (no noise).

    Returns
    -------
    ndarray, shape (K,)
        mm.
    """
    poses = np.atleast_2d(np.asarray(poses, float))
    th = kin.ik(robot, poses) - np.asarray(compensation_rad, float)
    return np.linalg.norm(plant.actual_pose(th) - poses, axis=1)


def home_error(robot, plant, compensation_rad=(0.0, 0.0)) -> float:
    """``dp0``: distance from P0 of the platform commanded to home (minus the compensation), mm."""
    th = robot.home_joints()[None, :] - np.asarray(compensation_rad, float)
    return float(np.linalg.norm(plant.actual_pose(th)[0] - robot.home_pose()))


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
