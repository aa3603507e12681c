"""Bias from the source errors an identification leaves out, for given tolerances.

The identification estimates a parameter set (default the paper's: the zero
offsets and the MAEMM) and holds every other source error at zero.  If those
*omitted* errors are not zero the estimate is biased; to first order
(:func:`zerocal_sym.identify.fisher.model_bias`)::

    b = S e_o,     S = (A^T C^-1 A)^-1 A^T C^-1 A_o          (p x r)

with ``A``, ``A_o`` the sensitivities of the K-1 measured changes to the
identified and to the omitted errors and ``C`` the covariance of the changes
(the weighting of the estimator).  :func:`bias_sensitivity` gives ``S``.

Tolerances
----------
A tolerance ``t_j`` bounds an omitted error: ``|e_j| <= t_j``.  Then, per
identified parameter ``i`` (model: first order, the errors independent)

* worst case ``sum_j |S_ij| t_j`` (the largest bias any errors within the
  tolerances give);
* RMS ``sqrt(sum_j S_ij^2 t_j^2 / 3)``: the root mean square bias when each
  ``e_j`` is uniform on ``[-t_j, t_j]`` (variance ``t_j^2 / 3``).

Defaults (:func:`default_tolerances`): the robot's own
(:meth:`Robot.tolerances <zerocal_sym.model.robot.Robot.tolerances>`: its
file's ``[tolerances]`` table, else those of a robot measured by hand,
:data:`DEFAULT_LENGTH_TOLERANCE_MM` per length and
:data:`DEFAULT_ANGLE_TOLERANCE_DEG` per angle; the paper's robot carries the
magnitudes of Table 2's set A: :mod:`zerocal_sym.model.tolerances`).  They
are overridden in user units (mm, deg) by name or group (``L`` for ``L1 L2
L3``, as in the table): ``NAME=VALUE`` items, a TOML or JSON file of ``name =
value``, and a scale factor (``10`` for ten times set A).

The MAEMM (identified) and the gauge: the omitted errors include the ones
that fix the mechanism's gauge (planar ``e1x e1y e2y``); part of their effect
is absorbed by the MAEMM estimate, which is what the first-order formula
gives.
"""
from __future__ import annotations

import math

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.noise import NoiseModel
# the defaults of a robot measured by hand (mm, deg), kept importable from here
from zerocal_sym.model.tolerances import DEFAULT_ANGLE_TOLERANCE_DEG, DEFAULT_LENGTH_TOLERANCE_MM  # noqa: F401

#: The model of the RMS bias: independent errors uniform within their tolerances.
RMS_MODEL = "independent uniform errors in [-t, t] (variance t^2/3)"


#: how the ``mse`` design criterion counts the bias (:class:`Tolerances`)
BIAS_MODELS = ("rms", "worst")


class Tolerances(dict):
    """Tolerances by name (internal units) and how a design criterion counts the bias from them.

    ``bias_model``: ``"rms"`` -- the expected squared bias for errors uniform
    within the tolerances, ``sum_j S_ij^2 t_j^2 / 3`` (the mean squared error
    averaged over such robots); ``"worst"`` -- the squared worst case
    ``(sum_j |S_ij| t_j)^2`` (a bound for every robot within the tolerances,
    e.g. a corner of the tolerance box such as Table 2's set A).
    """

    def __init__(self, values=(), bias_model: str = "rms"):
        super().__init__(values)
        if bias_model not in BIAS_MODELS:
            raise ZerocalError(f"unknown bias model {bias_model!r} (known: {', '.join(BIAS_MODELS)})")
        self.bias_model = bias_model


def omitted(robot, params="paper") -> tuple:
    """The source errors a fit of ``params`` holds at zero, in the mechanism's order."""
    keep = set(robot.errors.resolve(params))
    return tuple(n for n in robot.errors.names if n not in keep)


