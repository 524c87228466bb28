"""Is the DPsim GTI's larger dc-link swing physical or the co-simulation's? (issue 25)

The reference without co-simulation: the GTI grid of ``test_emt_gti`` (a GTI behind its
coupling reactance ``1/B``, a short R-L line to its reference bus — a load, R in parallel
with L — and an R-L line to an infinite bus) written as *one* ODE in the synchronous frame
(dynamic phasors, pu): weakgrid's own GTI equations (``GTI.compute``/``GTI.finish``) with the
power the source delivers, ``Re(Es conj(I))``, and every inductor's current a state,

    (X/w) dI/dt = v_from - v_to - (R + jX) I,

the node voltages algebraic (KCL: through the load's resistor where a node has one, else
``sum dI/dt = 0``), integrated by scipy's DOP853 at ``rtol = 1e-9`` — no delay, no explicit
coupling. Its quasi-static form (``dI/dt`` terms dropped: ``(R + jX) I = v_from - v_to``) is
the phasor engine's model. Oracles:

* the quasi-static ODE reproduces the phasor engine (the reference is the same grid);
* the DPsim DP run with ``gti_power = "measured"`` converges to the full ODE as its step is
  refined (100 µs → 20 µs) — so its swing, 3.4 times the phasor engine's, is the network's
  inductor dynamics, not the co-simulation's one-step delay or forward Euler;
* the eigenvalues: the phasor model's energy-control mode is undamped (``±20.2j``), the
  network's inductors make it slightly unstable (``+0.07 ± 20.2j``); in ``pq`` mode the
  phasor model is stable and the full ODE has a pair ``≈ +218 ± 551j`` — the reason the PQ
  GTI diverges in DPsim before any event, and why the DPsim bridge refuses it with measured
  power.
"""

import math

import numpy as np
import pytest

from weakgrid.sim.component import Context
from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402
from weakgrid.sim.emt.topology import _shunt_admittance  # noqa: E402

from test_emt_gti import _system  # noqa: E402

pytestmark = pytest.mark.emt

T_ON, T_OFF, T_END = 0.1, 0.15, 0.6
XF = 0.1
STIFF = 3                     # the infinite bus's external number


