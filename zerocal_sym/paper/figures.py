"""The paper's Figs. 8, 9 and the per-group Fig. 12 / convergence plots as PNG files (matplotlib, Agg backend).

matplotlib is imported inside the functions so that importing this module (and
the CLI) stays light.
"""
from __future__ import annotations

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def fig8_data(robot, ns=range(3, 22), maemm_prior=None) -> dict:
    """``kappa_1`` and ``kappa_m`` of the paper's scheme for each n.

    Returns
    -------
    dict
        ``n`` (list of int), ``kappa_1``, ``kappa_m`` (lists of float), ``maemm_prior_mm``.
    """
    from zerocal_sym.paper.reproduction import kappas
    from zerocal_sym.paper.tables import DEFAULT_MAEMM_PRIOR

    prior = DEFAULT_MAEMM_PRIOR if maemm_prior is None else tuple(maemm_prior)
    ns = [int(n) for n in ns]
    k = [kappas(robot, n, prior) for n in ns]
    return {"n": ns, "kappa_1": [a for a, _ in k], "kappa_m": [b for _, b in k], "maemm_prior_mm": list(prior)}


def fig8(path, data: dict, paper_point=(3, 475.34, 472.54), eps0=0.01) -> None:
    """Fig. 8: ``kappa_1`` and ``kappa_m`` vs n, written to ``path`` (PNG).

    Parameters
    ----------
    path : str or Path
    data : dict
        From :func:`fig8_data`.
    paper_point : (n, kappa_1, kappa_m)
        The paper's values, marked.
    eps0 : float
        Threshold of the eps rule, drawn in the lower panel.
    """
    plt = _pyplot()
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(6, 6), dpi=120, sharex=True,
                                  gridspec_kw={"height_ratios": [2, 1]})
    n = np.asarray(data["n"])
    k1, km = np.asarray(data["kappa_1"]), np.asarray(data["kappa_m"])
    ax.plot(n, k1, "o-", label=r"$\kappa_1$ (1st identification)")
    ax.plot(n, km, "s--", mfc="none", label=r"$\kappa_m$ (MAEMM prior %s mm)" % (tuple(data["maemm_prior_mm"]),))
    if paper_point:
        p, pk1, pkm = paper_point
        ax.plot([p, p], [pk1, pkm], "kx", ms=9, label=f"paper: n={p}, {pk1}, {pkm}")
    ax.set_ylabel("condition number of G")
    ax.set_title("Fig. 8: condition numbers vs n")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax2.plot(n, (k1 - km) / k1, "d-", color="C2", label=r"$\varepsilon = (\kappa_1 - \kappa_m)/\kappa_1$")
    ax2.axhline(eps0, color="k", ls=":", lw=1, label=rf"$\varepsilon_0$ = {eps0:g}")
    ax2.set_xlabel("n (poses per boundary)")
    ax2.set_ylabel(r"$\varepsilon$")
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)


def fig9(path, groups: list, mu0_deg=0.1) -> None:
    """Fig. 9: compensation values vs identification number, one panel per group.

    Plotted as the deviation from the set value (both joints on one scale).

    Parameters
    ----------
    path : str or Path
    groups : list of dict
        Per-group results of :func:`zerocal_sym.paper.run_group` (``history``,
        ``set_deg``, ``iterations``, ``group``).
    """
    plt = _pyplot()
    k = len(groups)
    cols = 3 if k > 2 else k
    rows = int(np.ceil(k / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), dpi=110, squeeze=False)
    for ax, g in zip(axes.ravel(), groups):
        comp = np.asarray(g["history"]["compensation_deg"], float)
        dev = comp - np.asarray(g["set_deg"], float)
        m = np.arange(1, comp.shape[0] + 1)
        for i, (mk, c) in enumerate((("o", "C0"), ("v", "C1"))):
            ax.plot(m, dev[:, i], mk + "-", color=c, ms=4,
                    label=rf"$\Delta\theta_{i + 1}$ (set {g['set_deg'][i]:g}°)")
        ax.axhline(0.0, color="k", lw=0.8)
        it = int(round(float(np.mean(g["iterations"]))))
        ax.axvline(it, color="grey", ls="--", lw=1)
        mu = [v for v in g["history"]["mu_deg"][it:] if v is not None]
        txt = f"after m={it}: max |δ|={np.max(np.abs(dev[it - 1:])):.3f}°"
        if mu:
            txt += f", max μ={max(mu):.3f}°"
        ax.set_title(f"group {g['group']}\n{txt}", fontsize=9)
        ax.set_xlabel("identification m")
        ax.set_ylabel("compensation - set [deg]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    for ax in axes.ravel()[k:]:
        ax.set_visible(False)
    fig.suptitle(f"Fig. 9: compensation value minus set value vs m (dashed: first mu < {mu0_deg:g} deg)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)


def reproduce_plots(out_dir, rep: dict, robot=None, K: int = 42) -> dict:
    """The per-group plots of a reproduction (``zerocal reproduce --plot DIR``).

    For each group of ``rep`` (:func:`zerocal_sym.paper.reproduction.reproduce`): the
    position error over the K boundary positions before and after its
    compensation value (Fig. 12 style, ``fig12_group{g}.png``) and the
    convergence of the compensation values of its first trial
    (``convergence_group{g}.png``).  Offsets are converted from Table 2's frame
    (``rep["settings"]["frame"]``) to the robot's for the plant.

    Parameters
    ----------
    out_dir : str or Path
    rep : dict
        From :func:`zerocal_sym.paper.reproduction.reproduce`.
    robot : Robot, optional
        Default: the paper's.
    K : int
        Number of boundary positions.

    Returns
    -------
    dict
        file name -> the figure's data.
    """
    from pathlib import Path

    from zerocal_sym.model.robot import paper_robot
    from zerocal_sym.paper.tables import group_errors, to_table_frame
    from zerocal_sym.report.plots import plot_boundary_errors, plot_convergence

    robot = robot or paper_robot()
    out_dir = Path(out_dir)
    frame = rep["settings"]["frame"]
    out = {}
    for g in rep["groups"]:
        n = int(g["group"])
        comp = to_table_frame(np.asarray(g["compensation_deg"], float), frame, "offsets")  # an involution
        name = f"fig12_group{n}.png"
        out[name] = plot_boundary_errors(robot, group_errors(n, frame), comp, out_dir / name, K=K,
                                         title=f"Group {n}: position error over the boundary (Fig. 12 style)")
        name = f"convergence_group{n}.png"
        out[name] = plot_convergence(g["history"], out_dir / name, set_values_deg=g["set_deg"],
                                     mu0_deg=rep["settings"].get("mu0_deg", 0.1))
    return out
