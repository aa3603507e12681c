"""Report plots: residuals per pose, position error over the workspace
boundary before and after compensation (the paper's Fig. 12), convergence of
the compensation values (Fig. 9-style).

Each plot has a plain function that returns the figure's data (a dict of
numpy arrays, so tests check numbers, not pixels) and a ``plot_*`` function
that draws it and writes a PNG atomically.  Matplotlib is imported lazily and
only through its object-oriented API with the Agg canvas: no pyplot, no global
backend change, nothing opened on screen.

The 42 boundary positions (paper Fig. 11)
-----------------------------------------
The paper measures the position error at K = 42 evenly spaced positions along
the boundary of the workspace rectangle (480 x 150 mm: perimeter 1260 mm, one
position every 30 mm, 16 intervals along each long side and 5 along each short
side).  The OCR of Fig. 11 keeps only some labels: P1..P3 and P42 together,
then ``P39 P38 P37 P36 ... P23 P22`` along one long side.  We read it as:
P1 at the corner ``(-b/2, H)``, P1..P17 along ``y = H`` towards ``+x`` (P17 at
``(b/2, H)``), P18..P21 up the side ``x = b/2``, P22 at ``(b/2, H + h)``,
P22..P38 back along ``y = H + h`` (P38 at ``(-b/2, H + h)``), P39..P42 down the
side ``x = -b/2`` (P42 next to P1).  This puts P22 and P38 on corners with
P23..P37 between them and P39..P42 between P38 and P1, as the surviving labels
require; the starting corner and direction follow the paper's measurement
poses (P1 at ``(-b/2, H)``, then ``+x``).  For other K the positions are
spaced evenly by arc length from the same corner in the same direction.

On a cylindrical workspace (the rotary Delta) the boundary positions are the
workspace's own boundary scheme with K/2 positions on each rim
(``robot.workspace.boundary_scheme(K // 2)``: the top circle at azimuths
``360 deg j/(K/2)``, then the bottom one).  Everything else here is generic
over the mechanism: m zero offsets, n pose coordinates.
"""
from __future__ import annotations

import io

import numpy as np

from zerocal_sym.model import units

from zerocal_sym.io.files import atomic_write_bytes


# --------------------------------------------------------------------------- figure plumbing

