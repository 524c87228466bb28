"""The grid-tie inverter (:class:`weakgrid.sim.gti.GTI`) in DPsim: co-simulation in the step loop.

DPsim has no GTI with weakgrid's dc link and phase control, but the GTI's network side is
circuit elements DPsim has: the inverter's ac voltage ``Es`` behind its coupling reactance
``1/B``. Each GTI becomes

* a DPsim ``VoltageSource`` from ground to an internal node, its set point ``Es`` [pu of the
  bus base, line-to-line RMS phasor scale as every node], and
* an ``Inductor`` of reactance ``1/B`` [pu on ``Sb``] from that node to the GTI's bus,

while its own dynamics — the dc link ``C Vc dVc/dt = Pin − Pe``, the phase control (``energy``:
``dϕ̂/dt = υ``; ``pq``: the PID loops, filters and the dc-voltage loop), the modulation limit
``ks_max`` — are weakgrid's own :class:`~weakgrid.sim.gti.GTI` equations
(:meth:`~weakgrid.sim.gti.GTI.compute`, :meth:`~weakgrid.sim.gti.GTI.finish`, unchanged),
evaluated between DPsim steps from the *measured* terminal quantities:

* the bus voltages ``V`` and the angle ``theta_r`` of the reference (UPQC shunt) bus: the
  DPsim node phasors (EMT: the space vector in the synchronous frame);
* the ac power ``P_ac = Re(Es conj(I))`` and ``Q = Im(V conj(I))`` with ``I`` the measured
  inductor current and ``Es`` the set point the source held over the last step — the power the
  DPsim source actually delivered, so the energy leaving the dc link is the energy the network
  received (``power="measured"``, the default). With ``power="model"`` the dc link pays
  weakgrid's model's own power, ``I = -jB(Es - V)`` at the measured ``V`` (the phasor
  engine's coupling), blind to the coupling inductor's current transients — which the
  network still receives from the source: not energy-consistent, but it isolates what the
  dc link's sight of those transients does (docs/engines.md: on the case-1 grid it is the whole
  difference to the phasor engine).

``measured`` is the physics of this circuit, not a co-simulation artefact: on a test grid it
converges in the step to the same circuit written as one ODE without delay
(``tests/sim/test_emt_gti_reference.py``; docs/engines.md). A GTI in ``pq`` mode is refused
with ``measured`` power: its P loop is unstable with the network's inductor dynamics, so the run
would show that instability rather than the PQ baseline.

Time stepping (stated, not hidden): at ``t_k`` the GTI states ``x_k`` and the measurements
give the derivatives; the states advance by forward Euler, ``x_{k+1} = x_k + dt f_k``, and the
new set point ``Es_k`` (from ``x_k`` and ``theta_r(t_k)``) is held by the DPsim source over
``[t_k, t_{k+1}]`` — a one-step delay (``dt`` = 1e-4 s by default, against the GTI's fastest
time constant ``Td`` = 10 ms). The phasor engine solves the same equations implicitly with
the network algebraic.

A reduced UPQC (:mod:`weakgrid.sim.emt.upqc`) draws its series power from the GTI's dc link:
``C Vc dVc/dt = Pin − Pe − P_series`` with ``P_series`` the power its series source delivered
over the last step (weakgrid's ``gti_p_series`` signal, set between ``compute`` and
``finish``).
"""

from __future__ import annotations

import math

import numpy as np

from ..component import Context
from ..errors import DataError

#: recorded GTI signals (the phasor engine's names ``<gti>.<name>``): states, then outputs
STATES = ("Vc", "phi_hat")
OUTPUTS = ("Vs", "ks", "phi_s", "P_ac", "Q", "Pe", "upsilon", "dVc", "P_series")
_KINDS = {"Vc": "pu", "phi_hat": "angle", "Vs": "pu", "ks": "pu", "phi_s": "angle",
          "P_ac": "power", "Q": "power", "Pe": "power", "upsilon": "pu", "dVc": "pu",
          "P_series": "power"}


def check_gti(system, power: str = "measured") -> None:
    """Refuse what the DPsim GTI cannot run: an unknown ``power`` coupling, or a PQ-mode GTI
    with ``power="measured"`` (its PQ loops act on the current of an ideal source behind
    ``1/B`` and are unstable with the network's inductor dynamics; docs/engines.md)."""
    if power not in ("measured", "model"):
        raise DataError("simulate_dpsim", "gti_power", power, "use 'measured' or 'model'")
    g = system.components.get("GTI")
    if power == "measured" and g is not None and g.n and g.pq.any():
        i = int(np.nonzero(g.pq)[0][0])
        raise DataError(g.element(i), "mode", "pq", "with gti_power = 'measured' its PQ "
                        "loops act on the current of an ideal source behind 1/B and are "
                        "unstable with the network's inductor dynamics (docs/engines.md: a "
                        "pair at +218 ± 551j 1/s on the test grid), so the run would show "
                        "that instability, not the PQ baseline; use gti_power = 'model' or "
                        "the energy mode")