class Reference:
    """The GTI grid as one ODE (``quasi=False``) or with the network algebraic (``quasi=True``).

    States: weakgrid's state vector (the GTI's), then (full ODE only) the real and imaginary
    parts of every branch current [pu on Sb]: the coupling ``1/B`` (from the source ``Es``),
    the network's branches, each load's inductance to ground, a fault branch while it is on.
    """

    def __init__(self, system, quasi=False):
        self.s, self.quasi = system, quasi
        net = system.network
        self.w = 2 * math.pi * net.f_hz
        g = self.g = system.components["GTI"]
        self.b, self.r = int(g.bus[0]), int(g.ref[0])
        self.Vpf = V = np.asarray(net.pf.V, complex)
        k = int(net.index_of(STIFF))
        self.stiff = {k: V[k]}
        y = _shunt_admittance(system)
        self.G = y.real
        self.br = [("E", self.b, 0.0, 1.0 / float(g.p["B"][0]))]
        for row in net.branch:
            self.br.append((int(net.index_of(int(row[0]))), int(net.index_of(int(row[1]))),
                            float(row[2]), float(row[3])))
        self.br += [(n, "G", 0.0, -1.0 / y[n].imag) for n in range(len(V))
                    if n not in self.stiff and y[n].imag < 0]
        self.nbase = len(self.br)
        Es0 = g.Vs0[0] * np.exp(1j * (np.angle(V[self.r]) + g.phi0[0]))
        self.I0 = np.array([(self._v(a, V, Es0) - self._v(c, V, Es0)) / complex(R, X)
                            for a, c, R, X in self.br])
        self.free = [n for n in range(len(V)) if n not in self.stiff]

    def _v(self, n, v, Es):
        return Es if n == "E" else 0.0 if n == "G" else v[n]

    def z0(self):
        x = np.array(self.s.z0[:self.s.nx], float)
        if self.quasi:
            return x
        return np.concatenate([x, np.column_stack([self.I0.real, self.I0.imag]).ravel()])

    def fault(self, on):
        """Switch the fault branch (``j XF`` at the reference bus) on or off."""
        if on:
            self.br.append((self.r, "G", 0.0, XF))
        else:
            del self.br[self.nbase:]

    def _network(self, I, Es):
        """Full ODE: ``(dI/dt, v)``; quasi-static: ``(I, v)``."""
        nb, pos = len(self.br), {n: i for i, n in enumerate(self.free)}
        m = nb + len(pos)
        A, rhs = np.zeros((m, m), complex), np.zeros(m, complex)
        for k, (a, c, R, X) in enumerate(self.br):
            if self.quasi:
                A[k, k] = complex(R, X)
            else:
                A[k, k], rhs[k] = X / self.w, -complex(R, X) * I[k]
            for n, sg in ((a, 1), (c, -1)):
                if n in pos:
                    A[k, nb + pos[n]] = -sg
                elif n == "E":
                    rhs[k] += sg * Es
                elif n in self.stiff:
                    rhs[k] += sg * self.stiff[n]
        for n, i in pos.items():
            derivative = self.G[n] == 0 and not self.quasi
            if not derivative:
                A[nb + i, nb + i] = self.G[n]
            for k, (a, c, _, _) in enumerate(self.br):
                sg = 1 if a == n else -1 if c == n else 0
                if derivative or self.quasi:
                    A[nb + i, k] += sg
                else:
                    rhs[nb + i] -= sg * I[k]
        u = np.linalg.solve(A, rhs)
        v = self.Vpf.copy()
        for n, i in pos.items():
            v[n] = u[nb + i]
        return u[:nb], v

    def rhs(self, t, z):
        s, g = self.s, self.g
        x = z[:s.nx]
        I = None if self.quasi else z[s.nx::2] + 1j * z[s.nx + 1::2]
        th = float(np.angle(self.Vpf[self.r]))
        for _ in range(100):        # the ideal PLL's angle: a fixed point (the source moves it)
            V = self.Vpf.copy()
            V[self.r] = np.exp(1j * th)
            ctx = Context(s, t, x, V)
            g.compute(ctx)
            Es = complex(g._Vs[0] * np.exp(1j * (th + g._phis[0])))
            u, v = self._network(I, Es)
            th_new = float(np.angle(v[self.r]))
            if abs(th_new - th) < 1e-14:
                break
            th = th_new
        ctx = Context(s, t, x, v)
        g.compute(ctx)
        Es = complex(g._Vs[0] * np.exp(1j * (np.angle(v[self.r]) + g._phis[0])))
        Ic = u[0] if self.quasi else I[0]
        g._Pac = np.array([(Es * np.conj(Ic)).real])
        g._Q = np.array([(v[self.b] * np.conj(Ic)).imag])
        g.finish(ctx)
        if self.quasi:
            return ctx.f
        return np.concatenate([ctx.f, np.column_stack([u.real, u.imag]).ravel()])

    def eigenvalues(self, h=1e-7):
        """Of the Jacobian at the power flow (central differences)."""
        z = self.z0()
        J = np.column_stack([(self.rhs(0.0, z + e) - self.rhs(0.0, z - e)) / (2 * h)
                             for e in h * np.eye(len(z))])
        return np.linalg.eigvals(J)

    def fault_run(self):
        """The fault ``j XF`` at the reference bus over ``[T_ON, T_OFF)``: ``max |Vc - 1|``
        [pu] over ``[0, T_END]`` (the fault's inductor current starts at zero and is cut at
        clearing)."""
        from scipy.integrate import solve_ivp

        z, peak = self.z0(), 0.0
        kvc = int(self.g.idx("Vc")[0])
        for t0, t1, on in ((0.0, T_ON, False), (T_ON, T_OFF, True), (T_OFF, T_END, False)):
            self.fault(on)
            n = self.s.nx + (0 if self.quasi else 2 * len(self.br))
            z = np.concatenate([z, np.zeros(max(0, n - len(z)))])[:n]
            sol = solve_ivp(self.rhs, (t0, t1), z, method="DOP853", rtol=1e-9, atol=1e-10,
                            max_step=2e-3)
            assert sol.success, sol.message
            peak = max(peak, float(np.max(np.abs(sol.y[kvc] - 1.0))))
            z = sol.y[:, -1]
        return peak


