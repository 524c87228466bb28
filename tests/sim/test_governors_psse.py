"""Turbine-governor models of PSS/E cases: DEGOV1, DEGOV, PIDGOV, WPIDHY, GGOV1.

Oracles, per model (ANDES 2.0 has none of them, so there is no ANDES peer):

* the initial point is an equilibrium (every derivative ~0 at t = 0, and a run without an
  event stays at rest);
* steady-state droop: a machine alone in an island (a GENCLS with constant E' and a lossless
  line to a constant-impedance load) after a load step settles where the governor's droop
  says: the new electrical power ``Pe_ss`` is known in closed form (E' behind x'd feeding the
  new load impedance) and ``omega_ss - 1 = -R * (Pe_ss - Pe0)`` on the machine base (or 0 for
  an isochronous governor);
* each limit driven (load steps beyond the unit's range), the limited quantity held exactly;
* bad data refused with a DataError naming the field;
* the results PowerSimulationsDynamics.jl ships for DEGOV (PowerWorld's, not PSS/E's: see
  tests/data/psid/cases.toml; read from the vendored PSID files, tests/data/psid).
"""

from pathlib import Path

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import LineTrip, LoadStep
from weakgrid.sim.integrate import simulate
from weakgrid.sim.sources import InfiniteBus
from weakgrid.sim.system import System

#: PSID's PSS/E benchmark files, vendored unedited (BSD-3, tests/data/psid/SOURCE.md)
PSID = Path(__file__).resolve().parents[1] / "data" / "psid"

# ---------------------------------------------------------------- data (PSID's PSS/E .dyr files)
#: DEGOV1 of ThreeBus_DEGOV1_nodelay_flag0.dyr (TMAX/TMIN 99.99 there)
DEGOV1 = dict(M=0, T1=0.1905, T2=0.0476, T3=0.018, K=1.0, T4=5.1, T5=0.322, T6=0.0, TD=0.0,
              TMAX=99.99, TMIN=-99.99, DROOP=0.07, TE=0.05)
#: DEGOV of ThreeBus_DEGOV_delay.dyr (TD = 1 s there)
DEGOV = dict(T1=0.0, T2=0.0, T3=0.0, K=18.0, T4=12.0, T5=5.0, T6=0.2, TD=0.0, TMAX=2.0, TMIN=-0.1)
#: GENROU of the PIDGOV/WPIDHY/DEGOV1 cases (H = 6.175, on 100 MVA)
GENROU = dict(Sn=100, M=12.35, D=0.05, ra=0.0, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25, xq2=0.25,
              xl=0.2, Td10=8.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.0, S12=1.0)


