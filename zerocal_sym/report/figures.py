"""The calibration report's figures, as PNG bytes: the robot and its poses, the accuracy maps, the fit's readings.

Any mechanism: the robot is drawn by its mechanism's optional ``sketch``
(:func:`zerocal_sym.model.kinematics.sketch`) and its measuring mechanism
(:func:`~zerocal_sym.model.kinematics.measuring_line`) at home; 2-D poses in
their plane, 3-D positions in a perspective view and from above.  A pose's
orientation coordinates (the hexapod's roll, pitch, yaw) colour its point by
the tilt ``|(roll, pitch, yaw)|`` (deg); the report's table lists them.
Matplotlib through its object-oriented API only (:func:`zerocal_sym.report.plots._figure`).
"""
from __future__ import annotations

import io

import numpy as np

from zerocal_sym.model import kinematics as kin
from zerocal_sym.model import units
from zerocal_sym.report.accuracy import position_axes
from zerocal_sym.report.plots import _figure

#: resolution of the report's PNGs
DPI = 96


def png(fig) -> bytes:
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


def _outline(robot) -> list:
    """The workspace's outline as polylines of its position coordinates, [ndarray (k, 2 or 3)]."""
    ws = robot.workspace
    pos, _ = position_axes(robot)
    lo, hi = (np.asarray(b, float)[pos] for b in ws.bounds())
    if len(pos) == 2:
        return [np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]], [lo[0], lo[1]]])]
    if ws.kind == "cylinder":
        t = np.linspace(0, 2 * np.pi, 73)
        ring = np.column_stack([hi[0] * np.cos(t), hi[0] * np.sin(t)])
        lines = [np.column_stack([ring, np.full(len(t), z)]) for z in (lo[2], hi[2])]
        return lines + [np.array([[hi[0] * np.cos(a), hi[0] * np.sin(a), lo[2]],
                                  [hi[0] * np.cos(a), hi[0] * np.sin(a), hi[2]]]) for a in np.arange(4) * np.pi / 2]
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    edges = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    return [corners[[i, j]] for i, j in edges]


def _tilt_deg(robot, P):
    """``|orientation|`` of each pose in degrees, shape (K,), or None for poses without orientation."""
    _, rot = position_axes(robot)
    return np.degrees(np.linalg.norm(P[:, rot], axis=1)) if rot else None


def figure_robot(robot, poses=None):
    """The robot at home (its sketch and measuring mechanism), the workspace and the measured poses.

    Parameters
    ----------
    poses : ndarray, shape (K, n), optional
        Internal units (mm, rad).
    """
    pos, _ = position_axes(robot)
    home = robot.home_pose()[None, :]
    seg = kin.sketch(robot, home)
    scale = kin.measuring_line(robot, home)[0]
    tilt = None if poses is None else _tilt_deg(robot, poses)
    names = robot.mechanism.pose_names
    if len(pos) == 2:
        fig = _figure((7.5, 5.0))
        views = [(fig.add_subplot(1, 1, 1), (0, 1))]
    else:
        fig = _figure((11.0, 5.0))
        views = [(fig.add_subplot(1, 2, 1, projection="3d"), (0, 1, 2)), (fig.add_subplot(1, 2, 2), (0, 1))]
    for ax, dims in views:
        def draw(pts, *a, **kw):
            ax.plot(*[pts[:, d] for d in dims], *a, **kw)

        for line in _outline(robot):
            draw(line, "-", color="0.65", lw=0.8)
        if seg is not None:
            for k, s in enumerate(seg[0]):
                draw(s, "-", color="tab:blue", lw=2.0, label="robot at home" if k == 0 else None)
        draw(scale, "--", color="tab:red", lw=1.4, label="measuring mechanism")
        P0 = home[0, pos]
        ax.scatter(*[P0[[d]] for d in dims], marker="*", s=120, color="k", label="home P0", zorder=5)
        if poses is not None:
            Q = poses[:, pos]
            colour = {"c": tilt, "cmap": "viridis"} if tilt is not None else {"color": "tab:orange"}
            sc = ax.scatter(*[Q[:, d] for d in dims], s=22, edgecolors="k", linewidths=0.4, zorder=6,
                            label=f"{len(Q)} measured poses", **colour)
            if len(Q) <= 24:
                for k, q in enumerate(Q):
                    if len(dims) == 2:
                        ax.annotate(f"{k}", q[list(dims)], fontsize=7, xytext=(3, 3), textcoords="offset points")
            if tilt is not None and len(dims) == 2:
                fig.colorbar(sc, ax=ax, label="pose tilt |(roll, pitch, yaw)| [deg]")
        ax.set_xlabel(f"{names[pos[dims[0]]]} [mm]")
        ax.set_ylabel(f"{names[pos[dims[1]]]} [mm]")
        if len(dims) == 3:
            ax.set_zlabel(f"{names[pos[2]]} [mm]")
            ax.set_title("the robot and its poses", fontsize=10)
        else:
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_title("from above" if len(pos) > 2 else "the robot and its poses in the workspace", fontsize=10)
    if len(views) == 1:
        views[0][0].legend(fontsize=7, loc="best")
    else:  # below the perspective view, out of the drawing
        views[0][0].legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2)
    return fig


