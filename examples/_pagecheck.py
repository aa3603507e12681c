"""Checks of recomputed numbers against the numbers a model page states (used by examples/*_numbers.py).

Each check prints one line::

    ok  <what>: <ours> (page: <theirs>)  [<tolerance>]
    BAD <what>: <ours> (page: <theirs>)  [<tolerance>]

and :meth:`Page.exit_code` is 1 if any check failed.

Tolerances
----------
* a value the page prints (``value``): relative 1 %, or half a unit of the
  page's last printed digit where that is coarser (``128`` mm: 0.5 mm).  Where
  ours, rounded to the page's digits, is not the page's figure, the line says
  so (a difference in the last digit within the tolerance is reported, not
  hidden);
* a count, a rank, a list of corners (``exact``): equal;
* a number at rounding-error level (``roundoff``: ``|FK(IK(P)) - P| < 4e-13``,
  a noise-free recovery "to 2e-13", finite differences agreeing "to 3e-9"):
  at most 10 times the page's; the last digits of rounding errors differ
  between two implementations of the same arithmetic;
* a Monte Carlo figure (``monte_carlo``): the page's range widened by three
  standard deviations of the difference of two Monte Carlo estimates, ours
  from the trials asked for and the page's from its 1000.
"""
from __future__ import annotations

import argparse
import math
from dataclasses import replace

import casadi as ca
import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import geometry_error

#: the page's Monte Carlo trials per case
PAGE_TRIALS = 1000


def decimals(text: str) -> int:
    """Digits after the decimal point of a number as printed (``"0.00433"``: 5, ``"128"``: 0)."""
    text = text.strip().lstrip("+-\u2212")
    return len(text.split(".")[1]) if "." in text else 0


def page_float(text: str) -> float:
    return float(text.strip().replace("\u2212", "-"))


def fmt(x, digits: int = 4) -> str:
    """``x`` (a number or a sequence) with ``digits`` significant digits beyond the page's."""
    if np.ndim(x) == 0:
        x = float(x)
        if x == 0 or 1e-3 <= abs(x) < 1e5:
            return f"{x:.{digits + 2}g}"
        return f"{x:.{digits}g}"
    return "(" + ", ".join(fmt(v, digits) for v in np.ravel(x)) + ")"


