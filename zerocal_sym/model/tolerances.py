"""How well each robot-file entry is known: the ``[tolerances]`` table of a robot file.

An identification estimates some source errors (the zero offsets and the
MAEMM by default) and holds every other one at the robot file's value.  A
tolerance ``t`` states how far the real robot may be from the file for an
entry held so: ``|e| <= t`` (mm; deg for angles).  The bias this can put on
the estimate is :mod:`zerocal_sym.identify.budget.bias`'s; the error budget of an
answer is :mod:`zerocal_sym.identify.budget.error_budget`'s.

The table
---------
::

    [tolerances]     # mm; deg for angles
    L = 1.0          # a group: every entry whose name is L and a number (L1, L2, L3: the upper arms)
    phi2 = 0.2       # one entry
    base = 0.3       # a set of the mechanism (base, lengths, platform, ...), or geometry, measuring

A key is one of

* a source error that is not a zero offset (``L1``, ``phi2``, ``rMz``, ``b3x``);
* a **group**: the entries whose names differ only in their digits (``L``
  for ``L1 L2 L3``, ``phi`` for ``phi1 phi2 phi3``, ``ex`` for the planar
  ``e1x e2x``, ``bx`` for the hexapod's ``b1x ... b6x``);
* a set: the mechanism's own (``lengths``, ``base``, ``platform``, ``rM``,
  ...), ``geometry`` (every geometric error) or ``measuring`` (the MAEMM).

A key naming fewer entries wins over one naming more (``L = 1`` over
``lengths = 0.3`` for ``L1``); between keys naming as many, the later one in
the table.  A zero offset has no tolerance (it is always identified).

Defaults
--------
An entry no key names gets the default of a robot **measured by hand**:
:data:`DEFAULT_LENGTH_TOLERANCE_MM` (0.5 mm: a caliper or a rule between
joint centres that cannot be seen) per length and
:data:`DEFAULT_ANGLE_TOLERANCE_DEG` (0.05 deg: an angle set by a base plate's
hole pattern, checked by hand) per angle.
These are 25 times the machining tolerances (0.02 mm, 0.002 deg) used before
(``--tolerance-scale 0.04`` gives those).  The paper's robot (built in, and
``examples/paper_robot.toml``) carries the magnitudes of the paper's Table 2
set A (:data:`PAPER_SET_A_TOLERANCES_MM`), its stated geometric errors.

The tolerances are not part of the robot's hash (:attr:`Robot.sha256
<zerocal_sym.model.robot.Robot.sha256>`): a measurement file taken with the
robot stays this robot's when a table is added or changed.
"""
from __future__ import annotations

import math
import re

#: default tolerance of a length held at the robot file's value (mm): a robot measured by hand
DEFAULT_LENGTH_TOLERANCE_MM = 0.5
#: default tolerance of an angle held at the robot file's value (deg): a robot measured by hand
DEFAULT_ANGLE_TOLERANCE_DEG = 0.05
#: the paper's planar robot: the magnitudes of Table 2's geometric error set A (mm)
PAPER_SET_A_TOLERANCES_MM = {"e1x": 0.03, "e1y": 0.02, "e2x": 0.02, "e2y": 0.01,
                             "L1": 0.01, "L2": 0.02, "l1": 0.03, "l2": 0.02}
#: sets of SourceErrors.resolve a tolerance key may name besides the mechanism's own
GENERIC_KEYS = ("geometry", "geometric", "measuring", "maemm")


def group_name(name: str) -> str:
    """The group of an entry: its name without digits (``L2`` -> ``L``, ``b3x`` -> ``bx``)."""
    return re.sub(r"\d+", "", name)


def held_names(errors) -> tuple:
    """The source errors a tolerance may be given for: every one but the zero offsets, in vector order."""
    offsets = set(errors.zero_offsets)
    return tuple(n for n in errors.names if n not in offsets)


