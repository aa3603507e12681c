"""The fit check's second test: the largest |standardised residual| over the K - 1 readings (Sidak), beside the
chi².  One reading far off among many hides in the chi² (the more so under a noise model that overstates the
noise); the second test refuses it and names it, for both methods, every mechanism, in the lean rounds of the
loops and in the batch; a robust fit is tested on the readings it kept."""
import decimal
import functools
import math
from pathlib import Path

import numpy as np
import pytest

from zerocal_sym.identify.batch import identify_batch
from zerocal_sym.identify.check.max_reading import max_p_value, max_p_values
from zerocal_sym.identify.chi2 import chi2_sf
from zerocal_sym.identify.fitcheck import fit_check
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.identify.nlls_rounds import identify_rounds
from zerocal_sym.identify.tsvd import identify_tsvd
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.model.robot import load_robot
from roundoff import cond_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ALPHA = 1e-3
#: mechanism -> robot file
FILES = {"planar_2dof": "paper_robot.toml", "delta_rotary": "delta.toml", "delta_linear": "linear_delta.toml",
         "hexapod": "hexapod.toml"}
#: poses per round: above the chi²'s reach of one reading 8 sigma off under a noise model 3 x too large
#: (chi2 ~ (K-1)/9 + 64 on ~K-1-p dof passes; the largest of K-1 normals at 8 sigma has p ~ K 1e-15), and
#: within the expanded CasADi functions (the lean rounds' range)
K = 100


class Round:
    """K random poses inside the workspace of a mechanism's example robot, measured with its own noise; the
    identifications use that noise overstated 3 x."""

    def __init__(self, mech, seed=7, K=K):
        self.robot = robot = load_robot(EXAMPLES / FILES[mech])
        e = robot.errors
        self.truth = e.from_user({**dict(zip(e.zero_offsets, (0.5, -0.3, 0.2, 0.1, -0.1, 0.2))),
                                  **dict(zip(e.measuring, (0.5, -0.2, 0.1)))})
        rng = np.random.default_rng(seed)
        lo, hi = robot.workspace.bounds()
        P = lo + (hi - lo) * rng.random((20 * K, len(lo)))
        P = P[robot.workspace.contains(P, 0.0)][:K]
        assert P.shape[0] == K
        self.theta = kin.ik(robot, P)
        self.noise = NoiseModel.of_robot(robot)
        self.stated = self.noise.scaled(3.0, 3.0)
        self.readings = VirtualPlant(robot, self.truth).measure(self.theta, self.noise, rng)

    def meas(self, pose=None, mm=0.0):
        rd = self.readings.copy()
        if pose is not None:
            rd[pose] += mm
        return Measurements(self.theta, rd)

    @functools.cached_property
    def clean(self):
        """The clean round identified (nlls, the stated noise)."""
        return identify_nlls(self.robot, self.meas(), noise=self.stated)

    def sd_mm(self, pose):
        """The standard deviation (mm) of reading ``pose``'s estimated error under the stated noise (the clean
        round's)."""
        r = self.clean.info["fit"]["readings"][pose - 1]
        return r["estimated_error_mm"] / r["standardised"]


@functools.lru_cache(maxsize=None)
def _round(mech):
    return Round(mech)


#: the hexapod's identification takes ~2 s at K = 100: slow-marked, and in the first test only
EVERY = [pytest.param(m, marks=pytest.mark.slow) if m == "hexapod" else m for m in FILES]
FAST = [m for m in FILES if m != "hexapod"]


def test_sidak_p_value():
    """One reading: the two-sided normal tail; n readings: 1 - (1 - q)^n, without cancellation for small q;
    beyond the doubles' tail: 0."""
    assert max_p_value(1.959963984540054, 1) == pytest.approx(0.05, rel=1e-12)
    q = decimal.Decimal(math.erfc(5.0 / math.sqrt(2.0)))
    with decimal.localcontext() as ctx:
        ctx.prec = 60
        exact = float(1 - (1 - q) ** 1000)
    assert max_p_value(5.0, 1000) == pytest.approx(exact, rel=1e-12)
    assert max_p_value(40.0, 10**6) == 0.0 and max_p_value(0.0, 10) == 1.0 and max_p_value(3.0, 0) == 1.0
    np.testing.assert_array_equal(max_p_values([5.0, np.nan], [1000, 3]), [max_p_value(5.0, 1000), np.nan])


