"""Monte Carlo comparison of the identification methods on the same simulated data.

Per trial (one seed per group and trial), the first measurement round is
simulated once; every method sees exactly that round first:

* ``tsvd-loop``  -- the paper's procedure: TSVD identification inside the
  compensation loop (:func:`zerocal_sym.paper.calibration_loop`), stopping at
  the first ``mu < mu0``;
* ``tsvd``       -- the first TSVD identification of that loop alone;
* ``nlls``       -- Ipopt on the exact model, one shot, on the first round;
* ``nlls-loop``  -- Ipopt as the identifier of the same loop (each round's
  estimate from that round's data only);
* ``nlls-seq``   -- the loop with sequential MAP (each round's Ipopt estimate
  uses the previous round's estimate and covariance as a Gaussian prior:
  the information of all rounds is kept) -- beyond the paper;
* ``scipy``      -- ``scipy.optimize.least_squares`` (``method="lm"``) on the
  first round's whitened problem, as an outside reference for the answer
  (difference to Ipopt on the identical problem) and the speed.

The loops draw their later rounds from the same seed, so the loop methods
share the first round but not (after their compensations differ) the later
ones.  Errors are reported in Table 2's frame (``frame="paper"``, as
``zerocal reproduce``; RMS values do not depend on the frame).
"""
from __future__ import annotations

import sys
import time

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import IdentificationError, ZerocalError
from zerocal_sym.model.noise import NoiseModel, VirtualPlant

METHODS = ("tsvd-loop", "tsvd", "nlls", "nlls-loop", "nlls-seq", "scipy")


class Progress:
    """A progress bar on a stream (stderr), redrawn at most every 0.2 s.

    On a terminal it redraws one line; otherwise it prints a line every 10 %.
    """

    def __init__(self, total: int, label: str = "compare", stream=None, enabled: bool = True):
        self.total, self.label, self.enabled = max(1, int(total)), label, enabled
        self.stream = sys.stderr if stream is None else stream
        self.t0 = self.last = time.perf_counter()
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.next_pct = 10

    def __call__(self, done: int) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        frac = done / self.total
        el = now - self.t0
        eta = el / frac - el if frac > 0 else float("nan")
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        text = f"{self.label} [{bar}] {done}/{self.total}  {el:.1f} s, eta {eta:.0f} s"
        if self.tty:
            if done == self.total or now - self.last > 0.2:
                self.last = now
                self.stream.write("\r" + text + ("\n" if done == self.total else ""))
                self.stream.flush()
        elif 100 * frac >= self.next_pct or done == self.total:
            while self.next_pct <= 100 * frac:
                self.next_pct += 10
            self.stream.write(text + "\n")
            self.stream.flush()


class _Timed:
    """Wrap an identifier: count the calls and the time spent in them."""

    def __init__(self, fn):
        self.fn, self.n, self.t = fn, 0, 0.0

    def __call__(self, robot, meas, prior=None):
        t = time.perf_counter()
        try:
            return self.fn(robot, meas, prior)
        finally:
            self.t += time.perf_counter() - t
            self.n += 1


def _scipy_least_squares():
    try:
        from scipy.optimize import least_squares
    except ImportError:  # pragma: no cover - scipy is a test extra
        raise ZerocalError("the scipy reference needs scipy (a test/benchmark extra: pip install "
                           "'zerocal_sym[test]'), or leave 'scipy' out of --methods") from None
    return least_squares


