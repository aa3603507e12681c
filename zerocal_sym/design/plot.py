"""Figure of a design and the boundary scheme in the workspace (:func:`plot_design`).

n = 2 (rectangle): the plane, with the area excluded by the singularity
margin.  n = 3 (cylinder): a top view (x-y, the workspace circle) and a side
view (radius ``sqrt(x^2 + y^2)`` against z, the workspace's section).
"""
from __future__ import annotations

import numpy as np

from zerocal_sym.design.shapes import Region, workspace_region
from zerocal_sym.design.optimize import DesignResult
from zerocal_sym.design.terms import _call_ik, pose_terms


def _labels(result):
    d = result.to_dict()
    ratio = d["ratio"]["crlb_rms_design_over_paper"]
    base = f"{result.baseline}'s scheme" if result.baseline == "paper" else f"{result.baseline} scheme"
    u = result.report.get("joint_unit", "deg")
    crlb = result.report[f"crlb_rms_{u}"]
    fmt = ".3f" if crlb >= 0.01 else ".3g"
    if result.paper is None:
        return (base, None, f"{result.criterion}-optimal (CRLB {format(crlb, fmt)} {u})",
                f"K = {len(result.poses)}, criterion {result.criterion}; no feasible baseline")
    pc = result.paper[f"crlb_rms_{u}"]
    return (base, f"{base} (CRLB {format(pc, '.3f' if pc >= 0.01 else '.3g')} {u})",
            f"{result.criterion}-optimal (CRLB {format(crlb, fmt)} {u})",
            f"K = {len(result.poses)}, criterion {result.criterion}; CRLB ratio design/{result.baseline} "
            f"{'-' if ratio is None else format(ratio, '.3g')}")


def _baseline_poses(result, n):
    if result.paper is None:
        return np.empty((0, n))
    P = getattr(result, "baseline_poses", None)
    return np.asarray(result.paper["poses"] if P is None else P)


def _numbered(ax, X, Y, color="tab:blue"):
    for k, (x, y) in enumerate(zip(X, Y)):
        ax.annotate(str(k + 1), (x, y), textcoords="offset points", xytext=(4, 4 + 8 * (k % 2)), fontsize=8,
                    color=color)


def _plot_2d(fig, plt, robot, result):
    cons = result.constraints
    ws = workspace_region(robot)
    reg = cons.region
    _, base_label, design_label, title = _labels(result)
    ax = fig.add_subplot(1, 1, 1)
    lo = np.minimum(ws.lo, reg.lo) - 20
    hi = np.maximum(ws.hi, reg.hi) + 20
    box = Region(lo[0], hi[0], lo[1], hi[1])
    grid = box.grid(97, 49)
    th, ratio = _call_ik(robot, grid)
    smin = np.full(len(grid), np.nan)
    okr = np.all(np.abs(ratio) < 1, axis=1)
    if np.any(okr):
        smin[okr] = np.min(np.abs(pose_terms(robot, grid[okr])["s"]), axis=1)
    Z = smin.reshape(49, 97)
    X, Y = grid[:, 0].reshape(49, 97), grid[:, 1].reshape(49, 97)
    if np.nanmin(Z) < cons.singularity_margin:
        ax.contourf(X, Y, Z, levels=[0, cons.singularity_margin], colors=["#f4c7c3"])
        ax.contour(X, Y, Z, levels=[cons.singularity_margin], colors=["#c0392b"], linewidths=0.8)
    ax.add_patch(plt.Rectangle(ws.lo, *(ws.hi - ws.lo), fill=False, ec="k", lw=1.2, label="workspace"))
    if reg.kind == "reachable":  # the feasible set: the region's own membership on the plot grid
        inside = reg.contains(grid, 0.0).reshape(49, 97).astype(float)
        ax.contour(X, Y, inside, levels=[0.5], colors=["tab:green"], linestyles="--", linewidths=1.2)
        ax.plot([], [], "--", color="tab:green", label="design region (reachable)")
    elif reg != ws:
        ax.add_patch(plt.Rectangle(reg.lo, *(reg.hi - reg.lo), fill=False, ec="tab:green", ls="--", lw=1.2,
                                   label="design region"))
    Pp = _baseline_poses(result, 2)
    if len(Pp):
        ax.plot(Pp[:, 0], Pp[:, 1], "s", mfc="none", mec="tab:gray", ms=10, label=base_label)
    P = result.poses
    ax.plot(P[:, 0], P[:, 1], "-", color="tab:blue", lw=0.6, alpha=0.6)
    ax.plot(P[:, 0], P[:, 1], "o", color="tab:blue", label=design_label)
    if len(P) <= 40:
        _numbered(ax, P[:, 0], P[:, 1])
    ax.set_aspect("equal")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)


