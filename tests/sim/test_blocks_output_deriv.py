"""``output_deriv`` of the lead-lag and washout blocks: the very values of ``output`` and
``deriv`` (the devices' residuals call it, so results stay bit for bit those of the two calls)."""

import numpy as np
import pytest

from weakgrid.sim.blocks import LeadLag, Washout, WashoutBypass, WashoutOrLag


def _blocks():
    on = [0.3, 1.5, 0.02]
    off = [0.3, 0.0, 0.02]            # one time constant zero: the np.where path
    return [("leadlag", LeadLag([0.1, 0.5, 2.0], on)),
            ("leadlag gain", LeadLag([0.1, 0.5, 2.0], on, K=[1.0, 2.5, -0.7])),
            ("leadlag bypassed", LeadLag([0.1, 0.5, 2.0], off, K=[1.0, 2.5, -0.7])),
            ("washout", Washout([0.2, 3.0, 0.5], on)),
            ("washout off", Washout([0.2, 3.0, 0.5], off)),
            ("washout bypass", WashoutBypass(on)),
            ("washout bypass off", WashoutBypass(off)),
            ("washout or lag", WashoutOrLag([0.2, 0.0, 0.5], on)),
            ("washout or lag all", WashoutOrLag([0.2, 3.0, 0.5], on))]


@pytest.mark.parametrize("name,block", _blocks(), ids=[n for n, _ in _blocks()])
def test_output_deriv_is_output_and_deriv(name, block):
    rng = np.random.default_rng(1)
    x, u = rng.normal(size=(2, 7, 3))      # a batch of 7 points of 3 instances
    y, dx = block.output_deriv(x, u)
    assert np.array_equal(y, block.output(x, u))
    assert np.array_equal(dx, block.deriv(x, u))