def groups(errors) -> dict:
    """Group name -> its entries (:func:`group_name`), in vector order; groups of one entry included."""
    out: dict = {}
    for n in held_names(errors):
        out.setdefault(group_name(n), []).append(n)
    return {g: tuple(v) for g, v in out.items()}


def keys(errors) -> dict:
    """Every key a ``[tolerances]`` table may hold -> the entries it names (a tuple, vector order)."""
    held = set(held_names(errors))
    out = {}
    for spec in GENERIC_KEYS + tuple(s for s in errors.extra_sets if s not in ("default", "gauge_fixed")):
        try:
            names = errors.resolve(spec)
        except ValueError:
            continue
        if names and set(names) <= held:  # a set with a zero offset in it is always partly identified
            out[spec] = tuple(names)
    out.update(groups(errors))
    out.update({n: (n,) for n in held_names(errors)})
    return out


def default_value(errors, name: str) -> float:
    """The default tolerance of ``name`` in its user unit (mm; deg for angles)."""
    return DEFAULT_ANGLE_TOLERANCE_DEG if errors[name].unit == "rad" else DEFAULT_LENGTH_TOLERANCE_MM


def check_key(errors, key: str) -> tuple:
    """The entries ``key`` names; ValueError saying why not (a zero offset, an unknown name)."""
    table = keys(errors)
    if key in table:
        return table[key]
    if key in errors.zero_offsets:
        raise ValueError(f"{key} is a zero offset: it is always identified, so it has no tolerance")
    groups_ = sorted(g for g, v in groups(errors).items() if len(v) > 1)
    sets = sorted(k for k, v in table.items() if k not in groups(errors) and k not in v)
    raise ValueError(f"unknown tolerance key {key!r} (an entry: {', '.join(held_names(errors))}; a group: "
                     f"{', '.join(groups_) or '-'}; a set: {', '.join(sets)})")


def resolve(errors, items) -> dict:
    """Tolerances by entry (user units) from ``items`` (key, value) in table order, defaults elsewhere.

    Parameters
    ----------
    errors : SourceErrors
    items : iterable of (str, float)
        Keys as :func:`keys`; values >= 0 in each entry's user unit.

    Returns
    -------
    dict
        name -> tolerance (user units: mm, deg) for every entry of :func:`held_names`.

    Raises
    ------
    ValueError
        An unknown key, a zero offset, a negative or non-finite value.
    """
    best: dict = {}   # name -> (size of the key that set it, -order, value)
    for order, (key, value) in enumerate(items):
        names = check_key(errors, key)
        v = float(value)
        if not math.isfinite(v) or v < 0:
            raise ValueError(f"tolerance {key} = {value!r}: must be finite and >= 0")
        rank = (len(names), -order)
        for n in names:
            if n not in best or rank <= best[n][0]:
                best[n] = (rank, v)
    return {n: (best[n][1] if n in best else default_value(errors, n)) for n in held_names(errors)}


def check_table(errors, table: dict, where, check_number, error, angle_limit: float) -> None:
    """A robot file's ``[tolerances]`` table: known keys (:func:`keys`), numbers >= 0 within the file's limits.

    ``where(key)`` names the file and line; ``check_number(key, value, unit, where)`` is the robot file's check
    of a number in ``unit``; ``error`` the exception raised (``error(message, where=...)``); ``angle_limit`` the
    largest angle (deg).
    """
    for k, v in table.items():
        try:
            names = check_key(errors, k)
        except ValueError as exc:
            raise error(f"[tolerances]: {exc}", where=where(k)) from None
        units_ = {errors[n].user_unit for n in names}
        check_number(k, v, "deg" if units_ == {"deg"} else "mm", where)
        if v < 0:
            raise error(f"[tolerances] {k} is a tolerance: >= 0, got {v!r}", where=where(k))
        if "deg" in units_ and float(v) > angle_limit:
            raise error(f"[tolerances] {k} = {v!r} deg is beyond {angle_limit:g} deg", where=where(k))
