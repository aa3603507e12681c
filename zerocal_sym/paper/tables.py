"""The paper's numbers: Table 2's source errors, Tables 3-6, the frame of Table 2.

* :data:`SET_A`, :data:`TABLE2`, :func:`table2_errors` -- Table 2's groups as
  printed; :func:`group_errors` -- the same in the frame they are read in;
* :data:`PAPER_TABLE3` .. :data:`PAPER_TABLE6`, :func:`paper_table` -- the
  values the paper reports, to compare with :func:`zerocal_sym.paper.reproduction.run_group`.

Frame of Table 2 (see ``docs/reproduction.md``)
-----------------------------------------------
Read literally in our frame (``y`` from the base towards the workspace, angles
counter-clockwise), Table 2's set values do not give the paper's ``dp0
(before)`` (Table 3) and ``dp_max (before)`` (Table 4): differences up to
0.19 mm.  Read in the frame mirrored about the ``x`` axis (``y -> -y``: the
zero offsets, the ``e_iy`` and ``rMy`` change sign, everything else is
unchanged) they reproduce Table 3 within 0.0015 mm and Table 4 within
0.0004 mm (exact forward kinematics).  ``frame="paper"`` (the default) applies
this reading; ``frame="literal"`` does not.  Offsets and MAEMM are *reported*
in Table 2's frame so that they compare directly with the paper.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import ZerocalError
from zerocal_sym.model.mechanism import get_mechanism

#: The paper's mechanism: Table 2 names its source errors.
PLANAR = get_mechanism("planar_2dof").errors

# ---------------------------------------------------------------- Table 2
#: Geometric error "set A" of the paper's Table 2, mm.
SET_A = {"e1x": 0.03, "e1y": -0.02, "e2x": -0.02, "e2y": 0.01,
         "L1": 0.01, "L2": 0.02, "l1": -0.03, "l2": -0.02}
#: Table 2: group -> (dtheta1 deg, dtheta2 deg, geometric scale of set A, MAEMM mm)
TABLE2 = {
    1: (2.0, -1.0, 1.0, (1.0, 0.5)),
    2: (-1.0, 0.5, 1.0, (1.0, 0.5)),
    3: (0.5, 0.25, 1.0, (1.0, 0.5)),
    4: (2.0, -1.0, 0.1, (1.0, 0.5)),
    5: (-1.0, 0.5, 0.1, (1.0, 0.5)),
    6: (0.5, 0.25, 0.1, (1.0, 0.5)),
}


def table2_errors(group: int, geometric: bool = True) -> np.ndarray:
    """Source errors of the paper's Table 2 group (1..6), ndarray shape (12,)."""
    if group not in TABLE2:
        raise ValueError(f"group must be 1..6, got {group}")
    t1, t2, s, maemm = TABLE2[group]
    geo = {k: s * v for k, v in SET_A.items()} if geometric else None
    return PLANAR.assemble((t1, t2), geo, maemm)


# ---------------------------------------------------------------- frames
#: Sign of each source error under the mirror y -> -y (angles and y components flip).
MIRROR_Y = PLANAR.vector({n: 1.0 for n in PLANAR.names}) - 2 * PLANAR.vector(
    {n: 1.0 for n in ("theta1", "theta2", "e1y", "e2y", "rMy")})
FRAMES = ("paper", "literal")
#: The paper's MAEMM prior (1, 0.5) mm read in the paper's (mirrored) frame, in our frame.
DEFAULT_MAEMM_PRIOR = (1.0, -0.5)
#: kappa_m readings of the paper's prior: label -> prior applied as lambda_k - rM (our frame).
MAEMM_PRIOR_READINGS = {
    "paper frame (y mirrored), lambda - rM": (1.0, -0.5),
    "literal, lambda - rM": (1.0, 0.5),
    "literal, lambda + rM": (-1.0, -0.5),
    "paper frame, lambda + rM": (-1.0, 0.5),
}

# ---------------------------------------------------------------- paper's numbers
PAPER_N = 3
PAPER_KAPPA_1 = 475.34
PAPER_KAPPA_M = 472.54
#: Table 3: group -> compensation (deg), delta (deg), dp0 before, dp0 after (mm)
PAPER_TABLE3 = {
    1: ((2.033, -0.957), (0.033, 0.043), 10.933, 0.402),
    2: ((-1.049, 0.463), (0.049, 0.037), 5.482, 0.423),
    3: ((0.536, 0.297), (0.036, 0.047), 3.796, 0.434),
    4: ((2.024, -0.978), (0.024, 0.022), 10.896, 0.228),
    5: ((-1.025, 0.474), (0.025, 0.026), 5.5195, 0.256),
    6: ((0.476, 0.225), (0.024, 0.025), 3.798, 0.239),
}
#: Table 4: group -> dp_max before, after (mm), over the six measurement poses
PAPER_TABLE4 = {1: (12.906, 0.493), 2: (6.418, 0.531), 3: (4.672, 0.533),
                4: (12.868, 0.279), 5: (6.455, 0.314), 6: (4.663, 0.293)}
#: Table 5: group -> |delta rMx|, |delta rMy| (mm)
PAPER_TABLE5 = {1: (0.069, 0.040), 2: (0.074, 0.045), 3: (0.071, 0.042),
                4: (0.044, 0.022), 5: (0.051, 0.028), 6: (0.047, 0.024)}
#: Table 6: group -> mean condition number
PAPER_TABLE6 = {1: 472.47, 2: 472.49, 3: 472.49, 4: 472.50, 5: 472.51, 6: 472.50}


def paper_table(group: int) -> dict:
    """The paper's reported values for one group, with the JSON keys of :func:`run_group`."""
    comp, delta, b, a = PAPER_TABLE3[group]
    return {"group": group, "compensation_deg": list(comp), "delta_deg": list(delta),
            "dp0_before_mm": b, "dp0_after_mm": a, "dpmax_before_mm": PAPER_TABLE4[group][0],
            "dpmax_after_mm": PAPER_TABLE4[group][1], "delta_maemm_mm": list(PAPER_TABLE5[group]),
            "kappa_mean": PAPER_TABLE6[group]}


def group_errors(group: int, frame: str = "paper") -> np.ndarray:
    """Source errors of Table 2's group in our frame, ndarray shape (12,).

    Parameters
    ----------
    group : int
        1..6.
    frame : {"paper", "literal"}
        ``paper``: Table 2 read in the frame mirrored about the x axis (module
        docstring); ``literal``: read in our frame as printed.

    Raises
    ------
    ZerocalError
        Unknown group or frame.
    """
    if group not in PAPER_TABLE3:
        raise ZerocalError(f"unknown group {group!r}: Table 2 has groups 1..6")
    if frame not in FRAMES:
        raise ZerocalError(f"unknown frame {frame!r} (known: {', '.join(FRAMES)})")
    err = table2_errors(group)
    return err * MIRROR_Y if frame == "paper" else err


def to_table_frame(vec, frame: str, which: str):
    """Offsets (``which="offsets"``) or MAEMM (``"maemm"``) from our frame to Table 2's."""
    v = np.asarray(vec, float)
    if frame == "literal":
        return v.copy()
    return v * PLANAR.take(MIRROR_Y, PLANAR.zero_offsets if which == "offsets" else PLANAR.measuring)