@pytest.mark.parametrize("mech", EVERY)
def test_one_reading_far_off_among_many_is_refused_and_named(mech):
    """8 sigma (of the stated noise) on the reading at pose 37: the chi² passes, the largest standardised residual
    rejects, naming pose 37 with its error, through both methods; the clean round passes both tests."""
    rnd = _round(mech)
    clean = rnd.clean
    fit = clean.info["fit"]
    assert clean.success and not fit["rejected"] and fit["max_reading"]["p_value"] >= ALPHA, clean.status
    assert fit["max_reading"]["readings"] == K - 1 and fit["max_reading"]["correction"] == "sidak"
    bad = 8.0 * rnd.sd_mm(37)
    m = rnd.meas(37, bad)
    for res in (identify_nlls(rnd.robot, m, noise=rnd.stated), identify_tsvd(rnd.robot, m, noise=rnd.stated)):
        fit = res.info["fit"]
        mr = fit["max_reading"]
        assert not res.success and fit["rejected"] and not fit["chi2_rejected"], res.status
        assert fit["p_value"] >= ALPHA and mr["rejected"] and mr["p_value"] < ALPHA
        assert mr["pose"] == 37 and mr["from_pose"] == 36
        assert mr["p_value"] == pytest.approx(max_p_value(abs(mr["standardised"]), K - 1), rel=1e-12)
        cause = fit["causes"][0]
        assert cause["cause"] == "bad reading" and cause["detected"] and cause["pose"] == 37
        # its estimated error: within 4 sd of the stated noise (the data's own noise is 3 x smaller)
        assert cause["estimated_error_mm"] == pytest.approx(bad, abs=4.0 * bad / 8.0)
        assert res.status.startswith("rejected: the noise model rejects the fit (one reading: standardised "
                                     "residual") and "passes; likely: the reading at pose 37 (the change from " \
                                     "pose 36 to pose 37) is off by about" in res.status, res.status
        assert res.to_dict()["fit"]["max_reading"]["pose"] == 37


@pytest.mark.parametrize("mech", FAST)
def test_accept_misfit_and_the_fit_check_recomputed(mech):
    """accept_misfit keeps the round of the test above, saying which test rejected it; fit_check recomputes the
    same verdict."""
    rnd = _round(mech)
    m = rnd.meas(37, 8.0 * rnd.sd_mm(37))
    kept = identify_nlls(rnd.robot, m, noise=rnd.stated, accept_misfit=True)
    assert kept.success and kept.status.startswith("accepted despite misfit (one reading")
    again = fit_check(rnd.robot, m, kept, diagnose=False)
    assert again["max_reading"]["pose"] == 37 and again["rejected"] and again["causes"][0]["pose"] == 37


@pytest.mark.parametrize("mech", FAST)
def test_a_robust_fit_is_tested_on_the_readings_it_kept(mech):
    """20 sigma on pose 37: the l2 fit is refused naming pose 37; huber and soft_l1 leave out that very reading,
    and the largest standardised residual of the readings they kept passes."""
    rnd = _round(mech)
    m = rnd.meas(37, 20.0 * rnd.sd_mm(37))
    l2 = identify_nlls(rnd.robot, m, noise=rnd.stated)
    assert not l2.success and l2.info["fit"]["max_reading"]["pose"] == 37 and "pose 37" in l2.status
    for loss in ("huber", "soft_l1"):
        res = identify_nlls(rnd.robot, m, noise=rnd.stated, loss=loss)
        fit = res.info["fit"]
        assert res.success and res.info["robust"]["excluded_readings"] == [37], res.status
        assert not fit["rejected"] and fit["max_reading"]["readings"] == K - 2 and fit["max_reading"]["pose"] != 37
        assert fit["max_reading"]["p_value"] >= ALPHA


def test_a_reading_the_loss_kept_is_refused_saying_so():
    """The planar robot, 0.1 mm on pose 50 (K = 150, the noise stated 3 x): huber down-weights the reading but keeps
    it (weight >= 0.25), and the largest standardised residual rejects the fit: the paragraph says so."""
    rnd = Round("planar_2dof", K=150)
    res = identify_nlls(rnd.robot, rnd.meas(50, 0.1), noise=rnd.stated, loss="huber")
    fit = res.info["fit"]
    assert res.info["robust"]["excluded_readings"] == [] and 0.25 <= res.info["robust"]["weights"][49] < 1
    assert not res.success and fit["max_reading"]["pose"] == 50 and not fit["chi2_rejected"], res.status
    assert "The huber loss down-weighted the reading at pose 50" in fit["diagnosis"]


@pytest.mark.parametrize("mech", FAST)
def test_lean_rounds_and_the_batch_give_the_same_verdict(mech):
    """identify_rounds (the loops' mapped Gauss-Newton) refuses the round as identify_nlls does; identify_batch
    gives the same p-value of the largest standardised residual (to the Gauss-Newton tolerance: its point is
    the last Gauss-Newton step, identify_nlls's Ipopt's)."""
    rnd = _round(mech)
    rounds = [rnd.meas(), rnd.meas(37, 8.0 * rnd.sd_mm(37))]
    names = rnd.robot.errors.resolve("paper")
    prior = [rnd.robot.errors.zeros()] * 2
    lean = identify_rounds(rnd.robot, rounds, prior, names, rnd.stated)
    for m, res in zip(rounds, lean):
        ref = identify_nlls(rnd.robot, m, names, noise=rnd.stated)
        assert res.success == ref.success and res.info["fit"]["rejected"] == ref.info["fit"]["rejected"]
        assert res.info["fit"]["max_reading"]["p_value"] == ref.info["fit"]["max_reading"]["p_value"]
        assert res.status.split(" (")[0] == ref.status.split(" (")[0]
    assert lean[0].success and not lean[1].success and "one reading" in lean[1].status
    b = identify_batch(rnd.robot, rnd.theta, np.array([m.readings for m in rounds]), names, noise=rnd.stated)
    assert b.p_value_max.shape == (2,) and list(b.rejected(ALPHA)) == [False, True]
    for i, m in enumerate(rounds):
        ref = identify_nlls(rnd.robot, m, names, noise=rnd.stated, accept_misfit=True).info["fit"]
        assert b.p_value[i] == pytest.approx(ref["p_value"], rel=1e-5)
        assert b.p_value_max[i] == pytest.approx(ref["max_reading"]["p_value"], rel=1e-5)


