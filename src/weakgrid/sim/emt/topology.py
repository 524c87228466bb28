"""A set-up weakgrid System's network as a DPsim circuit (nodes, branches, shunts, sources).

Per-unit data → SI: a bus of base ``kV`` has base impedance ``Zb = kV² / Sb`` [Ω]; a
reactance ``x`` [pu] is an inductance ``x Zb / (2π f)`` [H], a susceptance ``b`` [pu] a
capacitance ``b / (Zb 2π f)`` [F]. Node voltages are initialized at the power-flow solution
(line-to-line RMS phasors [V]; DPsim's EMT nodes hold phase-to-ground instantaneous values).

Mapping
-------
* branch (MATPOWER row, in service): series resistor (when ``BR_R > 0``) and inductor through an
  internal node, half the charging ``BR_B`` as a capacitor at each end; refused: ``BR_X <= 0``
  (a series capacitor). A branch a ``LineTrip`` opens or closes is built the same way between
  two end nodes of its own, joined to its buses by breakers (``switched``;
  :mod:`weakgrid.sim.emt.events`);
* transformer (a branch with an off-nominal ``TAP``, or ends at different base voltages):
  the exact π-equivalent of its ideal ratio ``N = TAP · kV_from / kV_to`` and series R–L,
  three scaled R–L branches (:func:`_transformer`; DPsim's own ``Transformer`` is not used, the
  reasons are there), the charging as capacitors at both buses; a phase shift
  (``SHIFT != 0``) is refused;
* bus loads ``PD + jQD`` and shunts ``GS + jBS``: one constant admittance per bus, the
  impedance weakgrid's phasor engine uses (:meth:`weakgrid.sim.network.Network.load_admittance` at the solved
  voltage): a resistor and an inductor or capacitor to ground;
* :class:`~weakgrid.sim.sources.InfiniteBus`: DPsim's ``NetworkInjection`` (an ideal source) at
  the power-flow phasor; the conventional UPQC: :mod:`weakgrid.sim.emt.upqc`; the GTI:
  :mod:`weakgrid.sim.emt.gti`; other devices (converters, PVSource, ZIP loads) are refused.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from ..network import BR_B, BR_R, BR_STATUS, BR_X, SHIFT, TAP, T_BUS, F_BUS, GS, BS

#: non-machine component types the DPsim engines map
DEVICE_MAP = {"InfiniteBus": "NetworkInjection",
              "GTI": "VoltageSource behind its coupling reactance, driven by weakgrid's GTI "
                     "equations between steps (weakgrid.sim.emt.gti)",
              "UPQC": "VoltageSource + CurrentSource (conventional structure, weakgrid.sim.emt.upqc)"}


class Circuit:
    """The DPsim objects of one translated system.

    Attributes
    ----------
    nodes : list
        One DPsim node per bus position (``System.network`` order).
    components : list
        Every DPsim component (branches, shunts, sources, machines, fault switches).
    extra_nodes : list
        Internal nodes (between a branch's resistor and inductor).
    f_hz : float
        Network frequency [Hz].
    branch_ends : dict
        ``{branch row: (from-end node, to-end node)}`` of the branches built behind breakers
        (``build_network(switched=...)``).
    """

    def __init__(self, nodes, f_hz):
        self.nodes, self.f_hz = nodes, f_hz
        self.components, self.extra_nodes = [], []
        self.branch_ends = {}


def check_devices(system) -> None:
    """Refuse every device (not a machine or control) without a DPsim mapping, in one message."""
    bad = [f"{', '.join(c.names)}: {c.type_name}" for c in system.components.values()
           if c.kind not in ("machine", "exciter", "governor", "pss", "compensator")
           and c.type_name not in DEVICE_MAP and c.n > 0]
    if bad:
        raise DataError("simulation", "engine", "dpsim",
                        "devices the DPsim engines do not map yet (refused, not substituted): "
                        + "; ".join(bad) + f". Mapped: machines (see weakgrid.sim.emt.machines), "
                        + ", ".join(DEVICE_MAP))


def bus_base(system):
    """Base voltage [V] and base impedance [Ω] per bus position."""
    kv = np.asarray(system.network.base_kv, float)
    return kv * 1e3, (kv ** 2) / system.Sb


def _shunt_admittance(system, removed=None):
    """Per bus position, the constant shunt admittance [pu on Sb] the circuit gets: loads at the
    power-flow voltage plus ``GS + j BS``, less ``removed``."""
    net = system.network
    y = net.load_admittance(net.pf.V) + (net.bus[:, GS] + 1j * net.bus[:, BS]) / system.Sb
    return y if removed is None else y - removed


def check_network(system, removed=None, switched=()) -> None:
    """Refuse (:class:`DataError`, naming the branch or bus and the field) what the circuit
    cannot hold: a non-inductive branch (``BR_X <= 0``, a series capacitor), a phase shifter
    (``SHIFT != 0``: its two-port is not reciprocal, which no network of R, L, C is), a
    negative shunt conductance (generation as a load), a load step removing more load than its
    bus holds (``removed``: :func:`weakgrid.sim.emt.events.removed_load`). Branches out of
    service are checked too when a ``LineTrip`` closes them (rows in ``switched``)."""
    net = system.network
    up = system.components.get("UPQC")
    upqc_rows = set(np.asarray(up.branch).tolist()) if up is not None and up.n else set()
    for k, row in enumerate(net.branch):
        if (row[BR_STATUS] <= 0 and k not in switched) or k in upqc_rows:
            continue
        where = f"branch {net.branch_label(k)}"
        if row[SHIFT] != 0:
            raise DataError(where, "SHIFT", float(row[SHIFT]),
                            "a phase-shifting transformer is not mapped to DPsim (its two-port is "
                            "not reciprocal: no network of R, L, C is one); use SHIFT = 0")
        if row[BR_X] <= 0:
            raise DataError(where, "BR_X", float(row[BR_X]),
                            "the DPsim engines need an inductive branch (BR_X > 0)")
    y0 = _shunt_admittance(system)
    y = _shunt_admittance(system, removed)
    for b in np.nonzero(y.real < -1e-12)[0]:
        if removed is not None and removed[b] != 0 and y0[b].real >= 0:
            raise DataError(f"LoadStep at bus {net.bus_ids[b]}", "dP", -removed[b].real * system.Sb,
                            f"removes more load than the bus holds ({y0[b].real * system.Sb:g} "
                            "MW at the power-flow voltage)")
        raise DataError(f"bus{net.bus_ids[b]}", "PD/GS", float(y0[b].real),
                        "a negative shunt conductance (generation as a load) is not mapped to "
                        "DPsim")


def build_network(system, kit, removed=None, switched=None) -> Circuit:
    """Nodes, branches, shunt admittances and ideal sources of a set-up system in DPsim.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        A set-up system (power flow solved).
    kit : weakgrid.sim.emt.dpsim_module.Kit
        The domain's classes.
    removed : ndarray of complex, optional
        Per bus position, admittance [pu] left out of the bus's permanent shunt (the part a
        load step removes: :func:`weakgrid.sim.emt.events.removed_load`).
    switched : dict, optional
        ``{branch row: in service at t = 0}`` of the branches ``LineTrip`` events open or
        close (:func:`weakgrid.sim.emt.events.line_switching`): each is built between two end
        nodes of its own (``Circuit.branch_ends``; initialized at its buses' power-flow
        voltages when in service, at zero when not: a dead branch), for
        :func:`weakgrid.sim.emt.events.build_events` to join to its buses by breakers.
    """
    switched = dict(switched or {})
    check_network(system, removed, switched)
    net = system.network
    w = 2 * math.pi * net.f_hz
    Vb, Zb = bus_base(system)
    Vpf = net.pf.V * Vb
    nodes = [kit.node(f"bus{bid}", Vpf[b]) for b, bid in enumerate(net.bus_ids)]
    cir = Circuit(nodes, net.f_hz)
    cir.Vpf = Vpf
    off = kit.d.LogLevel.off
    ph = kit.ph
    up = system.components.get("UPQC")
    upqc_rows = set(np.asarray(up.branch).tolist()) if up is not None and up.n else set()
    for k, row in enumerate(net.branch):
        if (row[BR_STATUS] <= 0 and k not in switched) or k in upqc_rows:
            continue                                   # a UPQC branch: weakgrid.sim.emt.upqc
        f, t = net.index_of(int(row[F_BUS])), net.index_of(int(row[T_BUS]))
        nf, nt, Vf, Vt = nodes[f], nodes[t], Vpf[f], Vpf[t]
        if k in switched:          # behind breakers: its own end nodes (dead if out of service)
            if not switched[k]:
                Vf = Vt = 0j
            nf, nt = kit.node(f"br{k}.f", Vf), kit.node(f"br{k}.t", Vt)
            cir.extra_nodes += [nf, nt]
            cir.branch_ends[k] = (nf, nt)
        tap = row[TAP] if row[TAP] != 0 else 1.0
        if tap != 1.0 or row[SHIFT] != 0 or Zb[f] != Zb[t]:
            _transformer(cir, kit, system, k, row, f, t, w, (nf, nt, Vf, Vt))
            continue
        r, x, bc = float(row[BR_R]), float(row[BR_X]), float(row[BR_B])
        z = Zb[f]
        _series_rl(cir, kit, f"br{k}", nf, nt, Vf, Vt, complex(r, x) * z, w)
        if bc > 0:
            for end, n in (("f", nf), ("t", nt)):
                cap = ph.Capacitor(f"br{k}.C{end}", off)
                cap.set_parameters(kit.param(0.5 * bc / (z * w)))
                cap.connect([kit.gnd, n])
                cir.components.append(cap)
    y = _shunt_admittance(system, removed)
    for b, yb in enumerate(y):
        _shunt(cir, kit, f"bus{net.bus_ids[b]}", nodes[b], complex(yb) / Zb[b], w)
    for c in system.components.values():
        if c.type_name == "InfiniteBus":
            for i, nm in enumerate(c.names):
                b = int(c.bus[i])
                src = ph.NetworkInjection(nm, off)
                V = kit.phasors(Vpf[b])
                if kit.three_phase:
                    src.set_parameters(V_ref=np.array(V, dtype=complex).reshape(3, 1), f_src=net.f_hz)
                else:
                    src.set_parameters(V_ref=V[0])
                src.connect([nodes[b]])
                cir.components.append(src)
    return cir


def _shunt(cir, kit, name, node, y, w):
    """A constant admittance ``y`` [S] from ``node`` to ground: resistor ∥ inductor or capacitor."""
    off, ph = kit.d.LogLevel.off, kit.ph
    if y.real > 0:
        r = ph.Resistor(f"{name}.G", off)
        r.set_parameters(kit.param(1.0 / y.real))
        r.connect([kit.gnd, node])
        cir.components.append(r)
    if y.imag < 0:      # inductive (a load absorbing vars)
        L = ph.Inductor(f"{name}.BL", off)
        L.set_parameters(kit.param(-1.0 / (y.imag * w)))
        L.connect([kit.gnd, node])
        cir.components.append(L)
    elif y.imag > 0:
        C = ph.Capacitor(f"{name}.BC", off)
        C.set_parameters(kit.param(y.imag / w))
        C.connect([kit.gnd, node])
        cir.components.append(C)


def _series_rl(cir, kit, name, na, nb, Va, Vb, Z, w):
    """A series R–L of impedance ``Z`` [Ω at the nominal frequency] from ``na`` to ``nb``
    (``nb`` may be ground, ``Vb = 0``); ``Va``, ``Vb``: the nodes' initial phasors [V]. The
    resistor (when ``Re Z != 0``) and the inductor meet at an internal node initialized at the
    steady-state phasor. ``Z`` may be negative (both parts of one sign: see :func:`_transformer`)."""
    off, ph = kit.d.LogLevel.off, kit.ph
    a = na
    if Z.real != 0:
        Is = (Va - Vb) / Z
        a = kit.node(f"{name}.mid", Va - Is * Z.real)
        cir.extra_nodes.append(a)
        res = ph.Resistor(f"{name}.R", off)
        res.set_parameters(kit.param(Z.real))
        res.connect([na, a])
        cir.components.append(res)
    ind = ph.Inductor(f"{name}.L", off)
    ind.set_parameters(kit.param(Z.imag / w))
    ind.connect([a, nb])
    cir.components.append(ind)


def _transformer(cir, kit, system, k, row, f, t, w, ends):
    """Branch ``k`` (positions ``f`` → ``t``) with an off-nominal ratio as its exact π-equivalent
    between the nodes ``ends = (from node, to node, from voltage, to voltage)`` (the buses'
    nodes and power-flow voltages [V], or a switched branch's end nodes).

    weakgrid's (MATPOWER's) two-port: from bus — ideal transformer ``TAP:1`` — series
    impedance ``z = BR_R + j BR_X`` [pu] — to bus, ``BR_B / 2`` at both ends of ``z``. In SI the
    ideal ratio is the real ``N = TAP · Vb_from / Vb_to`` and the impedance ``Z = z Zb_to`` [Ω]
    sits on the to side; its admittance matrix is ``y(s) [[1/N², −1/N], [−1/N, 1]]`` with
    ``y(s) = 1 / (R + s L)`` the series R–L's. Three R–L branches, each ``y(s)`` times a real
    constant, give the same matrix at every frequency: ``y/N`` from–to, ``y (1 − N) / N²`` from
    bus to ground and ``y (N − 1) / N`` to bus to ground (R and L both divided by the constant;
    one of the two shunts is negative unless ``N = 1``). A scaled R–L's trapezoidal companion is
    the original's scaled, so the *discretized* two-port is the transformer's too, in EMT
    and DP alike — exact, not an approximation; the negative shunt never stands alone (it is
    part of a passive two-port). The charging at the ideal transformer's secondary is
    ``j BR_B / (2 TAP²)`` [pu] at the from bus (the ideal transformer only rescales a shunt),
    ``j BR_B / 2`` at the to bus.

    DPsim's own ``Transformer`` is not used (measured in DPsim 1.4): it adds snubbers (a
    conductance of 0.1 % and a capacitance of 0.05 % of its rated power at each end), ignores
    the resistance unless built ``with_resistive_losses`` (and then a zero resistance opens the
    branch), swaps its terminals without re-referring the impedance when its ratio is below 1,
    and, in a first trial (a 2:1 ratio, source to resistive load, rated power 1e-3 VA to make
    the snubbers negligible), kicked its LV node by 13 % at the first step in DP and stayed
    18 % off the analytic steady state in EMT (not investigated further).

    Refused (:func:`check_network`): ``SHIFT != 0`` (a phase shifter's two-port is not
    reciprocal, ``Y_ft != Y_tf``, which no network of R, L, C is), ``BR_X <= 0``.
    """
    r, x, bc = float(row[BR_R]), float(row[BR_X]), float(row[BR_B])
    Vbase, Zb = bus_base(system)
    tap = float(row[TAP]) if row[TAP] != 0 else 1.0
    N = tap * Vbase[f] / Vbase[t]
    Z = complex(r, x) * Zb[t]
    nf, nt, Vf, Vt = ends
    _series_rl(cir, kit, f"br{k}", nf, nt, Vf, Vt, Z * N, w)
    if N != 1.0:
        _series_rl(cir, kit, f"br{k}.f", nf, kit.gnd, Vf, 0j, Z * N * N / (1 - N), w)
        _series_rl(cir, kit, f"br{k}.t", nt, kit.gnd, Vt, 0j, Z * N / (N - 1), w)
    if bc > 0:
        off = kit.d.LogLevel.off
        for end, node, C in (("f", nf, 0.5 * bc / (tap * tap) / (Zb[f] * w)),
                             ("t", nt, 0.5 * bc / (Zb[t] * w))):
            cap = kit.ph.Capacitor(f"br{k}.C{end}", off)
            cap.set_parameters(kit.param(C))
            cap.connect([kit.gnd, node])
            cir.components.append(cap)
