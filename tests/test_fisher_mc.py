"""The Fisher information against Monte Carlo (loose tolerances, fixed seeds)."""
import numpy as np
import pytest

from zerocal_sym.identify import fisher
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors


@pytest.fixture(scope="module")
def th6(robot):
    return kin.ik(robot, paper_poses(robot, 3))


def test_measurement_covariance_matches_simulation(robot, th6):
    """Cov(s) with the servo error propagated vs the plant's simulated changes (3000 draws)."""
    noise = NoiseModel.paper()
    err = table2_errors(2)
    plant = VirtualPlant(robot, err)
    rng = np.random.default_rng(7)
    S = np.array([plant.measure(th6, noise, rng)[1:] for _ in range(3000)])
    C = fisher.measurement_covariance(robot, th6, noise, err)
    Ce = np.cov(S.T)
    np.testing.assert_allclose(np.sqrt(np.diag(Ce)), np.sqrt(np.diag(C)), rtol=0.05)
    R, Re = C / np.sqrt(np.outer(np.diag(C), np.diag(C))), Ce / np.sqrt(np.outer(np.diag(Ce), np.diag(Ce)))
    np.testing.assert_allclose(Re, R, atol=0.06)  # consecutive changes share a pose: rho ~ -0.5


@pytest.mark.parametrize("noise_name", ["paper", "scale-only"])
def test_fisher_inverse_matches_estimator_covariance(robot, th6, noise_name):
    """Empirical covariance of the ML estimates (400 trials) vs F^-1 at the truth."""
    noise = NoiseModel.named(noise_name)
    err = table2_errors(3, geometric=False)
    plant = VirtualPlant(robot, err)
    rng = np.random.default_rng(11)
    E, misfits = [], 0
    for _ in range(400):
        # every round counts: the fit check rejects clean rounds at its level alpha = 0.001
        res = identify_nlls(robot, Measurements(th6, plant.measure(th6, noise, rng)), noise=noise,
                            accept_misfit=True)
        assert res.success
        misfits += res.info["fit"]["rejected"]
        E.append(res.estimate - err[[0, 1, 10, 11]])
    assert misfits <= 3  # expected 0.4 of 400
    E = np.array(E)
    Ce = np.cov(E.T)
    C = np.linalg.inv(fisher.fisher_information(robot, th6, "paper", noise, err0=err))
    sd, sde = np.sqrt(np.diag(C)), np.sqrt(np.diag(Ce))
    np.testing.assert_allclose(sde, sd, rtol=0.15)
    np.testing.assert_allclose(Ce / np.outer(sde, sde), C / np.outer(sd, sd), atol=0.1)
    # unbiased within 4 standard errors
    assert np.all(np.abs(E.mean(axis=0)) < 4 * sd / np.sqrt(len(E)))


def test_crlb_paper_numbers(robot, th6):
    """SPEC: ~0.048 deg with the scale error alone, ~0.52 deg with the servo error too (at zero errors)."""
    full = fisher.crlb_zero_offsets_deg(robot, th6, "paper", NoiseModel.paper())
    scale = fisher.crlb_zero_offsets_deg(robot, th6, "paper", NoiseModel.paper(servo=0.0))
    assert full == pytest.approx([0.522, 0.522], abs=0.005)
    assert scale == pytest.approx([0.048, 0.048], abs=0.001)


def test_model_bias_matches_nonlinear_fit(robot, th6):
    err = table2_errors(4)
    e0 = err.copy()
    e0[2:10] = 0
    b = fisher.model_bias(robot, th6, err, "paper", err0=e0)
    res = identify_nlls(robot, Measurements(th6, VirtualPlant(robot, err).measure(th6)), noise=NoiseModel.paper())
    np.testing.assert_allclose(res.estimate - err[[0, 1, 10, 11]], b, rtol=1e-3, atol=1e-9)
