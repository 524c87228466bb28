"""weakgrid events → DPsim switches and switch events.

* :class:`~weakgrid.sim.events.Fault` (three-phase to ground at a bus): a DPsim ``Switch`` from the
  bus to ground, open before ``t_on``, closed by a switch event at ``t_on``, opened at ``t_off``.
  DPsim's switch is resistive: a *bolted* fault, ``|rf + j xf| <= BOLTED_MAX`` [pu] (weakgrid's
  default ``xf = 1e-4``), or a purely resistive one (``xf = 0``) is the switch alone, its closed
  resistance ``|rf + j xf| Zb`` [Ω] (at that size the impedance's angle does not change the
  run). Any other fault impedance is the switch (closed: ``1e-6`` pu) in series with ``rf`` and
  ``xf`` as a resistor and an inductor to ground, and a damping resistor
  ``R_p = FAULT_DAMP |rf + j xf|`` across them: without it the fault inductor's current, cut
  when the switch opens, has no path but the open switch's ``OPEN_PU`` (its trapezoidal factor
  ``(1 - dt/2τ)/(1 + dt/2τ)``, ``τ = L/R``, then tends to −1: undamped alternation); with it
  the factor is −0.9 at 1e-4 s (gone in a few ms). ``R_p`` changes the fault impedance by
  ``1/FAULT_DAMP`` = 0.1 % (stated, not hidden); measured on the SMIB of
  ``tests/sim/test_emt_events.py`` (j0.05 pu for 0.1 s): the speed peak moves by 0.007 %
  between ``R_p = 1e3 |z|`` and ``1e9 |z|``, and no ringing reaches the bus either way (a guard
  for the fault branch's own node). The faulted bus's voltage with a permanent fault is the
  phasor engine's to 1.1e-4 pu (the test's oracle).
* a fault at a bus joined to the rest only by inductive branches (no load or shunt conductance,
  no machine, no source) is refused: opening the switch interrupts the difference of the branch
  currents, which then has no path but the open switch, and DPsim's trapezoidal rule rings
  undamped (measured: 9 pu at the bus, period 2 dt, after clearing). A load or a shunt
  conductance at the bus gives that current a path.
* :class:`~weakgrid.sim.events.LoadStep` (``dP + j dQ`` of constant-impedance load at the
  power-flow voltage, i.e. the admittance ``y = conj(dS) / |V0|²`` [pu]): with ``Re y >= 0`` (load
  added) a switch, open before ``t``, in series with ``y`` as a resistor and an inductor or
  capacitor to ground, closed at ``t``; with ``Re y < 0`` (load removed) the bus's permanent
  shunt is built without ``-y`` (:func:`removed_load`) and ``-y`` stands behind a switch closed
  before ``t``, opened at ``t`` (its inductance, if any, discharges into its own resistance: the
  removed part must have a resistance, ``dP != 0``, and the bus must hold that much load).
* :class:`~weakgrid.sim.events.GeneratorTrip` of a machine's row: the machine stands on its own
  terminal node (:func:`trip_terminals`), joined to its bus by a breaker (a switch closed before
  ``t``, opened at ``t``). Opening it interrupts the current of the machine's inductance, which
  DPsim's trapezoidal rule would ring undamped through the open switch; so at ``t`` a second
  switch connects the islanded machine to a dump resistor ``R = L'/dt`` (``L'`` its ``xd1`` as an
  inductance: the trapezoidal factor of that loop is 1/3, the current decays in a few steps). The
  grid side sees an open breaker (``OPEN_PU``); the islanded machine's states are recorded
  frozen at ``t`` and its power zero from ``t`` on, weakgrid's convention
  (:mod:`weakgrid.sim.disconnect`). Refused: a row whose bus holds another machine or device
  (one terminal node per tripped machine), a bus left without a resistive path (as a cleared
  fault), a tripped row that is not a mapped machine (a GTI).
* :class:`~weakgrid.sim.events.LineTrip` (a branch opened, or closed with ``close=True``): the
  phasor engine takes the whole branch out of the network admittance matrix (its series
  impedance and both charging halves, a transformer's whole two-port) or puts it back. In
  DPsim the branch, exactly as :mod:`weakgrid.sim.emt.topology` builds it (a line's R–L and
  its π capacitors, a transformer's π-equivalent), stands between two end nodes of its own
  (:func:`line_switching`, ``build_network(switched=...)``), joined to its buses by a breaker
  at *each* end (closed ``1e-6`` pu, open ``OPEN_PU``: the load-step and generator-trip
  switches' values and helper, :func:`_switch_seq`; closed, the two add ``2e-6`` pu to the
  branch's resistance): opening both at ``t`` removes everything the phasor engine removes,
  the charging included, and the grid sees two open switches. The switch is ideal: it chops
  the current at ``t`` (a real breaker waits for a current zero), so the bus sees the step a
  chopped inductive current gives (docs/engines.md: 1.7 pu for one step at a load bus without
  charging on the test grid).
  Opening them interrupts the series inductor's current, which would ring undamped through
  the open switches (as a tripped machine's), so at ``t`` each end node is also switched to
  ground through a dump resistance (the closed resistance of a switch to ground):
  ``TAP² x / (2 w dt)`` [pu of the from bus] and ``x / (2 w dt)`` [pu of the to bus],
  ``x = BR_X``, ``w = 2π f``: the islanded branch's loop, referred to its to side, then holds
  at least ``L/dt`` (``L`` its series inductance), the trapezoidal factor of the interrupted
  current is at most 1/3 (the tripped machine's), and the charging capacitors discharge too
  (a real line's trapped charge is not modelled: the branch is gone from the grid's point of
  view either way). A re-close (``close=True``) opens the dump switches and closes the
  breakers at ``t`` (the branch re-energized from its buses, its charging inrush included).
  A branch out of service in the case (``BR_STATUS = 0``) that an event closes is built dead
  (nodes at zero) behind open breakers. Refused at planning (a study stops before any run):
  a trip of a UPQC's branch (:mod:`weakgrid.sim.emt.upqc` builds it), a trip that leaves a
  bus without an in-service path to a slack bus (an island: the phasor engine's
  :meth:`~weakgrid.sim.network.Network.check_connected`), and a trip at a bus without a
  resistive path (as a cleared fault: the other branches' interrupted currents would ring).
* a bolted fault at a GTI's reference bus is refused (see :mod:`weakgrid.sim.emt.gti`); every
  other event is refused naming it.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ..events import Fault, GeneratorTrip, LineTrip, LoadStep

#: largest fault impedance [pu on the system base] mapped to DPsim's resistive switch
BOLTED_MAX = 1e-3
#: damping resistor across a non-bolted fault's R–L, in units of the fault impedance
#: ``abs(rf + j xf)``
FAULT_DAMP = 1e3
#: open-switch resistance [pu on the bus base impedance]
OPEN_PU = 1e7
#: the refusal of an event kind the DPsim engines do not map
UNMAPPED = ("the DPsim engines map bus faults (Fault), load steps (LoadStep), generator trips "
            "(GeneratorTrip) and branch trips and re-closures (LineTrip)")


def _step_admittance(system, ev):
    """Admittance [pu on Sb] of a :class:`LoadStep` at its bus's power-flow voltage."""
    b = system.network.index_of(ev.bus)
    V0 = system.network.pf.V[b]
    return b, np.conj(complex(ev.dP, ev.dQ) / system.Sb) / abs(V0) ** 2