def default_tolerances(robot, params="paper") -> dict:
    """Default tolerances of the omitted errors by name, internal units (mm, rad): the robot's
    (:meth:`Robot.tolerances <zerocal_sym.model.robot.Robot.tolerances>`: its file's ``[tolerances]``, else
    :data:`DEFAULT_LENGTH_TOLERANCE_MM` per length and :data:`DEFAULT_ANGLE_TOLERANCE_DEG` per angle)."""
    own = robot.tolerances()
    return {name: own[name] for name in omitted(robot, params)}


def make_tolerances(robot, items=None, file=None, scale: float = 1.0, params="paper", defaults: bool = True,
                    bias_model: str = "rms") -> "Tolerances":
    """Tolerances of the omitted errors by name (internal units): defaults, a file, ``NAME=VALUE`` items, a scale.

    Parameters
    ----------
    items : sequence of str, optional
        ``NAME=VALUE`` in user units (mm; deg for angles), later ones win; ``NAME`` an omitted error or a
        group or set of them (:func:`zerocal_sym.model.tolerances.keys`: ``L`` for ``L1 L2 L3``; an entry
        wins over a group, a smaller group over a larger one); they override the robot's own.
    file : path, optional
        TOML (``name = value``) or JSON (``{"name": value}``) file, user units;
        applied before ``items``.
    scale : float
        Every tolerance multiplied by this (e.g. 10).
    defaults : bool
        Start from :func:`default_tolerances` (else from zero).
    bias_model : {"rms", "worst"}
        How the ``mse`` design criterion counts the bias (:class:`Tolerances`).

    Raises
    ------
    ZerocalError
        Unknown or identified name, a negative or non-finite value, a bad file.
    """
    errors = robot.errors
    names = omitted(robot, params)
    tol = default_tolerances(robot, params) if defaults else {n: 0.0 for n in names}
    given = {}
    if file is not None:
        given.update(_read_file(file))
    for it in items or ():
        k, sep, v = str(it).partition("=")
        if not sep:
            raise ZerocalError(f"--tolerance {it!r}: expected NAME=VALUE (mm; deg for angles)")
        given[k.strip()] = v
    from zerocal_sym.model import tolerances as tl

    by_key = tl.keys(errors)
    for k, v in sorted(given.items(), key=lambda kv: -len(by_key.get(kv[0], ()))):  # an entry wins over its group
        members = [n for n in by_key.get(k, ()) if n in names]
        if not members:
            what = ("is identified (no bias from it)" if k in errors.names or k in by_key else
                    "is not a source error or a group of them")
            raise ZerocalError(f"tolerance {k!r} {what}; tolerances apply to {', '.join(names)}")
        try:
            val = float(v)
        except (TypeError, ValueError):
            raise ZerocalError(f"tolerance {k}={v!r}: not a number") from None
        except OverflowError:  # an integer beyond any float
            raise ZerocalError(f"tolerance {k}: an integer of {len(str(v))} digits: must be finite") from None
        if not math.isfinite(val) or val < 0:
            raise ZerocalError(f"tolerance {k}={v!r}: must be finite and >= 0")
        for n in members:
            tol[n] = errors.from_user_value(n, val)
    try:
        scale = float(scale)
    except (TypeError, ValueError):
        raise ZerocalError(f"tolerance scale {scale!r}: not a number") from None
    if not math.isfinite(scale) or scale < 0:
        raise ZerocalError(f"tolerance scale must be finite and >= 0, got {scale!r}")
    from zerocal_sym.model.robot import ANGLE_LIMIT_DEG, LENGTH_LIMIT_MM

    for n in names:  # (the robot file's limits: a tolerance beyond is no manufacturing error, and overflows)
        unit = errors[n].user_unit
        limit = ANGLE_LIMIT_DEG if unit == "deg" else LENGTH_LIMIT_MM
        if errors.to_user_value(n, tol[n]) * scale > limit:
            raise ZerocalError(f"tolerance {n} = {errors.to_user_value(n, tol[n]) * scale:g} {unit}"
                               + (f" (x {scale:g})" if scale != 1 else "") + f": beyond {limit:g} {unit}")
    return Tolerances({n: tol[n] * scale for n in names}, bias_model)


