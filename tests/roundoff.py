"""Tolerances for comparisons at round-off, derived from the problem's conditioning, and doc numbers' digits.

A test that compares the result of a solve (a least-squares estimate, an inverse, an optimum) with the truth, or
two routes to the same number, cannot ask for more than that problem's round-off: the floating-point error of its
data carried through its condition number.  A bare literal such as ``atol=1e-9`` holds on one machine and fails on
another (another BLAS, numpy or CasADi; fused multiply-adds); the bounds here scale with the problem, and each test
states the factor it allows on top of them and why.  A number a page of the docs prints is compared at the digits
the page shows (:func:`shown`).
"""
import re

import numpy as np

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel

EPS = float(np.finfo(float).eps)


def cond_tol(cond, factor):
    """``factor * cond * EPS``: the relative error of a backward-stable computation with condition number ``cond``.

    ``factor`` covers what surrounds it (forming the matrix, a second algorithm for the same number); the caller
    says why it is what it is.
    """
    return float(factor) * float(cond) * EPS


def distance_unit(robot, theta_cmd, err=None):
    """``EPS * max|rho|``, mm: the round-off of one computed distance at these joints (the unit of the floors)."""
    return EPS * float(np.max(np.abs(kin.distance(robot, np.atleast_2d(theta_cmd), err))))


def estimate_floor(robot, theta_cmd, params="paper", noise=None, err0=None):
    """Round-off floor of a least-squares estimate of ``params`` from ``theta_cmd``, shape (p,), rad / mm.

    Each distance ``rho_k`` is computed to a relative error of order ``EPS``, so each measured change
    ``s_k = rho_{k+1} - rho_k`` carries an absolute error up to ``2 EPS max|rho|`` (:func:`distance_unit`).  To
    first order the weighted least-squares estimate moves by ``G ds``, ``G = (W A)^+ W`` its gain (``A``:
    :func:`fisher.sensitivity` at ``err0``; ``W``: the whitener of ``noise``, read as ``identify_nlls`` reads
    it, ``None`` the paper's; the identity for a zero model), so by at most ``|G_j|_1 2 EPS max|rho|`` in
    parameter ``j``: no solver of that problem, however well converged, can be asked for less.  The bound is the
    worst alignment of the errors; a converged solve lands well inside it (measured: 0.05-0.8 of it).
    """
    theta_cmd = np.atleast_2d(theta_cmd)
    A = fisher.sensitivity(robot, theta_cmd, params, err0)
    noise = NoiseModel.coerce(noise)
    W = (np.eye(A.shape[0]) if noise.is_zero
         else fisher.whitener(fisher.change_covariance(robot, theta_cmd, noise, err0)))
    G = np.linalg.pinv(W @ A) @ W
    return np.sum(np.abs(G), axis=1) * 2 * distance_unit(robot, theta_cmd, err0)


def chi2_tol(chi2, robot, theta_cmd, noise, err0=None):
    """Round-off bound of a chi² ``|r|^2`` of whitened residuals, absolute.

    Each residual ``r = L^-1 (s - s_model)`` carries the changes' round-off ``2 EPS max|rho|`` through ``L^-1``
    (``|L^-1|_2 = 1 / sqrt(lambda_min(C))``), so ``|dr| <= sqrt(K - 1) 2 EPS max|rho| / sqrt(lambda_min(C))`` and
    ``|d chi2| <= 2 sqrt(chi2) |dr| + |dr|^2``.
    """
    theta_cmd = np.atleast_2d(theta_cmd)
    C = fisher.change_covariance(robot, theta_cmd, NoiseModel.coerce(noise), err0).dense()
    dr = np.sqrt(C.shape[0]) * 2 * distance_unit(robot, theta_cmd, err0) / np.sqrt(np.linalg.eigvalsh(C)[0])
    return 2 * np.sqrt(chi2) * dr + dr ** 2


def shown(text):
    """A number as a page prints it, ``(value, half a unit of its last digit)``: ``"1.1e-3"`` -> ``(1.1e-3, 5e-5)``.

    A test comparing a computed number with the page asserts ``|computed - value| <= half`` (the page's rounding);
    the page's minus sign (U+2212) is read as ``-``.
    """
    t = text.strip().replace("\u2212", "-")
    m = re.fullmatch(r"([+-]?)(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?", t)
    if not m or not (m.group(2) or m.group(3)):
        raise ValueError(f"not a number as a page prints it: {text!r}")
    decimals = len(m.group(3) or "")
    exponent = int(m.group(4) or 0)
    return float(t), 0.5 * 10.0 ** (exponent - decimals)


#: a converged estimate lies within this many floors (:func:`estimate_floor`) of the exact solution of its problem:
#: the floor counts one rounding per distance, computing one takes a few operations (loop closure, a square root),
#: and the solver stops within round-off of its fixed point.  Two estimates of one problem: twice this.
FLOORS = 4


def log_objective_tol(F):
    """Absolute round-off bound of a log-objective of a Fisher information ``F`` (p, p): ``log det F``,
    ``log tr F^-1``, ``log sum_j w_j [F^-1]_jj``.

    A backward-stable eigen-decomposition or inverse gives each eigenvalue or entry of ``F^-1`` to a relative
    ``cond(F) EPS``; ``log det`` sums p of them: ``p cond(F) EPS``.  Two algorithms (CasADi's symbolic LDL^T and
    inverse, numpy's banded solve and LAPACK) each within it, and each forming ``F`` from its own terms: ``4 p``.
    """
    F = np.asarray(F, float)
    return cond_tol(np.linalg.cond(F), 4 * F.shape[0])
