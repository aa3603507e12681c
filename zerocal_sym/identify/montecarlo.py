"""Monte Carlo comparison of the identification methods on the same simulated data.

For any mechanism: given the true source errors (one or more labelled
*truths*) and the measurement poses, per trial (one seed per truth and trial)
the first measurement round is simulated once; every method sees exactly that
round first:

* ``tsvd-loop``  -- the paper's procedure: TSVD identification inside the
  compensation loop (:func:`zerocal_sym.identify.loop.calibration_loop`), stopping at
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
ones.  Errors are reported in our frame, or through a ``report`` transform
(the paper's Table 2 frame: :func:`zerocal_sym.paper.compare.compare`; RMS
values do not depend on the frame).
"""
from __future__ import annotations

import sys
import time

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.errors import IdentificationError, ZerocalError
from zerocal_sym.identify.loop import calibration_loop, home_error, simulate_round
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
    p0 = robot.errors.zeros() if prior is None else np.asarray(prior, float)
    z0 = robot.errors.take(p0, robot.errors.resolve(params)) * scale
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


def _identity_report(values, which):
    return np.asarray(values, float)


def compare(robot, truths: dict, poses, trials: int = 100, params="paper", noise: NoiseModel | None = None,
            seed: int = 0, methods=METHODS, mu0_deg: float = 0.1, max_iter: int = 20,
            progress=None, report=None, settings=None) -> dict:
    """Run the Monte Carlo comparison.

    Parameters
    ----------
    robot : Robot
    truths : dict of label -> ndarray, shape (q,)
        The true source errors (rad, mm) of each study; the label keys the
        output (``rep["groups"][str(label)]``).  Seeds are ``(seed, label, trial)``
        for an integer label, ``(seed, index, trial)`` otherwise.
    poses : ndarray, shape (K, n)
        Measurement poses in visiting order.
    trials : int
        Trials per truth.
    params : str or sequence of str
        Parameters of the Ipopt methods (TSVD always has the zero offsets and the MAEMM).
    noise : NoiseModel, optional
        Simulation noise and the weights of Ipopt (default: the paper's).
    seed : int
    methods : sequence of str
        A subset of :data:`METHODS`.
    mu0_deg, max_iter : loop settings.
    progress : callable, optional
        ``progress(done)`` after each trial.
    report : callable, optional
        ``report(values, which)`` with ``which`` ``"offsets"`` (deg, m) or
        ``"maemm"`` (mm, n): how errors are reported (default: as they are).
    settings : dict, optional
        Extra entries for ``rep["settings"]``.

    Returns
    -------
    dict
        ``settings``, ``crlb_zero_offsets_deg`` (per truth, at the truth and the
        first round's poses), and per group and method: ``bias_deg``,
        ``rms_deg``, ``rms_crlb_ratio`` (zero offsets), ``bias_maemm_mm``,
        ``rms_maemm_mm``, ``dp0_rms_mm`` / ``dp0_mean_mm`` / ``dp0_max_mm``
        (home position error after compensating with the estimate),
        ``failures`` (identification failed or raised), ``not_converged``
        (loops that did not reach ``mu < mu0``), ``identifications``
        (per trial, mean), ``time_per_identification_ms``; ``scipy``:
        ``max_abs_diff_to_ipopt_deg`` and the time ratio.
    """
    from zerocal_sym.identify.nlls import identify_nlls, make_nlls_identifier
    from zerocal_sym.identify.tsvd import identify_tsvd

    report = report or _identity_report
    errors = robot.errors
    offs, meas_names = errors.zero_offsets, errors.measuring
    paper4 = errors.resolve("offsets+measuring")
    m_ = len(offs)

    noise = NoiseModel.paper() if noise is None else noise
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ZerocalError(f"unknown method(s) {', '.join(unknown)} (known: {', '.join(METHODS)})")
    if "scipy" in methods:
        _scipy_least_squares()
    try:
        names = errors.resolve(params)
    except ValueError as exc:
        raise ZerocalError(str(exc)) from None
    if any(n not in names for n in offs):
        raise ZerocalError(f"the parameter set must contain the zero offsets {', '.join(offs)}")
    poses = np.atleast_2d(np.asarray(poses, float))
    th0 = kin.check_poses(robot, poses)
    K = poses.shape[0]
    if K - 1 < len(names):
        raise ZerocalError(f"{K} poses give {K - 1} measured changes: fewer than the {len(names)} parameters")
    out = {"settings": {"mechanism": robot.mechanism_name, "groups": [str(g) for g in truths], "trials": trials,
                        "K": K, "poses_mm": poses.tolist(),
                        "params": list(names), "noise": {"sigma_scale_mm": noise.sigma_scale_mm,
                                                         "sigma_servo_rad": noise.sigma_servo_rad},
                        "seed": seed, "methods": list(methods), "mu0_deg": mu0_deg,
                        "max_iter": max_iter, "error_frame": "ours", **(settings or {})},
           "groups": {}}
    done = 0
    for gi, (g, err) in enumerate(truths.items()):
        err = errors.check_vector(err, f"truth {g!r}")
        plant = VirtualPlant(robot, err)
        true4 = errors.take(err, paper4)
        stream = g if isinstance(g, int) else gi
        try:
            crlb = fisher.crlb_zero_offsets_deg(robot, th0, names, noise, err0=err) if not noise.is_zero else None
        except ZerocalError:
            crlb = None
        rec = {m: {"E": [], "M": [], "dp0": [], "fail": 0, "nc": 0, "nid": 0, "t": 0.0} for m in methods}
        sc_diff, sc_t, ip_t = [], [], []
        for trial in range(trials):
            ss = np.random.SeedSequence([seed, stream, trial])
            meas1 = simulate_round(robot, plant, poses, None, noise, np.random.default_rng(ss))

            def record(m, est4, t, n_ident=1, converged=True):
                r = rec[m]
                r["t"] += t
                r["nid"] += n_ident
                if est4 is None:
                    r["fail"] += 1
                    return
                r["nc"] += 0 if converged else 1
                e = est4 - true4
                r["E"].append(report(np.degrees(e[:m_]), "offsets"))
                r["M"].append(report(e[m_:], "maemm"))
                r["dp0"].append(home_error(robot, plant, est4[:m_]))

            for m in ("tsvd-loop", "nlls-loop", "nlls-seq"):
                if m not in methods and not (m == "tsvd-loop" and "tsvd" in methods):
                    continue
                ident = _Timed(identify_tsvd if m == "tsvd-loop" else
                               make_nlls_identifier(params=names, noise=noise, sequential=(m == "nlls-seq")))
                try:
                    loop = calibration_loop(robot, plant, poses, identify=ident, noise=noise,
                                            rng=np.random.default_rng(ss), mu0_deg=mu0_deg, max_iter=max_iter)
                except (IdentificationError, ZerocalError):
                    loop = None
                if m == "tsvd-loop" and "tsvd" in methods:
                    first = loop.history[0].result if loop is not None and loop.history else None
                    if first is None or not first.success:
                        record("tsvd", None, 0.0)
                    else:
                        record("tsvd", np.array([first.value(n) for n in paper4]), ident.t / max(1, ident.n))
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
                est = np.array([res.value(n) for n in paper4]) if res.success else None
                if "nlls" in methods:
                    record("nlls", est, dt)
            if "scipy" in methods:
                ref = identify_nlls(robot, meas1, names, noise=noise, warm_start=None, reweight=0)
                p_sc, info = scipy_identify(robot, meas1, names, noise)
                ok = info["success"] and ref.success
                record("scipy", np.array([p_sc[names.index(n)] if n in names else 0.0 for n in paper4]) if ok else None,
                       info["time_s"])
                if ok:
                    pos = [names.index(n) for n in offs]
                    sc_diff.append(np.max(np.abs(np.degrees(p_sc[pos] - ref.estimate[pos]))))
                    sc_t.append(info["time_s"])
                    ip_t.append(ref.info["time_s"])
            done += 1
            if progress:
                progress(done)
        gout = {"crlb_zero_offsets_deg": None if crlb is None else np.asarray(crlb).tolist(),
                "set_deg": report(np.degrees(errors.take(err, offs)), "offsets").tolist(),
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


def _vec(v, fmt):
    return ",".join(format(x, fmt) for x in v)


def format_compare(rep: dict) -> str:
    """The comparison as text tables (one column group per zero offset and MAEMM component)."""
    s = rep["settings"]
    lines = [f"Monte Carlo: {s['trials']} trials per group, K = {s['K']} poses, Ipopt parameters "
             f"{', '.join(s['params'])}, noise scale {s['noise']['sigma_scale_mm'] * 1e3:.4g} um, servo "
             f"{np.degrees(s['noise']['sigma_servo_rad']):.4g} deg, seed {s['seed']}"
             + (f"; geometric errors {'on' if s['geometric_errors'] else 'off'}" if "geometric_errors" in s else "")
             + f"; errors in {s['error_frame']} frame"]
    for g, go in rep["groups"].items():
        cr = go["crlb_zero_offsets_deg"]
        m = len(go["set_deg"])
        lines.append("")
        lines.append(f"group {g}: set offsets {_vec(go['set_deg'], '+.3f')} deg;  CRLB "
                     + ("n/a" if cr is None else f"{_vec(cr, '.4f')} deg"))
        offs = ",".join(f"dth{k + 1}" for k in range(m))
        w = 11 * m
        lines.append(f"  {'method':10s} {'bias ' + offs + ' [deg]':>{w}s} {'RMS ' + offs + ' [deg]':>{w}s} "
                     f"{'RMS/CRLB':>{6 * m + 1}s} {'RMS rM [mm]':>{8 * m}s} {'dp0 RMS':>8s} {'fail':>4s} "
                     f"{'noconv':>6s} {'ident':>5s} {'ms/ident':>8s}")
        for name, r in go["methods"].items():
            if r["rms_deg"] is None:
                lines.append(f"  {name:10s} all {r['failures']} trials failed")
                continue
            ratio = "n/a" if r["rms_crlb_ratio"] is None else _vec(r["rms_crlb_ratio"], ".3f")
            nc = "-" if r["not_converged"] is None else str(r["not_converged"])
            lines.append(f"  {name:10s} {_vec(r['bias_deg'], '+10.4f'):>{w}s} {_vec(r['rms_deg'], '10.4f'):>{w}s} "
                         f"{ratio:>{6 * m + 1}s} {_vec(r['rms_maemm_mm'], '7.4f'):>{8 * m}s} {r['dp0_rms_mm']:8.4f} "
                         f"{r['failures']:4d} {nc:>6s} {r['identifications']:5.1f} "
                         f"{r['time_per_identification_ms']:8.2f}")
        sr = go.get("scipy_reference")
        if sr:
            lines.append(f"  scipy least_squares (lm) on the same problem: max |diff| to Ipopt "
                         f"{sr['max_abs_diff_to_ipopt_deg']:.2e} deg; time Ipopt {sr['time_ipopt_ms']:.2f} ms "
                         f"(whole identification) vs scipy {sr['time_scipy_ms']:.2f} ms (solver call): "
                         f"ratio {sr['time_ratio_ipopt_over_scipy']:.2f}")
    return "\n".join(lines)