def _read_file(path) -> dict:
    import json
    import tomllib
    from pathlib import Path

    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8").removeprefix("\ufeff")  # a byte-order mark is accepted
    except OSError as exc:
        raise ZerocalError(f"cannot read the tolerance file: {exc.strerror}", where=str(path)) from None
    except UnicodeDecodeError as exc:
        raise ZerocalError(f"cannot read the tolerance file: not UTF-8 text ({exc.reason} at byte {exc.start})",
                           where=str(path)) from None
    try:
        data = json.loads(text) if p.suffix.lower() == ".json" else tomllib.loads(text)
    except (ValueError, tomllib.TOMLDecodeError) as exc:
        raise ZerocalError(f"bad tolerance file: {exc}", where=str(path)) from None
    except RecursionError:  # arrays nested thousands deep
        raise ZerocalError("bad tolerance file: arrays or tables nested too deeply", where=str(path)) from None
    if not isinstance(data, dict) or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                             for v in data.values()):
        raise ZerocalError("a tolerance file holds name = value pairs (mm; deg for angles)", where=str(path))
    return dict(data)


def tolerance_vector(robot, tolerances, names) -> np.ndarray:
    """Tolerances of ``names`` (internal units), 0 where not given, shape (r,)."""
    return np.array([float(tolerances.get(n, 0.0)) for n in names])


def tsvd_bias_operator(robot, theta_cmd, prior=None, t=None, rtol=None) -> np.ndarray:
    """TSVD's own operator ``A`` (p, K-1): measured changes (mm) to its estimate (internal units), at its
    linearisation point.

    TSVD is unweighted and truncated: its estimate moves by ``A A_o e_o`` when the omitted errors are ``e_o``
    (``A_o`` the changes' sensitivity to them), not by the weighted least-squares ``S`` -- pass ``A`` as
    ``operator`` to :func:`bias_sensitivity` and :func:`tolerance_bias`.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
    prior : ndarray, shape (q,), optional
        TSVD's linearisation point: the prior of its (last) step (default zero; an iterated TSVD's last step is
        linearised at its estimate minus its last increment).
    t : int, optional
        Truncation level (default: the ``threshold`` rule,
        :data:`~zerocal_sym.identify.estimate.truncated_svd.DEFAULT_RTOL` or ``rtol``); give the identification's own ``info["truncation"]`` for another rule.

    Returns
    -------
    ndarray, shape (p, K - 1)
        Rows the mechanism's default set (zero offsets, measuring errors).
    """
    from zerocal_sym.identify.linear import identification_matrix
    from zerocal_sym.identify.estimate.truncated_svd import DEFAULT_RTOL

    errors = robot.errors
    names = errors.resolve("default")
    prior = errors.zeros() if prior is None else errors.check_vector(prior)
    P = kin.fk(robot, np.atleast_2d(theta_cmd) + errors.take(prior, errors.zero_offsets))
    G, _ = identification_matrix(robot, P, maemm_prior=errors.take(prior, errors.measuring))
    U, sv, Vt = np.linalg.svd(G, full_matrices=False)
    if t is None:
        t = int(np.count_nonzero(sv > (DEFAULT_RTOL if rtol is None else rtol) * sv[0]))
    T = 1.0 / robot.error_scale(names)
    return (T[:, None] * Vt[:t].T / sv[:t]) @ U[:, :t].T


