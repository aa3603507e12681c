"""The paper's Figs. 8 and 9 as PNG files (matplotlib, Agg backend).

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
    from zerocal_sym.paper import DEFAULT_MAEMM_PRIOR, kappas

    prior = DEFAULT_MAEMM_PRIOR if maemm_prior is None else tuple(maemm_prior)
    ns = [int(n) for n in ns]
    k = [kappas(robot, n, prior) for n in ns]
    return {"n": ns, "kappa_1": [a for a, _ in k], "kappa_m": [b for _, b in k], "maemm_prior_mm": list(prior)}


def fig8(path, data: dict, paper_point=(3, 475.34, 472.54)) -> None:
    """Fig. 8: ``kappa_1`` and ``kappa_m`` vs n, written to ``path`` (PNG).

    Parameters
    ----------
    path : str or Path
    data : dict
        From :func:`fig8_data`.
    paper_point : (n, kappa_1, kappa_m)
        The paper's values, marked.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4), dpi=120)
    ax.plot(data["n"], data["kappa_1"], "o-", label=r"$\kappa_1$ (1st identification)")
    ax.plot(data["n"], data["kappa_m"], "s--",
            label=r"$\kappa_m$ (MAEMM prior %s mm)" % (tuple(data["maemm_prior_mm"]),))
    if paper_point:
        n, k1, km = paper_point
        ax.plot([n, n], [k1, km], "kx", ms=9, label=f"paper: n={n}, {k1}, {km}")
    ax.set_xlabel("n (poses per boundary)")
    ax.set_ylabel("condition number of G")
    ax.set_title("Fig. 8: condition numbers vs n")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)


def fig9(path, groups: list, mu0_deg=0.1) -> None:
    """Fig. 9: compensation values vs identification number, one panel per group.

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
        m = np.arange(1, comp.shape[0] + 1)
        for i, (mk, c) in enumerate((("o", "C0"), ("v", "C1"))):
            ax.plot(m, comp[:, i], mk + "-", color=c, ms=4, label=rf"$\Delta\theta_{i + 1}$")
            ax.axhline(g["set_deg"][i], color=c, ls=":", lw=1)
        it = int(round(float(np.mean(g["iterations"]))))
        ax.axvline(it, color="grey", ls="--", lw=1)
        mu = [v for v in g["history"]["mu_deg"][it:] if v is not None]
        after = comp[it - 1:] - np.asarray(g["set_deg"])
        txt = f"after m={it}: max $\\delta$={np.max(np.abs(after)):.3f}°"
        if mu:
            txt += f", max $\\mu$={max(mu):.3f}°"
        ax.set_title(f"group {g['group']}", fontsize=10)
        ax.text(0.98, 0.5, txt, transform=ax.transAxes, ha="right", fontsize=7)
        ax.set_xlabel("identification m")
        ax.set_ylabel("compensation [deg]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    for ax in axes.ravel()[k:]:
        ax.set_visible(False)
    fig.suptitle(f"Fig. 9: compensation values vs m (dotted: set values; dashed: first mu < {mu0_deg:g} deg)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)
