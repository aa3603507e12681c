"""The paper's measurement-pose scheme (Sections 4-5).

``n`` evenly spaced poses on the boundary ``y = H`` from ``x = -b/2`` to
``+b/2``, then ``n`` on ``y = H + h``, again from ``-b/2`` to ``+b/2``
(``K = 2n``).  This order reproduces the paper's ``kappa_1 = 475.34`` at
``n = 3`` (``docs/model.md``); the order matters because G differences consecutive rows.
It is the rectangle's boundary scheme
(:meth:`zerocal_sym.model.workspace.Rectangle.boundary_scheme`); the paper's
identification matrix G is :func:`zerocal_sym.identify.linear.identification_matrix`.
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.errors import PoseError


def paper_poses(robot, n: int) -> np.ndarray:
    """The paper's 2n boundary poses.

    Returns
    -------
    ndarray, shape (2n, 2)
        mm, in visiting order.
    """
    if robot.workspace.kind != "rectangle":
        raise PoseError(f"the paper's scheme is for a rectangular workspace; robot {robot.name!r} has a "
                        f"{robot.workspace.kind} (use its scheme {robot.workspace.scheme_name!r})")
    return robot.workspace.boundary_scheme(n)
