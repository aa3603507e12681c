import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci")
os.environ.setdefault("MPLBACKEND", "Agg")
# the compiled tier (zerocal_sym.model.compiled) would start C compilers in the background of every Monte Carlo
# test on a fresh machine; the tests run interpreted unless asked (tests/test_compiled.py checks the compiled
# Functions against the interpreted ones, bit for bit, in a temporary cache)
os.environ.setdefault("ZEROCAL_COMPILE", "never")


@pytest.fixture(scope="session")
def robot():
    from zerocal_sym.model.robot import paper_robot

    return paper_robot()


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
