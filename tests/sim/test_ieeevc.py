"""IEEEVC voltage compensator: the exciter regulates |Vt + (rc + j xc) It| (invariants, no peer).

ANDES 2.0 cannot serve as the peer here: it fails to initialize its own IEEEVC cases (the
exciters' input starts at the bus voltage, off by the compensation; see the sim README).
"""

import numpy as np
import pytest

from sim_cases import two_machine_case
from weakgrid.sim.events import LoadStep
from weakgrid.sim.integrate import simulate
from weakgrid.sim.system import System

SN = 200.0        # machine rating [MVA] != system base (100 MVA): the base conversion matters
K = 100.0         # SEXS gain: steady-state error of the proportional regulator is vf / K


def build(comp=None, sn=SN):
    s = System(two_machine_case(x_line=0.2, p=0.8))
    s.add_generator("G1", 0, ("GENROU", dict(Sn=sn)), exciter=("SEXS", dict(K=K, TE=0.05)))
    if comp is not None:
        s.add_compensator("IEEEVC", "G1.vc", "G1", **comp)
    s.add_generator("G2", 1, ("GENCLS", dict(Sn=1000.0, M=100.0)))
    s.setup()
    return s


def compensated(r, k, zc_sys):
    """|Vt + Zc It| from the recorded terminal voltage and machine power (system base)."""
    V = r["bus1.v"][k] * np.exp(1j * r["bus1.a"][k])
    It = np.conj((r["G1.Pe"][k] + 1j * r["G1.Qe"][k]) / V)
    return np.abs(V + zc_sys * It)


@pytest.mark.parametrize("on_Sb, scale", [(0.0, 100.0 / SN), (1.0, 1.0)])
def test_initial_point_and_trajectory_follow_the_definition(on_Sb, scale):
    rc, xc = 0.01, 0.08
    s = build(dict(rc=rc, xc=xc, on_Sb=on_Sb))
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9                     # setup's equilibrium includes Ecomp
    ev = [LoadStep(bus=1, t=0.2, dP=20.0, dQ=30.0)]
    r = simulate(s, 2.0, events=ev)
    zc = (rc + 1j * xc) * scale                          # machine base -> system base (Vn = Vb)
    for k in (0, 10, 60, -1):
        assert r["G1.vc.Ecomp"][k] == pytest.approx(compensated(r, k, zc), abs=1e-9)
    # the compensation is not negligible: Ecomp differs from Vt by more than 1e-3 pu
    assert abs(r["G1.vc.Ecomp"][0] - r["bus1.v"][0]) > 1e-3


def test_the_exciter_regulates_the_compensated_voltage():
    # SEXS's input is vi = vref - Ecomp (no PSS): vi + Ecomp stays at vref through a load step,
    # while vi + Vt does not; at the new operating point Ecomp has moved by only -dvf/K
    s = build(dict(rc=0.0, xc=0.1))
    r = simulate(s, 10.0, events=[LoadStep(bus=1, t=0.2, dP=0.0, dQ=40.0)])
    vi, E, V = r["G1.avr.vi"], r["G1.vc.Ecomp"], r["bus1.v"]
    assert np.ptp(vi + E) < 1e-12
    assert np.ptp(vi + V) > 1e-2
    dE, dvf = E[-1] - E[0], r["G1.vf"][-1] - r["G1.vf"][0]
    assert dE == pytest.approx(-dvf / K, rel=0.05)
    assert abs(V[-1] - V[0]) > 5 * abs(dE)     # the terminal voltage itself is not what is held


def test_zero_compensation_is_no_compensator():
    a = simulate(build(), 1.5, events=[LoadStep(bus=1, t=0.2, dP=20.0, dQ=30.0)])
    b = simulate(build(dict(rc=0.0, xc=0.0)), 1.5, events=[LoadStep(bus=1, t=0.2, dP=20.0, dQ=30.0)])
    assert np.max(np.abs(a["G1.omega"] - b["G1.omega"])) < 1e-12
    assert np.max(np.abs(a["G1.vf"] - b["G1.vf"])) < 1e-12
