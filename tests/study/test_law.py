"""A study run's controller law (weakgrid.study.law.StudyLaw): its batched evaluation for the
members of a batch equals each run's own call, and each run logs its own samples."""

import numpy as np

from weakgrid.sim.design_states import GTIStateMap
from weakgrid.study.law import StudyLaw
from weakgrid.study.studyfile import load_study
from weakgrid.study.sweep import prepare_point, sweep_points


def _policies():
    st = load_study("case1-weak-grid")
    pts = {p.params["controller"]: p.inputs for p in sweep_points(st, quick=True)}
    return {name: prepare_point(pts[name]).choice.policy
            for name in ("hji", "nonlinear-29", "hji-bounded")}


def test_rows_equal_each_laws_own_call_and_log_each_run():
    rng = np.random.default_rng(3)
    maps = [GTIStateMap(0.31 + 0.02 * k, 110.0, 1.0 + 0.01 * k) for k in range(4)]
    Y = np.column_stack([0.31 + rng.normal(0, 0.2, 4), 1.0 + rng.normal(0, 0.02, 4)])
    for name, pol in list(_policies().items()) + [("idle", None), ("closure", lambda x: -x)]:
        for n in (1, 4):
            own = [StudyLaw(pol, mp) for mp in maps[:n]]
            together = [StudyLaw(pol, mp) for mp in maps[:n]]
            assert len({law.batch_key() for law in together}) == 1
            U = StudyLaw.rows(together, Y[:n])
            ref = np.stack([law(y) for law, y in zip(own, Y[:n])])
            if n == 1:                           # the run's own call: bit for bit
                assert np.array_equal(U, ref), name
            np.testing.assert_allclose(U, ref, rtol=1e-12, atol=1e-15, err_msg=name)
            for a, b in zip(own, together):
                assert np.array_equal(np.array(a.xs), np.array(b.xs))
                assert np.array_equal(np.array(a.ys), np.array(b.ys))
