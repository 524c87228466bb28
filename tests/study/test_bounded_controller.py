"""The study hook of the bounded HJI controller: trained with the UPQC rating as the bound."""

import numpy as np
import pytest

from weakgrid.game import ParameterError
from weakgrid.models import load_preset
from weakgrid.study.controllers import make_controller


def test_hji_bounded_uses_the_rating_and_respects_it():
    p = load_preset("case2-paper")
    ch = make_controller("hji-bounded", "case2-lv-microgrid", p.system, u_bound=0.1)
    assert ch.info["u_bound"] == {"shape": "disk", "limit": [0.1]}
    X = p.mesh.points
    assert np.hypot(*ch.policy(X).T).max() <= 0.1
    # an unbounded trained controller in the cache is not taken for the bounded one
    free = p.train()
    ch2 = make_controller("hji-bounded", "case2-lv-microgrid", p.system, trained=free,
                          u_bound=0.1)
    assert np.hypot(*ch2.policy(X).T).max() <= 0.1
    with pytest.raises(ParameterError, match="rating"):
        make_controller("hji-bounded", "case2-lv-microgrid", p.system)
