"""The DPsim machine with capacitance at its own node (weakgrid.sim.emt.damping).

Grid: a classical machine G1 (xd1 = 0.25 pu, 0.8 pu, M = 6 s) at bus 1, two parallel lines
0.01 + j0.3 pu with b = 0.1 pu each to an infinite bus: b = 0.1 pu at the machine's node (or
the lines without charging and a 0.1 pu shunt capacitor at bus 1; or case 1's GENROU with
xd2 = 0.25 pu). A bolted fault at bus 1 from 0.1 s to 0.15 s.
Oracles: DPsim's VBR machine is the impedance ``j x`` at every frequency (an algebraic
stator), so with the node's capacitance ``b`` it forms the first-order mode
``λ = −j ω0 / (x b)`` (undamped), which the trapezoidal rule keeps at ``(2/dt) atan(ω0 dt /
(2 x b))``; with the damping resistor in series with the capacitors the mode's damping ratio
is ``ZETA`` and it is gone within milliseconds; the electromechanical response moves by less
than 0.1 %.
"""

import math

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.emt import damping
from weakgrid.sim.emt.topology import _shunt_admittance

XD1, B, DT, T_END = 0.25, 0.1, 1e-4, 0.4
T_ON, T_OFF = 0.1, 0.15
W0 = 2 * math.pi * 60.0


#: case 1's GENROU, its xd2 = 0.25 pu the classical machine's xd1, without ra (undamped mode)
GENROU = dict(Sn=100, M=6.0, D=0.0, ra=0.0, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55,
              xd2=XD1, xq2=XD1, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.0)


