"""The Monte Carlo comparison on Table 2's groups (``zerocal compare`` on the paper's robot).

:func:`compare` builds the truths from Table 2 (read in ``frame``, optionally
without the geometric errors) and reports the errors in Table 2's frame, then
runs the generic :func:`zerocal_sym.identify.montecarlo.compare`.
"""
from __future__ import annotations

from functools import partial

from zerocal_sym.identify import montecarlo
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import group_errors, to_table_frame


def _report(values, which, frame):
    """Errors in Table 2's frame (module level: picklable for worker processes)."""
    return to_table_frame(values, frame, which)


def compare(robot, groups=(1,), trials: int = 100, poses=None, frame: str = "paper", geometric: bool = True,
            **kwargs) -> dict:
    """Table 2's groups through :func:`zerocal_sym.identify.montecarlo.compare`.

    Parameters
    ----------
    groups : sequence of int
        Table 2 groups (1..6), read in ``frame``.
    poses : ndarray, shape (K, 2), optional
        Default: the paper's 6 poses.
    frame : {"paper", "literal"}
    geometric : bool
        Keep Table 2's geometric errors in the plant (False: only offsets and
        MAEMM, so the 4-parameter model is exact).
    **kwargs
        ``params``, ``noise``, ``seed``, ``methods``, ``mu0_deg``, ``max_iter``, ``progress``,
        ``workers``, ``scheduler``, ``chunk``.
    """
    errors = robot.errors
    truths = {}
    for g in groups:
        err = group_errors(g, frame)
        truths[g] = err if geometric else errors.put(err, errors.geometry, 0.0)
    poses = paper_poses(robot, 3) if poses is None else poses
    return montecarlo.compare(robot, truths, poses, trials=trials,
                              report=partial(_report, frame=frame),
                              settings={"frame": frame, "geometric_errors": bool(geometric),
                                        "error_frame": "Table 2's" if frame == "paper" else "ours"}, **kwargs)
