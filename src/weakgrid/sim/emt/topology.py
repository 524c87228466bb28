"""A set-up weakgrid System's network as a DPsim circuit (nodes, branches, shunts, sources).

Per-unit data → SI: a bus of base ``kV`` has base impedance ``Zb = kV² / Sb`` [Ω]; a
reactance ``x`` [pu] is an inductance ``x Zb / (2π f)`` [H], a susceptance ``b`` [pu] a
capacitance ``b / (Zb 2π f)`` [F]. Node voltages are initialized at the power-flow solution
(line-to-line RMS phasors [V]; DPsim's EMT nodes hold phase-to-ground instantaneous values).

Mapping
-------
* branch (MATPOWER row, in service): series resistor (when ``BR_R > 0``) and inductor through an
  internal node, half the charging ``BR_B`` as a capacitor at each end; refused: ``BR_X <= 0``
  (a series capacitor), an off-nominal ``TAP`` or a ``SHIFT``, ends at different base voltages
  (a transformer: not mapped in this first slice);
* bus loads ``PD + jQD`` and shunts ``GS + jBS``: one constant admittance per bus, the
  impedance weakgrid's phasor engine uses (:meth:`weakgrid.sim.network.Network.load_admittance` at the solved
  voltage): a resistor and an inductor or capacitor to ground;
* :class:`~weakgrid.sim.sources.InfiniteBus`: DPsim's ``NetworkInjection`` (an ideal source) at
  the power-flow phasor; the conventional UPQC: :mod:`weakgrid.sim.emt.upqc`; other devices (GTI,
  converters, PVSource, ZIP loads) are refused.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from ..network import BR_B, BR_R, BR_STATUS, BR_X, SHIFT, TAP, T_BUS, F_BUS, GS, BS

#: non-machine component types the DPsim engines map
DEVICE_MAP = {"InfiniteBus": "NetworkInjection",
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
    """

    def __init__(self, nodes, f_hz):
        self.nodes, self.f_hz = nodes, f_hz
        self.components, self.extra_nodes = [], []


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


def build_network(system, kit) -> Circuit:
    """Nodes, branches, shunt admittances and ideal sources of a set-up system in DPsim.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        A set-up system (power flow solved).
    kit : weakgrid.sim.emt.dpsim_module.Kit
        The domain's classes.
    """
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
        if row[BR_STATUS] <= 0 or k in upqc_rows:     # a UPQC branch: weakgrid.sim.emt.upqc
            continue
        f, t = net.index_of(int(row[F_BUS])), net.index_of(int(row[T_BUS]))
        where = f"branch {net.branch_label(k)}"
        tap = row[TAP] if row[TAP] != 0 else 1.0
        if tap != 1.0 or row[SHIFT] != 0:
            raise DataError(where, "TAP", float(row[TAP]), "transformers with an off-nominal ratio or a "
                            "phase shift are not mapped to DPsim yet; use TAP = 0 or 1, SHIFT = 0")
        if Zb[f] != Zb[t]:
            raise DataError(where, "BASE_KV", (float(net.base_kv[f]), float(net.base_kv[t])),
                            "a branch between buses of different base voltage is a transformer, "
                            "not mapped to DPsim yet")
        r, x, bc = float(row[BR_R]), float(row[BR_X]), float(row[BR_B])
        if x <= 0:
            raise DataError(where, "BR_X", x, "the DPsim engines need an inductive branch (BR_X > 0)")
        z = Zb[f]
        nf, nt = nodes[f], nodes[t]
        a = nf
        if r > 0:
            Is = (Vpf[f] - Vpf[t]) / ((r + 1j * x) * z)
            a = kit.node(f"br{k}.mid", Vpf[f] - Is * r * z)
            cir.extra_nodes.append(a)
            res = ph.Resistor(f"br{k}.R", off)
            res.set_parameters(kit.param(r * z))
            res.connect([nf, a])
            cir.components.append(res)
        ind = ph.Inductor(f"br{k}.L", off)
        ind.set_parameters(kit.param(x * z / w))
        ind.connect([a, nt])
        cir.components.append(ind)
        if bc > 0:
            for end, n in (("f", nf), ("t", nt)):
                cap = ph.Capacitor(f"br{k}.C{end}", off)
                cap.set_parameters(kit.param(0.5 * bc / (z * w)))
                cap.connect([kit.gnd, n])
                cir.components.append(cap)
    y = net.load_admittance(net.pf.V) + (net.bus[:, GS] + 1j * net.bus[:, BS]) / system.Sb
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
    elif y.real < 0:
        raise DataError(name, "PD/GS", y.real, "a negative shunt conductance (generation as a load) "
                        "is not mapped to DPsim")
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
