"""The step, not the Newton tolerance, sets the error of a run (issue 8, item 8).

ANDES's SMIB case is a lightly damped 10-s swing: the iteration error of every step
(up to ``tol``) accumulates. With the old fixed default 1e-7 at 1/480 s, the result
moved 2.5e-5 pu when the tolerance was tightened 1000x — as much as halving the step.
"""

import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.integrate import default_tol  # noqa: E402
from weakgrid.sim.peer.andes_runs import compare, run_weakgrid  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]


def test_default_tol_scales_like_the_local_error():
    assert default_tol(1 / 120) == pytest.approx(1e-7)
    assert default_tol(1 / 480) == pytest.approx(1e-7 / 64)
    assert default_tol(1e-4) == 1e-10 and default_tol(0.1) == 1e-7


def test_halving_the_step_matters_more_than_a_1000x_tighter_tolerance():
    case, h = "smib/SMIB.xlsx", 1 / 480
    base = run_weakgrid(case, 10.0, h, tol=None)                 # the defaults
    tight = run_weakgrid(case, 10.0, h, tol=default_tol(h) / 1000)
    half = run_weakgrid(case, 10.0, h / 2, tol=None)
    assert base["ok"] and tight["ok"] and half["ok"]
    d_tol = compare(base, tight)[0]
    d_step = compare(base, half)[0]
    assert d_tol < 0.1 * d_step, f"tolerance effect {d_tol:.3g} pu vs step effect {d_step:.3g} pu"
