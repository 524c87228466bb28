"""Two machines on one bus (issue 8, item 1) and the initial-point check of System.setup.

With repeated bus indices, ``I[..., bus] += current`` keeps one machine's current only;
the network then starts out of balance and the machines swing with no event at all.
Oracle: a flat run — no event, so every speed stays at 1 and every voltage at its
power-flow value.
"""

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import simulate
from weakgrid.sim.system import System

from sim_cases import two_machine_case

GENROU = dict(Sn=100, M=7.0, D=0.0, ra=0.002, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55,
              xd2=0.25, xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)


def _shared_case(model):
    """Buses 1 (PV) and 2 (slack), each with two generators; machines of type ``model``."""
    case = two_machine_case(x_line=0.2, p=0.8)
    g = case["gen"]
    extra = g.copy()
    extra[0, 1] = 40.0               # a second, different generator at bus 1 ...
    extra[1, 1] = 0.0                # ... and at the slack bus 2
    case["gen"] = np.vstack([g, extra])
    s = System(case)
    prm = GENROU if model == "GENROU" else dict(Sn=100, M=7.0, D=0.0, ra=0.0, xd1=0.3)
    for k in range(4):
        p = dict(prm, M=prm["M"] + k, xd1=prm["xd1"] * (1 + 0.2 * k))
        s.add_machine(model, f"G{k}", gen=k, **p)
    return s


@pytest.mark.parametrize("model", ["GENCLS", "GENROU"])
def test_two_machines_on_one_bus_flat_run(model):
    s = _shared_case(model)
    s.setup()
    res = simulate(s, 5.0, dt=1 / 120)
    for k in range(4):
        assert np.max(np.abs(res[f"G{k}.omega"] - 1.0)) < 1e-8
    for b in (1, 2):
        v = res[f"bus{b}.v"]
        assert np.max(np.abs(v - v[0])) < 1e-8


def test_shared_bus_currents_accumulate():
    """The network residual at t = 0 is zero at the shared buses (all four currents arrive)."""
    s = _shared_case("GENROU")
    s.setup()
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F[s.nx:])) < 1e-9


def test_setup_refuses_an_initial_point_that_is_not_a_steady_state():
    """A model whose initialization disagrees with its equations is refused by name and size."""
    s = _shared_case("GENCLS")
    comp = s._component("GENCLS")
    orig = comp.init

    def bad_init(system, x, sig):
        orig(system, x, sig)
        x[comp.idx("delta")[2]] += 0.01      # a rotor angle 0.01 rad off its steady state

    comp.init = bad_init
    with pytest.raises(DataError, match=r"bus \d.*current mismatch|G2"):
        s.setup()
