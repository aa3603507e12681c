"""Designs that can see what they assume: the fit check's power per design, and the checked design.

The K = 6 crlb-optimal design of the paper's robot leaves one spare degree of freedom and mirror-symmetric
poses: a robot file with every length 2 % short, or the poses visited in reverse, fit it.  The checked
design (the default) has the fit check reject both.
"""
import json
import math

import numpy as np
import pytest

from zerocal_sym import design
from zerocal_sym.cli import main
from zerocal_sym.design import power as pw
from zerocal_sym.design.detection import Requirement, detection
from zerocal_sym.identify.estimate.exact_model import _Exact
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import VirtualPlant

#: the issue's truth: offsets 0.156 / -1.859 deg, MAEMM (1, 0.5) mm
TRUTH = {"theta1": math.radians(0.156), "theta2": math.radians(-1.859), "rMx": 1.0, "rMy": 0.5}


@pytest.fixture(scope="module")
def designs(robot):
    """The default (checked) and the crlb-optimal K = 6 designs, default settings."""
    return (design.optimize_design(robot, 6, "checked", certificate=False),
            design.optimize_design(robot, 6, "crlb", certificate=False))


def _rounds(robot, P, seed):
    """Two wrong-data identifications of the design P: a robot file 2 % short, the poses visited in reverse."""
    plant = VirtualPlant(robot, TRUTH)
    short = pw.lengths_scaled(robot, 0.98)
    th = kin.ik(short, P)  # the controller commands what the wrong file says
    a = identify_nlls(short, Measurements(theta_cmd=th, readings=plant.measure(th, robot.noise, seed), target=P,
                                          meta={}, source="short"), noise=robot.noise)
    th = kin.ik(robot, P)
    rd = plant.measure(th[::-1], robot.noise, seed)  # visited in reverse, read against the file's order
    b = identify_nlls(robot, Measurements(theta_cmd=th, readings=rd, target=P, meta={}, source="rev"),
                      noise=robot.noise)
    return a, b


# ----------------------------------------------------------------- the non-central chi²
def test_noncentral_chi2_against_scipy():
    """ncx2_sf, chi2_isf and required_noncentrality against scipy (a Poisson mixture of chi2_sf terms, each
    ~1e-14 relative: 1e-10 absolute)."""
    from scipy import stats

    for x, dof, lam in [(10.83, 1, 20.9), (3.0, 4, 0.5), (37.7, 15, 40.0), (200.0, 100, 150.0), (10.0, 2, 0.0),
                        (50.0, 3, 5000.0)]:
        assert pw.ncx2_sf(x, dof, lam) == pytest.approx(stats.ncx2.sf(x, dof, lam) if lam else stats.chi2.sf(x, dof),
                                                        abs=1e-10)
    for a, dof in [(1e-3, 1), (1e-3, 15), (0.05, 7)]:
        assert pw.chi2_isf(a, dof) == pytest.approx(stats.chi2.isf(a, dof), rel=1e-10)
        lam = pw.required_noncentrality(dof, a, 0.9)
        assert stats.ncx2.sf(stats.chi2.isf(a, dof), dof, lam) == pytest.approx(0.9, abs=1e-8)
    assert pw.power(1e6, 0) == 0.0  # no spare degree of freedom: the check cannot run


def test_noncentrality_is_the_exact_fits_chi2_to_first_order(robot, designs):
    """lambda (first order) against the chi² of the exact model's fit to the noise-free wrong readings: every
    length off by 0.1 % and 0.01 %; the difference is second order (falls tenfold with the size)."""
    P = designs[0].poses
    th = kin.ik(robot, P)
    err = []
    for f in (1e-3, 1e-4):
        d = detection(robot, P, requirement=Requirement(robot, scale_error=f))
        lam = next(s["noncentrality"] for s in d["scenarios"] if s["name"] == "scale")
        rd = np.concatenate([[0.0], np.diff(kin.distance(pw.lengths_scaled(robot, 1 + f), th))])
        chi2, dof = _Exact(robot, th, rd, robot.errors.resolve("paper"), robot.errors.zeros(),
                           robot.noise).chi2_fit()
        assert dof == 1
        err.append(abs(chi2 / lam - 1))
    assert err[1] < err[0] / 5 and err[0] < 0.05, err


# ----------------------------------------------------------------- the K = 6 designs of the paper's robot
def test_crlb_design_fits_wrong_data_checked_design_refuses_it(robot, designs):
    """The crlb-optimal design accepts a robot file 2 % short and the reversed order, offsets many sigma off;
    the checked design (the default) rejects both, at a few per cent of CRLB."""
    checked, crlb = designs
    dc, d0 = checked.report["detection"], crlb.report["detection"]
    assert dc["meets"] and not d0["meets"]
    assert {"reversed", "scale"} <= set(d0["unmet"]) and d0["power"]["reversed"] < 2 * d0["alpha"]
    assert dc["power"]["reversed"] > 0.999 and dc["power"]["scale_error"] >= 0.9
    cost = checked.checked["cost"]
    assert cost == pytest.approx(checked.report["crlb_rms_deg"] / crlb.report["crlb_rms_deg"])
    assert 1 <= cost < 1.1
    for seed in range(3):
        short, rev = _rounds(robot, crlb.poses, seed)
        for res in (short, rev):
            assert res.success and not res.info["fit"]["rejected"]
            z = np.abs(res.zero_offsets - [TRUTH["theta1"], TRUTH["theta2"]]) / [res.std("theta1"), res.std("theta2")]
            assert z.max() > 3  # a confident wrong answer (the reversed order swaps the offsets: 4.4 sigma)
        short, rev = _rounds(robot, checked.poses, seed)
        for res in (short, rev):
            assert not res.success and res.info["fit"]["rejected"], res.status


def test_design_json_reports_each_designs_detection(capsys):
    """`design --json`: the fit check's power for the design and the baseline, per scenario."""
    rc = main(["design", "--optimize", "--K", "6", "--criterion", "crlb", "--starts", "1", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0
    for x in (d["detection"], d["paper"]["detection"]):
        assert x["dof"] == 1 and x["alpha"] == 1e-3
        assert set(x["power"]) == {"entries_at_tolerance", "scale_error", "reversed", "swaps", "bad_reading"}
        names = {s["name"] for s in x["scenarios"]}
        assert {"L1", "scale", "reversed", "swap0", "reading1"} <= names
        assert all(0 <= s["power"] <= 1 for s in x["scenarios"])
        assert x["invisible_entries"] == ["e1y", "e2y"]  # the gauge: absorbed by the MAEMM on every design
    assert d["paper"]["detection"]["power"]["reversed"] > 0.999
    assert "reversed" in d["detection"]["unmet"]
    assert main(["design", "--scheme", "paper", "--json"]) == 0  # the boundary scheme's report too
    x = json.loads(capsys.readouterr().out)["detection"]
    assert x["power"] == d["paper"]["detection"]["power"]  # the same six poses as the baseline


def test_checked_needs_a_spare_degree_of_freedom(robot, capsys):
    with pytest.raises(design.DesignError, match="no spare degree of freedom"):
        design.optimize_design(robot, 5, "checked")
    assert main(["design", "--optimize", "--K", "6", "--power", "1.5"]) == 2
    assert "power" in capsys.readouterr().err
