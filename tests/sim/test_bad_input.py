"""Bad input gets a clear error naming the element, the field and the fix."""

import pytest

from sim_cases import two_machine_case
from weakgrid.sim.errors import DataError, PowerFlowError
from weakgrid.sim.events import Fault, LineTrip
from weakgrid.sim.integrate import simulate
from weakgrid.sim.network import Network
from weakgrid.sim.system import System


def test_unknown_bus_in_branch():
    case = two_machine_case()
    case["branch"][0, 1] = 7
    with pytest.raises(DataError) as e:
        Network(case)
    assert e.value.element == "branch 0" and e.value.field == "T_BUS" and e.value.value == 7
    assert "known buses" in str(e.value)


def test_negative_time_constant():
    s = System(two_machine_case())
    s.add_machine("GENROU", "G1", 0, Td10=8.0)
    with pytest.raises(DataError) as e:
        s.add_exciter("EXDC2", "AVR1", "G1", TA=-0.02)
    assert e.value.field == "TA" and "EXDC2 'AVR1'" in str(e.value) and e.value.value == -0.02


def test_unknown_parameter_and_machine():
    s = System(two_machine_case())
    with pytest.raises(DataError, match="unknown parameter"):
        s.add_machine("GENCLS", "G1", 0, Xd1=0.3)
    s.add_machine("GENCLS", "G1", 0)
    with pytest.raises(DataError, match="no such machine"):
        s.add_governor("TGOV1", "gov", "G9")


def test_unusual_data_said_once_per_model_with_a_count():
    """Two GENROU with xl >= xd2: one warning for the model, counting and naming both (ANDES's
    ieee39 has nine; one warning per machine repeated nine times on every set-up)."""
    import warnings

    from weakgrid.sim.errors import DataWarning

    s = System(two_machine_case())
    s.add_machine("GENROU", "G1", 0, xl=0.2, xd2=0.1, xq2=0.1)
    s.add_machine("GENROU", "G2", 1, xl=0.15, xd2=0.12, xq2=0.12)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s.setup()
    msgs = [str(w.message) for w in caught if issubclass(w.category, DataWarning)]
    assert len(msgs) == 1, msgs
    assert msgs[0].startswith("GENROU (2 of 2): leakage reactance xl >= xd2")
    assert "'G1' xl = 0.2 >= xd2 = 0.1" in msgs[0] and "'G2' xl = 0.15 >= xd2 = 0.12" in msgs[0]
    assert caught[0].filename.endswith("system.py")     # where the model is set up


def test_remove_controls_before_setup():
    """A machine's stabilizer taken out before the set-up: the system initializes without it
    (the `none` baseline of a study); the other machine keeps its own."""
    s = System(two_machine_case())
    for g, name in ((0, "G1"), (1, "G2")):
        s.add_generator(name, g, ("GENROU", {}), exciter=("SEXS", {}),
                        pss=("IEEEST", {"MODE": 3}))
    assert s.controls_of("G1") == [("IEEEST", "G1.pss")]
    assert s.remove_controls("G1") == [("IEEEST", "G1.pss")]
    assert s.controls_of("G1") == [] and s.controls_of("G2") == [("IEEEST", "G2.pss")]
    s.setup()                                       # the initial-point check passes
    assert s.components["IEEEST"].names == ["G2.pss"]
    assert s.remove_controls("G2") == [("IEEEST", "G2.pss")] and "IEEEST" not in s.components
    assert not s.is_setup
    s.setup()
    with pytest.raises(DataError, match="no such machine"):
        s.remove_controls("G9")


def test_unconverged_power_flow():
    case = two_machine_case(p=50.0)          # 5000 MW over a 0.3 pu line: infeasible
    s = System(case)
    s.add_machine("GENCLS", "G1", 0)
    s.add_machine("GENCLS", "G2", 1)
    with pytest.raises(PowerFlowError, match="Fix"):
        s.setup()


def test_fault_on_missing_bus():
    s = System(two_machine_case())
    s.add_machine("GENCLS", "G1", 0)
    s.add_machine("GENCLS", "G2", 1)
    s.setup()
    with pytest.raises(DataError) as e:
        simulate(s, 0.1, events=[Fault(42, 0.01, 0.02)])
    assert e.value.field == "bus" and e.value.value == 42 and "Fault at bus 42" in str(e.value)


def test_bad_line_trip_and_missing_machine_for_gen():
    s = System(two_machine_case())
    s.add_machine("GENCLS", "G1", 0)
    with pytest.raises(DataError, match="every in-service generator"):
        s.setup()
    s.add_machine("GENCLS", "G2", 1)
    s.setup()
    with pytest.raises(DataError, match="branch"):
        simulate(s, 0.1, events=[LineTrip(5, 0.05)])


def test_genrou_requires_equal_subtransient():
    s = System(two_machine_case())
    s.add_machine("GENROU", "G1", 0, xd2=0.25, xq2=0.3)
    s.add_machine("GENCLS", "G2", 1)
    with pytest.raises(DataError, match="xq2 == xd2"):
        s.setup()


def test_genrou_accepts_data_that_andes_ships():
    """ANDES's ieee39 has xl > xd2 and its wecc has xq1 = xq: both well defined, accepted (the first
    with a warning, as ANDES does) and the initial point is steady; xl >= xd1 is still refused."""
    import numpy as np

    for kw, warns in ((dict(xl=0.2, xd2=0.1, xq2=0.1), True), (dict(xq=0.6, xq1=0.6), False)):
        s = System(two_machine_case())
        s.add_machine("GENROU", "G1", 0, **kw)
        s.add_machine("GENCLS", "G2", 1)
        if warns:
            with pytest.warns(UserWarning, match="xl = 0.2 >= xd2"):
                s.setup()
        else:
            s.setup()
        F, _ = s.residual(0.0, s.z0)
        assert np.max(np.abs(F)) < 1e-9
    s = System(two_machine_case())
    s.add_machine("GENROU", "G1", 0, xl=0.5, xd1=0.3)
    s.add_machine("GENCLS", "G2", 1)
    with pytest.raises(DataError, match="xl"):
        s.setup()
