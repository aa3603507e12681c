"""What identify_batch and identify_nlls say about bad input: the argument, the data set (row) and the pose."""
import types

import numpy as np
import pytest

from zerocal_sym.errors import IdentificationError
from zerocal_sym.identify import batch
from zerocal_sym.identify.batch import identify_batch
from zerocal_sym.identify.nlls import identify_nlls
from zerocal_sym.model import kinematics as kin
from zerocal_sym.model.measurements import Measurements
from zerocal_sym.model.noise import NoiseModel, VirtualPlant
from zerocal_sym.paper.scheme import paper_poses
from zerocal_sym.paper.tables import table2_errors
from roundoff import FLOORS, estimate_floor


@pytest.fixture(scope="module")
def th6(robot):
    return kin.ik(robot, paper_poses(robot, 3))


@pytest.fixture(scope="module")
def R(robot, th6):
    """Four noisy data sets of the paper's 6 poses, shape (4, 6)."""
    plant = VirtualPlant(robot, table2_errors(1))
    return np.array([plant.measure(th6, NoiseModel.paper(), k) for k in range(4)])


@pytest.fixture
def no_work(monkeypatch):
    """identify_batch must refuse before it builds or fetches the problem."""
    def fail(*a, **k):
        raise AssertionError("identify_batch started work on bad input")

    monkeypatch.setattr(batch, "get_problem", fail)


# ----------------------------------------------------------------------------- shapes
@pytest.mark.parametrize("bad, got", [(lambda R: R.T, r"\(6, 4\) \(transposed\?"),
                                      (lambda R: R[:, :5], r"\(4, 5\)$"),
                                      (lambda R: np.array([]), r"\(0,\)$"),
                                      (lambda R: R[None], r"\(1, 4, 6\)$")],
                         ids=["transposed", "K=5", "empty", "3-D"])
def test_readings_of_the_wrong_shape_blame_readings(robot, th6, R, no_work, bad, got):
    with pytest.raises(ValueError, match=r"^readings must have shape \(N, K\) = \(N, 6\) for the 6 poses of "
                                         r"theta_cmd \(one row per data set\), got " + got):
        identify_batch(robot, th6, bad(R))


@pytest.mark.parametrize("bad, got", [(lambda th: th.T, r"\(2, 6\) \(transposed\?"),
                                      (lambda th: th[:, :1], r"\(6, 1\)$"),
                                      (lambda th: th[0], r"\(2,\)$")],
                         ids=["transposed", "one column", "one pose"])
def test_theta_cmd_of_the_wrong_shape_blames_theta_cmd(robot, th6, R, no_work, bad, got):
    with pytest.raises(ValueError, match=r"^theta_cmd must have shape \(K, m\) = \(K, 2\), the 2 commanded joint "
                                         r"angles of robot .* got " + got):
        identify_batch(robot, bad(th6), R)


def test_identify_nlls_blames_the_mismatched_array(robot, th6, R):
    """A Measurements checks its shapes when made; a changed or hand-made one is checked again here."""
    m = types.SimpleNamespace(theta_cmd=th6, readings=R[0, :5], source="round.csv")
    with pytest.raises(IdentificationError, match=r"^round.csv: readings must have shape \(K,\) = \(6,\) for the 6 "
                                                  r"poses of theta_cmd, got \(5,\)$"):
        identify_nlls(robot, m)
    m = types.SimpleNamespace(theta_cmd=th6[:, :1], readings=R[0], source="round.csv")
    with pytest.raises(IdentificationError, match=r"theta_cmd must have shape \(K, m\) = \(K, 2\).* got \(6, 1\)$"):
        identify_nlls(robot, m)


# ----------------------------------------------------------------------------- noise by name
def test_noise_by_name_is_the_named_model(robot, th6, R):
    """The CLI's --noise names, in the batch and the single path: the very numbers of NoiseModel.named."""
    b = identify_batch(robot, th6, R[:2], noise="scale-only")
    ref = identify_batch(robot, th6, R[:2], noise=NoiseModel.named("scale-only"))
    assert b.success.all()
    np.testing.assert_array_equal(b.estimate, ref.estimate)
    np.testing.assert_array_equal(b.p_value, ref.p_value)
    one = identify_nlls(robot, Measurements(th6, R[0]), noise="scale-only")
    assert one.info["noise"] == {"sigma_scale_mm": NoiseModel.named("scale-only").sigma_scale_mm,
                                 "sigma_servo_rad": 0.0}
    # two solvers of one problem: within twice FLOORS of its round-off floor (tests/roundoff.py)
    floor = estimate_floor(robot, th6, "paper", "scale-only", one.full_vector())
    assert np.all(np.abs(one.estimate - b.estimate[0]) <= 2 * FLOORS * floor)


def test_noise_names_are_the_cli_and_study_names():
    from zerocal_sym.cli import build_parser
    from zerocal_sym.cli.study_spec import NAMED_NOISE
    from zerocal_sym.model.noise import NOISE_NAMES

    assert NAMED_NOISE == NOISE_NAMES
    sub = next(a for a in build_parser()._actions if a.choices and "identify" in a.choices)
    noise = next(a for a in sub.choices["identify"]._actions if "--noise" in a.option_strings)
    assert tuple(noise.choices) == NOISE_NAMES
    for name in NOISE_NAMES:
        assert NoiseModel.coerce(name) == NoiseModel.named(name)
    assert NoiseModel.coerce(None) == NoiseModel.paper()