def test_one_spare_degree_of_freedom_max_test_adds_nothing():
    """With one spare degree of freedom every |t_k| is sqrt(chi2) (I - H has rank 1): Sidak's p is above the
    chi²'s, so the second test never rejects what the chi² accepts."""
    rnd = Round("planar_2dof", seed=1, K=6)
    m = rnd.meas(3, 0.05)
    res = identify_nlls(rnd.robot, m, noise=rnd.noise, accept_misfit=True)
    fit = fit_check(rnd.robot, m, res, diagnose=False)  # (numpy's bidiagonal solves, as whitened.py states them)
    assert fit["dof"] == 1
    for r in fit["readings"]:  # a^T (I - H) a cancels to 1 - leverage of a^T a: round-off / (1 - leverage)
        tol = cond_tol(1.0 / (1.0 - r["leverage"]), 10 * len(fit["readings"]))
        assert abs(r["standardised"]) == pytest.approx(math.sqrt(fit["chi2"]), rel=tol)
    assert fit["max_reading"]["p_value"] >= fit["p_value"] == pytest.approx(chi2_sf(fit["chi2"], 1))
    assert res.info["fit"]["max_reading"]["p_value"] >= res.info["fit"]["p_value"]


def test_the_report_and_the_verdict_line_say_which_test():
    """A results file's fit record with the second test's rejection (kept by --accept-misfit): the report reads it
    (a wrong type is an error naming the key), its fit-check section and the verdict line name the reading."""
    from types import SimpleNamespace

    from zerocal_sym.cli._identify_text import accepted_why
    from zerocal_sym.errors import DataFileError
    from zerocal_sym.report.contents import fit_record
    from zerocal_sym.report.html import _fit

    fit = {"chi2": 1302.2, "dof": 1995, "p_value": 1.0, "alpha": 1e-3, "checked": True, "rejected": True,
           "chi2_rejected": False, "accepted_despite_misfit": True, "diagnosis": "The noise model rejects this fit.",
           "max_reading": {"pose": 700, "from_pose": 699, "standardised": 32.94, "readings": 1999,
                           "p_value": 1.06e-234, "rejected": True}}
    rec = fit_record(SimpleNamespace(raw={"fit": fit}, source="r.json"))
    assert rec["max_reading"] == {"pose": 700.0, "standardised": 32.94, "readings": 1999.0, "p_value": 1.06e-234,
                                  "rejected": True}
    html = _fit({"fit": rec}, None)
    assert 'id="max-reading"' in html and "pose 700</strong>" in html and "1999" in html
    assert accepted_why(rec, 1e-3) == ("accepted despite misfit (--accept-misfit; the largest standardised "
                                       "residual's p-value 1.06e-234 < 0.001, at pose 700)")
    with pytest.raises(DataFileError, match="max_reading"):
        fit_record(SimpleNamespace(raw={"fit": {**fit, "max_reading": [700]}}, source="r.json"))


def test_with_the_revisits_shared_error():
    """The poses visited twice with a shared revisit error in the noise model (the full covariance, not the bands):
    the same refusal, naming the reading, its error from the exact refit without it, both methods."""
    rnd = _round("planar_2dof")
    theta = np.concatenate([rnd.theta, rnd.theta])
    noise = NoiseModel(rnd.noise.sigma_scale_mm, rnd.noise.sigma_joint, 0.002)
    rd = VirtualPlant(rnd.robot, rnd.truth).measure(theta, noise, np.random.default_rng(2))
    rd[37] += 0.15
    m = Measurements(theta, rd)
    for res in (identify_nlls(rnd.robot, m, noise=noise.scaled(3, 3, 3)),
                identify_tsvd(rnd.robot, m, noise=noise.scaled(3, 3, 3))):
        fit = res.info["fit"]
        assert not res.success and not fit["chi2_rejected"] and fit["max_reading"]["pose"] == 37, res.status
        # (the stated noise puts ~0.015 mm on the estimated error: t ~ 10 for 0.15 mm; 0.03 mm is 2 of it)
        assert fit["causes"][0]["pose"] == 37 and fit["causes"][0]["estimated_error_mm"] == pytest.approx(0.15, abs=0.03)