def removed_load(system, events) -> np.ndarray:
    """Per bus position, the admittance [pu] the run's load steps *remove* (``Re y < 0`` steps,
    as a positive admittance): the network's permanent shunts are built without it."""
    out = np.zeros(system.network.nb, complex)
    for ev in events or ():
        if isinstance(ev, LoadStep):
            b, y = _step_admittance(system, ev)
            if y.real < 0:
                out[b] -= y
    return out


def tripped_machines(system, events) -> dict:
    """``{machine name: trip time [s]}`` of the run's :class:`GeneratorTrip` events."""
    out = {}
    for ev in events or ():
        if isinstance(ev, GeneratorTrip):
            for c, i in _unit(system, ev):
                out[c.names[i]] = float(ev.t)
    return out


def _unit(system, ev):
    from ..disconnect import unit_instances

    ev.validate(system)
    where = repr(ev)
    inst = [(c, i) for c, i in unit_instances(system, int(ev.gen)) if c.kind == "machine"]
    others = [c.element(i) for c, i in unit_instances(system, int(ev.gen)) if c.kind != "machine"]
    if not inst or others:
        raise DataError(where, "gen", ev.gen, "the DPsim engines trip a machine's row only (found "
                        f"{', '.join(others) or 'no machine'})")
    b = int(inst[0][0].bus[inst[0][1]])
    on_bus = [c.element(i) for c in system.components.values()
              if c.kind in ("machine", "device") and c.n and getattr(c, "bus", None) is not None
              for i in range(c.n)
              if b in np.atleast_1d(c.bus)[i:i + 1] and (c, i) not in inst]
    if on_bus:
        raise DataError(where, "gen", ev.gen, f"its bus also holds {', '.join(on_bus)}; the DPsim "
                        "engines trip a machine standing alone on its bus")
    return inst


