import os

import numpy as np
import pytest
from hypothesis import settings

settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True)
settings.register_profile("dev", max_examples=40, deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")


@pytest.fixture(scope="session")
def trained_presets():
    """Both presets trained once per session (δu = δw = 1e-7)."""
    from weakgrid.models import load_preset

    out = {}
    for name in ("case1-paper", "case2-paper"):
        p = load_preset(name)
        out[name] = (p, p.train())
    return out


@pytest.fixture
def rng():
    return np.random.default_rng(20151)
