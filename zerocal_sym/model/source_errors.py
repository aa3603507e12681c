"""Source errors by name and role: the one place that knows their positions.

A mechanism's source errors (its generated ``SOURCE_ERRORS``) are additive
errors on the actuated joints (role ``zero_offset``), on geometric parameters
(``geometry``) or on the measuring mechanism's base point (``measuring``, the
MAEMM).  Every numeric layer keeps them as a vector of length q in the
mechanism's order — but reads and writes it only through :class:`SourceErrors`,
by name: ``errors.vector(theta1=..., rMx=...)``, ``errors.take(v, names)``,
``errors.resolve("offsets+measuring")``.

Parameter sets (:meth:`SourceErrors.resolve`)
---------------------------------------------
``offsets``
    the zero offsets (joint order);
``measuring`` (alias ``maemm``)
    the MAEMM components (pose-coordinate order);
``geometry`` (alias ``geometric``)
    every geometric error;
``offsets+measuring``
    the zero offsets and every measuring error;
``default`` (alias ``paper``)
    the mechanism's default identified set: the paper's identification
    parameters (Eq. 28, the offsets and the MAEMM) where the data identify
    them; a mechanism declares a smaller one where they do not (the linear
    Delta holds ``rMz``: a common carriage offset is a vertical shift);
``all``
    every source error;
``gauge_fixed``
    every source error but those the mechanism holds at zero to fix the gauge;
plus the mechanism's own sets (``lengths``, ``base``) and single names,
combined with ``+`` or ``,`` (``offsets+measuring+L1,L2``).

Units: rad for angles, mm for lengths inside; :meth:`SourceErrors.to_user_value` /
:meth:`SourceErrors.from_user` convert angles to and from degrees.  The zero
offsets have their joints' unit (:attr:`SourceErrors.offset_unit`: rad for
revolute joints, mm for prismatic ones).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ROLES = ("zero_offset", "geometry", "measuring")
GENERIC_SETS = {
    "offsets": ("zero_offset",),
    "measuring": ("measuring",),
    "maemm": ("measuring",),
    "geometry": ("geometry",),
    "geometric": ("geometry",),
    "offsets+measuring": ("zero_offset", "measuring"),
    "all": ROLES,
}
#: set names standing for another (``paper``: the mechanism's default set)
SET_ALIASES = {"paper": "default"}


@dataclass(frozen=True)
class SourceError:
    """One source error (see :mod:`derivations.mechanism`).

    Attributes
    ----------
    name, role, unit : str
    target : str
        The joint or geometry entry it is added to (``cx`` for ``rMx``).
    lever : str or None
        Geometry entry whose value (mm) turns an angular error into a length.
    """

    name: str
    role: str
    unit: str
    target: str
    lever: str | None = None

    @property
    def user_unit(self) -> str:
        """``deg`` for angles, ``mm`` otherwise."""
        return "deg" if self.unit == "rad" else "mm"

    @property
    def length_unit(self) -> str:
        """The unit of ``lever * value``, what the paper's linear model estimates: always mm."""
        return "mm"