def _figure(figsize=(7.0, 4.0)):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_png(fig, path) -> None:
    """Write a matplotlib figure as PNG, atomically."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    atomic_write_bytes(path, buf.getvalue())


# --------------------------------------------------------------------------- residuals per pose

def residuals_data(result, meas, robot=None) -> dict:
    """Residuals of an identification, per measured change.

    Parameters
    ----------
    result : IdentificationResult
        With ``residuals`` shape (K-1,): measured minus predicted changes, mm.
    meas : Measurements
        The measurements it was identified from (K poses).
    robot : Robot, optional
        If given, also the residuals of the nominal model (no source errors)
        for comparison, ``before_mm``.

    Returns
    -------
    dict
        ``pose`` (K-1,) int: the pose k (1..K-1) at which the change from
        pose k-1 was read; ``after_mm`` (K-1,): residuals at the estimate;
        ``before_mm`` (K-1,) or None; ``rms_after_mm``, ``rms_before_mm``
        (float or None); ``method``.
    """
    from zerocal_sym.model import kinematics as kin

    r = np.asarray(result.residuals, float)
    if r.shape != (meas.K - 1,):
        raise ValueError(f"result has {r.size} residuals, the measurements {meas.K - 1} changes")
    before = None
    if robot is not None:
        before = np.asarray(meas.readings, float)[1:] - np.diff(kin.distance(robot, meas.theta_cmd))
    return {
        "pose": np.arange(1, meas.K),
        "after_mm": r,
        "before_mm": before,
        "rms_after_mm": float(np.sqrt(np.mean(r**2))),
        "rms_before_mm": None if before is None else float(np.sqrt(np.mean(before**2))),
        "method": result.method,
    }


def figure_residuals(d: dict):
    """Figure of :func:`residuals_data`: residuals at the estimate (um) per pose,
    and those of the nominal model (mm) in a second panel if present."""
    two = d["before_mm"] is not None
    fig = _figure((7.0, 5.0 if two else 3.5))
    k = d["pose"]
    ax = fig.add_subplot(2 if two else 1, 1, 1)
    ax.bar(k, 1e3 * d["after_mm"], 0.6, color="tab:blue")
    ax.axhline(0, color="k", lw=0.6)
    if len(k) <= 25:  # every pose labelled; more: integer ticks that do not overlap
        ax.set_xticks(k)
    else:
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("residual [um]")
    ax.set_title(f"Residuals at the {d['method']} estimate (rms {1e3 * d['rms_after_mm']:.3g} um): "
                 "measured minus predicted scale change", fontsize=10)
    if two:
        ax2 = fig.add_subplot(2, 1, 2, sharex=ax)
        ax2.bar(k, d["before_mm"], 0.6, color="tab:gray")
        ax2.axhline(0, color="k", lw=0.6)
        ax2.set_ylabel("residual [mm]")
        ax2.set_title(f"Nominal model, no source errors (rms {d['rms_before_mm']:.3g} mm)", fontsize=10)
        ax2.set_xlabel("pose k (change read from pose k-1 to k)")
    else:
        ax.set_xlabel("pose k (change read from pose k-1 to k)")
    return fig


def plot_residuals(result, meas, path, robot=None) -> dict:
    """Write the residuals-per-pose PNG; returns :func:`residuals_data`."""
    d = residuals_data(result, meas, robot)
    save_png(figure_residuals(d), path)
    return d


# --------------------------------------------------------------------------- boundary positions (Figs. 11, 12)

def boundary_positions(robot, K: int = 42) -> np.ndarray:
    """K positions on the workspace boundary (paper Fig. 11 on a rectangle).

    Rectangle: evenly spaced along the perimeter, numbered as in the module
    docstring (from the corner ``(-b/2, H)`` along ``y = H`` towards ``+x``,
    up ``x = b/2``, back along ``y = H + h``, down ``x = -b/2``).  Other
    shapes (the Delta's cylinder): the workspace's boundary scheme with K/2
    positions per boundary (K even).

    Parameters
    ----------
    robot : Robot
    K : int
        Number of positions (>= 4).

    Returns
    -------
    ndarray, shape (K, n)
        mm; row k is the paper's P(k+1) on the rectangle.
    """
    if K < 4:
        raise ValueError(f"K must be >= 4, got {K}")
    ws = robot.workspace
    if ws.kind != "rectangle":
        if K % 2:
            raise ValueError(f"K must be even on a {ws.kind} workspace (K/2 per boundary), got {K}")
        return ws.boundary_scheme(K // 2)
    lo, hi = ws.bounds()
    x0, y0 = (float(v) for v in lo)
    x1, y1 = (float(v) for v in hi)
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]])
    seg = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.arange(K) * cum[-1] / K
    P = np.empty((K, 2))
    for k, sk in enumerate(s):
        i = min(int(np.searchsorted(cum, sk, side="right")) - 1, 3)
        t = (sk - cum[i]) / seg[i]
        P[k] = corners[i] + t * (corners[i + 1] - corners[i])
    # snap round-off so that corner positions are exact
    P[np.isclose(P[:, 0], x0), 0] = x0
    P[np.isclose(P[:, 0], x1), 0] = x1
    P[np.isclose(P[:, 1], y0), 1] = y0
    P[np.isclose(P[:, 1], y1), 1] = y1
    return P


def boundary_errors(robot, err_true, compensation_deg, P=None, K: int = 42) -> dict:
    """Position error over the boundary before and after compensation (Fig. 12).

    The errors are computed with the :class:`~zerocal_sym.model.noise.VirtualPlant`
    (noise-free): ``|actual pose - target|`` for the commands ``IK(P)``
    (before) and ``IK(P) - compensation`` (after).

    Parameters
    ----------
    robot : Robot
        Nominal robot.
    err_true : ndarray, shape (q,)
        True source errors of the plant (rad, mm).
    compensation_deg : array_like, shape (m,)
        Identified zero offsets (the compensation) in the joints' unit (deg for revolute joints, mm for prismatic
        ones; the name keeps the revolute spelling), joint order.
    P : ndarray, shape (K, n), optional
        Target positions (default :func:`boundary_positions`).
    K : int
        Number of boundary positions if ``P`` is not given.

    Returns
    -------
    dict
        ``index`` (K,) 1..K, ``P`` (K, n) mm, ``before_mm`` (K,),
        ``after_mm`` (K,), ``max_before_mm``, ``max_after_mm`` (float),
        ``compensation_deg`` (m,), ``workspace`` (its kind).
    """
    from zerocal_sym.model.noise import VirtualPlant
    from zerocal_sym.identify.loop import position_errors

    P = boundary_positions(robot, K) if P is None else np.atleast_2d(np.asarray(P, float))
    comp = units.joints_from_user(robot, np.asarray(compensation_deg, float))
    if comp.shape != (robot.m,):
        raise ValueError(f"compensation_deg must have one value per joint ({robot.m}), got shape {comp.shape}")
    plant = VirtualPlant(robot, err_true)
    before = position_errors(robot, plant, P)
    after = position_errors(robot, plant, P, comp)
    return {
        "index": np.arange(1, len(P) + 1),
        "P": P,
        "before_mm": before,
        "after_mm": after,
        "max_before_mm": float(np.max(before)),
        "max_after_mm": float(np.max(after)),
        "compensation_deg": units.joints_to_user(robot, comp),
        "workspace": robot.workspace.kind,
    }


def figure_boundary_errors(d: dict, title: str | None = None):
    """Figure of :func:`boundary_errors`: error vs position index, and the positions (3-D: azimuth against z)."""
    fig = _figure((9.0, 3.8))
    gs = fig.add_gridspec(1, 3)
    ax = fig.add_subplot(gs[0, :2])
    ax.plot(d["index"], d["before_mm"], "o-", ms=3, label=f"before (max {d['max_before_mm']:.3f} mm)")
    ax.plot(d["index"], d["after_mm"], "s-", ms=3, label=f"after (max {d['max_after_mm']:.3f} mm)")
    ax.set_xlabel("position k on the workspace boundary")
    ax.set_ylabel(r"$\Delta p$ [mm]")
    ax.set_xlim(0, len(d["index"]) + 1)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8)
    ax.set_title(title or "Position error over the boundary (Fig. 12 style)")
    ax2 = fig.add_subplot(gs[0, 2])
    P = d["P"]
    if P.shape[1] == 2:
        ax2.plot(np.append(P[:, 0], P[0, 0]), np.append(P[:, 1], P[0, 1]), "-", color="0.7", lw=0.8)
        ax2.scatter(P[:, 0], P[:, 1], c=d["after_mm"], s=12, cmap="viridis")
        xs, ys = (P[:, 0].min(), P[:, 0].max()), (P[:, 1].min(), P[:, 1].max())
        corner = [k for k in range(len(P)) if P[k, 0] in xs and P[k, 1] in ys]
        for k in sorted(set(corner) | {len(P) - 1}):
            ax2.annotate(f"P{k + 1}", P[k], fontsize=7, xytext=(2, 2), textcoords="offset points")
        ax2.invert_yaxis()  # the paper draws the base (y = 0) at the top
        ax2.set_ylabel("y [mm]")
        ax2.set_title("positions (colour: after)", fontsize=9)
        ax2.set_aspect("equal")
        ax2.set_xlabel("x [mm]")
    else:  # 3-D: the positions unrolled, azimuth about z against z
        az = np.degrees(np.arctan2(P[:, 1], P[:, 0])) % 360.0
        sc = ax2.scatter(az, P[:, 2], c=d["after_mm"], s=14, cmap="viridis")
        for k in (0, len(P) - 1):
            ax2.annotate(f"P{k + 1}", (az[k], P[k, 2]), fontsize=7, xytext=(2, 2), textcoords="offset points")
        fig.colorbar(sc, ax=ax2, label="after [mm]")
        ax2.set_xlim(-10, 370)
        ax2.set_xticks([0, 90, 180, 270, 360])
        ax2.set_xlabel("azimuth atan2(y, x) [deg]")
        ax2.set_ylabel("z [mm]")
        ax2.set_title("positions (colour: after)", fontsize=9)
    return fig


def plot_boundary_errors(robot, err_true, compensation_deg, path, K: int = 42, title: str | None = None) -> dict:
    """Write the Fig. 12-style PNG; returns :func:`boundary_errors`."""
    d = boundary_errors(robot, err_true, compensation_deg, K=K)
    save_png(figure_boundary_errors(d, title), path)
    return d


# --------------------------------------------------------------------------- convergence (Fig. 9 style)

def _get(obj, name, default=None):
    if isinstance(obj, dict):
        return obj.get(name, default)
    return getattr(obj, name, default)


def convergence_data(history, set_values_deg=None) -> dict:
    """Compensation values and compensation accuracy vs iteration.

    Parameters
    ----------
    history : LoopResult, sequence or dict
        A :class:`~zerocal_sym.identify.loop.LoopResult` (its ``history``), a sequence
        with one entry per identification round (mappings or objects with
        ``compensation_deg`` (m,): the compensation value after that round,
        i.e. the sum of the increments, deg; or ``compensation`` in rad), or
        the ``history`` dict of :func:`zerocal_sym.paper.reproduction.run_group` (a dict
        with a list ``compensation_deg``).
    set_values_deg : array_like, shape (m,), optional
        True zero offsets (simulation): also ``delta_deg``, the absolute
        difference between the set and the compensation values.

    Returns
    -------
    dict
        ``iteration`` (r,) 1..r over the r rounds, ``compensation_deg`` (r, m)
        for the m joints, ``mu_deg`` (r,) (RMS of the increment over the
        joints; NaN for the first round), ``delta_deg`` (r, m) or None.
    """
    if hasattr(history, "history"):
        history = history.history
    if isinstance(history, dict):
        history = [{"compensation_deg": c} for c in history["compensation_deg"]]
    comp = []
    for h in history:
        c = _get(h, "compensation_deg")
        if c is None and _get(h, "compensation") is not None:
            c = np.degrees(np.asarray(_get(h, "compensation"), float))
        if c is None:
            raise ValueError("history entries need 'compensation_deg' (deg) or 'compensation' (rad)")
        comp.append(np.atleast_1d(np.asarray(c, float)))
    if len({c.shape for c in comp}) > 1:
        raise ValueError("history entries must all have the same number of joints")
    m = comp[0].size if comp else 2
    comp = np.array(comp).reshape(-1, m)
    mu = np.full(len(comp), np.nan)
    mu[1:] = np.sqrt(np.sum(np.diff(comp, axis=0) ** 2, axis=1) / m)
    delta = None if set_values_deg is None else np.abs(np.asarray(set_values_deg, float) - comp)
    return {"iteration": np.arange(1, len(comp) + 1), "compensation_deg": comp, "mu_deg": mu, "delta_deg": delta}


def figure_convergence(d: dict, mu0_deg: float = 0.1, set_values_deg=None):
    """Figure of :func:`convergence_data`: compensation values and mu vs iteration."""
    fig = _figure((7.0, 5.0))
    ax = fig.add_subplot(2, 1, 1)
    m = d["iteration"]
    for j in range(d["compensation_deg"].shape[1]):
        mk = "ov^sD<>"[j % 7] + "-"
        ax.plot(m, d["compensation_deg"][:, j], mk, ms=4, label=rf"$\Delta\theta_{j + 1}$ compensation")
        if set_values_deg is not None:
            ax.axhline(set_values_deg[j], color=f"C{j}", ls=":", lw=0.8)
    ax.set_ylabel("compensation value [deg]")
    ax.legend(fontsize=8)
    ax.set_title("Convergence of the compensation values (Fig. 9 style)")
    ax2 = fig.add_subplot(2, 1, 2, sharex=ax)
    ax2.semilogy(m[1:], d["mu_deg"][1:], "s-", ms=4, color="tab:red", label=r"$\mu$")
    ax2.axhline(mu0_deg, color="k", ls="--", lw=0.8, label=rf"$\mu_0$ = {mu0_deg:g} deg")
    ax2.set_xlabel("identification round m")
    from matplotlib.ticker import MaxNLocator

    ax2.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax2.set_ylabel(r"$\mu$ [deg]")
    ax2.legend(fontsize=8)
    return fig


def plot_convergence(history, path, set_values_deg=None, mu0_deg: float = 0.1) -> dict:
    """Write the convergence PNG; returns :func:`convergence_data`."""
    d = convergence_data(history, set_values_deg)
    save_png(figure_convergence(d, mu0_deg, set_values_deg), path)
    return d


# --------------------------------------------------------------------------- one call per command

def identify_plots(out_dir, result, meas, robot, err_true=None) -> dict:
    """The plots of one identification (``zerocal identify --plot DIR``), any mechanism.

    Writes ``residuals.png`` in ``out_dir`` and, if the true source errors
    are known (simulated data), ``boundary_errors.png``: the position error
    over the workspace boundary (:func:`boundary_positions`) before and after
    compensating with the identified zero offsets.

    Parameters
    ----------
    err_true : ndarray, shape (q,), optional
        The plant's true source errors (rad, mm).

    Returns
    -------
    dict
        file name -> the figure's data (:func:`residuals_data`,
        :func:`boundary_errors`).
    """
    from pathlib import Path

    out_dir = Path(out_dir)
    out = {"residuals.png": plot_residuals(result, meas, out_dir / "residuals.png", robot)}
    if err_true is not None:
        out["boundary_errors.png"] = plot_boundary_errors(
            robot, err_true, result.zero_offsets_user, out_dir / "boundary_errors.png",
            title=f"Boundary position error (simulated truth), {result.method} compensation")
    return out
