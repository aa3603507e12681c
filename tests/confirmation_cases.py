"""A reference set of identifications over both methods, every mechanism and every option of ``identify_nlls``
(tests/test_confirmation.py).

``python tests/confirmation_cases.py`` writes ``tests/data/reference_confirmation.json``: the results as the
code at that commit computes them, and the versions of the libraries that computed them.  It was written while Ipopt solved the confirmation of every converged
Gauss-Newton point; the test recomputes every case now that the confirmation is Ipopt's own first-order
test on the Jacobian and residuals already computed (Ipopt solving whenever it does not pass) and asks for
the same statuses, word for word, and the same answers.

A case: (id, robot, poses, data noise, truth, bad reading (pose, mm) or None, method, keyword arguments).
``poses``: ``"scheme"`` (the robot's boundary scheme at its default n) or an int K (K random poses in the
workspace, seeded); ``truth``: ``"small"`` (zero offsets and measuring errors only: the model exact),
``"geometric"`` (geometric errors too: the model misses them), ``"far"`` (offsets of 6 deg / 6 mm: Gauss-Newton
from zero needs its blocks).
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
from reference_cases import _f, summary  # noqa: E402

REFERENCE = Path(__file__).resolve().parent / "data" / "reference_confirmation.json"

ROBOTS = ("planar", "delta", "linear_delta", "hexapod")


def _cases():
    out = []
    opts = [
        ("default", {}),
        ("noise-none", {"noise": "none"}),
        ("scale-only", {"noise": "scale-only"}),
        ("servo-only", {"noise": "servo-only"}),
        ("reweight0", {"reweight": 0}),
        ("warm-tsvd", {"warm_start": "tsvd"}),
        ("warm-given", {"warm_start": "half-truth"}),
        ("prior", {"prior": "half-truth"}),
        ("prior-std", {"prior_std": {"<measuring0>": 0.05}}),
        ("prior-cov", {"prior_cov": "diag"}),
        ("bounds-inactive", {"bounds": "wide"}),
        ("bounds-active", {"bounds": "tight"}),
        ("max-iter-0", {"max_iter": 0}),
        ("max-iter-2", {"max_iter": 2}),
        ("huber", {"loss": "huber"}),
        ("soft_l1", {"loss": "soft_l1", "loss_scale": 2.0}),
        ("fit-alpha", {"fit_alpha": 0.5}),
        ("offsets-only", {"params": "offsets"}),
    ]
    for robot in ("planar", "delta", "linear_delta"):
        for name, kw in opts:
            out.append((f"{robot}-{name}", robot, "scheme", "paper", "small", None, "nlls", kw))
        out.append((f"{robot}-far", robot, "scheme", "paper", "far", None, "nlls", {}))
        out.append((f"{robot}-far-max-iter-0", robot, "scheme", "paper", "far", None, "nlls", {"max_iter": 0}))
        out.append((f"{robot}-geometric", robot, "scheme", "paper", "geometric", None, "nlls", {}))
        out.append((f"{robot}-geometric-accept", robot, "scheme", "paper", "geometric", None, "nlls",
                    {"accept_misfit": True}))
        out.append((f"{robot}-bad", robot, 24, "scale-only", "small", (8, 0.5), "nlls", {}))
        out.append((f"{robot}-bad-accept", robot, 24, "scale-only", "small", (8, 0.5), "nlls", {"accept_misfit": True}))
        out.append((f"{robot}-bad-max-iter-3", robot, 24, "scale-only", "small", (8, 0.5), "nlls", {"max_iter": 3}))
        out.append((f"{robot}-bad-max-iter-0", robot, 24, "scale-only", "small", (8, 0.5), "nlls", {"max_iter": 0}))
        out.append((f"{robot}-bad-huber", robot, 24, "scale-only", "small", (8, 0.5), "nlls", {"loss": "huber"}))
        out.append((f"{robot}-clean-24", robot, 24, "paper", "small", None, "nlls", {}))
        out.append((f"{robot}-noisefree-data", robot, "scheme", "none", "small", None, "nlls", {"noise": "none"}))
        out.append((f"{robot}-all", robot, 40, "paper", "small", None, "nlls", {"params": "all"}))
        out.append((f"{robot}-tsvd", robot, "scheme", "paper", "small", None, "tsvd", {}))
        out.append((f"{robot}-tsvd-bad", robot, 24, "scale-only", "small", (8, 0.5), "tsvd", {}))
        out.append((f"{robot}-tsvd-geometric", robot, "scheme", "paper", "geometric", None, "tsvd", {}))
        out.append((f"{robot}-large-K", robot, 130, "paper", "small", None, "nlls", {}))
    # the hexapod's identifications take seconds each (its model is not expanded): the default of each method
    out.append(("hexapod-default", "hexapod", "scheme", "paper", "small", None, "nlls", {}))
    out.append(("hexapod-tsvd", "hexapod", "scheme", "paper", "small", None, "tsvd", {}))
    return out


CASES = _cases()


def robot_of(which):
    from zerocal_sym.model.robot import load_robot, paper_robot

    return paper_robot() if which == "planar" else load_robot(ROOT / "examples" / f"{which}.toml")


def truth_of(robot, kind):
    """The true source errors (rad, mm) of a case."""
    e = robot.errors
    m, u = len(e.zero_offsets), len(e.measuring)
    off = np.resize([0.5, -0.3, 0.2, -0.4, 0.3, -0.1], m) * (12.0 if kind == "far" else 1.0)
    v = e.put(e.zeros(), e.zero_offsets, off if e.offset_unit != "rad" else np.radians(off))
    v = e.put(v, e.measuring, np.resize([0.5, -0.2, 0.1, 0.3, -0.3, 0.2], u))
    if kind == "geometric":
        geo = [n for n in e.geometry if n not in e.zero_offsets and n not in e.measuring][:4]
        for k, n in enumerate(geo):
            v = e.put(v, [n], [(0.4 if e[n].unit != "rad" else np.radians(0.4)) * (-1) ** k])
    return v


def measurements(robot, poses, noise_name, truth, bad, seed=11):
    from zerocal_sym.cli._common import scheme_poses
    from zerocal_sym.model import kinematics as kin
    from zerocal_sym.model.measurements import Measurements
    from zerocal_sym.model.noise import NoiseModel, VirtualPlant

    rng = np.random.default_rng(seed)
    if poses == "scheme":
        P, _ = scheme_poses(robot)
    else:
        lo, hi = robot.workspace.bounds()
        P = lo + (hi - lo) * rng.random((8 * poses, len(lo)))
        P = P[robot.workspace.contains(P, -1.0)][:poses]
    th = kin.ik(robot, P)
    rd = VirtualPlant(robot, truth).measure(th, NoiseModel.named(noise_name, robot), rng)
    if bad is not None:
        rd[bad[0]] += bad[1]
    return Measurements(th, rd)


def keywords(robot, truth, kw) -> dict:
    """The case's keyword arguments with its symbolic values made concrete."""
    from zerocal_sym.model.noise import NoiseModel

    e = robot.errors
    kw = dict(kw)
    names = e.resolve(kw.get("params", "paper"))
    if "noise" in kw:
        kw["noise"] = NoiseModel.named(kw["noise"], robot)
    else:
        kw["noise"] = NoiseModel.named("paper", robot)
    if kw.get("warm_start") == "half-truth":
        kw["warm_start"] = 0.5 * e.take(truth, names)
    if kw.get("prior") == "half-truth":
        kw["prior"] = 0.5 * truth
    if "prior_std" in kw:
        kw["prior_std"] = {e.measuring[0]: 0.05}
    if kw.get("prior_cov") == "diag":
        kw["prior_cov"] = np.diag([(0.02 if e[n].unit == "rad" else 0.5) ** 2 for n in names])
    if kw.get("bounds") == "wide":
        kw["bounds"] = {n: (-1.0, 1.0) if e[n].unit == "rad" else (-20.0, 20.0) for n in names}
    elif kw.get("bounds") == "tight":  # the first zero offset bounded below its true value
        n0 = e.zero_offsets[0]
        t0 = float(e.take(truth, [n0])[0])
        kw["bounds"] = {n0: (-abs(t0), 0.5 * abs(t0))}
    return kw


def run_case(case) -> dict:
    from zerocal_sym.identify.nlls import identify_nlls
    from zerocal_sym.identify.tsvd import identify_tsvd

    cid, which, poses, noise_name, tkind, bad, method, kw = case
    robot = robot_of(which)
    truth = truth_of(robot, tkind)
    meas = measurements(robot, poses, noise_name, truth, bad)
    kw = keywords(robot, truth, kw)
    if method == "tsvd":
        noise = kw.pop("noise")
        res = identify_tsvd(robot, meas, noise=None if noise.is_zero else noise, **kw)
    else:
        res = identify_nlls(robot, meas, **kw)
    out = summary(res)
    out["K"] = int(meas.theta_cmd.shape[0])
    out["solver"] = _f({k: res.info.get(k) for k in ("solver_status", "iterations", "gauss_newton")})
    return out


def main():
    from reference_files import write_reference

    write_reference(REFERENCE, CASES, run_case, note=lambda r: r["status"][:100])


if __name__ == "__main__":
    main()
