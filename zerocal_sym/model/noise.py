"""The measuring process: source errors, noise model and a virtual plant.

The scale's reading head is reset after each measurement, so what is measured
at pose k (k >= 1) is the change ``s_k = rho_k - rho_{k-1} + m_k`` of the
measuring-mechanism length; the reading at the first pose is 0 by definition.
(The paper indexes the same changes as ``s_k = rho_{k+1} - rho_k``, k = 1..K-1.)

Noise (paper Section 6.1, each switchable and scalable):

* scale error per measured change ``m_k ~ N(0, sigma_m^2)``,
  ``sigma_m = (3 + l0/1000)/3 um`` with ``l0 = 350 mm`` (Eq. 34);
* joint positioning error per joint per pose ``xi ~ N(0, sigma_xi^2)``, in the
  joints' unit; the paper's servo error (revolute joints)
  ``sigma_xi = (1/3)(4/10^4)(1/eta) 360 deg`` with ``eta = 20`` (Eq. 35);
* a per-pose systematic error of the measured length ``u_g ~ N(0, sigma_r^2)``
  (mm, default 0), shared by every visit of pose ``g`` (revisits of a pose
  repeat it; distinct poses have independent ones): what a revisit does not
  average out (``[noise] revisit_std_mm``).  A pose visited once carries it
  as one more independent error.

A robot's noise (:meth:`NoiseModel.of_robot`, the ``default`` of
:data:`NOISE_NAMES`) is its robot file's ``[noise]`` (``scale`` mm, ``joint``
in the joints' unit, ``revisit_std_mm``), else its mechanism's default (the
linear Delta's 0.002 mm and 0.005 mm), else the paper's (no shared error).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.fastcall import columns

#: the names of :meth:`NoiseModel.named` (the CLI's ``--noise`` choices): ``paper`` is the robot's default noise
#: (the paper's Eqs. 34 and 35 unless the robot file or its mechanism gives its own), ``servo-only`` its joint term
NOISE_NAMES = ("paper", "scale-only", "servo-only", "none")
#: names that stand for another (also accepted)
NOISE_ALIASES = {"default": "paper", "joint-only": "servo-only"}


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
    sigma_joint : float
        Std of each joint's positioning error at each pose, in the joints' internal unit (rad for revolute
        joints: the paper's servo error; mm for prismatic ones).
    sigma_revisit_mm : float
        Std of a pose's systematic error of the measured length, mm, shared by its revisits (default 0).
        Needs an independent term (scale or joint) beside it.
    """

    sigma_scale_mm: float = 0.0
    sigma_joint: float = 0.0
    sigma_revisit_mm: float = 0.0

    @property
    def sigma_servo_rad(self) -> float:
        """The joint term's former name (revolute joints: rad)."""
        return self.sigma_joint

    def __post_init__(self):
        for name in ("sigma_scale_mm", "sigma_joint", "sigma_revisit_mm"):
            v = getattr(self, name)
            try:
                ok = bool(np.isfinite(v) and v >= 0)
            except TypeError:
                ok = False
            if not ok:
                raise ValueError(f"NoiseModel: {name} must be a finite standard deviation >= 0, got {v!r}")
        if self.sigma_revisit_mm > 0 and self.sigma_scale_mm == 0 and self.sigma_joint == 0:
            raise ValueError("NoiseModel: a shared revisit error (sigma_revisit_mm) needs an independent term "
                             "beside it (sigma_scale_mm or sigma_joint): revisits of a pose would measure "
                             "exactly the same length")

    @property
    def has_shared(self) -> bool:
        """Whether the revisits of a pose share a systematic error (``sigma_revisit_mm > 0``)."""
        return self.sigma_revisit_mm > 0

    @classmethod
    def paper(cls, scale: float = 1.0, servo: float = 1.0) -> "NoiseModel":
        """The paper's noise, each term multiplied by a factor."""
        return cls(scale * paper_sigma_scale_mm(), servo * paper_sigma_servo_rad())

    @classmethod
    def of_robot(cls, robot) -> "NoiseModel":
        """The robot's noise: its file's ``[noise]``, else its mechanism's default, else the paper's."""
        from zerocal_sym.model import units

        mech = robot.mechanism
        given = {**mech.noise_defaults, **dict(getattr(robot, "noise_values", ()))}
        base = cls.paper()
        scale = float(given.get("scale", base.sigma_scale_mm))
        if "joint" in given:
            joint = float(units.joints_from_user(mech, given["joint"]))
        elif mech.joint_kind == "revolute":
            joint = base.sigma_joint
        else:
            raise ValueError(f"mechanism {mech.name!r} (prismatic joints) has no default joint noise: give "
                             "[noise] joint = ... (mm) in the robot file")
        return cls(scale, joint, float(given.get("revisit_std_mm", 0.0)))

    def scaled(self, scale: float = 1.0, joint: float = 1.0, revisit: float | None = None) -> "NoiseModel":
        """Each term multiplied by a factor (the shared revisit term by ``revisit``; default: kept unless
        both other terms become zero)."""
        sm, sj = self.sigma_scale_mm * scale, self.sigma_joint * joint
        if revisit is None:
            revisit = 1.0 if (sm > 0 or sj > 0) else 0.0
        return NoiseModel(sm, sj, self.sigma_revisit_mm * revisit)

    @classmethod
    def named(cls, name: str, robot=None) -> "NoiseModel":
        """``paper`` (the robot's default) | ``scale-only`` | ``servo-only`` | ``none`` (:data:`NOISE_NAMES`).

        With ``robot`` the terms are the robot's (:meth:`of_robot`); without, the paper's.  The shared
        revisit term belongs to ``paper`` alone (the robot's full noise).
        """
        name = NOISE_ALIASES.get(name, name) if isinstance(name, str) else name
        if name not in NOISE_NAMES:
            raise ValueError(f"unknown noise model {name!r} (known: {', '.join(NOISE_NAMES)})")
        base = cls.paper() if robot is None else cls.of_robot(robot)
        table = {"paper": base, "scale-only": base.scaled(joint=0.0, revisit=0.0),
                 "servo-only": base.scaled(scale=0.0, revisit=0.0), "none": cls()}
        return table[name]

    @classmethod
    def coerce(cls, noise, what: str = "noise", robot=None) -> "NoiseModel":
        """The noise model an identification argument names.

        ``None``: the robot's (:meth:`of_robot`; the paper's without a robot); a :class:`NoiseModel`: itself;
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
            return cls.paper() if robot is None else cls.of_robot(robot)
        if isinstance(noise, NoiseModel):
            return noise
        if isinstance(noise, str):
            try:
                return cls.named(noise, robot)
            except ValueError as exc:
                raise ValueError(f"{what}: {exc}") from None
        raise TypeError(f"{what} must be a NoiseModel, one of the names {', '.join(NOISE_NAMES)} or None (the "
                        f"paper's), got {noise!r} ({type(noise).__name__}); a factor f of the paper's noise is "
                        "NoiseModel.paper(f, f)")

    @property
    def is_zero(self) -> bool:
        return self.sigma_scale_mm == 0 and self.sigma_joint == 0

    def to_dict(self, robot=None) -> dict:
        """``{"sigma_scale_mm": ..., "sigma_servo_rad": ...}`` (revolute joints) or ``{..., "sigma_joint_mm": ...}``
        (prismatic), the joint term in the robot's internal unit; ``sigma_revisit_mm`` when nonzero."""
        if robot is not None and robot.mechanism.joint_kind == "prismatic":
            d = {"sigma_scale_mm": float(self.sigma_scale_mm), "sigma_joint_mm": float(self.sigma_joint)}
        else:
            d = {"sigma_scale_mm": float(self.sigma_scale_mm), "sigma_servo_rad": float(self.sigma_joint)}
        if self.sigma_revisit_mm:
            d["sigma_revisit_mm"] = float(self.sigma_revisit_mm)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "NoiseModel":
        """The inverse of :meth:`to_dict`."""
        joint = d.get("sigma_servo_rad", d.get("sigma_joint_mm", d.get("sigma_joint", 0.0)))
        return cls(d["sigma_scale_mm"], joint, d.get("sigma_revisit_mm", 0.0))


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
        return kin.distance(self.robot, self._servo(theta_cmd, noise, rng), self.err)

    @staticmethod
    def _servo(theta_cmd, noise, rng):
        """The joints reached for the commanded ``theta_cmd`` (K, m) rad: the servo error drawn from ``rng``."""
        theta_cmd = np.atleast_2d(np.asarray(theta_cmd, float))
        if noise is not None and noise.sigma_joint > 0:
            theta_cmd = theta_cmd + np.random.default_rng(rng).normal(0.0, noise.sigma_joint, theta_cmd.shape)
        return theta_cmd

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
            ``readings[0] = 0``; ``readings[k] = rho_k - rho_{k-1} + m_k``, mm; with a shared revisit
            error, ``rho_k`` carries ``u_g`` of its pose ``g`` (drawn last: the other draws are those
            without it).
        """
        rng = np.random.default_rng(rng)
        return self._readings(self.lengths(theta_cmd, noise, rng), theta_cmd, noise, rng)

    def measure_many(self, theta_cmds, noise: NoiseModel | None, rngs) -> list:
        """:meth:`measure` of N rounds at once, the same numbers: ``theta_cmds`` (N, K, m) rad, ``rngs`` one
        numpy Generator per round, each drawn from in :meth:`measure`'s order; the N K lengths in one mapped
        call of the distance (each column evaluated as alone).  Returns a list of N readings, shape (K,)."""
        theta = [self._servo(t, noise, g) for t, g in zip(theta_cmds, rngs)]
        if not theta:
            return []
        K = theta[0].shape[0]
        distance = columns(self.robot.mechanism["distance"], (True, False, False))
        rho = distance(np.concatenate(theta).T, self.robot.geometry, self.err)[0]
        rho = rho.reshape(len(theta), K)
        return [self._readings(rho[i], t, noise, g) for i, (t, g) in enumerate(zip(theta_cmds, rngs))]

    @staticmethod
    def _readings(rho, theta_cmd, noise, rng):
        """The readings (K,) from the lengths ``rho`` (K,): their changes, the scale and shared errors drawn."""
        s = np.diff(rho)
        if noise is not None and noise.sigma_scale_mm > 0:
            s = s + rng.normal(0.0, noise.sigma_scale_mm, s.shape)
        if noise is not None and noise.has_shared:
            from zerocal_sym.model.revisits import pose_groups

            lab = pose_groups(np.atleast_2d(np.asarray(theta_cmd, float)), 0.0)  # one pose: the same commands
            u = rng.normal(0.0, noise.sigma_revisit_mm, int(lab.max()) + 1)[lab]
            s = s + np.diff(u)
        return np.concatenate([[0.0], s])


def geometry_error(robot, err) -> np.ndarray:
    """The geometry and measuring part of the source errors on the geometry vector, shape (G,) (or (N, G) for
    ``err`` of shape (N, q)).

    A measuring-mechanism error is carried on its target, an entry of the base
    point ``c`` or of the platform point ``d``.
    """
    names = robot.mechanism.geometry_names
    errors = robot.errors
    key = (id(errors), tuple(names))
    hit = _TARGETS.get(key)
    if hit is None or hit[0] is not errors:  # which errors add to which geometry entry: once per mechanism
        sel = [k for k, e in enumerate(errors) if e.role != "zero_offset"]
        hit = _TARGETS[key] = (errors, np.array(sel, int), np.array([names.index(errors.items[k].target)
                                                                      for k in sel], int))
    _, sel, tgt = hit
    v = errors.check_vector(err)
    dg = np.zeros(v.shape[:-1] + (len(names),))
    for s_, t_ in zip(sel.tolist(), tgt.tolist()):  # in the errors' order, one after the other
        dg[..., t_] += v[..., s_]
    return dg


#: geometry_error's index maps per (source errors, geometry names)
_TARGETS: dict = {}