def bias_sensitivity(robot, theta_cmd, params="paper", noise: NoiseModel | None = None, err0=None,
                     operator=None):
    """``S = d(estimate) / d(omitted errors)`` of the weighted least-squares fit, first order.

    ``operator`` (p, K-1): an estimator linear in the changes instead (TSVD: :func:`tsvd_bias_operator`):
    ``S = operator A_o``, ``noise`` then unused.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joints in visiting order, rad.
    params : str or list of str
        The identified parameters.
    noise : NoiseModel, optional
        The estimator's weighting (default the paper's; a zero model: unweighted).
    err0 : ndarray, shape (q,), optional
        Linearisation point (default zero).

    Returns
    -------
    S : ndarray, shape (p, r)
        Row per identified parameter, column per omitted error (internal units).
    names : tuple of str
        The omitted errors (columns).
    """
    noise = NoiseModel.coerce(noise, robot=robot)
    from zerocal_sym.identify import fisher

    errors = robot.errors
    idx = errors.indices(params)
    names = omitted(robot, params)
    om = [errors.index(n) for n in names]
    err0 = errors.zeros() if err0 is None else errors.check_vector(err0)
    _, de, _ = kin.distance_jacobians(robot, np.atleast_2d(theta_cmd), err0)
    A, Ao = np.diff(de[:, idx], axis=0), np.diff(de[:, om], axis=0)
    if operator is not None:
        operator = np.asarray(operator, float)
        if operator.shape != (len(idx), A.shape[0]):
            raise ValueError(f"operator must be ({len(idx)}, {A.shape[0]}): the {len(idx)} parameters from the "
                             f"{A.shape[0]} changes, got {operator.shape}")
        return operator @ Ao, names
    if not noise.is_zero:  # whitened by the banded Cholesky factor of Cov(s), O(K p)
        C = fisher.change_covariance(robot, theta_cmd, noise, err0)
        A, Ao = C.whiten(A), C.whiten(Ao)
    S, *_ = np.linalg.lstsq(A, Ao, rcond=None)
    return S, names


def tolerance_bias(robot, theta_cmd, tolerances=None, params="paper", noise: NoiseModel | None = None,
                   err0=None, operator=None, estimator="weighted least squares") -> dict:
    """Worst-case and RMS bias of each identified parameter from the omitted errors' tolerances.

    ``operator``: the estimator's own linear operator (TSVD, :func:`tsvd_bias_operator`), named ``estimator``
    in the result; default the weighted least-squares fit's sensitivity.

    Parameters
    ----------
    theta_cmd : ndarray, shape (K, m)
        Commanded joints in visiting order, rad.
    tolerances : dict name -> value (internal units), optional
        Default :func:`default_tolerances`.

    Returns
    -------
    dict
        ``params``, ``units`` (user units per parameter), ``worst_case`` and
        ``rms`` (user units, per parameter), ``zero_offsets`` {``names``,
        ``unit``, ``worst_case_deg``, ``rms_deg``} (``_mm`` for prismatic joints), ``tolerances`` (user units by
        name), ``sensitivity`` (per omitted error, user units per user unit:
        rows the parameters), ``model``, ``estimator``.
    """
    errors = robot.errors
    names = errors.resolve(params)
    tol = default_tolerances(robot, params) if tolerances is None else dict(tolerances)
    S, om = bias_sensitivity(robot, theta_cmd, params, noise, err0, operator=operator)
    t = tolerance_vector(robot, tol, om)
    worst = np.abs(S) @ t
    rms = np.sqrt((S ** 2) @ (t ** 2) / 3.0)
    to_user = np.array([errors.to_user_value(n, 1.0) for n in names])
    from_user = np.array([errors.from_user_value(n, 1.0) for n in om])
    off = [names.index(z) for z in errors.zero_offsets if z in names]
    return {
        "params": list(names),
        "units": {n: errors[n].user_unit for n in names},
        "worst_case": (worst * to_user).tolist(),
        "rms": (rms * to_user).tolist(),
        "zero_offsets": {"names": [names[i] for i in off], "unit": errors.offset_user_unit,
                         f"worst_case_{errors.offset_user_unit}": (worst * to_user)[off].tolist(),
                         f"rms_{errors.offset_user_unit}": (rms * to_user)[off].tolist()},
        "tolerances": {n: errors.to_user_value(n, v) for n, v in zip(om, t)},
        "tolerance_units": {n: errors[n].user_unit for n in om},
        "sensitivity": {"rows": list(names), "columns": list(om),
                        "values": (S * to_user[:, None] * from_user[None, :]).tolist()},
        "model": f"first order; worst case sum_j |S_ij| t_j; RMS sqrt(sum_j S_ij^2 t_j^2 / 3): {RMS_MODEL}",
        "estimator": estimator,
    }