def line_switching(system, events) -> dict:
    """The branches the run's :class:`LineTrip` events open or close, checked.

    Returns
    -------
    dict
        ``{branch row: (in service at t = 0, [(t [s], closed, event), ...])}``, the changes of
        state in time order (an event that leaves the branch as it is is dropped: it changes
        nothing in the phasor engine either).

    Raises
    ------
    DataError
        Naming the event: a UPQC's branch; a trip that islands a bus (no in-service path to a
        slack bus); a trip at an end bus without a resistive path (no load or shunt
        conductance, machine or source).
    """
    from ..network import BR_STATUS, F_BUS, T_BUS

    net = system.network
    trips = sorted((ev for ev in events or () if isinstance(ev, LineTrip)), key=lambda e: e.t)
    if not trips:
        return {}
    up = system.components.get("UPQC")
    upqc_rows = set(np.asarray(up.branch).tolist()) if up is not None and up.n else set()
    status = net.branch[:, BR_STATUS] > 0
    out = {}
    damped = None
    for ev in trips:
        ev.validate(system)
        k = int(ev.branch)
        where = f"{ev!r} (branch {net.branch_label(k)})"
        if k in upqc_rows:
            raise DataError(where, "branch", k, "a UPQC's own branch is not switched in the DPsim "
                            "engines (weakgrid.sim.emt.upqc builds it); trip another branch")
        closed = bool(ev.close)
        if status[k] == closed:
            continue
        status = status.copy()
        status[k] = closed
        try:
            net.check_connected(status)
        except DataError as err:
            raise DataError(where, "branch", k, f"the trip islands {err.element} (no in-service "
                            "branch to a slack bus): the DPsim engines do not run islands "
                            "opened by a trip; trip a branch with a parallel path") from None
        if not closed:
            damped = _damped_buses(system) if damped is None else damped
            ends = [int(net.branch[k, F_BUS]), int(net.branch[k, T_BUS])]
            bad = [b for b in ends if net.index_of(b) not in damped]
            if bad:
                raise DataError(where, "branch", k, f"opening it at bus {bad[0]}, a bus without a "
                                "resistive path (no load or shunt conductance, machine or "
                                "source), rings undamped in DPsim's trapezoidal rule; put a load "
                                "or a shunt conductance (GS) there")
        out.setdefault(k, (bool(net.branch[k, BR_STATUS] > 0), []))[1].append((ev.t, closed, ev))
    return out


def trip_terminals(system, kit, cir, events) -> list:
    """The node each bus's machines connect to: the bus node, or for a tripped machine its own
    terminal node (initialized at the bus's power-flow voltage)."""
    nodes = list(cir.nodes)
    cir.trips = []
    for ev in events or ():
        if isinstance(ev, GeneratorTrip):
            for c, i in _unit(system, ev):
                b = int(c.bus[i])
                if nodes[b] is cir.nodes[b]:
                    term = kit.node(f"{c.names[i]}.term", cir.Vpf[b])
                    cir.extra_nodes.append(term)
                    nodes[b] = term
                cir.trips.append((ev, c, i, b, nodes[b]))
    return nodes


