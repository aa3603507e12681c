import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def robot():
    from zerocal_sym.model.robot import paper_robot

    return paper_robot()


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