def figure_accuracy(acc, unit_label: str = "mm"):
    """The accuracy maps: before compensation, its 1 sigma, and after compensation (rows; a single level: side by
    side), one column per level of the third position coordinate."""
    levels = acc["levels"]
    rows = (("before_mm", "before compensation: |position error|", "magma"),
            ("before_std_mm", "before: its 1 sigma (from the covariance)", "cividis"),
            ("after_mm", "after compensation: predicted RMS error (1 sigma)", "viridis"))
    L = len(levels)
    nrows, ncols = (1, 3) if L == 1 else (3, L)
    fig = _figure((11.0, 2.7) if L == 1 else (3.6 * L + 1.2, 8.4))
    ext = [acc["x"][0], acc["x"][-1], acc["y"][0], acc["y"][-1]]
    for r, (key, title, cmap) in enumerate(rows):
        data = acc[key]
        finite = data[np.isfinite(data)]
        vmax = float(finite.max()) if finite.size else 1.0
        vmin = float(finite.min()) if finite.size else 0.0
        axes = []
        for c, (name, value) in enumerate(levels):
            ax = fig.add_subplot(nrows, ncols, r + 1 if L == 1 else r * L + c + 1)
            im = ax.imshow(np.ma.masked_invalid(data[c]), origin="lower", extent=ext, cmap=cmap, vmin=vmin,
                           vmax=vmax if vmax > vmin else vmin + 1e-12, aspect="equal", interpolation="nearest")
            level = "" if name is None else f"{name} = {value:.4g} mm"
            ax.set_title(f"{title}\n{level}" if c == 0 and level else (level or title), fontsize=8)
            ax.set_xlabel(f"{acc['axes'][0]} [mm]", fontsize=8)
            ax.set_ylabel(f"{acc['axes'][1]} [mm]", fontsize=8)
            ax.tick_params(labelsize=7)
            axes.append(ax)
        fig.colorbar(im, ax=axes, label=unit_label, shrink=0.9, location="right" if L > 1 else "bottom")
    return fig


def figure_readings(fit):
    """The fit check's standardised residual per reading (``t_k``, N(0, 1) under the noise model), the worst
    reading marked."""
    readings = fit.get("readings") or []
    k = np.array([r.get("pose") for r in readings], float)
    t = np.array([np.nan if r.get("standardised") is None else r["standardised"] for r in readings], float)
    fig = _figure((7.0, 3.0))
    ax = fig.add_subplot(1, 1, 1)
    colors = ["tab:blue"] * len(k)
    worst = (fit.get("worst") or {}).get("pose")
    for j, pose in enumerate(k):
        if worst is not None and pose == worst:
            colors[j] = "tab:red"
    ax.bar(k, t, 0.6, color=colors)
    for y in (-3, 3):
        ax.axhline(y, color="0.5", ls=":", lw=0.8)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel("reading k (the change from pose k-1 to pose k)")
    ax.set_ylabel("standardised residual")
    ax.set_title("Fit check: standardised residual per reading (N(0, 1) under the noise model; red: the worst)",
                 fontsize=9)
    return fig


def pose_table(robot, P) -> tuple:
    """``(header, rows)``: the poses in file units (mm, deg) for the report's table."""
    mech = robot.mechanism
    header = [f"{name}_{units.pose_unit(mech, name)}" for name in mech.pose_names]
    V = units.pose_to_user(mech, np.asarray(P, float))
    return header, V
