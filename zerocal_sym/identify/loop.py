"""The identify-compensate loop (Sections 5-6), with a pluggable identifier.

* :func:`simulate_round` -- one identification round on a virtual plant;
* :func:`calibration_loop` -- identify, compensate, re-measure, identify the
  remainder until ``mu < mu0`` (Eq. 30-33), with a pluggable identifier;
* :func:`position_errors`, :func:`home_error` -- how far the actual robot
  misses nominal poses after a compensation.

Stopping rule
-------------
``mu_j = sqrt(sum_i (c_i,j - c_i,j-1)^2 / m)`` over the m joints (the paper's
``sqrt(((c1_j - c1_{j-1})^2 + (c2_j - c2_{j-1})^2) / 2)``) with ``c_j`` the
compensation value (sum of the increments) after the ``j``-th
identification, i.e. the RMS of the ``j``-th increment; defined from ``j = 2``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from zerocal_sym.errors import IdentificationError
from zerocal_sym.identify.linear import condition_number, identification_matrix
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.model.measurements import Measurements


def simulate_round(robot, plant, poses, compensation_rad=None, noise=None, rng=None, theta=None) -> Measurements:
    """One identification round: command the poses, read the scale.

    Parameters
    ----------
    robot : Robot
        Nominal robot (the controller's model).
    plant : VirtualPlant
    poses : ndarray, shape (K, n)
        Nominal target poses, mm, in visiting order.
    compensation_rad : sequence of m floats, optional
        Current compensation: commanded = IK(poses) - compensation (default zero).
    noise : NoiseModel, optional
    rng : numpy Generator or seed, optional
    theta : ndarray, shape (K, m), optional
        ``IK(poses)`` if already known (a loop commands the same poses every round).

    Returns
    -------
    Measurements
        ``theta_cmd`` (K, m) rad, ``readings`` (K,) mm, ``target`` = poses.
    """
    poses = np.atleast_2d(np.asarray(poses, float))
    comp = np.zeros(robot.m) if compensation_rad is None else np.asarray(compensation_rad, float)
    theta_cmd = (kin.ik(robot, poses) if theta is None else np.asarray(theta, float)) - comp
    readings = plant.measure(theta_cmd, noise, rng)
    return Measurements(theta_cmd=theta_cmd, readings=readings, target=poses.copy(),
                        meta={}, source="<simulated>")


def position_errors(robot, plant, poses, compensation_rad=None) -> np.ndarray:
    """``|P_actual - P|`` at nominal poses commanded as ``IK(P) - compensation``.

    Exact forward kinematics of the actual robot (no noise).

    Parameters
    ----------
    poses : ndarray, shape (K, n)
    compensation_rad : sequence of m floats, optional

    Returns
    -------
    ndarray, shape (K,)
        mm.
    """
    poses = np.atleast_2d(np.asarray(poses, float))
    comp = np.zeros(robot.m) if compensation_rad is None else np.asarray(compensation_rad, float)
    th = kin.ik(robot, poses) - comp
    return np.linalg.norm(plant.actual_pose(th) - poses, axis=1)


def home_error(robot, plant, compensation_rad=None) -> float:
    """``dp0``: distance from P0 of the platform commanded to home (minus the compensation), mm."""
    comp = np.zeros(robot.m) if compensation_rad is None else np.asarray(compensation_rad, float)
    th = robot.home_joints()[None, :] - comp
    return float(np.linalg.norm(plant.actual_pose(th)[0] - robot.home_pose()))


@dataclass
class IterationRecord:
    """One identification of the loop.

    Attributes
    ----------
    result : IdentificationResult
    compensation_deg : ndarray, shape (m,)
        Compensation value (sum of increments) after this identification, our frame, in the joints' file
        unit: deg for revolute joints, mm for prismatic ones (so are the increment and mu; the names keep the
        revolute spelling).
    increment_deg : ndarray, shape (m,)
    mu_deg : float or None
        Compensation accuracy (None at the first identification).
    kappa : float
        Condition number of G of this identification (Eq. 28's G when the identifier does not report it).
    maemm_mm : ndarray, shape (u,)
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
    compensation_deg : ndarray, shape (m,)
        Compensation value when the loop stopped (at the first ``mu < mu0``
        if it converged, else after the last identification), our frame.
    maemm_mm : ndarray, shape (n,)
        MAEMM estimate at the same identification.
    converged : bool
    iterations : int
        Identifications up to and including the stopping one.
    misfits : int
        Identifications whose fit the fit check rejected
        (:mod:`zerocal_sym.identify.fitcheck`) and that the loop used anyway:
        the paper's loop has no fit check, and the loop reproduces it.
    """

    history: list = field(default_factory=list)
    compensation_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    maemm_mm: np.ndarray = field(default_factory=lambda: np.zeros(0))
    converged: bool = False
    iterations: int = 0
    misfits: int = 0

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


def _misfit_only(res) -> bool:
    """True when ``res`` failed only because the fit check rejected its fit (the estimate itself converged)."""
    info = getattr(res, "info", None)
    fit = info.get("fit") if isinstance(info, dict) else None
    return bool(fit and fit.get("rejected") and str(getattr(res, "status", "")).startswith("rejected"))


def calibration_loop(robot, plant, poses, identify=identify_tsvd, noise=None, rng=None, mu0_deg=0.1,
                     max_iter=20, maemm_prior=None, run_all=False, kappa: bool = True, theta=None,
                     first=None) -> LoopResult:
    """The paper's iterative identification and compensation (Eq. 30-33).

    Each round commands ``IK(poses) - compensation``, measures, and calls
    ``identify(robot, meas, prior)`` with ``prior`` the source-error vector
    (length q) of the current total estimates (offsets = compensation, MAEMM = previous
    estimate; from the 2nd identification on this corrects the nominal
    measuring-mechanism vector, Eq. 30).  The identifier returns totals; the
    new compensation is its offset estimate (= the sum of the increments).

    Parameters
    ----------
    robot : Robot
    plant : VirtualPlant
    poses : ndarray, shape (K, n)
    identify : callable
        ``identify(robot, meas, prior) -> IdentificationResult`` (TSVD by default;
        an Ipopt identifier plugs in the same way).
    noise : NoiseModel, optional
    rng : numpy Generator or seed, optional
    mu0_deg : float
        Threshold of the compensation accuracy mu.
    max_iter : int
        Maximum number of identifications.
    maemm_prior : sequence of n floats, optional
        MAEMM prior of the first identification (default zero, as the paper).
    run_all : bool
        Continue to ``max_iter`` after convergence (the paper's robustness
        study, Fig. 9); the reported state is still the one at convergence.

    An identification that fails raises :class:`IdentificationError`, except
    one the fit check rejected: the paper's loop has no fit check, so its
    estimate is used and counted in :attr:`LoopResult.misfits`.
    kappa : bool
        Compute the paper's condition number of G for each identification
        whose identifier does not report it (False: NaN, and one
        identification matrix less per round; the Monte Carlo does not use it).
    theta : ndarray, shape (K, m), optional
        ``IK(poses)`` if already known.
    first : Measurements, optional
        The first round, already simulated (``simulate_round(robot, plant,
        poses, None, noise, g)``) with a generator ``g`` that ``rng`` continues
        (``rng`` in the state ``g`` was left in): the loop starts from it
        instead of simulating it, with the same result.  Several loops of a
        Monte Carlo trial share their first round this way.  Identifiers must
        not modify the measurements.

    Returns
    -------
    LoopResult
    """
    if max_iter < 1:
        raise ValueError("max_iter must be >= 1")
    steps = _steps(robot, plant, poses, noise, rng, mu0_deg, max_iter, maemm_prior, run_all, kappa, theta, first)
    try:
        meas, prior = next(steps)
        while True:
            meas, prior = steps.send(identify(robot, meas, prior))
    except StopIteration as stop:
        return stop.value


def calibration_loops(robot, plant, poses, identify_many, rngs, noise=None, mu0_deg=0.1, max_iter=20,
                      maemm_prior=None, run_all=False, kappa: bool = True, theta=None, firsts=None,
                      catch=(Exception,), pass_loops: bool = False) -> list:
    """Several :func:`calibration_loop` in lockstep, each round's identifications in one call.

    Loop ``i`` is ``calibration_loop(robot, plant, poses, identify, noise,
    rngs[i], ..., first=firsts[i])`` with ``identify`` one round of
    ``identify_many(robot, rounds, priors)``, which identifies the rounds of
    all loops still running at once and returns per round its result or the
    exception raised for it (e.g.
    :func:`zerocal_sym.identify.tsvd.identify_tsvd_many`): the same loops, the
    batch only saves time.

    Parameters
    ----------
    identify_many : callable
        ``identify_many(robot, rounds, priors) -> list`` of results or exceptions.
    rngs : sequence of numpy Generators (or seeds)
        One per loop.
    firsts : sequence of Measurements or None, optional
        Each loop's first round (see ``first`` of :func:`calibration_loop`).
    catch : tuple of exception types
        Exceptions that end one loop (its entry is the exception); others propagate.
    pass_loops : bool
        Also pass the indices of the loops whose rounds these are:
        ``identify_many(robot, rounds, priors, loops)`` (an identifier that keeps a state per loop: the
        sequential MAP).

    Returns
    -------
    list of (outcome, identifications, seconds)
        Per loop: its :class:`LoopResult` or the exception that ended it;
        the identifications it asked for (a failed one included); its share
        of the time spent in ``identify_many`` (each call's time split
        evenly over its rounds).
    """
    if max_iter < 1:
        raise ValueError("max_iter must be >= 1")
    n = len(rngs)
    firsts = [None] * n if firsts is None else list(firsts)
    out = [None] * n
    calls, secs = [0] * n, [0.0] * n
    pending = {}  # loop -> (steps, meas, prior)

    def step(i, steps, value=None, start=False):
        try:
            meas, prior = next(steps) if start else (steps.throw(value) if isinstance(value, BaseException)
                                                     else steps.send(value))
            pending[i] = (steps, meas, prior)
        except StopIteration as stop:
            out[i] = stop.value
        except catch as exc:
            out[i] = exc

    for i in range(n):
        step(i, _steps(robot, plant, poses, noise, rngs[i], mu0_deg, max_iter, maemm_prior, run_all, kappa,
                       theta, firsts[i], batched=True), start=True)
    while pending:
        sim = sorted(i for i in pending if pending[i][1] is SIMULATE)
        if sim:  # the rounds to simulate, in one mapped call
            for i, meas in zip(sim, simulate_rounds(robot, plant, poses, [pending[i][2] for i in sim], noise)):
                step(i, pending.pop(i)[0], meas)
            continue
        live = sorted(pending)
        t0 = time.perf_counter()
        args = (robot, [pending[i][1] for i in live], [pending[i][2] for i in live]) + ((live,) if pass_loops else ())
        results = identify_many(*args)
        dt = (time.perf_counter() - t0) / len(live)
        for i, res in zip(live, results):
            calls[i] += 1
            secs[i] += dt
            step(i, pending.pop(i)[0], res)
    return list(zip(out, calls, secs))


#: what :func:`_steps` (``batched``) yields in place of a round: it is sent the round simulated
SIMULATE = object()


def simulate_rounds(robot, plant, poses, requests, noise) -> list:
    """The rounds ``simulate_round(robot, plant, poses, comp, noise, rng, theta=theta)`` of several loops, the same
    numbers, their lengths in one mapped call (:meth:`~zerocal_sym.model.noise.VirtualPlant.measure_many`).

    ``requests``: per loop ``(comp, theta, rng)``, compensation (m,) rad, ``IK(poses)`` (K, m), its Generator.
    Returns a list of :class:`Measurements`."""
    poses = np.atleast_2d(np.asarray(poses, float))
    cmds = [np.asarray(theta, float) - np.asarray(comp, float) for comp, theta, _ in requests]
    readings = plant.measure_many(cmds, noise, [g for _, _, g in requests])
    return [Measurements(theta_cmd=c, readings=r, target=poses.copy(), meta={}, source="<simulated>")
            for c, r in zip(cmds, readings)]


def _steps(robot, plant, poses, noise, rng, mu0_deg, max_iter, maemm_prior, run_all, kappa, theta, first,
           batched=False):
    """The loop as a generator: yields ``(meas, prior)`` per identification, is sent its result;
    returns the :class:`LoopResult` (an identification that raised is thrown in).  ``batched``: yields
    ``(SIMULATE, (comp, theta, rng))`` for each round after ``first`` and is sent the round
    (:func:`simulate_rounds`)."""
    rng = np.random.default_rng(rng)
    errors = robot.errors
    offs, meas_names = errors.zero_offsets, errors.measuring
    prior = errors.zeros()
    if maemm_prior is not None:
        prior = errors.put(prior, meas_names, np.asarray(maemm_prior, float))
    out = LoopResult(compensation_deg=np.zeros(robot.m), maemm_mm=np.zeros(len(meas_names)))

    def user(v):  # the joints' file unit: deg (revolute), mm (prismatic); the attribute names say deg
        return units.to_user(v, errors.offset_unit)

    comp = np.zeros(robot.m)
    theta = kin.ik(robot, poses) if theta is None else theta
    i_off, i_meas = [errors.index(n) for n in offs], [errors.index(n) for n in meas_names]  # take / put
    for j in range(1, max_iter + 1):
        if j == 1 and first is not None:
            meas = first
        elif batched:  # the driver simulates the rounds of all its loops at once (simulate_rounds)
            meas = yield SIMULATE, (comp, theta, rng)
        else:
            meas = simulate_round(robot, plant, poses, comp, noise, rng, theta=theta)
        res = yield meas, prior.copy()
        if not getattr(res, "success", True):
            if not _misfit_only(res):
                raise IdentificationError(f"identification {j} failed: {res.status}")
            out.misfits += 1
        new = np.array([res.value(n) for n in offs])
        maemm = np.array([res.value(n, v) for n, v in zip(meas_names, prior[i_meas])])
        inc = new - comp
        mu = None if j == 1 else float(user(np.sqrt(np.mean(inc**2))))
        kap = float(res.info.get("kappa", np.nan)) if isinstance(res.info, dict) else float("nan")
        if kappa and not np.isfinite(kap):  # the paper's G (Eq. 28) of this round
            P = kin.fk(robot, meas.theta_cmd + errors.take(prior, offs))
            kap = condition_number(identification_matrix(robot, P, errors.take(prior, meas_names))[0])
        new_user = user(new)
        out.history.append(IterationRecord(res, new_user, user(inc), mu, kap, maemm.copy()))
        comp = new
        prior = prior.copy()
        prior[i_off], prior[i_meas] = new, maemm
        if not out.converged:
            out.compensation_deg, out.maemm_mm, out.iterations = new_user, maemm.copy(), j
            if mu is not None and mu < mu0_deg:
                out.converged = True
                if not run_all:
                    break
    return out