class Page:
    """Collects the checks of one page; ``name`` is how the lines call the page."""

    def __init__(self, name: str = "page"):
        self.name = name
        self.failures: list[str] = []
        self.last_digit: list[str] = []
        self.count = 0

    # ------------------------------------------------------------------ printing
    def line(self, ok: bool, what: str, ours: str, theirs: str, tol: str) -> bool:
        self.count += 1
        print(f"{'ok ' if ok else 'BAD'} {what}: {ours} ({self.name}: {theirs})  [{tol}]", flush=True)
        if not ok:
            self.failures.append(what)
        return ok

    @staticmethod
    def note(text: str) -> None:
        """A line that is not a check (the reason for a tolerance, a null direction)."""
        print(f"    {text}", flush=True)

    # ------------------------------------------------------------------ checks
    def value(self, what: str, ours, page, rel: float = 0.01) -> bool:
        """``ours`` (a number or a sequence) against the page's figures (strings, as printed)."""
        texts = [page] if isinstance(page, str) else list(page)
        ours_v = np.atleast_1d(np.asarray(ours, float))
        if ours_v.size != len(texts):
            return self.line(False, what, fmt(ours), ", ".join(texts), f"{len(texts)} values expected")
        ok, shown, off = True, [], False
        for o, t in zip(ours_v, texts):
            v, dec = page_float(t), decimals(t)
            tol = max(rel * abs(v), 0.5 * 10.0**-dec)
            ok &= bool(abs(o - v) <= tol)
            shown.append(f"{o:.{dec}f}".replace("-0." + "0" * dec, "0." + "0" * dec) if dec else f"{o:.0f}")
            off |= page_float(shown[-1]) != v
        theirs = texts[0] if len(texts) == 1 else "(" + ", ".join(texts) + ")"
        tol = (f"relative {rel:.0%}, or half a unit of the page's last digit where coarser"
               + (f"; to the page's digits ours is ({', '.join(shown)}): the last digit differs" if off else ""))
        if off:
            self.last_digit.append(what)
        printed = [f"{o:.{decimals(t) + 2}f}" for o, t in zip(ours_v, texts)]  # two digits beyond the page's
        return self.line(ok, what, printed[0] if len(printed) == 1 else "(" + ", ".join(printed) + ")", theirs, tol)

    def exact(self, what: str, ours, page) -> bool:
        """Equal (counts, ranks, shapes, lists)."""
        return self.line(ours == page, what, str(ours), str(page), "equal")

    def within(self, what: str, ours, lo: float, hi: float, theirs: str, tol: str) -> bool:
        """Every value of ``ours`` in ``[lo, hi]`` (a range the page states in words)."""
        v = np.atleast_1d(np.asarray(ours, float))
        return self.line(bool(np.all((v >= lo) & (v <= hi))), what, fmt(v if v.size > 1 else v[0]), theirs,
                         f"{tol}: within [{lo:g}, {hi:g}]")

    def below(self, what: str, ours: float, bound: float, theirs: str, tol: str = "") -> bool:
        return self.line(bool(ours < bound), what, fmt(ours), theirs, tol or f"below {bound:g}")

    def roundoff(self, what: str, ours: float, page: str) -> bool:
        """A figure at rounding-error level: at most 10 times the page's."""
        bound = 10 * page_float(page.lstrip("<").strip())
        return self.line(bool(ours <= bound), what, f"{ours:.2g}", page,
                         f"rounding-error level: at most 10x the page's, {bound:.2g}")

    def monte_carlo(self, what: str, ours, lo: float, hi: float, sd, trials: int, theirs: str,
                    page_trials: int = PAGE_TRIALS) -> bool:
        """Monte Carlo figures against the page's range ``[lo, hi]`` (or its one figure, ``lo = hi``).

        ``sd(N)`` is the sampling standard deviation of one such figure from N trials.  Ours (``trials``)
        and the page's (``page_trials``) are independent samples: a difference has the standard deviation
        ``sqrt(sd(trials)^2 + sd(page_trials)^2)``; the range is widened by 3 of those.
        """
        v = np.atleast_1d(np.asarray(ours, float))
        s = math.hypot(sd(trials), sd(page_trials))
        a, b = lo - 3 * s, hi + 3 * s
        return self.line(bool(np.all((v >= a) & (v <= b))), what, fmt(v if v.size > 1 else v[0], 3), theirs,
                         f"{trials} trials, the page {page_trials}: widened by 3 x {s:.3f}: [{a:.3f}, {b:.3f}]")

    # ------------------------------------------------------------------ the end
    def exit_code(self) -> int:
        print(f"{self.count} checks, {len(self.failures)} BAD"
              + (f": {'; '.join(self.failures)}" if self.failures else ""))
        if self.last_digit:
            print(f"within tolerance but not the page's last printed digit: {'; '.join(self.last_digit)}")
        return 1 if self.failures else 0


def rms_ratio_sd(trials: int) -> float:
    """Sampling std of RMS/sigma estimated from ``trials`` Gaussian trials: ``1/sqrt(2 N)``."""
    return 1.0 / math.sqrt(2.0 * trials)


def chi2_mean_sd(dof: int):
    """``N -> `` the sampling std of the mean of N chi-square(``dof``) values: ``sqrt(2 dof / N)``."""
    return lambda trials: math.sqrt(2.0 * dof / trials)


