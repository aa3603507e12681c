"""The measuring process: source errors, noise model and a virtual plant.

The scale's reading head is reset after each measurement, so what is measured
at pose k (k >= 1) is the change ``s_k = rho_k - rho_{k-1} + m_k`` of the
measuring-mechanism length; the reading at the first pose is 0 by definition.
(The paper indexes the same changes as ``s_k = rho_{k+1} - rho_k``, k = 1..K-1.)

Noise (paper Section 6.1, each switchable and scalable):

* scale error per measured change ``m_k ~ N(0, sigma_m^2)``,
  ``sigma_m = (3 + l0/1000)/3 um`` with ``l0 = 350 mm`` (Eq. 34);
* servo motion error per joint per pose ``xi ~ N(0, sigma_xi^2)``,
  ``sigma_xi = (1/3)(4/10^4)(1/eta) 360 deg`` with ``eta = 20`` (Eq. 35).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from zerocal_sym.model import kinematics as kin

#: the names of :meth:`NoiseModel.named` (the CLI's ``--noise`` choices)
NOISE_NAMES = ("paper", "scale-only", "servo-only", "none")


def paper_sigma_scale_mm(l0_mm: float = 350.0) -> float:
    """Eq. (34): std of the scale error per measured change, mm."""
    return (3.0 + l0_mm / 1000.0) / 3.0 * 1e-3


def paper_sigma_servo_rad(eta: float = 20.0, pulses: float = 1e4, pulse_err: float = 4.0) -> float:
    """Eq. (35): std of the servo motion error per joint per pose, rad."""
    return np.radians((1.0 / 3.0) * (pulse_err / pulses) * (1.0 / eta) * 360.0)


@dataclass(frozen=True)
class NoiseModel:
    """Gaussian measurement noise.

    Attributes
    ----------
    sigma_scale_mm : float
        Std of each measured change of the scale, mm.
    sigma_servo_rad : float
        Std of each joint's motion error at each pose, rad.
    """

    sigma_scale_mm: float = 0.0
    sigma_servo_rad: float = 0.0

    def __post_init__(self):
        for name in ("sigma_scale_mm", "sigma_servo_rad"):
            v = getattr(self, name)
            try:
                ok = bool(np.isfinite(v) and v >= 0)
            except TypeError:
                ok = False
            if not ok:
                raise ValueError(f"NoiseModel: {name} must be a finite standard deviation >= 0, got {v!r}")

    @classmethod
    def paper(cls, scale: float = 1.0, servo: float = 1.0) -> "NoiseModel":
        """The paper's noise, each term multiplied by a factor."""
        return cls(scale * paper_sigma_scale_mm(), servo * paper_sigma_servo_rad())

    @classmethod
    def named(cls, name: str) -> "NoiseModel":
        """``paper`` | ``scale-only`` | ``servo-only`` | ``none`` (:data:`NOISE_NAMES`)."""
        table = {"paper": cls.paper(), "scale-only": cls.paper(servo=0.0),
                 "servo-only": cls.paper(scale=0.0), "none": cls()}
        if name not in table:
            raise ValueError(f"unknown noise model {name!r} (known: {', '.join(table)})")
        return table[name]

    @classmethod
    def coerce(cls, noise, what: str = "noise") -> "NoiseModel":
        """The noise model an identification argument names.

        ``None``: the paper's (:meth:`paper`); a :class:`NoiseModel`: itself;
        a name (``str``): :meth:`named`, the names the CLI's ``--noise`` and
        a study spec's ``noise`` list accept.

        Raises
        ------
        ValueError
            An unknown name.
        TypeError
            Anything else (a factor of the paper's noise is
            ``NoiseModel.paper(f, f)``).
        """
        if noise is None:
            return cls.paper()
        if isinstance(noise, NoiseModel):
            return noise
        if isinstance(noise, str):
            try:
                return cls.named(noise)
            except ValueError as exc:
                raise ValueError(f"{what}: {exc}") from None
        raise TypeError(f"{what} must be a NoiseModel, one of the names {', '.join(NOISE_NAMES)} or None (the "
                        f"paper's), got {noise!r} ({type(noise).__name__}); a factor f of the paper's noise is "
                        "NoiseModel.paper(f, f)")

    @property
    def is_zero(self) -> bool:
        return self.sigma_scale_mm == 0 and self.sigma_servo_rad == 0


class VirtualPlant:
    """A simulated robot with source errors and the measuring mechanism.

    Parameters
    ----------
    robot : Robot
        Nominal robot (what the controller believes).
    err : ndarray, shape (q,) or dict
        True source errors (rad, mm), a vector in the mechanism's order or
        ``{name: value}`` (internal units).
    """

    def __init__(self, robot, err):
        self.robot = robot
        self.err = robot.errors.vector(err) if isinstance(err, dict) else robot.errors.check_vector(err).copy()

    def actual_pose(self, theta_cmd):
        """Where the platform actually is for commanded joints (no noise).

        Returns
        -------
        ndarray, shape (K, n)
        """
        errors = self.robot.errors
        actual = replace(self.robot, geometry=self.robot.geometry + geometry_error(self.robot, self.err))
        return kin.fk(actual, np.asarray(theta_cmd) + errors.take(self.err, errors.zero_offsets))

    def lengths(self, theta_cmd, noise: NoiseModel | None = None, rng=None):
        """Actual measuring-mechanism lengths, servo error included.

        Returns
        -------
        ndarray, shape (K,)
        """
        theta_cmd = np.atleast_2d(np.asarray(theta_cmd, float))
        if noise is not None and noise.sigma_servo_rad > 0:
            rng = np.random.default_rng(rng)
            theta_cmd = theta_cmd + rng.normal(0.0, noise.sigma_servo_rad, theta_cmd.shape)
        return kin.distance(self.robot, theta_cmd, self.err)

    def measure(self, theta_cmd, noise: NoiseModel | None = None, rng=None):
        """Scale readings at K commanded poses (head reset after each reading).

        Parameters
        ----------
        theta_cmd : ndarray, shape (K, m)
            Commanded joint angles, rad.
        noise : NoiseModel, optional
        rng : numpy Generator or seed, optional

        Returns
        -------
        ndarray, shape (K,)
            ``readings[0] = 0``; ``readings[k] = rho_k - rho_{k-1} + m_k``, mm.
        """
        rng = np.random.default_rng(rng)
        rho = self.lengths(theta_cmd, noise, rng)
        s = np.diff(rho)
        if noise is not None and noise.sigma_scale_mm > 0:
            s = s + rng.normal(0.0, noise.sigma_scale_mm, s.shape)
        return np.concatenate([[0.0], s])


def geometry_error(robot, err) -> np.ndarray:
    """The geometry and measuring part of the source errors on the geometry vector, shape (G,).

    A measuring-mechanism error is carried on the base point ``c`` (it enters
    the distance only through ``c + d``).
    """
    names = robot.mechanism.geometry_names
    dg = np.zeros(len(names))
    for e, v in zip(robot.errors, robot.errors.check_vector(err)):
        if e.role != "zero_offset":
            dg[names.index(e.target)] += v
    return dg