def build_events(system, kit, cir, events, dt):
    """Add the switches of every mapped event to ``cir`` and return the DPsim switch events.

    Parameters
    ----------
    system : weakgrid.sim.system.System
    kit : weakgrid.sim.emt.dpsim_module.Kit
    cir : weakgrid.sim.emt.topology.Circuit
        Built with :func:`removed_load` and :func:`trip_terminals`.
    events : list
        weakgrid events.
    dt : float
        DPsim step [s] (sizes a tripped machine's dump resistor).
    """
    from .topology import _shunt, bus_base

    _, Zb = bus_base(system)
    w = 2 * np.pi * system.network.f_hz
    out = _branch_breakers(system, kit, cir, events, dt)
    for j, ev in enumerate(events or ()):
        if isinstance(ev, LineTrip):
            continue
        if isinstance(ev, LoadStep):
            ev.validate(system)
            b, y = _step_admittance(system, ev)
            where = f"LoadStep at bus {ev.bus}"
            close = y.real >= 0
            ys = y if close else -y
            if not close and ys.imag < 0 and ys.real == 0:
                raise DataError(where, "dP", ev.dP, "removing a purely inductive load interrupts "
                                "its current with no resistive path; give dP != 0")
            mid = kit.node(f"step{j}", 0j if close else cir.Vpf[b])
            cir.extra_nodes.append(mid)
            out.append(_switch(kit, cir, f"step{j}", cir.nodes[b], mid, Zb[b], ev.t, close,
                               closed_pu=1e-6))
            _shunt(cir, kit, f"step{j}", mid, complex(ys) / Zb[b], w)
            continue
        if isinstance(ev, GeneratorTrip):
            for (e2, c, i, b, term) in cir.trips:
                if e2 is not ev:
                    continue
                if b not in _damped_buses(system, exclude={c.names[i]}):
                    raise DataError(repr(ev), "gen", ev.gen, "opening the breaker of a machine on "
                                    "a bus with only inductive branches rings undamped in DPsim's "
                                    "trapezoidal rule; put a load or a shunt conductance there")
                nm = c.names[i]
                out.append(_switch(kit, cir, f"{nm}.breaker", cir.nodes[b], term, Zb[b], ev.t,
                                   False, closed_pu=1e-6))
                L = float(c.p["xd1"][i]) * Zb[b] / w                 # H
                dump = kit.node(f"{nm}.dump", 0j)
                cir.extra_nodes.append(dump)
                out.append(_switch(kit, cir, f"{nm}.dumpsw", term, dump, Zb[b], ev.t, True,
                                   closed_pu=1e-6))
                res = kit.ph.Resistor(f"{nm}.Rdump", kit.d.LogLevel.off)
                res.set_parameters(kit.param(L / dt))
                res.connect([kit.gnd, dump])
                cir.components.append(res)
            continue
        if not isinstance(ev, Fault):
            raise DataError(f"event {j}", "kind", type(ev).__name__, UNMAPPED)
        ev.validate(system)
        z = abs(complex(ev.rf, ev.xf))
        bolted = z <= BOLTED_MAX
        b = system.network.index_of(ev.bus, f"Fault at bus {ev.bus}", "bus")
        gti = system.components.get("GTI")
        if bolted and gti is not None and gti.n and b in set(np.asarray(gti.ref).tolist()):
            raise DataError(f"Fault at bus {ev.bus}", "bus", ev.bus,
                            "a bolted fault at a GTI's reference bus (ref_bus): the GTI's ideal "
                            "PLL would follow the angle of a zero voltage, which in DPsim spins "
                            "with the fault current's dc offset (measured: the dc link collapses "
                            "within 20 ms); fault another bus, or through an impedance")
        if ev.t_off is not None and b not in _damped_buses(system):
            raise DataError(f"Fault at bus {ev.bus}", "bus", ev.bus,
                            "clearing a fault at a bus with only inductive branches (no load or "
                            "shunt conductance, machine or source) rings undamped in DPsim's "
                            "trapezoidal rule; fault a bus with a load, or add a shunt "
                            "conductance (GS) there")
        if bolted or ev.xf == 0:
            sw = kit.ph.Switch(f"fault{j}", kit.d.LogLevel.off)
            sw.set_parameters(kit.param(OPEN_PU * Zb[b]), kit.param(z * Zb[b]))
            sw.open()
            sw.connect([kit.gnd, cir.nodes[b]])
            cir.components.append(sw)
        else:
            from .topology import _series_rl

            node = kit.node(f"fault{j}", 0j)
            cir.extra_nodes.append(node)
            sw = kit.ph.Switch(f"fault{j}", kit.d.LogLevel.off)
            sw.set_parameters(kit.param(OPEN_PU * Zb[b]), kit.param(1e-6 * Zb[b]))
            sw.open()
            sw.connect([cir.nodes[b], node])
            cir.components.append(sw)
            _series_rl(cir, kit, f"fault{j}", node, kit.gnd, 0j, 0j,
                       complex(ev.rf, ev.xf) * Zb[b], w)
            rp = kit.ph.Resistor(f"fault{j}.Rp", kit.d.LogLevel.off)
            rp.set_parameters(kit.param(FAULT_DAMP * z * Zb[b]))
            rp.connect([kit.gnd, node])
            cir.components.append(rp)
        out.append(kit.event(ev.t_on, sw, True))
        if ev.t_off is not None:
            out.append(kit.event(float(ev.t_off), sw, False))
    return out


