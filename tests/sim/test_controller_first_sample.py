"""A controller that fails at its first sample (t = 0) is a run's failure like any later one.

Before, the first sample ran outside the integrator's failure handling: with
``on_failure="return"`` (what every study run uses) a policy raising at t = 0 escaped as an
exception instead of becoming the run's recorded failure.
"""

import pytest

from sim_cases import build_gti_upqc_sg
from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
from weakgrid.sim.errors import SimulationError
from weakgrid.sim.integrate import simulate


def _policy_that_raises(m):
    raise RuntimeError("policy evaluated outside its domain")


def _controller():
    return DigitalController(_policy_that_raises, 1e-2, gti_design_states("PV"), UPQCTarget("U"),
                             name="broken")


def test_a_failure_at_the_first_sample_is_returned():
    s = build_gti_upqc_sg("conventional")
    r = simulate(s, 0.1, dt=1e-2, controllers=[_controller()], on_failure="return")
    assert not r.ok
    assert r.failure.cause == "controller" and r.failure.t == 0.0
    assert "broken" in str(r.failure) and "outside its domain" in str(r.failure)
    assert r.t[-1] == 0.0                 # the initial point is recorded, nothing after it


def test_a_failure_at_the_first_sample_raises_when_asked():
    s = build_gti_upqc_sg("conventional")
    with pytest.raises(SimulationError, match="broken"):
        simulate(s, 0.1, dt=1e-2, controllers=[_controller()])