@pytest.mark.parametrize("noise, exc, msg", [("papr", ValueError, r"^noise: unknown noise model 'papr' \(known: "
                                                                    r"paper, scale-only, servo-only, none\)$"),
                                             (0.5, TypeError, r"^noise must be a NoiseModel, one of the names paper, "
                                                              r"scale-only, servo-only, none or None .* got 0\.5 "
                                                              r"\(float\); .*NoiseModel\.paper\(f, f\)$")],
                         ids=["unknown name", "number"])
def test_a_bad_noise_says_what_to_pass(robot, th6, R, no_work, noise, exc, msg):
    with pytest.raises(exc, match=msg):
        identify_batch(robot, th6, R, noise=noise)
    with pytest.raises(exc, match=msg):
        identify_nlls(robot, Measurements(th6, R[0]), noise=noise)


# ----------------------------------------------------------------------------- non-finite values
def test_non_finite_readings_name_the_data_sets_and_poses(robot, th6, R, no_work):
    bad = R.copy()
    bad[1, 2], bad[3, 4], bad[3, 2] = np.nan, np.inf, np.nan
    with pytest.raises(ValueError, match=r"^readings must be finite: 3 NaN or inf value\(s\) in data set\(s\) "
                                         r"\(row\) 1, 3 at pose\(s\) \(column\) 2, 4; the first: "
                                         r"readings\[1, 2\] = nan$"):
        identify_batch(robot, th6, bad)


def test_non_finite_theta_cmd_names_the_pose(robot, th6, R, no_work):
    th = th6.copy()
    th[3, 1] = np.inf
    with pytest.raises(ValueError, match=r"^theta_cmd must be finite: NaN or inf joint angles at pose\(s\) 3 "):
        identify_batch(robot, th, R)


def test_identify_nlls_refuses_non_finite_values_before_ipopt(robot, th6, R):
    m = Measurements(th6, R[0].copy())
    m.readings[[2, 5]] = np.nan
    with pytest.raises(IdentificationError, match=r"^readings must be finite: NaN or inf at pose\(s\) "
                                                  r"2, 5$"):
        identify_nlls(robot, m)
    m = Measurements(th6.copy(), R[0])
    m.theta_cmd[4, 0] = np.nan
    with pytest.raises(IdentificationError, match=r"theta_cmd \(commanded joint angles\) must be finite: NaN or "
                                                  r"inf at pose\(s\) 4$"):
        identify_nlls(robot, m)


# ----------------------------------------------------------------------------- too few readings; readings[:, 0]
def test_fewer_changes_than_parameters_is_an_error(robot, th6, R, no_work):
    """identify_nlls (which may have a Gaussian prior) reports such a fit as not identifiable; the batch has no
    prior, so every data set would be: refused, in the CLI's words."""
    with pytest.raises(IdentificationError, match=r"^6 poses give 5 measured changes: fewer than the 12 parameters "
                                                  r"theta1, .*, rMy: every data set would be rank deficient"):
        identify_batch(robot, th6, R, "all")


def test_the_first_reading_is_not_used(robot, th6, R):
    """Documented (not refused), as identify_nlls: only the K - 1 changes readings[:, 1:] enter."""
    shifted = R[:2].copy()
    shifted[:, 0] = [1.0, -3.0]
    np.testing.assert_array_equal(identify_batch(robot, th6, shifted).estimate,
                                  identify_batch(robot, th6, R[:2]).estimate)


def test_nonfinite_fail_leaves_those_data_sets_failed_and_the_rest_unchanged(robot, th6, R):
    """Monte Carlo callers (a simulated pose the robot cannot reach reads NaN) count such data sets as failed."""
    Rb = R.copy()
    Rb[[1, 3], 2] = np.nan
    full = identify_batch(robot, th6, R, noise="paper")
    b = identify_batch(robot, th6, Rb, noise="paper", nonfinite="fail")
    keep = np.array([i not in (1, 3) for i in range(len(R))])
    assert not b.success[~keep].any() and not b.confirmed[~keep].any() and np.isnan(b.estimate[~keep]).all()
    np.testing.assert_array_equal(b.estimate[keep], full.estimate[keep])
    np.testing.assert_array_equal(b.p_value[keep], full.p_value[keep])
    assert b.success[keep].all() and b.dof == full.dof
    allbad = identify_batch(robot, th6, np.full_like(R, np.nan), noise="paper", nonfinite="fail")
    assert allbad.estimate.shape == R.shape[:1] + (4,) and not allbad.success.any()
    with pytest.raises(ValueError, match="nonfinite must be"):
        identify_batch(robot, th6, R, noise="paper", nonfinite="skip")


def test_identify_nlls_says_what_meas_must_be(robot, th6, R):
    with pytest.raises(TypeError, match="Measurements"):
        identify_nlls(robot, (th6, R[0]))
    bad = R[0].copy()
    bad[2] = np.nan
    with pytest.raises(IdentificationError) as info:
        identify_nlls(robot, Measurements(th6, bad))
    assert not str(info.value).startswith("<memory>")  # an object in memory is not a file to name


@pytest.mark.parametrize("scale, servo", [(-1.0, 1.0), (1.0, -0.5), (np.nan, 1.0), (1.0, np.inf)])
def test_a_noise_model_is_finite_and_non_negative(scale, servo):
    with pytest.raises(ValueError, match="finite standard deviation >= 0"):
        NoiseModel.paper(scale, servo)