def _branch_breakers(system, kit, cir, events, dt):
    """The breakers and dump switches of every switched branch (``cir.branch_ends``, built
    with :func:`line_switching`'s rows) and their switch events."""
    from ..network import BR_X, F_BUS, T_BUS, TAP
    from .topology import bus_base

    net = system.network
    _, Zb = bus_base(system)
    w = 2 * np.pi * net.f_hz
    out = []
    for k, (closed0, changes) in line_switching(system, events).items():
        row = net.branch[k]
        tap = float(row[TAP]) if row[TAP] != 0 else 1.0
        dump = float(row[BR_X]) / (2 * w * dt)                 # pu of the to bus
        toggles = [(t, closed) for t, closed, _ in changes]
        for end, bus, node, dump_pu in (("f", row[F_BUS], cir.branch_ends[k][0], tap * tap * dump),
                                        ("t", row[T_BUS], cir.branch_ends[k][1], dump)):
            b = net.index_of(int(bus))
            out += _switch_seq(kit, cir, f"br{k}.brk{end}", cir.nodes[b], node, Zb[b], closed0,
                               toggles, closed_pu=1e-6)
            out += _switch_seq(kit, cir, f"br{k}.dump{end}", kit.gnd, node, Zb[b], not closed0,
                               [(t, not closed) for t, closed in toggles], closed_pu=dump_pu)
    return out


def _switch(kit, cir, name, a, b, zb, t, close, closed_pu):
    """A switch from node ``a`` to ``b`` (open: ``OPEN_PU``, closed: ``closed_pu`` [pu of
    ``zb`` Ω]), open before ``t`` if ``close`` else closed; return its event at ``t``."""
    return _switch_seq(kit, cir, name, a, b, zb, not close, [(t, close)], closed_pu)[0]


def _switch_seq(kit, cir, name, a, b, zb, closed0, toggles, closed_pu):
    """A switch from node ``a`` to ``b`` (open: ``OPEN_PU``, closed: ``closed_pu`` [pu of
    ``zb`` Ω]), closed at ``t = 0`` if ``closed0``; return its switch events, one per
    ``(t [s], closed)`` of ``toggles``."""
    sw = kit.ph.Switch(name, kit.d.LogLevel.off)
    sw.set_parameters(kit.param(OPEN_PU * zb), kit.param(closed_pu * zb))
    if closed0:
        sw.close()
    else:
        sw.open()
    sw.connect([a, b])
    cir.components.append(sw)
    return [kit.event(float(t), sw, bool(closed)) for t, closed in toggles]


def _damped_buses(system, exclude=()) -> set:
    """Bus positions with a resistive shunt (load or GS > 0), a machine (but those named in
    ``exclude``) or an ideal source."""
    net = system.network
    from ..network import GS

    g = net.load_admittance(net.pf.V).real + net.bus[:, GS] / system.Sb
    out = {int(b) for b in np.nonzero(g > 0)[0]}
    for c in system.components.values():
        if c.kind == "machine" or c.type_name == "InfiniteBus":
            out.update(int(b) for nm, b in zip(c.names, np.atleast_1d(c.bus)) if nm not in exclude)
    return out