class SourceErrors:
    """The ordered source errors of one mechanism.

    Parameters
    ----------
    rows : sequence of (name, role, unit, target, lever)
    extra_sets : dict of str -> tuple of str, optional
        The mechanism's own named parameter sets.
    """

    def __init__(self, rows, extra_sets=None):
        self.items = tuple(SourceError(*r) for r in rows)
        self.names = tuple(e.name for e in self.items)
        self._index = {n: k for k, n in enumerate(self.names)}
        if len(self._index) != len(self.names):
            raise ValueError(f"duplicate source-error names in {self.names}")
        for e in self.items:
            if e.role not in ROLES:
                raise ValueError(f"source error {e.name!r}: unknown role {e.role!r}")
        self.extra_sets = dict(extra_sets or {})
        self.extra_sets.setdefault("default", tuple(e.name for e in self.items if e.role in ("zero_offset", "measuring")))
        self._resolved = {}   # resolve(spec) by spec: the sets and names do not change after construction
        self._roles = {}      # of_role(role) by role, likewise

    def __len__(self) -> int:
        return len(self.items)

    def __iter__(self):
        return iter(self.items)

    def __getitem__(self, name: str) -> SourceError:
        return self.items[self.index(name)]

    # -------------------------------------------------------------- by role
    def of_role(self, role: str) -> tuple:
        """Names with this role, in vector order."""
        hit = self._roles.get(role)
        if hit is None:
            hit = self._roles[role] = tuple(e.name for e in self.items if e.role == role)
        return hit

    @property
    def zero_offsets(self) -> tuple:
        return self.of_role("zero_offset")

    @property
    def measuring(self) -> tuple:
        return self.of_role("measuring")

    @property
    def geometry(self) -> tuple:
        return self.of_role("geometry")

    @property
    def offset_unit(self) -> str:
        """Internal unit of the zero offsets: ``rad`` (revolute joints) or ``mm`` (prismatic)."""
        return self[self.zero_offsets[0]].unit

    @property
    def offset_user_unit(self) -> str:
        """File unit of the zero offsets: ``deg`` or ``mm``."""
        return self[self.zero_offsets[0]].user_unit

    @property
    def default(self) -> tuple:
        """The mechanism's default identified set."""
        return self.extra_sets["default"]

    @property
    def set_names(self) -> tuple:
        return tuple(GENERIC_SETS) + tuple(SET_ALIASES) + tuple(self.extra_sets)

    # ------------------------------------------------------------- by name
    def index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise ValueError(f"unknown parameter {name!r} (known: {', '.join(self.names)}; "
                             f"sets: {', '.join(self.set_names)})") from None

    def indices(self, spec) -> list:
        """Positions of the parameters named by ``spec`` (see :meth:`resolve`)."""
        return [self._index[n] for n in self.resolve(spec)]

    def resolve(self, spec) -> tuple:
        """Parameter names selected by ``spec``, in vector order, without duplicates.

        Parameters
        ----------
        spec : str or sequence of str
            Set names, parameter names, or a string combining both with ``+``
            or ``,`` (``"offsets+measuring+L1,L2"``).

        Raises
        ------
        ValueError
            An unknown name, or an empty set.
        """
        spec = spec if isinstance(spec, str) else tuple(spec)
        try:
            hit = self._resolved.get(spec)
        except TypeError:  # unhashable entries: _resolve says what is wrong
            return self._resolve(spec)
        if hit is None:
            hit = self._resolved[spec] = self._resolve(spec)
        return hit

    def _resolve(self, spec) -> tuple:
        if isinstance(spec, str):
            spec = [p.strip() for p in spec.replace("+", ",").split(",") if p.strip()]
        chosen = set()
        for p in spec:
            p = SET_ALIASES.get(p, p)
            if p in GENERIC_SETS:
                chosen.update(n for role in GENERIC_SETS[p] for n in self.of_role(role))
            elif p in self.extra_sets:
                chosen.update(self.extra_sets[p])
            else:
                self.index(p)
                chosen.add(p)
        if not chosen:
            raise ValueError("empty parameter set")
        return tuple(n for n in self.names if n in chosen)

    # -------------------------------------------------------------- vectors
    def zeros(self) -> np.ndarray:
        """ndarray, shape (q,)."""
        return np.zeros(len(self.items))

    def vector(self, values=None, **kw) -> np.ndarray:
        """A source-error vector (internal units) from ``{name: value}`` and keywords; others zero."""
        v = self.zeros()
        for name, val in {**(values or {}), **kw}.items():
            v[self.index(name)] = float(val)
        return v

    def assemble(self, zero_offsets_deg=None, geometry=None, maemm_mm=None, zero_offsets_user=None) -> np.ndarray:
        """A vector from the zero offsets (file units, joint order), geometric errors by name and the MAEMM (mm).

        Parameters
        ----------
        zero_offsets_user : sequence of m floats, optional
            In the joints' file unit (deg for revolute joints, mm for prismatic ones).
        zero_offsets_deg : sequence of m floats, optional
            The same for revolute joints (its former name).
        geometry : dict of str -> float, optional
            Geometric errors by name (mm, rad for angles).
        maemm_mm : sequence of u floats, optional
            The measuring errors, in their order.
        """
        if zero_offsets_deg is not None:
            if self.offset_unit != "rad":
                raise ValueError("zero_offsets_deg: these zero offsets are lengths (mm): pass zero_offsets_user")
            zero_offsets_user = zero_offsets_deg
        v = self.vector(geometry or {})
        off_conv = np.radians if self.offset_unit == "rad" else np.asarray
        for names, vals, conv in ((self.zero_offsets, zero_offsets_user, off_conv), (self.measuring, maemm_mm, np.asarray)):
            if vals is None:
                continue
            vals = np.asarray(vals, float)
            if vals.shape != (len(names),):
                raise ValueError(f"expected {len(names)} values for {', '.join(names)}, got {vals.shape}")
            v = self.put(v, names, conv(vals))
        return v

    def from_user(self, values: dict) -> np.ndarray:
        """A vector from ``{name: value}`` in user units (degrees for angles, mm)."""
        return self.vector({n: self.from_user_value(n, v) for n, v in values.items()})

    def from_user_value(self, name: str, value: float) -> float:
        return float(np.radians(value)) if self[name].unit == "rad" else float(value)

    def to_user_value(self, name: str, value: float) -> float:
        return float(np.degrees(value)) if self[name].unit == "rad" else float(value)

    def to_dict(self, v, names=None, user: bool = False) -> dict:
        """``{name: value}`` of the vector ``v`` (all names, or ``names``)."""
        v = self.check_vector(v)
        names = self.names if names is None else names
        return {n: (self.to_user_value(n, v[self.index(n)]) if user else float(v[self.index(n)])) for n in names}

    def take(self, v, names) -> np.ndarray:
        """The entries ``names`` of ``v`` (shape (q,) or (..., q)), shape (p,) or (..., p)."""
        return np.asarray(v, float)[..., [self.index(n) for n in names]]

    def put(self, v, names, values) -> np.ndarray:
        """A copy of ``v`` with the entries ``names`` set to ``values``."""
        out = np.array(v, float)
        out[..., [self.index(n) for n in names]] = values
        return out

    def embed(self, names, values) -> np.ndarray:
        """A vector with ``names`` set to ``values`` and zeros elsewhere."""
        return self.put(self.zeros(), names, values)

    def check_vector(self, v, what: str = "source-error vector") -> np.ndarray:
        v = np.asarray(v, float)
        if v.shape[-1:] != (len(self.items),):
            raise ValueError(f"{what} must have length q = {len(self.items)} ({', '.join(self.names)}), "
                             f"got shape {v.shape}")
        return v

    def scale(self, names, geometry_value) -> np.ndarray:
        """mm per unit of each parameter: the lever arm for angles, 1 for lengths, shape (p,).

        Parameters
        ----------
        geometry_value : callable
            ``name -> value`` of the robot's geometry (mm).
        """
        return np.array([geometry_value(self[n].lever) if self[n].lever else 1.0 for n in names])
