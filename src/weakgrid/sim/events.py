"""Timed events: three-phase bus faults, branch trips, generator trips and load steps.

Events are applied exactly at their time: the integrator steps onto ``t``,
calls :meth:`Event.apply`, and re-solves the network with the states fixed.
All events are validated against the system before the run starts, so that a
fault on a missing bus fails immediately with a :class:`DataError`.
"""

from __future__ import annotations

import numpy as np

from .errors import DataError


class Event:
    """Base class: something that happens at time ``t`` [s]."""

    t: float = 0.0

    def validate(self, system):
        if not np.isfinite(self.t) or self.t < 0:
            raise DataError(repr(self), "t", self.t, "event times must be finite and >= 0 s")

    def apply(self, sim):
        raise NotImplementedError


class _FaultSwitch(Event):
    def __init__(self, owner, t, on):
        self.owner, self.t, self.on = owner, float(t), on

    def validate(self, system):
        Event.validate(self, system)
        self.owner.validate(system)

    def apply(self, sim):
        s = sim.sys
        b = s.network.index_of(self.owner.bus)
        nx = s.nx
        if self.on:
            self.owner._y_pre = sim.z[nx:].copy()
        elif getattr(self.owner, "_y_pre", None) is not None:
            # as ANDES: start the post-clearing network solution from the pre-fault voltages
            sim.z = sim.z.copy()
            sim.z[nx:] = self.owner._y_pre
        s.fault_shunt[b] += self.owner.y if self.on else -self.owner.y
        if not self.on and abs(s.fault_shunt[b]) < 1e-9:
            s.fault_shunt[b] = 0.0
        s.update_network()

    def __repr__(self):
        return f"{'FaultOn' if self.on else 'FaultOff'}(bus={self.owner.bus}, t={self.t})"


class Fault:
    """Three-phase fault at a bus through ``rf + j xf`` [pu], from ``t_on`` to ``t_off`` [s].

    Parameters
    ----------
    bus : int
        External bus number (MATPOWER ``BUS_I``).
    t_on, t_off : float
        Application and clearing times [s]; ``t_off=None`` for a permanent fault.
    rf, xf : float
        Fault resistance and reactance [pu on the system base] (ANDES default ``xf = 1e-4``).
    """

    def __init__(self, bus, t_on, t_off=None, rf=0.0, xf=1e-4):
        self.bus, self.t_on, self.t_off, self.rf, self.xf = bus, float(t_on), t_off, float(rf), float(xf)

    @property
    def y(self):
        return 1.0 / complex(self.rf, self.xf)

    def validate(self, system):
        el = f"Fault at bus {self.bus}"
        system.network.index_of(self.bus, el, "bus")
        if self.rf < 0 or self.xf < 0 or (self.rf == 0 and self.xf == 0):
            raise DataError(el, "xf", self.xf, "fault impedance rf + j xf must be non-zero with rf, xf >= 0")
        if self.t_off is not None and not self.t_off > self.t_on:
            raise DataError(el, "t_off", self.t_off, f"clearing time must be after t_on = {self.t_on} s")

    def parts(self):
        out = [_FaultSwitch(self, self.t_on, True)]
        if self.t_off is not None:
            out.append(_FaultSwitch(self, float(self.t_off), False))
        return out


class LineTrip(Event):
    """Open (or re-close) branch ``branch`` (0-based row of the branch table) at ``t`` [s]."""

    def __init__(self, branch, t, close=False):
        self.branch, self.t, self.close = branch, float(t), close

    def validate(self, system):
        Event.validate(self, system)
        nl = system.network.nl
        if not isinstance(self.branch, (int, np.integer)) or not 0 <= self.branch < nl:
            raise DataError(f"LineTrip at t={self.t}", "branch", self.branch, f"give a branch row 0..{nl - 1}")

    def apply(self, sim):
        sim.sys.branch_status[self.branch] = bool(self.close)
        sim.sys.update_network()

    def __repr__(self):
        return f"LineTrip(branch={self.branch}, t={self.t}, close={self.close})"


class GeneratorTrip(Event):
    """Disconnect the unit on gen-table row ``gen`` (0-based) at ``t`` [s]: PSS/E's machine
    trip, PSID's ``GeneratorTrip``.

    The unit is the machine or converter on that row (all models sharing it) with its controls
    (exciter, governor, stabilizer, REECA1/REECB1, REPCA1, ...): from ``t`` on it injects no
    current, its states are frozen and its power outputs record zero
    (:mod:`weakgrid.sim.disconnect`). The network itself is unchanged (the row's bus stays).
    A PSS/E unit (bus, id) is row ``system.psse_gen_row[(bus, id)]`` of a system read by
    :func:`weakgrid.sim.io.psse.from_psse`.
    """

    def __init__(self, gen, t):
        self.gen, self.t = gen, float(t)

    def validate(self, system):
        Event.validate(self, system)
        ng = system.network.gen.shape[0]
        if not isinstance(self.gen, (int, np.integer)) or not 0 <= self.gen < ng:
            raise DataError(repr(self), "gen", self.gen, f"give a gen-table row 0..{ng - 1}")
        from .disconnect import unit_instances

        unit_instances(system, int(self.gen))   # a row without models, or with a source: refused now

    def apply(self, sim):
        sim.sys.disconnect_unit(int(self.gen))

    def __repr__(self):
        return f"GeneratorTrip(gen={self.gen}, t={self.t})"


class LoadStep(Event):
    """Add ``dP + j dQ`` [MW, Mvar, at the power-flow voltage] of constant-impedance load at ``bus``."""

    def __init__(self, bus, t, dP=0.0, dQ=0.0):
        self.bus, self.t, self.dP, self.dQ = bus, float(t), float(dP), float(dQ)

    def validate(self, system):
        Event.validate(self, system)
        system.network.index_of(self.bus, f"LoadStep at t={self.t}", "bus")

    def apply(self, sim):
        s = sim.sys
        b = s.network.index_of(self.bus)
        V0 = s.network.pf.V[b]
        s.y_load[b] += np.conj(complex(self.dP, self.dQ) / s.Sb) / abs(V0) ** 2
        s.update_network()


def flatten(events):
    """Expand composite events (e.g. :class:`Fault`) into elementary timed events."""
    out = []
    for e in events:
        out.extend(e.parts() if hasattr(e, "parts") else [e])
    return out


def prepare(events, system, t_end: float) -> list:
    """A run's events checked against ``system`` and ``t_end`` [s] and flattened into
    elementary events in time order (what the integrator and the batch step onto).

    Raises :class:`DataError` for an event after ``t_end`` or one that does not fit the
    system (a missing bus, branch or unit)."""
    events = list(events)
    for ev in flatten(events):
        if ev.t > t_end:
            raise DataError(repr(ev), "t", ev.t, f"the event comes after the end of the run "
                            f"(t_end = {t_end:g} s): move it earlier or simulate longer")
    for ev in events:
        if hasattr(ev, "parts"):
            ev.validate(system)
    events = sorted(flatten(events), key=lambda e: e.t)
    for ev in events:
        ev.validate(system)
    return events
