"""Figure of a design and the paper's scheme in the workspace (:func:`plot_design`)."""
from __future__ import annotations

import numpy as np

from zerocal_sym.design.constraints import Region
from zerocal_sym.design.optimize import DesignResult
from zerocal_sym.design.terms import _call_ik, pose_terms


# --------------------------------------------------------------------------- plot
def plot_design(path, robot, result: DesignResult) -> None:
    """PNG of the design and the paper's scheme in the workspace (atomic write).

    Shows the workspace and design region, the area excluded by the
    singularity margin (if any), the design poses numbered in visiting order
    with the path between them, and the paper's scheme with the same K.
    """
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from zerocal_sym.io.files import atomic_write_bytes

    cons = result.constraints
    ws = Region.workspace(robot)
    reg = cons.region
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    try:
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
        if reg != ws:
            ax.add_patch(plt.Rectangle(reg.lo, *(reg.hi - reg.lo), fill=False, ec="tab:green", ls="--", lw=1.2,
                                       label="design region"))
        Pp = np.asarray(result.paper["poses"])
        ax.plot(Pp[:, 0], Pp[:, 1], "s", mfc="none", mec="tab:gray", ms=10,
                label=f"paper's scheme (CRLB {result.paper['crlb_rms_deg']:.3f} deg)")
        P = result.poses
        ax.plot(P[:, 0], P[:, 1], "-", color="tab:blue", lw=0.6, alpha=0.6)
        ax.plot(P[:, 0], P[:, 1], "o", color="tab:blue",
                label=f"{result.criterion}-optimal (CRLB {result.report['crlb_rms_deg']:.3f} deg)")
        for k, p in enumerate(P):
            ax.annotate(str(k + 1), p, textcoords="offset points", xytext=(4, 4 + 8 * (k % 2)), fontsize=8,
                        color="tab:blue")
        ax.set_aspect("equal")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ratio = result.to_dict()["ratio"]["crlb_rms_design_over_paper"]
        ax.set_title(f"K = {len(P)}, criterion {result.criterion}; CRLB ratio design/paper "
                     f"{'-' if ratio is None else format(ratio, '.3f')}", fontsize=10)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=120)
    finally:
        plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())