def _plot_3d(fig, plt, robot, result):
    cons = result.constraints
    ws = workspace_region(robot)
    reg = cons.region
    _, base_label, design_label, title = _labels(result)
    top, side = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    P, Pp = result.poses, _baseline_poses(result, 3)
    t = np.linspace(0, 2 * np.pi, 241)
    cyl = reg if reg.kind == "cylinder" else getattr(reg, "clip", None)
    cyl = cyl if getattr(cyl, "kind", "") == "cylinder" else None
    # top view
    top.plot(ws.rw * np.cos(t), ws.rw * np.sin(t), "k-", lw=1.2, label="workspace")
    if cyl is not None and cyl != ws:
        top.plot(cyl.rw * np.cos(t), cyl.rw * np.sin(t), "--", color="tab:green", lw=1.2, label="design region")
    elif reg.kind == "reachable":
        top.add_patch(plt.Rectangle(reg.lo[:2], *(reg.hi[:2] - reg.lo[:2]), fill=False, ec="tab:green", ls="--",
                                    lw=1.2, label="design region (bounding box)"))
    if len(Pp):
        top.plot(Pp[:, 0], Pp[:, 1], "s", mfc="none", mec="tab:gray", ms=10, label=base_label)
    top.plot(P[:, 0], P[:, 1], "-", color="tab:blue", lw=0.6, alpha=0.6)
    top.plot(P[:, 0], P[:, 1], "o", color="tab:blue", label=design_label)
    if len(P) <= 40:
        _numbered(top, P[:, 0], P[:, 1])
    rmax = float(np.max(np.hypot(P[:, 0], P[:, 1]))) if len(P) else 0.0
    lim = max(ws.rw, cyl.rw if cyl is not None else 0.0, rmax) + 20
    top.set_xlim(-lim, lim)
    top.set_ylim(-lim, lim)
    top.set_aspect("equal")
    top.set_xlabel("x [mm]")
    top.set_ylabel("y [mm]")
    top.set_title("top view", fontsize=9)
    # side view: radius against z
    side.add_patch(plt.Rectangle((0, ws.zmin), ws.rw, ws.zmax - ws.zmin, fill=False, ec="k", lw=1.2))
    if cyl is not None and cyl != ws:
        side.add_patch(plt.Rectangle((0, cyl.zmin), cyl.rw, cyl.zmax - cyl.zmin, fill=False, ec="tab:green",
                                     ls="--", lw=1.2))
    rp, r = np.hypot(Pp[:, 0], Pp[:, 1]), np.hypot(P[:, 0], P[:, 1])
    if len(Pp):
        side.plot(rp, Pp[:, 2], "s", mfc="none", mec="tab:gray", ms=10)
    side.plot(r, P[:, 2], "o", color="tab:blue")
    if len(P) <= 40:
        _numbered(side, r, P[:, 2])
    zs = np.concatenate([[ws.zmin, ws.zmax, reg.lo[2], reg.hi[2]], P[:, 2]])
    zlo, zhi = float(zs.min()) - 20, float(zs.max()) + 20
    side.set_xlim(-10, lim)
    side.set_ylim(zlo, zhi)
    side.set_aspect("equal")
    side.set_xlabel("r = sqrt(x^2 + y^2) [mm]")
    side.set_ylabel("z [mm]")
    side.set_title("side view", fontsize=9)
    fig.suptitle(title, fontsize=10)
    handles, labels = top.get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=2)


# --------------------------------------------------------------------------- plot
def plot_design(path, robot, result: DesignResult) -> None:
    """PNG of the design and the boundary scheme in the workspace (atomic write).

    Shows the workspace and design region, the design poses numbered in
    visiting order with the path between them, and the baseline (the
    paper's scheme on a rectangle, the ring scheme on a cylinder) with the
    same K.  n = 2: one plane, with the area excluded by the singularity
    margin (if any).  n = 3: a top view (x-y) and a side view (radius
    against z).
    """
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from zerocal_sym.io.files import atomic_write_bytes

    if robot.n not in (2, 3):
        raise ValueError(f"plot_design draws 2-D and 3-D workspaces, not n = {robot.n}")
    fig = plt.figure(figsize=(7.5, 4.8) if robot.n == 2 else (10.0, 5.4))
    try:
        if robot.n == 2:
            _plot_2d(fig, plt, robot, result)
            fig.tight_layout()
        else:
            _plot_3d(fig, plt, robot, result)
            fig.tight_layout(rect=(0, 0.1, 1, 0.95))
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=120)
    finally:
        plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())