def monte_carlo_note(trials: int, what: str, chi2_dof: int | None = None) -> None:
    """Say how the Monte Carlo checks' tolerances come about."""
    sd = chi2_mean_sd(chi2_dof) if chi2_dof else None
    Page.note(f"Monte Carlo, {what}; {trials} trials per case (the page: {PAGE_TRIALS}).  An RMS/CRLB from N "
              f"trials has a sampling std of 1/sqrt(2N) ({rms_ratio_sd(trials):.3f} here, "
              f"{rms_ratio_sd(PAGE_TRIALS):.3f} for the page's)"
              + (f", a mean of e^T F e (chi-square, p = {chi2_dof} degrees of freedom) sqrt(2p/N) ({sd(trials):.3f} "
                 f"here, {sd(PAGE_TRIALS):.3f} for the page's)" if chi2_dof else "")
              + "; ours and the page's are independent samples, so each check allows 3 standard deviations of "
              "their difference around the page's range")


def arguments(doc: str, trials: int) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    p.add_argument("--trials", type=int, default=trials,
                   help=f"Monte Carlo trials per case (default {trials}; the page's figures came from {PAGE_TRIALS})")
    p.add_argument("--seed", type=int, default=None,
                   help="another set of random draws: trial t of case c uses default_rng([seed, c, t]) "
                        "(default: default_rng([c, t]))")
    args = p.parse_args()
    if args.trials < 10:
        p.error("--trials: at least 10")
    return args


def trial_rng(seed, case: int, trial: int) -> np.random.Generator:
    """The random draws of one trial: ``default_rng([case, trial])``, or ``[seed, case, trial]`` with a seed."""
    return np.random.default_rng([case, trial] if seed is None else [seed, case, trial])


# ---------------------------------------------------------------------- the Jacobian against central differences
def analytic_distance_jacobian(robot, th_cmd, err):
    """``d rho / d(every source error)`` by implicit differentiation at the actual robot, shape (K, q).

    The generated ``pose_error_jacobian`` (``dP/d(robot errors)`` from the loop closure, evaluated at the actual
    geometry, joints and pose) times ``d rho / dP``, and ``d rho / d(c, d)`` for the measuring errors; the
    derivatives of ``rho = |lambda(P, g)|`` are CasADi's of the generated closed form ``measuring``.
    """
    errors = robot.errors
    actual = replace(robot, geometry=robot.geometry + geometry_error(robot, err))
    th = np.atleast_2d(th_cmd) + errors.take(err, errors.zero_offsets)
    P = kin.fk(actual, th)
    Jsrc = kin.pose_error_jacobian(actual, P, th)  # (K, n, r)
    Ps, gs = ca.SX.sym("P", robot.n), ca.SX.sym("g", len(robot.geometry))
    lam = robot.mechanism["measuring"](Ps, gs)[0]
    dlam = ca.Function("dlam", [Ps, gs], [ca.jacobian(lam, Ps), ca.jacobian(lam, gs)])
    cols = [robot.mechanism.geometry_names.index(errors[m].target) for m in errors.measuring]
    out = []
    for k in range(th.shape[0]):
        dP, dg = (np.array(x.full()).ravel() for x in dlam(P[k], actual.geometry))
        out.append(np.concatenate([dP @ Jsrc[k], dg[cols]]))
    return np.array(out)


def central_differences(robot, th_cmd, err, h_mm: float = 1e-3, h_rad: float = 1e-5):
    """``d rho / d(every source error)`` by central differences of the exact distance, shape (K, q)."""
    errors = robot.errors
    out = np.empty((np.atleast_2d(th_cmd).shape[0], len(errors)))
    for j, name in enumerate(errors.names):
        h = h_rad if errors[name].unit == "rad" else h_mm
        e = errors.vector({name: h})
        out[:, j] = (kin.distance(robot, th_cmd, err + e) - kin.distance(robot, th_cmd, err - e)) / (2 * h)
    return out


def relative_disagreement(a, b) -> float:
    """``max_k |a_k - b_k|_inf / |a_k|_inf`` over the poses k (rows)."""
    return float(np.max(np.max(np.abs(a - b), axis=1) / np.max(np.abs(a), axis=1)))