class GTIBridge:
    """Every GTI of a system as a DPsim source behind its coupling reactance, driven by
    weakgrid's GTI equations between steps.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up.
    kit : weakgrid.sim.emt.dpsim_module.Kit
    cir : weakgrid.sim.emt.topology.Circuit
        The translated network (its nodes, components and initial phasors ``Vpf`` [V]).
    """

    def __init__(self, system, kit, cir, power="measured"):
        from .topology import bus_base

        check_gti(system, power)
        self.power = power
        self.system, self.kit = system, kit
        self.g = g = system.components.get("GTI")
        self.items = []
        if g is None or g.n == 0:
            return
        check_gti(system, power)
        net = system.network
        w = 2 * math.pi * net.f_hz
        Vb, Zb = bus_base(system)
        self.Vb = Vb
        self.x = np.array(system.z0[:system.nx], float)     # weakgrid's state vector
        off = kit.d.LogLevel.off
        Vpf = net.pf.V
        for i, nm in enumerate(g.names):
            b, r = int(g.bus[i]), int(g.ref[i])
            Es0 = g.Vs0[i] * np.exp(1j * (np.angle(Vpf[r]) + g.phi0[i]))      # pu
            mid = kit.node(f"{nm}.Es", Es0 * Vb[b])
            cir.extra_nodes.append(mid)
            src = kit.ph.VoltageSource(f"{nm}.src", off)
            kit.set_source(src, "V_ref", Es0 * Vb[b], init=True, f=net.f_hz)
            src.connect([kit.gnd, mid])
            ind = kit.ph.Inductor(f"{nm}.L", off)
            ind.set_parameters(kit.param(Zb[b] / (float(g.p["B"][i]) * w)))
            ind.connect([mid, cir.nodes[b]])
            cir.components += [src, ind]
            self.items.append(dict(name=nm, i=i, bus=b, src=src, ind=ind, Es=Es0,
                                   ib=system.Sb * 1e6 / Vb[b]))

    def _evaluate(self, V, I, p_series=None):
        """weakgrid's GTI equations at the current states, the measured bus voltages ``V`` [pu]
        and inverter currents ``I`` [pu, into the bus], the reduced UPQCs' draw ``p_series``
        [pu, per GTI]: ``(ctx, Es)``."""
        g = self.g
        ctx = Context(self.system, 0.0, self.x, np.asarray(V, complex))
        g.compute(ctx)
        if p_series is not None:
            ctx.sig["gti_p_series"] = np.asarray(p_series, float)
        if self.power == "measured":
            Es_applied = np.array([it["Es"] for it in self.items])
            g._Pac = (Es_applied * np.conj(I)).real
            g._Q = (ctx.V[g.bus] * np.conj(I)).imag
        g.finish(ctx)
        th_r = np.angle(ctx.V[g.ref])
        Es = g._Vs * np.exp(1j * (th_r + g._phis))
        return ctx, Es

    def update(self, dt, phasors, current_of, p_series=None):
        """At a measurement instant ``t_k``: evaluate every GTI at its states ``x_k`` and the
        measured bus ``phasors`` [pu, one per bus position] and inverter currents, advance the
        states to ``x_{k+1}`` (forward Euler over ``dt`` [s]) and set each source for the next
        step; return the signals at ``t_k``, ``{"<gti>.<signal>": value}``. ``p_series``: the
        dc power [pu] the reduced UPQCs draw from each GTI (None: none)."""
        if not self.items:
            return {}
        g = self.g
        I = np.array([current_of(it["ind"]) / it["ib"] for it in self.items])
        ctx, Es = self._evaluate(phasors, I, p_series)
        rec = self._record(ctx)
        for k in range(len(g.states)):
            sl = g.sl(k)
            self.x[sl] = self.x[sl] + dt * ctx.f[sl]
        for it, e in zip(self.items, Es):
            it["Es"] = complex(e)
            self.kit.set_source(it["src"], "V_ref", e * self.Vb[it["bus"]])
        return rec

    def _record(self, ctx):
        g = self.g
        out = {}
        for it in self.items:
            i, nm = it["i"], it["name"]
            for s in STATES:
                out[f"{nm}.{s}"] = float(ctx.x[g.idx(s)[i]])
            for o in OUTPUTS:
                out[f"{nm}.{o}"] = float(np.asarray(ctx.out[f"GTI.{o}"])[i])
        return out

    def names(self):
        """``[(signal, kind)]`` recorded per GTI, in :meth:`update`'s order."""
        return [(f"{it['name']}.{s}", _KINDS[s]) for it in self.items for s in STATES + OUTPUTS]