def _peak(r):
    return float(np.max(np.abs(r["PV.Vc"] - 1.0)))


@pytest.fixture(scope="module")
def peaks():
    ev = [Fault(bus=2, t_on=T_ON, t_off=T_OFF, xf=XF)]
    out = {"ode": Reference(_system()).fault_run(),
           "quasi": Reference(_system(), quasi=True).fault_run(),
           "phasor": _peak(simulate(_system(), T_END, dt=1e-4, events=ev))}
    for p, dt in (("measured", 1e-4), ("measured", 2e-5), ("model", 1e-4)):
        out[p, dt] = _peak(simulate_dpsim(_system(), T_END, engine="dpsim-dp", dt=dt, events=ev,
                                          gti_power=p))
    return out


def test_quasi_static_reference_is_the_phasor_engine(peaks):
    """The reference's grid and GTI are the phasor engine's (measured: 0.13278 both)."""
    assert peaks["quasi"] == pytest.approx(peaks["phasor"], rel=1e-3), peaks


def test_measured_power_converges_to_the_one_ode_reference(peaks):
    """DP with measured power against the ODE without co-simulation (measured: ODE 0.45206;
    DP 0.45121, 0.45157, 0.45187, 0.45198 at 100, 50, 20, 10 µs): within 0.3 % at 100 µs and
    closer at 20 µs, while the phasor engine is 3.4 times smaller — the swing is physical."""
    ode = peaks["ode"]
    err = {dt: abs(peaks["measured", dt] - ode) for dt in (1e-4, 2e-5)}
    assert err[1e-4] < 3e-3 * ode, peaks
    assert err[2e-5] < 0.5 * err[1e-4], peaks
    assert ode > 3.0 * peaks["phasor"], peaks
    # the model power is the one off the reference (blind to the inductors' currents)
    assert abs(peaks["model", 1e-4] - ode) > 0.5 * ode, peaks


def test_inductor_dynamics_shift_the_gti_modes():
    """Energy control: the phasor model's dc-link/angle mode is undamped (the law has no
    damping term), the inductors make it grow slowly. PQ control: stable in phasors, a pair far
    in the right half-plane with the inductors (the P loop acting through the network's
    60-Hz mode)."""
    def spectrum(mode, quasi):
        lam = Reference(_system(mode), quasi=quasi).eigenvalues()
        return lam[np.abs(lam) > 1e-6]

    ph = spectrum("energy", True)
    assert np.max(np.abs(ph.real)) < 1e-3 and np.max(np.abs(ph.imag)) == pytest.approx(20.2, abs=0.1)
    full = spectrum("energy", False)
    slow = full[np.abs(full.imag - 20.2) < 1.0]
    assert len(slow) == 1 and 0.02 < slow[0].real < 0.2, full
    assert np.max(spectrum("pq", True).real) < 1e-6
    assert np.max(spectrum("pq", False).real) > 100.0


def test_pq_gti_with_measured_power_is_refused():
    """Its DPsim result is the instability above, not the PQ baseline's response."""
    with pytest.raises(DataError, match="gti_power"):
        simulate_dpsim(_system("pq"), 0.01, engine="dpsim-dp")
    r = simulate_dpsim(_system("pq"), 0.05, engine="dpsim-dp", gti_power="model")
    assert _peak(r) < 1e-3