def scipy_identify(robot, meas, params="paper", noise=None, prior=None):
    """``scipy.optimize.least_squares`` on the problem Ipopt solves (reference).

    The whitened, scaled residuals of :func:`zerocal_sym.identify.nlls.residual_problem`
    (weights at ``prior``), Levenberg-Marquardt from ``prior``.

    Returns
    -------
    estimate : ndarray, shape (p,)
        rad / mm.
    info : dict
        ``success``, ``nfev``, ``cost``, ``time_s`` (the solver call only).
    """
    from zerocal_sym.identify.nlls import residual_problem

    least_squares = _scipy_least_squares()
    fun, jac, scale = residual_problem(robot, meas, params, noise, prior)
    p0 = np.zeros(12) if prior is None else np.asarray(prior, float)
    z0 = p0[fisher.param_indices(params)] * scale
    t = time.perf_counter()
    sol = least_squares(fun, z0, jac=jac, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    dt = time.perf_counter() - t
    return sol.x / scale, {"success": bool(sol.success), "nfev": int(sol.nfev), "cost": float(sol.cost),
                           "time_s": dt}


def _stats(E):
    E = np.asarray(E, float)
    if E.size == 0:
        return None, None
    return np.mean(E, axis=0), np.sqrt(np.mean(E**2, axis=0))


def compare(robot, groups=(1,), trials: int = 100, poses=None, params="paper", noise: NoiseModel | None = None,
            seed: int = 0, frame: str = "paper", methods=METHODS, mu0_deg: float = 0.1, max_iter: int = 20,
            progress=None, geometric: bool = True) -> dict:
    """Run the Monte Carlo comparison.

    Parameters
    ----------
    robot : Robot
    groups : sequence of int
        Table 2 groups (1..6), read in ``frame``.
    trials : int
        Trials per group.
    poses : ndarray, shape (K, 2), optional
        Measurement poses in visiting order (default: the paper's 6).
    params : str or sequence of str
        Parameters of the Ipopt methods (TSVD always has the paper's 4).
    noise : NoiseModel, optional
        Simulation noise and the weights of Ipopt (default: the paper's).
    seed : int
    frame : {"paper", "literal"}
    methods : sequence of str
        A subset of :data:`METHODS`.
    mu0_deg, max_iter : loop settings.
    geometric : bool
        Keep Table 2's geometric errors in the plant (False: only offsets and MAEMM,
        so the 4-parameter model is exact).
    progress : callable, optional
        ``progress(done)`` after each trial.

    Returns
    -------
    dict
        ``settings``, ``crlb_zero_offsets_deg`` (per group, at the truth and the
        first round's poses), and per group and method: ``bias_deg``,
        ``rms_deg``, ``rms_crlb_ratio`` (zero offsets), ``bias_maemm_mm``,
        ``rms_maemm_mm``, ``dp0_rms_mm`` / ``dp0_mean_mm`` / ``dp0_max_mm``
        (home position error after compensating with the estimate),
        ``failures`` (identification failed or raised), ``not_converged``
        (loops that did not reach ``mu < mu0``), ``identifications``
        (per trial, mean), ``time_per_identification_ms``; ``scipy``:
        ``max_abs_diff_to_ipopt_deg`` and the time ratio.
    """
    from zerocal_sym.paper import reproduction as paper
    from zerocal_sym.identify.nlls import identify_nlls, make_nlls_identifier
    from zerocal_sym.paper.scheme import paper_poses
    from zerocal_sym.identify.tsvd import identify_tsvd

    noise = NoiseModel.paper() if noise is None else noise
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ZerocalError(f"unknown method(s) {', '.join(unknown)} (known: {', '.join(METHODS)})")
    if "scipy" in methods:
        _scipy_least_squares()
    names = fisher.param_names(params)
    if "theta1" not in names or "theta2" not in names:
        raise ZerocalError("the parameter set must contain theta1 and theta2")
    poses = paper_poses(robot, 3) if poses is None else np.atleast_2d(np.asarray(poses, float))
    th0 = kin.check_poses(robot, poses)
    K = poses.shape[0]
    if K - 1 < len(names):
        raise ZerocalError(f"{K} poses give {K - 1} measured changes: fewer than the {len(names)} parameters")
    out = {"settings": {"groups": list(groups), "trials": trials, "K": K, "poses_mm": poses.tolist(),
                        "params": list(names), "noise": {"sigma_scale_mm": noise.sigma_scale_mm,
                                                         "sigma_servo_rad": noise.sigma_servo_rad},
                        "seed": seed, "frame": frame, "methods": list(methods), "mu0_deg": mu0_deg,
                        "max_iter": max_iter, "geometric_errors": bool(geometric), "error_frame": "Table 2's" if frame == "paper" else "ours"},
           "groups": {}}
    done = 0
    for g in groups:
        err = paper.group_errors(g, frame)
        if not geometric:
            err[2:10] = 0.0
        plant = VirtualPlant(robot, err)
        true4 = err[[0, 1, 10, 11]]
        try:
            crlb = fisher.crlb_zero_offsets_deg(robot, th0, names, noise, err0=err) if not noise.is_zero else None
        except ZerocalError:
            crlb = None
        rec = {m: {"E": [], "M": [], "dp0": [], "fail": 0, "nc": 0, "nid": 0, "t": 0.0} for m in methods}
        sc_diff, sc_t, ip_t = [], [], []
        for trial in range(trials):
            ss = np.random.SeedSequence([seed, g, trial])
            meas1 = paper.simulate_round(robot, plant, poses, (0.0, 0.0), noise, np.random.default_rng(ss))

            def record(m, est4, t, n_ident=1, converged=True):
                r = rec[m]
                r["t"] += t
                r["nid"] += n_ident
                if est4 is None:
                    r["fail"] += 1
                    return
                r["nc"] += 0 if converged else 1
                e = est4 - true4
                r["E"].append(paper.to_table_frame(np.degrees(e[:2]), frame, "offsets"))
                r["M"].append(paper.to_table_frame(e[2:], frame, "maemm"))
                r["dp0"].append(paper.home_error(robot, plant, est4[:2]))

            for m in ("tsvd-loop", "nlls-loop", "nlls-seq"):
                if m not in methods and not (m == "tsvd-loop" and "tsvd" in methods):
                    continue
                ident = _Timed(identify_tsvd if m == "tsvd-loop" else
                               make_nlls_identifier(params=names, noise=noise, sequential=(m == "nlls-seq")))
                try:
                    loop = paper.calibration_loop(robot, plant, poses, identify=ident, noise=noise,
                                                  rng=np.random.default_rng(ss), mu0_deg=mu0_deg, max_iter=max_iter)
                except (IdentificationError, ZerocalError):
                    loop = None
                if m == "tsvd-loop" and "tsvd" in methods:
                    first = loop.history[0].result if loop is not None and loop.history else None
                    if first is None or not first.success:
                        record("tsvd", None, 0.0)
                    else:
                        record("tsvd", np.array([first.value(n) for n in ("theta1", "theta2", "rMx", "rMy")]),
                               ident.t / max(1, ident.n))
                if m not in methods:
                    continue
                if loop is None:
                    record(m, None, ident.t, ident.n)
                    continue
                est = np.concatenate([np.radians(loop.compensation_deg), loop.maemm_mm])
                record(m, est, ident.t, ident.n, loop.converged)
            if "nlls" in methods or "scipy" in methods:
                t = time.perf_counter()
                res = identify_nlls(robot, meas1, names, noise=noise)
                dt = time.perf_counter() - t
                est = (np.array([res.value(n) for n in ("theta1", "theta2", "rMx", "rMy")])
                       if res.success else None)
                if "nlls" in methods:
                    record("nlls", est, dt)
            if "scipy" in methods:
                ref = identify_nlls(robot, meas1, names, noise=noise, warm_start=None, reweight=0)
                p_sc, info = scipy_identify(robot, meas1, names, noise)
                ok = info["success"] and ref.success
                record("scipy", np.array([p_sc[names.index(n)] if n in names else 0.0
                                          for n in ("theta1", "theta2", "rMx", "rMy")]) if ok else None,
                       info["time_s"])
                if ok:
                    sc_diff.append(np.max(np.abs(np.degrees(p_sc[:2] - ref.estimate[:2]))))
                    sc_t.append(info["time_s"])
                    ip_t.append(ref.info["time_s"])
            done += 1
            if progress:
                progress(done)
        gout = {"crlb_zero_offsets_deg": None if crlb is None else np.asarray(crlb).tolist(),
                "set_deg": paper.to_table_frame(np.degrees(err[:2]), frame, "offsets").tolist(),
                "methods": {}}
        for m in methods:
            r = rec[m]
            bias, rms = _stats(r["E"])
            mb, mr = _stats(r["M"])
            dp0 = np.asarray(r["dp0"])
            ok = len(r["E"])
            gout["methods"][m] = {
                "trials": trials,
                "failures": r["fail"],
                "not_converged": r["nc"] if m.endswith(("loop", "seq")) else None,
                "bias_deg": None if bias is None else bias.tolist(),
                "rms_deg": None if rms is None else rms.tolist(),
                "rms_crlb_ratio": (None if rms is None or crlb is None else (rms / np.asarray(crlb)).tolist()),
                "bias_maemm_mm": None if mb is None else mb.tolist(),
                "rms_maemm_mm": None if mr is None else mr.tolist(),
                "dp0_rms_mm": float(np.sqrt(np.mean(dp0**2))) if ok else None,
                "dp0_mean_mm": float(np.mean(dp0)) if ok else None,
                "dp0_max_mm": float(np.max(dp0)) if ok else None,
                "identifications": r["nid"] / trials if trials else None,
                "time_per_identification_ms": 1e3 * r["t"] / max(1, r["nid"]),
            }
        if "scipy" in methods and sc_t:
            gout["scipy_reference"] = {
                "problem": "whitened residuals, weights at zero, start at zero (Ipopt: warm_start=None, reweight=0)",
                "max_abs_diff_to_ipopt_deg": float(np.max(sc_diff)),
                "time_scipy_ms": 1e3 * float(np.mean(sc_t)),
                "time_ipopt_ms": 1e3 * float(np.mean(ip_t)),
                "time_ratio_ipopt_over_scipy": float(np.mean(ip_t) / np.mean(sc_t)),
            }
        out["groups"][str(g)] = gout
    return out


def format_compare(rep: dict) -> str:
    """The comparison as text tables."""
    s = rep["settings"]
    lines = [f"Monte Carlo: {s['trials']} trials per group, K = {s['K']} poses, Ipopt parameters "
             f"{', '.join(s['params'])}, noise scale {s['noise']['sigma_scale_mm'] * 1e3:.4g} um, servo "
             f"{np.degrees(s['noise']['sigma_servo_rad']):.4g} deg, seed {s['seed']}; geometric errors "
             f"{'on' if s['geometric_errors'] else 'off'}; errors in {s['error_frame']} frame"]
    for g, go in rep["groups"].items():
        cr = go["crlb_zero_offsets_deg"]
        lines.append("")
        lines.append(f"group {g}: set offsets {go['set_deg'][0]:+.3f}, {go['set_deg'][1]:+.3f} deg;  CRLB "
                     + ("n/a" if cr is None else f"{cr[0]:.4f}, {cr[1]:.4f} deg"))
        lines.append(f"  {'method':10s} {'bias dth1,dth2 [deg]':>22s} {'RMS dth1,dth2 [deg]':>21s} "
                     f"{'RMS/CRLB':>13s} {'RMS rM [mm]':>15s} {'dp0 RMS':>8s} {'fail':>4s} {'noconv':>6s} "
                     f"{'ident':>5s} {'ms/ident':>8s}")
        for m, r in go["methods"].items():
            if r["rms_deg"] is None:
                lines.append(f"  {m:10s} all {r['failures']} trials failed")
                continue
            ratio = "n/a" if r["rms_crlb_ratio"] is None else f"{r['rms_crlb_ratio'][0]:.3f},{r['rms_crlb_ratio'][1]:.3f}"
            nc = "-" if r["not_converged"] is None else str(r["not_converged"])
            lines.append(f"  {m:10s} {r['bias_deg'][0]:+10.4f},{r['bias_deg'][1]:+10.4f} "
                         f"{r['rms_deg'][0]:10.4f},{r['rms_deg'][1]:10.4f} {ratio:>13s} "
                         f"{r['rms_maemm_mm'][0]:7.4f},{r['rms_maemm_mm'][1]:7.4f} {r['dp0_rms_mm']:8.4f} "
                         f"{r['failures']:4d} {nc:>6s} {r['identifications']:5.1f} "
                         f"{r['time_per_identification_ms']:8.2f}")
        sr = go.get("scipy_reference")
        if sr:
            lines.append(f"  scipy least_squares (lm) on the same problem: max |diff| to Ipopt "
                         f"{sr['max_abs_diff_to_ipopt_deg']:.2e} deg; time Ipopt {sr['time_ipopt_ms']:.2f} ms "
                         f"(whole identification) vs scipy {sr['time_scipy_ms']:.2f} ms (solver call): "
                         f"ratio {sr['time_ratio_ipopt_over_scipy']:.2f}")
    return "\n".join(lines)
