"""A study run's controller law (weakgrid.study.law.StudyLaw): its batched evaluation for the
members of a batch equals each run's own call, and each run logs its own samples."""

import numpy as np

from weakgrid.sim.design_states import GTIStateMap
from weakgrid.study.controllers import make_controller
from weakgrid.study.law import StudyLaw
from weakgrid.study.studyfile import load_study
from weakgrid.study.sweep import prepare_point, sweep_points


def _policies():
    st = load_study("case1-weak-grid")
    pts = {p.params["controller"]: p.inputs for p in sweep_points(st, quick=True)}
    out = {name: prepare_point(pts[name]).choice.policy
           for name in ("hji", "nonlinear-29", "hji-bounded")}
    out["lqr"] = make_controller(st, "lqr", prepare_point(pts["hji"]).setup.design).policy
    return out


def test_rows_equal_each_laws_own_call_bit_for_bit_and_log_each_run():
    """Each row of a batched call is the run's own call to the last bit, for any number of
    rows: a closed loop amplifies a last-bit difference (case 1's 6-s runs: one ulp at 0.3 s
    became 1.8e-8 rad in the SG's angle when a matrix product rounded an (n, 2) call otherwise
    than a (2,) one). 17 and 40 rows pass the bounded law's point-by-point threshold."""
    rng = np.random.default_rng(3)
    n_max = 40
    maps = [GTIStateMap(0.31 + 0.002 * k, 110.0, 1.0 + 0.001 * k) for k in range(n_max)]
    Y = np.column_stack([0.31 + rng.normal(0, 0.2, n_max), 1.0 + rng.normal(0, 0.02, n_max)])
    for name, pol in list(_policies().items()) + [("idle", None), ("closure", lambda x: -x)]:
        for n in (1, 2, 4, 17, n_max):
            own = [StudyLaw(pol, mp) for mp in maps[:n]]
            together = [StudyLaw(pol, mp) for mp in maps[:n]]
            assert len({law.batch_key() for law in together}) == 1
            U = StudyLaw.rows(together, Y[:n])
            ref = np.stack([law(y) for law, y in zip(own, Y[:n])])
            assert np.array_equal(U, ref), (name, n, np.abs(U - ref).max())
            for a, b in zip(own, together):
                assert np.array_equal(np.array(a.xs), np.array(b.xs))
                assert np.array_equal(np.array(a.ys), np.array(b.ys))
