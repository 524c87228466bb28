"""weakgrid events → DPsim switches and switch events.

* :class:`~weakgrid.sim.events.Fault` (three-phase to ground at a bus): a DPsim ``Switch`` from the
  bus to ground, open before ``t_on``, closed by a switch event at ``t_on``, opened at ``t_off``.
  DPsim's switch is resistive, so a fault is mapped only when it is *bolted*,
  ``|rf + j xf| <= BOLTED_MAX`` [pu] (weakgrid's default ``xf = 1e-4``): its closed resistance is
  ``|rf + j xf| Zb`` [Ω] — at that size the impedance's angle does not change the run. A larger
  fault impedance is refused (field ``xf``/``rf``), not replaced by a resistance.
* a fault at a bus joined to the rest only by inductive branches (no load or shunt conductance,
  no machine, no source) is refused: opening the switch interrupts the difference of the branch
  currents, which then has no path but the open switch, and DPsim's trapezoidal rule rings
  undamped (measured: 9 pu at the bus, period 2 dt, after clearing). A load or a shunt
  conductance at the bus gives that current a path.
* every other event (line trips, generator trips, load steps) is refused naming it.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ..events import Fault

#: largest fault impedance [pu on the system base] mapped to DPsim's resistive switch
BOLTED_MAX = 1e-3
#: open-switch resistance [pu on the bus base impedance]
OPEN_PU = 1e7


def build_events(system, kit, cir, events):
    """Add a fault switch per :class:`Fault` to ``cir`` and return the DPsim switch events.

    Parameters
    ----------
    system : weakgrid.sim.system.System
    kit : weakgrid.sim.emt.dpsim_module.Kit
    cir : weakgrid.sim.emt.topology.Circuit
    events : list
        weakgrid events.
    """
    from .topology import bus_base

    _, Zb = bus_base(system)
    out = []
    for j, ev in enumerate(events or ()):
        if not isinstance(ev, Fault):
            raise DataError(f"event {j}", "kind", type(ev).__name__,
                            "the DPsim engines map three-phase bus faults (Fault) only so far")
        ev.validate(system)
        z = abs(complex(ev.rf, ev.xf))
        if z > BOLTED_MAX:
            raise DataError(f"Fault at bus {ev.bus}", "xf" if ev.xf >= ev.rf else "rf", max(ev.xf, ev.rf),
                            f"DPsim's fault switch is resistive; only a bolted fault "
                            f"(|rf + j xf| <= {BOLTED_MAX:g} pu) is mapped")
        b = system.network.index_of(ev.bus, f"Fault at bus {ev.bus}", "bus")
        if ev.t_off is not None and b not in _damped_buses(system):
            raise DataError(f"Fault at bus {ev.bus}", "bus", ev.bus,
                            "clearing a fault at a bus with only inductive branches (no load or "
                            "shunt conductance, machine or source) rings undamped in DPsim's "
                            "trapezoidal rule; fault a bus with a load, or add a shunt "
                            "conductance (GS) there")
        sw = kit.ph.Switch(f"fault{j}", kit.d.LogLevel.off)
        sw.set_parameters(kit.param(OPEN_PU * Zb[b]), kit.param(z * Zb[b]))
        sw.open()
        sw.connect([kit.gnd, cir.nodes[b]])
        cir.components.append(sw)
        out.append(kit.event(ev.t_on, sw, True))
        if ev.t_off is not None:
            out.append(kit.event(float(ev.t_off), sw, False))
    return out


def _damped_buses(system) -> set:
    """Bus positions with a resistive shunt (load or GS > 0), a machine or an ideal source."""
    net = system.network
    from ..network import GS

    g = net.load_admittance(net.pf.V).real + net.bus[:, GS] / system.Sb
    out = {int(b) for b in np.nonzero(g > 0)[0]}
    for c in system.components.values():
        if c.kind == "machine" or c.type_name == "InfiniteBus":
            out.update(int(b) for b in np.atleast_1d(c.bus))
    return out
