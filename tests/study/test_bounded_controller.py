"""The study hook of the bounded HJI controller: trained with the UPQC rating as the bound."""

import numpy as np

from weakgrid.models import load_preset
from weakgrid.study.controllers import make_controller
from weakgrid.study.studyfile import load_study


def _study(**values):
    st = load_study("case2-lv-microgrid")
    compare = list(st.controllers) + ["hji-bounded"]
    return st.with_values(**{"controllers.compare": compare}, **values)


def test_hji_bounded_uses_the_rating_and_respects_it():
    p = load_preset("case2-paper")
    st = _study()
    ubar = st.data["upqc"]["rating"]
    ch = make_controller(st, "hji-bounded", p.system)
    assert ch.info["u_bound"] == {"shape": "disk", "limit": [ubar]}
    X = p.mesh.points
    assert np.hypot(*ch.policy(X).T).max() <= ubar * (1 + 1e-12)
    # an unbounded trained controller in the cache is not taken for the bounded one
    ch2 = make_controller(st, "hji-bounded", p.system, trained=p.train())
    assert np.hypot(*ch2.policy(X).T).max() <= ubar * (1 + 1e-12)
    # another rating, another bound
    st3 = _study(**{"upqc.rating": 0.05})
    ch3 = make_controller(st3, "hji-bounded", p.system)
    assert np.hypot(*ch3.policy(X).T).max() <= 0.05 * (1 + 1e-12)
    assert np.hypot(*ch3.policy(X).T).max() > 0.049