def threebus(p102=100.0, load=250.0):
    """PSID's PSS/E benchmark network ThreeBusMulti.raw (v33) in MATPOWER form: infinite bus 101,
    the studied unit at 102, a load at 103, three equal lines. The DEGOV/DEGOV1 cases: 100 MW at
    102, 250 + j30 MVA of load; the PIDGOV/WPIDHY cases: 70 MW, 200 + j30 MVA."""
    bus = np.array([
        [101, 3, 0, 0, 0, 0, 1, 1.05, 0, 138, 1, 1.1, 0.9],
        [102, 2, 0, 0, 0, 0, 1, 1.02, -0.944, 138, 1, 1.1, 0.9],
        [103, 1, load, 30, 0, 0, 1, 0.99341, -8.7697, 138, 1, 1.1, 0.9]], float)
    gen = np.array([
        [101, load - p102 + 3.335, 73.271, 100, -100, 1.05, 100, 1, 318, 0] + [0] * 11,
        [102, p102, -3.247, 100, -100, 1.02, 100, 1, 318, 0] + [0] * 11], float)
    br = np.array([[101, 102, 0.01, 0.12, 0, 250, 250, 250, 0, 0, 1, -360, 360],
                   [101, 103, 0.01, 0.12, 0, 250, 250, 250, 0, 0, 1, -360, 360],
                   [102, 103, 0.01, 0.12, 0, 250, 250, 250, 0, 0, 1, -360, 360]], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": br}


def threebus_system(governor, machine="GENROU", sexs=True, hydro=False):
    """The three-bus case with ``governor = (model, params)`` on the unit at bus 102 (``hydro``:
    the 70-MW dispatch of PSID's PIDGOV/WPIDHY cases)."""
    s = System(threebus(70.0, 200.0) if hydro else threebus())
    if machine == "GENROU":
        s.add_machine("GENROU", "G", gen=1, psse_shaft=1.0, **GENROU)
        if sexs:   # SEXS of the PIDGOV/WPIDHY cases
            s.add_exciter("SEXS", "G.avr", "G", TATB=0.4, TB=5.0, K=20.0, TE=1.0, EMIN=-50.0, EMAX=50.0)
    else:
        s.add_machine("GENCLS", "G", gen=1, Sn=100, M=16.0, D=0.03, ra=0.0, xd1=0.25,
                      psse_shaft=1.0)
    s.add_governor(governor[0], "G.gov", "G", **governor[1])
    ib = InfiniteBus()
    ib.add_source("IB", 0)
    s.add_component(ib)
    return s


# island: machine at bus 1 (the slack), lossless line to a constant-impedance load at bus 2
XD1, XL, P0, Q0, SN = 0.25, 0.1, 60.0, 10.0, 100.0


def island_case():
    bus = np.array([[1, 3, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
                    [2, 1, P0, Q0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5]], float)
    gen = np.array([[1, P0, 0, 999, -999, 1.0, SN, 1, 999, -999] + [0] * 11], float)
    br = np.array([[1, 2, 0.0, XL, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": br}


def island_system(governor, M=10.0):
    s = System(island_case())
    s.add_machine("GENCLS", "G", gen=0, Sn=SN, M=M, D=0.0, ra=0.0, xd1=XD1, psse_shaft=1.0)
    s.add_governor(governor[0], "G.gov", "G", **governor[1])
    return s.setup()


def island_pe(s, dP):
    """Electrical power [pu, system base] of the island machine at constant E' after ``dP`` MW of
    constant-impedance load is added at bus 2 (the network is linear: E' behind j x'd, the line,
    the load admittance at its power-flow voltage)."""
    V2 = s.network.pf.V[1]
    yL = np.conj(complex(P0 + dP, Q0) / 100.0) / abs(V2) ** 2
    E = s.sig_defaults["vf0"][0]
    I = E / (1j * XD1 + 1j * XL + 1.0 / yL)
    return abs(I) ** 2 * (1.0 / yL).real


def at_rest(s, t=1.0, dt=1 / 120):
    """Largest state derivative at t = 0 and the speed excursion of an event-free run."""
    F, _ = s.residual(0.0, s.z0)
    res = simulate(s, t, dt=dt)
    return float(np.max(np.abs(F))), float(np.max(np.abs(res["G.omega"] - 1.0)))


# ====================================================================== DEGOV1 / DEGOV
@pytest.mark.parametrize("gov", [
    ("DEGOV1", DEGOV1), ("DEGOV1", dict(DEGOV1, M=1)), ("DEGOV1", dict(DEGOV1, TD=0.3)),
    ("DEGOV", DEGOV), ("DEGOV", dict(DEGOV, TD=1.0))],
    ids=["DEGOV1-M0", "DEGOV1-M1", "DEGOV1-delay", "DEGOV", "DEGOV-delay"])
def test_degov_initial_point_is_an_equilibrium(gov):
    s = threebus_system(gov, machine="GENROU" if gov[0] == "DEGOV1" else "GENCLS", sexs=False).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10


#: GENROU of PSID's ThreeBus_DEGOV1_*.dyr (H = 6.175, D = 0.05, S(1.0) = 0.1, S(1.2) = 0.8)
GENROU_DEGOV1 = dict(GENROU, S10=0.1, S12=0.8)
#: small-signal eigenvalues of PSID's test_case63 (ThreeBus_DEGOV1_nodelay_flag0/1.dyr: GENROU +
#: DEGOV1 at bus 102, no exciter) as PowerSimulationsDynamics.jl computes them
#: (test/results/results_eigenvalues.jl, BSD-3-Clause, (c) Alliance for Sustainable Energy)
PSID_DEGOV1_EIGS = {
    0: [-39.22517856531171 - 0.23706643304840616j, -39.22517856531171 + 0.23706643304840616j,
        -13.403547886572664, -8.122746726423252, -5.391500486820183 - 2.241842433737118j,
        -5.391500486820183 + 2.241842433737118j, -0.6466138560537371 - 8.624155441599354j,
        -0.6466138560537371 + 8.624155441599354j, -0.20824914641735212, -0.05243031034640425],
    1: [-39.224926800052884 - 0.23735163098908485j, -39.224926800052884 + 0.23735163098908485j,
        -19.85028250949885, -13.323569303234533, -7.521736802553002,
        -5.905690613400367 - 2.3710175079240416j, -5.905690613400367 + 2.3710175079240416j,
        -0.5479840603712405 - 8.276315089713018j, -0.5479840603712405 + 8.276315089713018j,
        -0.2082414387220071, -0.05252688447358956],
}


def state_matrix_eigs(s, h=1e-7):
    """Eigenvalues of the reduced state matrix at the initial point (finite differences of the
    DAE residual; the structurally zero ones of unused states dropped)."""
    z0, nx = s.z0.copy(), s.nx
    F0, _ = s.residual(0.0, z0)
    J = np.zeros((len(z0), len(z0)))
    for j in range(len(z0)):
        z = z0.copy()
        z[j] += h
        J[:, j] = (s.residual(0.0, z)[0] - F0) / h
    A = J[:nx, :nx] - J[:nx, nx:] @ np.linalg.solve(J[nx:, nx:], J[nx:, :nx])
    ev = np.linalg.eigvals(A)
    return np.sort_complex(ev[np.abs(ev) > 1e-6])


@pytest.mark.parametrize("M", [0, 1])
def test_degov1_eigenvalues_as_psid(M, monkeypatch):
    """PSID case 63 (GENROU + DEGOV1, throttle or electrical-power droop): the small-signal
    eigenvalues of the initial point equal PSID's (within PSID's own test tolerance, 1e-3 on
    the norm; measured 7.3e-4, at most 5.1e-4 on one eigenvalue: the -39 pair of the machine)
    -- the governor's structure and its TE lag on Pe included."""
    monkeypatch.setitem(globals(), "GENROU", GENROU_DEGOV1)
    s = threebus_system(("DEGOV1", dict(DEGOV1, M=M)), sexs=False).setup()
    ev = state_matrix_eigs(s)
    ref = np.sort_complex(np.array(PSID_DEGOV1_EIGS[M], dtype=complex))
    assert len(ev) == len(ref)
    assert np.linalg.norm(ev - ref) < 1e-3

@pytest.mark.parametrize("M", [0, 1])
def test_degov1_droop(M):
    """Throttle (M = 0) or electrical-power (M = 1) droop: omega_ss - 1 = -DROOP * d(feedback)
    (machine base). PSS/E's GENCLS balances PMECH/omega against Pe/omega, so in the steady state
    PMECH = THR*omega = Pe: the throttle settles at Pe/omega."""
    s = island_system(("DEGOV1", dict(DEGOV1, M=M, K=5.0)))
    dP = 10.0
    res = simulate(s, 60.0, dt=0.02, events=[LoadStep(2, 0.5, dP=dP)])
    pe0, pe1 = (v * 100.0 / SN for v in (s.sig_defaults["Pe0"][0], island_pe(s, dP)))
    if M == 1:
        expected = -DEGOV1["DROOP"] * (pe1 - pe0)
    else:
        expected = 0.0
        for _ in range(50):   # the throttle is Pe/omega
            expected = -DEGOV1["DROOP"] * (pe1 / (1 + expected) - pe0)
    assert abs(expected) > 3e-3
    assert res["G.omega"][-1] - 1 == pytest.approx(expected, rel=1e-5)
    assert res["G.Pe"][-1] == pytest.approx(pe1 * SN / 100.0, rel=1e-7)
    assert res["G.gov.THR"][-1] == pytest.approx(pe1 / (1 + expected), rel=1e-6)   # lossless: THR*omega = Pe


def test_degov_is_isochronous():
    # PSID's DEGOV data are tuned for a unit on a stiff grid; alone in an island (M = 10 s) they
    # swing for minutes. A loop with ~50 deg of phase margin at 1.5 rad/s:
    s = island_system(("DEGOV", dict(DEGOV, K=7.5, T4=2.0, T5=0.2, T6=0.05)))
    res = simulate(s, 40.0, dt=0.02, events=[LoadStep(2, 0.5, dP=10.0)])
    assert np.min(res["G.omega"]) < 1 - 1e-3                     # it did move
    assert abs(res["G.omega"][-1] - 1) < 1e-7
    assert res["G.gov.THR"][-1] == pytest.approx(island_pe(s, 10.0), rel=1e-6)


@pytest.mark.parametrize("model, base", [("DEGOV1", DEGOV1), ("DEGOV", DEGOV)])
@pytest.mark.parametrize("dP, field", [(20.0, "TMAX"), (-30.0, "TMIN")])
def test_degov_throttle_limits(model, base, dP, field):
    """A load step beyond the throttle range: THR is held at TMAX / TMIN (non-windup) and the
    torque equals the limit; the speed keeps moving (no equilibrium within the limits)."""
    tm0 = P0 / SN
    lim = dict(TMAX=tm0 + 0.05, TMIN=tm0 - 0.05)
    s = island_system((model, dict(base, K=5.0, **lim)))
    res = simulate(s, 5.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    thr = res["G.gov.THR"]
    L = lim[field]
    assert np.max(thr) <= lim["TMAX"] + 1e-9 and np.min(thr) >= lim["TMIN"] - 1e-9
    assert thr[-1] == pytest.approx(L, abs=1e-9)
    # tm is PSS/E's PMECH = THRD*omega (the PSS/E shaft divides it by the speed)
    assert res["G.tm"][-1] == pytest.approx(L * res["G.omega"][-1] * SN / 100.0, abs=1e-9)
    w = res["G.omega"]
    assert (w[-1] - w[-50]) * np.sign(dP) < 0                   # still decelerating / accelerating


def test_degov_delay_is_exact():
    """The torque is the throttle TD seconds earlier (stored history, linear interpolation)."""
    TD = 0.37
    s = island_system(("DEGOV1", dict(DEGOV1, K=5.0, TD=TD)), M=20.0)
    res = simulate(s, 8.0, dt=0.01, events=[LoadStep(2, 0.5, dP=10.0)])
    t, thr, thrd = res.t, res["G.gov.THR"], res["G.gov.THRD"]
    late = t > TD
    assert np.ptp(thr) > 0.05
    assert np.max(np.abs(thrd[late] - np.interp(t[late] - TD, t, thr))) < 1e-12
    assert np.max(np.abs(thrd[~late] - thr[0])) < 1e-12
    assert np.max(np.abs(res["G.tm"] - thrd * res["G.omega"] * SN / 100.0)) < 1e-12



def test_degov_delay_shorter_than_the_step():
    """TD < dt: the delayed point lies inside the step, interpolated between the last accepted
    point and the current state (which the Jacobian then sees); still THR(t - TD) exactly."""
    TD, dt = 0.004, 0.01
    s = island_system(("DEGOV1", dict(DEGOV1, K=5.0, TD=TD)), M=20.0)
    res = simulate(s, 4.0, dt=dt, events=[LoadStep(2, 0.5, dP=10.0)])
    t, thr, thrd = res.t, res["G.gov.THR"], res["G.gov.THRD"]
    late = t > TD
    assert np.max(np.abs(thrd[late] - np.interp(t[late] - TD, t, thr))) < 1e-12
    assert np.max(np.abs(thrd - thr)) > 1e-5                     # it is delayed

@pytest.mark.parametrize("model, params, field", [
    ("DEGOV1", dict(DEGOV1, TMAX=0.5, TMIN=0.6), "TMAX"),
    ("DEGOV1", dict(DEGOV1, T1=0.0, T2=0.0, T3=0.1), "T3"),
    ("DEGOV", dict(DEGOV, T5=0.0, T6=0.0), "T4"),
    ("DEGOV1", dict(DEGOV1, TE=-0.1), "TE"),
    ("DEGOV1", dict(DEGOV1, M=2), "M"),
    ("DEGOV", dict(DEGOV, K=0.0), "K"),
    ("DEGOV1", dict(DEGOV1, TMAX=0.5), "TMAX"),        # tm0 = 0.6 pu beyond TMAX, at setup
    ("DEGOV", dict(DEGOV, TMIN=0.7), "TMIN"),
])
def test_degov_bad_data(model, params, field):
    with pytest.raises(DataError) as e:
        island_system((model, params))
    assert e.value.field == field


# ------------------------------------------ PSID's DEGOV benchmark (PowerWorld's results)
def _psid_csv(path):
    return np.loadtxt(PSID / path, delimiter=",")


@pytest.mark.psse
@pytest.mark.parametrize("TD, csv, psid_tol", [
    (0.0, "DEGOV/degov_nodelay_speed_final.csv", 4.7e-5),
    (1.0, "DEGOV/degov_delay_speed_final.csv", 3.1e-5)], ids=["nodelay", "delay"])
def test_degov_against_psse(TD, csv, psid_tol):
    """PSID test_case57: GENCLS (H = 8, D = 0.03, x'd = 0.25) + DEGOV at bus 102, line 101-102
    tripped at 1 s; rotor speed against the CSV PSID ships -- PowerWorld's results, not PSS/E's
    (PSID names them omega_pw; 1/240-s samples, absolute speed: tests/data/psid/cases.toml).
    With PSS/E's GENCLS (electrical torque Pe/omega: PSS/E's own OMIB results need it) the
    difference is 8.7e-5 pu (no delay) and 5.4e-5 pu (1 s delay) on swings of 9.2e-4 / 9.1e-4 pu,
    below 10 % of the swing: the governor's dynamics are PowerWorld's, the machine's damping
    convention is not (with the governor's power alone divided by the speed: 4.7e-5 / 3.05e-5)."""
    ref = _psid_csv(csv)
    s = threebus_system(("DEGOV", dict(DEGOV, TD=TD)), machine="GENCLS").setup()
    res = simulate(s, 5.0, dt=1 / 240, events=[LineTrip(0, 1.0)])
    w = np.interp(ref[:, 0], res.t, res["G.omega"])
    err = np.max(np.abs(w - ref[:, 1]))
    assert err < 2 * psid_tol
    assert err < 0.10 * np.ptp(ref[:, 1])


# ============================================================================== PIDGOV
#: PIDGOV of PSID's ThreeBus_PIDGOV_*.dyr, as shipped (Flag 0 = PowerFlag, 1 = GateFlag)
PIDGOV_PSID = dict(Flag=0, Rperm=0.05, Treg=0.01, Kp=5.0, Ki=1.0, Kd=0.1, Ta=0.5, Tb=0.99, Dturb=0.001,
                   G0=0.1, G1=0.7, P1=0.3, G2=0.9, P2=0.5, P3=0.9, Gmax=1.0, Gmin=0.05, Atw=1.0,
                   Tw=0.6, Velmax=0.04, Velmin=-0.04)
#: the same with P3 = 1.1 at full gate, so that the 100-MW unit can start (gate 0.983)
PIDGOV = dict(PIDGOV_PSID, P3=1.1)
#: a loop that settles alone in the island (PSID's gains are for a unit on a stiff grid)
PIDGOV_ISLAND = dict(PIDGOV, Dturb=0.0, Kp=1.0, Ki=0.3, Kd=0.2, Ta=0.1, Tb=0.2, Velmax=0.2, Velmin=-0.2)


@pytest.mark.parametrize("flag", [0, 1])
def test_pidgov_initial_point_is_an_equilibrium(flag):
    """PSID's ThreeBus_PIDGOV_PowerFlag / _GateFlag cases (70 MW): at rest at PSID's initial gate
    0.95 (the inverse of the gate table at 0.7 pu), then the line trip of PSID's case 58."""
    s = threebus_system(("PIDGOV", dict(PIDGOV_PSID, Flag=flag)), hydro=True).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10
    assert s.z0[s.components["PIDGOV"].idx("GATE")][0] == pytest.approx(0.95, rel=1e-12)
    res = simulate(s, 10.0, dt=1 / 120, events=[LineTrip(0, 1.0)])
    assert res.ok and abs(res["G.omega"][-1] - 1) < 2e-5


def test_pidgov_beyond_full_gate_refused():
    """100 MW with PSID's table (P3 = 0.9 at full gate) needs gate 1.025 > Gmax = 1: refused."""
    with pytest.raises(DataError) as e:
        threebus_system(("PIDGOV", PIDGOV_PSID)).setup()
    assert e.value.field == "Gmax" and "1.025" in str(e.value)


def test_pidgov_droop_on_power():
    s = island_system(("PIDGOV", PIDGOV_ISLAND))
    dP = 10.0
    res = simulate(s, 60.0, dt=0.02, events=[LoadStep(2, 0.5, dP=dP)])
    pe1 = island_pe(s, dP)
    expected = -PIDGOV["Rperm"] * (pe1 - P0 / 100) * 100.0 / SN
    assert res["G.omega"][-1] - 1 == pytest.approx(expected, rel=1e-5)


def test_pidgov_droop_on_gate():
    """Flag 1: omega_ss - 1 = -Rperm*(gate_ss - gate0), gate_ss the gate giving PMECH = Pe (PSS/E's
    GENCLS balances PMECH/omega against Pe/omega)."""
    from weakgrid.sim.governors._gate import power_gate

    s = island_system(("PIDGOV", dict(PIDGOV_ISLAND, Flag=1)))
    res = simulate(s, 60.0, dt=0.02, events=[LoadStep(2, 0.5, dP=10.0)], tol=1e-11)
    gov = s.components["PIDGOV"]
    te1 = island_pe(s, 10.0) * 100.0 / SN
    g0 = power_gate(gov, np.array([P0 / SN]))[0]
    dw = -PIDGOV["Rperm"] * (power_gate(gov, np.array([te1]))[0] - g0)   # PMECH = Pe in the steady state
    assert abs(dw) > 5e-4
    assert res["G.omega"][-1] - 1 == pytest.approx(dw, rel=1e-5)


@pytest.mark.parametrize("dP, field", [(20.0, "Gmax"), (-30.0, "Gmin")])
def test_pidgov_gate_limits(dP, field):
    s0 = island_system(("PIDGOV", PIDGOV_ISLAND))
    g0 = s0.z0[s0.components["PIDGOV"].idx("GATE")][0]
    lim = dict(Gmax=g0 + 0.01, Gmin=g0 - 0.02)
    s = island_system(("PIDGOV", dict(PIDGOV_ISLAND, **lim)))
    res = simulate(s, 8.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    gate = res["G.gov.GATE"]
    assert np.max(gate) <= lim["Gmax"] + 1e-9 and np.min(gate) >= lim["Gmin"] - 1e-9
    assert gate[-1] == pytest.approx(lim[field], abs=1e-9)


@pytest.mark.parametrize("dP, field", [(30.0, "Velmax"), (-30.0, "Velmin")])
def test_pidgov_gate_velocity_limits(dP, field):
    """The gate moves at exactly Velmax / Velmin while the servo demand is beyond them."""
    vel = dict(Velmax=0.01, Velmin=-0.01)
    s = island_system(("PIDGOV", dict(PIDGOV_ISLAND, **vel)))
    dt = 0.01
    res = simulate(s, 3.0, dt=dt, events=[LoadStep(2, 0.5, dP=dP)], tol=1e-11)
    dt_ = np.diff(res.t)
    rate = np.diff(res["G.gov.GATE"])[dt_ > 0] / dt_[dt_ > 0]      # (an event records t twice)
    assert np.max(rate) <= vel["Velmax"] + 1e-8 and np.min(rate) >= vel["Velmin"] - 1e-8
    assert np.sum(np.abs(rate - vel[field]) < 1e-8) > 100            # held over 1 s and more


@pytest.mark.parametrize("params, field", [
    (dict(PIDGOV, Gmax=0.5, Gmin=0.6), "Gmax"),
    (dict(PIDGOV, Velmax=-0.1), "Velmax"),
    (dict(PIDGOV, G1=0.05), "G1"),
    (dict(PIDGOV, P2=0.2), "P2"),
    (dict(PIDGOV, G2=1.0), "G2"),
    (dict(PIDGOV, Tb=0.0), "Tb"),
    (dict(PIDGOV, Flag=2), "Flag"),
    (dict(PIDGOV, Gmin=0.95), "Gmin"),          # the initial gate 0.917 (60 MW) below Gmin
])
def test_pidgov_bad_data(params, field):
    with pytest.raises(DataError) as e:
        island_system(("PIDGOV", params))
    assert e.value.field == field


# ============================================================================== WPIDHY
#: WPIDHY of PSID's ThreeBus_WPIDHY.dyr (100 MW needs the full gate, GATMX = 1)
WPIDHY = dict(TREG=0.01, REG=-0.05, KP=3.0, KI=0.5, KD=3.0, TA=0.02, TB=0.01, VELMX=0.025, VELMN=-0.025,
              GATMX=1.0, GATMN=0.2, TW=3.25, PMAX=52001., PMIN=0.0, D=0.0, G0=0.12, G1=0.545, P1=0.4,
              G2=0.827, P2=0.83, P3=1.0)
#: gains that settle alone in the island (KD is the speed-to-gate gain, see the model)
WPIDHY_ISLAND = dict(WPIDHY, KD=2.0, KP=0.5, KI=0.05, TW=1.0, VELMX=0.2, VELMN=-0.2)


def test_wpidhy_initial_point_is_an_equilibrium():
    """PSID's ThreeBus_WPIDHY case (70 MW): at rest at PSID's initial gate 0.7417, then the line
    trip of PSID's case 60."""
    s = threebus_system(("WPIDHY", WPIDHY), hydro=True).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10
    assert s.z0[s.components["WPIDHY"].idx("GATE")][0] == pytest.approx(0.7417441860465115, rel=1e-12)
    res = simulate(s, 10.0, dt=1 / 120, events=[LineTrip(0, 1.0)])
    assert res.ok and abs(res["G.omega"][-1] - 1) < 1e-4


def test_wpidhy_at_full_gate():
    """100 MW needs the full gate (GATMX = 1): at rest on the limit, held there after the trip."""
    s = threebus_system(("WPIDHY", WPIDHY)).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10
    res = simulate(s, 10.0, dt=1 / 120, events=[LineTrip(0, 1.0)])
    assert res.ok and np.max(res["G.gov.GATE"]) <= 1.0 + 1e-9


def test_wpidhy_droop():
    """omega_ss - 1 = REG*(Pe_ss - Pe0) on the machine base (REG < 0)."""
    s = island_system(("WPIDHY", WPIDHY_ISLAND))
    res = simulate(s, 250.0, dt=0.1, events=[LoadStep(2, 0.5, dP=10.0)], tol=1e-11)
    expected = WPIDHY["REG"] * (island_pe(s, 10.0) - P0 / 100) * 100.0 / SN
    assert abs(expected) > 3e-3
    assert res["G.omega"][-1] - 1 == pytest.approx(expected, rel=1e-5)


def _wpidhy_gate0():
    s = island_system(("WPIDHY", WPIDHY_ISLAND))
    return s.z0[s.components["WPIDHY"].idx("GATE")][0]


@pytest.mark.parametrize("dP, field", [(20.0, "GATMX"), (-30.0, "GATMN")])
def test_wpidhy_gate_limits(dP, field):
    g0 = _wpidhy_gate0()
    lim = dict(GATMX=g0 + 0.01, GATMN=g0 - 0.02)
    s = island_system(("WPIDHY", dict(WPIDHY_ISLAND, **lim)))
    res = simulate(s, 10.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    gate = res["G.gov.GATE"]
    assert np.max(gate) <= lim["GATMX"] + 1e-9 and np.min(gate) >= lim["GATMN"] - 1e-9
    assert gate[-1] == pytest.approx(lim[field], abs=1e-9)


@pytest.mark.parametrize("dP, field", [(30.0, "VELMX"), (-30.0, "VELMN")])
def test_wpidhy_gate_velocity_limits(dP, field):
    vel = dict(VELMX=0.01, VELMN=-0.01)
    s = island_system(("WPIDHY", dict(WPIDHY_ISLAND, **vel)))
    res = simulate(s, 3.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)], tol=1e-11)
    dt_ = np.diff(res.t)
    rate = np.diff(res["G.gov.GATE"])[dt_ > 0] / dt_[dt_ > 0]
    assert np.max(rate) <= vel["VELMX"] + 1e-8 and np.min(rate) >= vel["VELMN"] - 1e-8
    assert np.sum(np.abs(rate - vel[field]) < 1e-8) > 100


@pytest.mark.parametrize("dP, field", [(20.0, "PMAX"), (-30.0, "PMIN")])
def test_wpidhy_power_limits(dP, field):
    """The turbine power is clipped at PMAX / PMIN (a static limit after the water column)."""
    lim = dict(PMAX=P0 / SN + 0.02, PMIN=P0 / SN - 0.03)
    s = island_system(("WPIDHY", dict(WPIDHY_ISLAND, **lim)))
    res = simulate(s, 10.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    pm = res["G.gov.PMECH"]
    assert np.max(pm) <= lim["PMAX"] + 1e-12 and np.min(pm) >= lim["PMIN"] - 1e-12
    assert pm[-1] == pytest.approx(lim[field], abs=1e-12)
    assert res["G.tm"][-1] == pytest.approx(lim[field] * SN / 100, rel=1e-12)   # PMECH


@pytest.mark.parametrize("params, field", [
    (dict(WPIDHY, TA=0.0), "KD"),
    (dict(WPIDHY, GATMX=0.1), "GATMX"),
    (dict(WPIDHY, VELMN=0.1), "VELMX"),
    (dict(WPIDHY, P1=0.9), "P2"),
    (dict(WPIDHY, G0=0.6), "G1"),
    (dict(WPIDHY, PMAX=0.5), "PMAX"),            # tm0 = 0.6 pu beyond PMAX, at setup
    (dict(WPIDHY, GATMN=0.95), "GATMN"),
    (dict(WPIDHY, KI=0.0), "KI"),
])
def test_wpidhy_bad_data(params, field):
    with pytest.raises(DataError) as e:
        island_system(("WPIDHY", params))
    assert e.value.field == field


# =============================================================================== GGOV1
#: typical GGOV1 data (WECC / PSS/E example values; Ldref raised so that the 100-MW unit of the
#: three-bus case starts below its load limit: fsr0 = 1/1.5 + 0.2 = 0.867 < TLIM = 0.933)
GGOV1 = dict(Rselect=1, Flag=1, R=0.04, Tpelec=1.0, maxerr=0.05, minerr=-0.05, Kpgov=10.0, Kigov=2.0,
             Kdgov=0.0, Tdgov=1.0, Vmax=1.0, Vmin=0.15, Tact=0.5, Kturb=1.5, Wfnl=0.2, Tb=0.1, Tc=0.0,
             Teng=0.0, Tfload=3.0, Kpload=2.0, Kiload=0.67, Ldref=1.1, Dm=0.0, Ropen=0.1, Rclose=-0.1,
             Kimw=0.0, Aset=0.01, Ka=10.0, Ta=0.1, Trate=0.0, db=0.0, Tsa=4.0, Tsb=5.0, Rup=99.0,
             Rdown=-99.0)


@pytest.mark.parametrize("params", [
    GGOV1, dict(GGOV1, Rselect=0, R=0.0), dict(GGOV1, Rselect=-1), dict(GGOV1, Rselect=-2),
    dict(GGOV1, Flag=0, Dm=0.05, Teng=0.1, Tc=0.05, Kdgov=0.5, db=0.001, Kimw=0.01, Trate=120.0)],
    ids=["Pe", "isochronous", "governor-output", "valve-stroke", "Flag0-Dm-Teng-Tc-Kd-db-Kimw-Trate"])
def test_ggov1_initial_point_is_an_equilibrium(params):
    s = threebus_system(("GGOV1", params)).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10
    res = simulate(s, 10.0, dt=1 / 120, events=[LineTrip(0, 1.0)])
    assert res.ok and abs(res["G.omega"][-1] - 1) < 1e-4


def _ggov1_valve(gov, te, dw, i=0):
    """Valve stroke giving PMECH = Pe in the steady state (PSS/E's GENCLS: PMECH/omega = Pe/omega)."""
    p = {k: v[i] for k, v in gov.p.items()}
    w = 1 + dw
    wf = (te + p["Dm"] * w) / p["Kturb"] + p["Wfnl"]
    return wf / (w if p["Flag"] > 0 else 1.0)


@pytest.mark.slow
@pytest.mark.parametrize("rselect", [1, -1, -2, 0])
def test_ggov1_droop(rselect):
    """Rselect 1: dw = -R*dPe; -1 / -2: dw = -R*dFSR = -R*dVAL (the steady valve is the one whose
    power balances the new load, solved by fixed point); 0: isochronous (dw = 0)."""
    params = dict(GGOV1, Rselect=rselect, Trate=80.0)
    s = island_system(("GGOV1", params))
    res = simulate(s, 60.0, dt=0.02, events=[LoadStep(2, 0.5, dP=10.0)], tol=1e-11)
    gov = s.components["GGOV1"]
    kT = 80.0 / 100.0
    te0, te1 = P0 / 100 / kT, island_pe(s, 10.0) / kT             # turbine base (lossless: te = Pe)
    R = params["R"]
    if rselect == 1:
        dw = -R * (te1 - te0)
    elif rselect == 0:
        dw = 0.0
    else:
        dw = 0.0
        for _ in range(50):
            dw = -R * (_ggov1_valve(gov, te1, dw) - _ggov1_valve(gov, te0, 0.0))
    assert res["G.omega"][-1] - 1 == pytest.approx(dw, rel=1e-5, abs=1e-8)     # (1e-9 after 120 s)
    assert res["G.gov.FSR"][-1] == pytest.approx(_ggov1_valve(gov, te1, dw), rel=1e-7)


@pytest.mark.slow
def test_ggov1_supervisory_controller_held_at_its_limit():
    """Kimw > 0 in an island: Pe cannot return to Pmwset, the load controller integrates to
    -1.1*R and is held there; the speed settles at -R*dPe - 1.1*R."""
    params = dict(GGOV1, Kimw=0.2)
    s = island_system(("GGOV1", params))
    res = simulate(s, 60.0, dt=0.05, events=[LoadStep(2, 0.5, dP=10.0)], tol=1e-11)
    R = params["R"]
    assert res["G.gov.PMW"][-1] == pytest.approx(-1.1 * R, abs=1e-12)
    assert np.min(res["G.gov.PMW"]) >= -1.1 * R - 1e-12
    expected = -R * (island_pe(s, 10.0) - P0 / 100) - 1.1 * R
    assert res["G.omega"][-1] - 1 == pytest.approx(expected, rel=1e-6)


@pytest.mark.slow
def test_ggov1_load_limiter_takes_control():
    """A load limit just above the initial exhaust temperature: after the load step the load
    limiter is the low value, and its integral brings the temperature exactly to TLIM."""
    fsr0 = 0.6 / 1.5 + 0.2
    Ldref = (fsr0 + 0.02 - 0.2) * 1.5                 # TLIM = fsr0 + 0.02
    s = island_system(("GGOV1", dict(GGOV1, Ldref=Ldref)))
    # 120 s: the island GENCLS has D = 0 and PSS/E's GENCLS adds no speed damping of its own
    res = simulate(s, 120.0, dt=0.05, events=[LoadStep(2, 0.5, dP=10.0)], tol=1e-11)
    fsr, fsrt, fsrn = res["G.gov.FSR"], res["G.gov.FSRT"], res["G.gov.FSRN"]
    assert fsr[-1] == pytest.approx(fsrt[-1], abs=1e-9)
    assert res["G.gov.ERR"][-1] > 0.01 and fsrn[-1] > fsr[-1]   # the governor asks for more fuel
    assert res["G.gov.TEXM"][-1] == pytest.approx(fsr0 + 0.02, abs=1e-8)
    assert np.max(fsrn - fsr) < 0.5                   # the governor PID did not wind up


@pytest.mark.parametrize("dP, field", [(40.0, "Vmax"), (-45.0, "Vmin")])
def test_ggov1_valve_limits(dP, field):
    fsr0 = 0.6 / 1.5 + 0.2
    lim = dict(Vmax=fsr0 + 0.03, Vmin=fsr0 - 0.03, Ropen=1.0, Rclose=-1.0)
    s = island_system(("GGOV1", dict(GGOV1, **lim)))
    res = simulate(s, 10.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    val = res["G.gov.VAL"]
    assert np.max(val) <= lim["Vmax"] + 1e-9 and np.min(val) >= lim["Vmin"] - 1e-9
    assert val[-1] == pytest.approx(lim[field], abs=1e-9)
    assert res["G.gov.FSR"][-1] == pytest.approx(lim[field], abs=1e-9)


@pytest.mark.parametrize("dP, field", [(30.0, "Ropen"), (-30.0, "Rclose")])
def test_ggov1_valve_rate_limits(dP, field):
    rates = dict(Ropen=0.02, Rclose=-0.02)
    s = island_system(("GGOV1", dict(GGOV1, Aset=1.0, **rates)))
    res = simulate(s, 3.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)], tol=1e-11)
    dt_ = np.diff(res.t)
    rate = np.diff(res["G.gov.VAL"])[dt_ > 0] / dt_[dt_ > 0]
    assert np.max(rate) <= rates["Ropen"] + 1e-8 and np.min(rate) >= rates["Rclose"] - 1e-8
    assert np.sum(np.abs(rate - rates[field]) < 1e-8) > 100


@pytest.mark.parametrize("dP, field", [(30.0, "maxerr"), (-30.0, "minerr")])
def test_ggov1_error_limits(dP, field):
    lim = dict(maxerr=0.002, minerr=-0.002)
    s = island_system(("GGOV1", dict(GGOV1, Aset=1.0, **lim)))
    res = simulate(s, 5.0, dt=0.01, events=[LoadStep(2, 0.5, dP=dP)])
    err = res["G.gov.ERR"]
    assert np.max(err) <= lim["maxerr"] + 1e-15 and np.min(err) >= lim["minerr"] - 1e-15
    assert np.sum(np.abs(err - lim[field]) < 1e-15) > 50


def test_ggov1_acceleration_limiter():
    """Load rejection: the speed rises faster than Aset, the acceleration limiter takes the low
    value and the fuel demand falls at exactly Ka*(Aset - accel)."""
    params = dict(GGOV1, Aset=0.001, Ka=5.0, Rclose=-5.0, Ropen=5.0, Tact=0.05)
    s = island_system(("GGOV1", params), M=4.0)
    res = simulate(s, 3.0, dt=0.005, events=[LoadStep(2, 0.5, dP=-30.0)], tol=1e-11)
    t, fsr, fsra, acc = res.t, res["G.gov.FSR"], res["G.gov.FSRA"], res["G.gov.ACC"]
    sel = (np.abs(fsr - fsra) < 1e-12) & (res["G.gov.FSRN"] > fsr + 1e-6)
    assert np.sum(sel) > 20                                    # the limiter was in control
    ok = sel[:-1] & sel[1:] & (np.diff(t) > 0)
    dfsr = np.diff(fsr)[ok] / np.diff(t)[ok]
    target = params["Ka"] * (params["Aset"] - 0.5 * (acc[:-1] + acc[1:])[ok])
    assert np.max(np.abs(dfsr - target)) < 1e-6


def test_ggov1_engine_delay():
    """Tc = Tb = 0: PMECH is Kturb*(wf - Wfnl) Teng seconds earlier, minus Dm*(1 + dw)."""
    Teng = 0.25
    params = dict(GGOV1, Teng=Teng, Tb=0.0, Dm=0.02)
    s = island_system(("GGOV1", params))
    res = simulate(s, 6.0, dt=0.01, events=[LoadStep(2, 0.5, dP=10.0)])
    t, val, w, pm = res.t, res["G.gov.VAL"], res["G.omega"], res["G.gov.PMECH"]
    ut = params["Kturb"] * (val * w - params["Wfnl"])
    late = t > Teng
    expect = np.interp(t[late] - Teng, t, ut) - params["Dm"] * w[late]
    assert np.ptp(val) > 0.02
    assert np.max(np.abs(pm[late] - expect)) < 1e-10


@pytest.mark.parametrize("params, field", [
    (dict(GGOV1, Rselect=2), "Rselect"),
    (dict(GGOV1, Dm=-0.1), "Dm"),
    (dict(GGOV1, Vmax=0.1), "Vmax"),
    (dict(GGOV1, maxerr=-0.1), "maxerr"),
    (dict(GGOV1, Tc=0.1, Tb=0.0), "Tc"),
    (dict(GGOV1, Kdgov=1.0, Tdgov=0.0), "Kdgov"),
    (dict(GGOV1, Tact=0.0), "Tact"),
    (dict(GGOV1, Ldref=0.5), "Ldref"),          # fsr0 = 0.6 above TLIM = 0.533: load limiter in control
    (dict(GGOV1, Vmax=0.55, Vmin=0.15), "Vmax"),   # fsr0 = 0.6 beyond Vmax, at setup
    (dict(GGOV1, Flag=0.5), "Flag"),
])
def test_ggov1_bad_data(params, field):
    with pytest.raises(DataError) as e:
        island_system(("GGOV1", params))
    assert e.value.field == field


# ======================================================================= PSS/E records
#: governor records of PSID's PSS/E benchmark .dyr files (test/benchmarks/psse/*, BSD-3-Clause,
#: (c) Alliance for Sustainable Energy), after ``IBUS 'MODEL' ID``
PSID_DYR = {
    "DEGOV1": """0      0.19050      0.47600E-01  0.18000E-01
          1.0000       5.1000      0.32200       0.0000      0.0000
          99.99      -99.99      0.70000E-01  0.50000E-01  /""",
    "DEGOV": "0 0 0 18 12 5 0.2 1 2 -0.1 /",
    "PIDGOV": """1      0.50000E-01  0.10000E-01   5.0000
          1.0000      0.10000      0.50000      0.99000      0.10000E-02
         0.10000      0.70000      0.30000      0.90000      0.50000
         0.90000       1.0000      0.50000E-01   1.0000      0.60000
         0.40000E-01 -0.40000E-01    /""",
    "WPIDHY": """0.10000E-01  -0.50000E-01   3.0000      0.50000
          3.0000      0.20000E-01  0.10000E-01  0.25000E-01 -0.25000E-01
          1.0000      0.20000       3.2500       52001.       0.0000
          0.0000      0.12000      0.54500      0.40000      0.82700
         0.83000       1.0000       /""",
}


@pytest.mark.parametrize("model, expected", [
    ("DEGOV1", DEGOV1), ("DEGOV", dict(DEGOV, TD=1.0)), ("PIDGOV", dict(PIDGOV_PSID, Flag=1)),
    ("WPIDHY", WPIDHY)])
def test_psse_records_read_as_pss_e_orders_them(model, expected):
    """psse_record names the .dyr fields in PSS/E's order (ICONs first): PSID's files give the
    parameters their PSS/E documentation names (the dicts above, written from the diagrams)."""
    from weakgrid.sim.system import _registry

    cls = _registry()[model]
    fields = [float(v) for v in PSID_DYR[model].split("/")[0].split()]
    assert len(fields) == len(cls.psse_record)
    values = cls.psse_params(dict(zip(cls.psse_record, fields)), None)
    assert values == pytest.approx(expected)
    assert set(cls.psse_record) <= {p.name for p in cls.params}


def test_ggov1_record_layout():
    """GGOV1: 2 ICONs (Rselect, Flag) then 33 CONs, as PSS/E and PowerSystems.jl's PSS/E parser."""
    from weakgrid.sim.governors import GGOV1 as cls

    assert len(cls.psse_record) == 35 and cls.psse_record[:2] == ("Rselect", "Flag")
    assert cls.psse_record[-2:] == ("Rup", "Rdown") and cls.psse_record[29] == "Trate"
    assert set(cls.psse_record) == {p.name for p in cls.params} - {"Ttrack"}


#: a GGOV1 record of ACTIVSg2000_dynamics.dyr (bus 1050; Texas A&M synthetic grid ACTIVSg2000,
#: CC BY 4.0, as shipped in NREL-Sienna/PowerSystemsTestData psse_dyr/): a 107.28-MW turbine
ACTIVSG2000_GGOV1 = ("1  1  0.04  1  0.05  -0.05  21.071  0.0553  0  1  1  0.15  0.2767  1.5  0.2  0.5  "
                     "0  0  3  2  1  1  0  1  -1  0  0.01  10  0.1  107.28  0  4  5  99  -99  /")


def test_ggov1_activsg2000_record():
    """One of ACTIVSg2000's 367 GGOV1 records (all Rselect = 1, Flag = 1, Dm = 0, with a turbine
    rating Trate) read through psse_record: at rest on the turbine base, then the line trip of
    PSID's benchmark; the speed settles on the infinite bus."""
    from weakgrid.sim.governors import GGOV1 as cls

    fields = [float(v) for v in ACTIVSG2000_GGOV1.split("/")[0].split()]
    params = cls.psse_params(dict(zip(cls.psse_record, fields)), None)
    assert params["Trate"] == 107.28 and params["Kpgov"] == 21.071
    s = threebus_system(("GGOV1", params)).setup()
    worst, dw = at_rest(s)
    assert worst < 1e-9 and dw < 1e-10
    gov = s.components["GGOV1"]
    fsr0 = (100.0 / 107.28) / 1.5 + 0.2                     # PMECH0 = 100 MW on the 107.28-MW base
    assert s.z0[gov.idx("VAL")][0] == pytest.approx(fsr0, rel=1e-9)
    res = simulate(s, 20.0, dt=1 / 120, events=[LineTrip(0, 1.0)])
    assert res.ok and abs(res["G.omega"][-1] - 1) < 1e-5
    assert np.max(res["G.gov.VAL"]) <= 1.0 + 1e-12



#: small-signal eigenvalues of PSID's test cases 58 (GENROU + SEXS + PIDGOV, Flag 0 / 1) and 60
#: (GENROU + SEXS + WPIDHY), 70 MW at bus 102 (test/results/results_eigenvalues.jl, BSD-3-Clause,
#: (c) Alliance for Sustainable Energy)
PSID_HYDRO_EIGS = {
    ("PIDGOV", 0): [-99.99999037034084, -41.17481961789709, -38.789855128930164, -5.647427439841257,
                    -3.8982943228132214 - 1.5754284098308229j, -3.8982943228132214 + 1.5754284098308229j,
                    -2.000000000000001, -0.9492553729947647, -0.8686675700247483 - 8.496111510550772j,
                    -0.8686675700247483 + 8.496111510550772j, -0.28282148961179976 - 1.1097759323927108j,
                    -0.28282148961179976 + 1.1097759323927108j, -0.1975067616652887 - 0.17956822187766j,
                    -0.1975067616652887 + 0.17956822187766j, -0.11697960134622151],
    ("PIDGOV", 1): [-100.00010646060846, -41.17482850153586, -38.789870976223455, -5.718238174509167,
                    -3.7935658880265133, -2.0454156913133885, -1.9999999999999976,
                    -1.2228555790477964 - 0.7200047656459937j, -1.2228555790477964 + 0.7200047656459937j,
                    -0.9655206559688869, -0.9001334037955144 - 8.447836359367825j,
                    -0.9001334037955144 + 8.447836359367825j, -0.19849913626541832 - 0.17939599481963514j,
                    -0.19849913626541832 + 0.17939599481963514j, -0.04238523317744444],
    ("WPIDHY", None): [-106.13231871102334, -91.13024819676329, -63.8688081304463, -40.03565106938418,
                       -38.75323547447537 - 8.125818822049656j, -38.75323547447537 + 8.125818822049656j,
                       -6.104826779980879, -1.395127240875047 - 5.966607970662552j,
                       -1.395127240875047 + 5.966607970662552j, -0.9449531063097173, -0.48179149983179287,
                       -0.1941504953444676 - 0.18213498194497163j, -0.1941504953444676 + 0.18213498194497163j,
                       -0.03057660237077197 - 0.30118043163774183j, -0.03057660237077197 + 0.30118043163774183j],
}


@pytest.mark.parametrize("model, flag", list(PSID_HYDRO_EIGS), ids=["PIDGOV-power", "PIDGOV-gate", "WPIDHY"])
def test_hydro_pid_eigenvalues_as_psid(model, flag):
    """The small-signal eigenvalues of PSID's PIDGOV / WPIDHY cases (with their SEXS and GENROU)
    equal PSID's (PSID's own test tolerance 1e-3 on the norm)."""
    params = dict(PIDGOV_PSID, Flag=flag) if model == "PIDGOV" else WPIDHY
    s = threebus_system((model, params), hydro=True).setup()
    ev = state_matrix_eigs(s)
    ref = np.sort_complex(np.array(PSID_HYDRO_EIGS[(model, flag)], dtype=complex))
    assert len(ev) == len(ref)
    assert np.linalg.norm(ev - ref) < 1e-3