def _grid(b=B, ra=0.0, load1=0.0, bs1=0.0, model="GENCLS"):
    from weakgrid.sim.sources import InfiniteBus
    from weakgrid.sim.system import System

    bus = np.array([[1, 2, load1, 0, 0, bs1, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]], float)
    gen = np.array([[1, 80, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[1, 2, 0.01, 0.3, b, 0, 0, 0, 0, 0, 1, -360, 360]] * 2, float)
    s = System({"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch})
    if model == "GENCLS":
        s.add_machine("GENCLS", "G1", 0, Sn=100, M=6.0, D=0.0, ra=ra, xd1=XD1)
    else:
        s.add_machine(model, "G1", 0, **dict(GENROU, ra=ra))
    src = InfiniteBus()
    src.add_source("S2", 1)
    s.add_component(src)
    s.setup()
    return s


def _rd(s):
    return damping.terminal_damping(s, _shunt_admittance(s))


def test_resistor_gives_the_mode_its_damping_ratio():
    s = _grid()
    rd = _rd(s)
    assert rd[1] == 0.0                          # the infinite bus: no machine
    z = rd[0] + 1j * XD1                         # the capacitors' loop: R_d + j x
    lam = -1.0 / (B * z)                         # × ω0
    assert -lam.real / abs(lam) == pytest.approx(damping.ZETA, rel=1e-12)
    # its fundamental-frequency cost: each capacitor b/2 gets the conductance (b/2)² R_d
    assert 2 * (B / 2) ** 2 * rd[0] < 1e-3


@pytest.mark.parametrize("kw", [dict(b=0.0), dict(ra=0.06), dict(load1=100.0)],
                         ids=["no-capacitance", "stator-resistance", "load"])
def test_no_resistor_where_the_mode_is_damped_or_absent(kw):
    # ra = 0.06: ζ = ra/|ra + j x| = 0.23; a load of 1 pu: ζ = g/|g − j/x| = 0.24
    assert not np.any(_rd(_grid(**kw)))


def test_large_capacitance_at_the_machine_is_refused_naming_bus_and_machine():
    s = _grid(bs1=150.0)                         # 1.5 pu capacitor bank at the machine's bus
    with pytest.raises(DataError, match=r"bus 1 \(G1 \(GENCLS\).*step-up transformer"):
        _rd(s)
    from weakgrid.sim.emt.support import check_supported
    with pytest.raises(DataError, match="bus 1"):
        check_supported(s, [Fault(1, T_ON, T_OFF)], engine="dpsim-dp")


def _ringing(r, t0):
    """Peak-to-peak [pu] of the node-mode ringing of bus 1's voltage magnitude from ``t0``: the
    second difference (which passes the kHz mode with gain ``4 sin²(ω dt/2)`` ≈ 1.5 and the
    electromechanical and 100–160 Hz network transients with < 0.01) over that gain."""
    if "bus1.va" in r.names:
        v = np.sqrt((r["bus1.va"] ** 2 + r["bus1.vb"] ** 2 + r["bus1.vc"] ** 2) * 2 / 3)
    else:
        v = r["bus1.v"]
    d2 = v[2:] - 2 * v[1:-1] + v[:-2]
    m = r.t[1:-1] >= t0
    wd = 2 / DT * math.atan(W0 / (XD1 * B) * DT / 2)
    return float(np.ptp(d2[m]) / (4 * math.sin(wd * DT / 2) ** 2))


@pytest.mark.emt
@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
@pytest.mark.parametrize("kw", [dict(), dict(b=0.0, bs1=10.0), dict(model="GENROU")],
                         ids=["line-charging", "shunt-capacitor", "GENROU"])
def test_cleared_fault_leaves_no_ringing(engine, kw):
    pytest.importorskip("dpsimpy")
    from weakgrid.sim.emt import simulate_dpsim
    r = simulate_dpsim(_grid(**kw), T_END, engine=engine, dt=DT, events=[Fault(1, T_ON, T_OFF)])
    # with ζ = 0.2 the mode (≈ 2 pu at clearing) decays as exp(−ζ |λ| t), e^-30 in 10 ms; what
    # the measure leaves is the post-clearing 100–160 Hz transient (≈ 1 pu × 0.01 gain).
    # Without the resistor (DPsim 1.4 as built on main): 2.06 / 2.11 pu (EMT / DP) for the
    # classical machine with line charging or a 0.1 pu shunt capacitor, 1.05 / 1.14 pu GENROU.
    assert _ringing(r, T_OFF + 0.01) < 0.03
    assert np.all(np.isfinite(r["G1.omega"]))


@pytest.mark.emt
def test_undamped_mode_is_the_algebraic_stator_and_the_resistor_leaves_the_swing(monkeypatch):
    pytest.importorskip("dpsimpy")
    from weakgrid.sim.emt import simulate_dpsim
    ev = [Fault(1, T_ON, T_OFF)]
    damped = simulate_dpsim(_grid(), T_END, engine="dpsim-dp", dt=DT, events=ev)
    monkeypatch.setattr(damping, "ZETA", 0.0)              # no resistor: DPsim as it is
    assert not np.any(_rd(_grid()))
    bare = simulate_dpsim(_grid(), T_END, engine="dpsim-dp", dt=DT, events=ev)
    assert _ringing(bare, T_OFF + 0.01) > 1.0               # rings, barely damped
    # its frequency: the trapezoid-warped ω0/(x b) (in DP's frame), not a real stator's ω0/√(x b)
    m = bare.t >= T_OFF + 0.01
    v = bare["bus1.v"][m]
    d2 = v[2:] - 2 * v[1:-1] + v[:-2]
    spec = np.abs(np.fft.rfft(d2 * np.hanning(d2.size)))
    f = np.fft.rfftfreq(d2.size, DT)[np.argmax(spec)]
    f_pred = 2 / DT * math.atan(W0 / (XD1 * B) * DT / 2) / (2 * math.pi)
    assert f == pytest.approx(f_pred, rel=0.03)
    assert abs(f - W0 / math.sqrt(XD1 * B) / (2 * math.pi)) > 1000.0
    # the electromechanical response: speed excursion and angle peak within 0.1 %
    for sig, ref in (("G1.omega", 1.0), ("G1.delta", 0.0)):
        a, b = (np.max(np.abs(x[sig] - ref)) for x in (damped, bare))
        assert a == pytest.approx(b, rel=1e-3), sig
