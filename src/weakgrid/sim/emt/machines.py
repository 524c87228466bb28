"""weakgrid machine models → DPsim synchronous-generator models (the one mapping table).

=================  ============================================  ======================================
weakgrid model     DPsim model (EMT ``emt.ph3``, DP ``dp.ph1``)  parameters (pu on the system base)
=================  ============================================  ======================================
``GENCLS``         ``SynchronGenerator4OrderVBR``                ``Ld = Lq = Ld' = Lq' = xd1``
``GENROU``         ``SynchronGenerator6bOrderVBR``               ``Ld, Lq = xd, xq``; ``Ld', Lq' = xd1,
                                                                 xq1``; ``Ld'', Lq'' = xd2, xq2``;
                                                                 ``Td0', Tq0', Td0'', Tq0'' = Td10,
                                                                 Tq10, Td20, Tq20``; ``H = M/2``
``GENSAL``         ``SynchronGenerator6bOrderVBR``               as GENROU with ``Lq' = Lq = xq`` (no
                                                                 q-axis transient winding)
=================  ============================================  ======================================

GENCLS. The 4th-order model is the classical machine exactly: its transient EMFs obey
``Td0' dE'q/dt = Ef - E'q - (Ld - Ld') Id`` and ``Tq0' dE'd/dt = -E'd + (Lq - Lq') Iq``;
with ``Ld = Ld'`` and ``Lq = Lq'`` and the field voltage held at its initial value
``Ef = E'q(0)`` (no exciter), ``E'q`` stays constant and ``E'd`` stays at its initial zero:
a constant EMF behind ``xd1``, the classical model, for any time constants. DPsim has no
classical machine in its EMT domain (``SynchronGeneratorTrStab`` is DP/SP only), so the same
4th-order model is used in both domains.

GENROU and GENSAL. DPsim's ``6bOrderVBR`` is Anderson–Fouad's sixth-order model (DPsim 1.4
``Base_ReducedOrderSynchronGenerator::calculateVBRconstants`` with ``Yd = Yq = 0``; its
``6aOrderVBR`` is Marconato's, which adds the ``Taa`` leakage terms ``Yd, Yq``, and its
``5OrderVBR`` always carries ``Yd``, so neither is used)::

    Td0'  dE'q/dt  = Ef - E'q - (Ld - Ld') Id          Tq0'  dE'd/dt  = -E'd + (Lq - Lq') Iq
    Td0'' dE''q/dt = E'q - E''q - (Ld' - Ld'') Id      Tq0'' dE''d/dt = E'd - E''d + (Lq' - Lq'') Iq
    Vq = E''q - Ld'' Id,  Vd = E''d + Lq'' Iq,  2H dw/dt = Tm - (Vd Id + Vq Iq)

weakgrid's GENROU (PSS/E's, as ANDES writes it: :mod:`weakgrid.sim.machines.genrou`) has the
same reactances, time constants, stator, steady state and shaft (the parameters map one to one,
nothing is fitted), but its rotor circuits are coupled differently: with ``psi''d =
gd1 e1q + (1 - gd1) psi_kd`` (``gd1 = (xd2 - xl)/(xd1 - xl)``) its equations read

* ``Td10 de1q/dt = Efd - e1q - (xd - xd1) Id - (xd - xd1)(e1q - psi''d - (xd1 - xd2) Id)/(xd1 - xl)``
  (the field sees the damper current; Anderson–Fouad drops the last term),
* ``Td20 dpsi''d/dt = e1q - psi''d - (xd1 - xd2) Id + gd1 Td20 de1q/dt`` (the damper flux moves
  with the field flux; Anderson–Fouad drops the last term),

and the same two terms on the q axis (with ``xq1, xq2, Tq10, Tq20``). Both extra terms vanish
in steady state and are of the order of the sub-transient decay (``Td20/Td10``): the two models
agree on the electromechanical response and differ during the first tens of milliseconds after a
disturbance (measured: ``tests/sim/test_emt_machines.py``, docs/engines.md). GENSAL has no
q-axis transient winding (``xq1 = xq``): ``Lq' = Lq`` makes ``E'd`` stay zero and its
``Tq0''`` equation ``Tq20 dpsi''q/dt = -psi''q + (xq - xq2) Iq``, GENSAL's own; the d axis is
as GENROU's. Only the 6th-order machine's ``E''q, E''d`` enter the stator, so ``xl`` enters
no DPsim equation (it is used as the zero-sequence ``L0``, which balanced operation never sees).

Residual differences to weakgrid (stated, not hidden):

* the shaft: both integrate ``2H dw/dt = Tm - Te`` (weakgrid's default ``psse_shaft = 0``; a
  machine read from PSS/E with ``psse_shaft = 1`` divides by the speed, DPsim does not), DPsim by
  forward Euler at its step, weakgrid by the trapezoid;
* the network: DPsim's EMT and DP domains keep the inductors' and capacitors' dynamics (the
  machine is a voltage behind the inductance ``xd1``, or ``xd2``), the phasor engine makes the
  network algebraic. On the SMIB of ``tests/sim/test_emt_dpsim.py`` (bolted fault cleared after
  0.1 s) the network transients, damped by the line resistance, take 1.5-4.3 % off the
  post-clearing speed excursion for ``BR_R`` from 0.003 to 0.1 pu; EMT and DP agree to 0.02 %.
* saturation: DPsim's machines have none. A GENROU or GENSAL with ``S10 != 0`` is refused
  unless ``drop_saturation=True`` is given (``simulate_dpsim``); then the machine runs
  unsaturated, and its power flow initialization is DPsim's own (unsaturated), so the field
  voltage ``Ef(0)`` differs from weakgrid's saturated ``vf0``.

The stator of every DPsim machine used here is algebraic (no ``dψ/dt``): the network sees the
machine as ``ra + j x`` at every frequency, not as an inductance, which with capacitance at the
machine's node is an undamped kHz mode; such a node's capacitors get a series damping resistor
(or the bus is refused): :mod:`weakgrid.sim.emt.damping`.

The stator resistance ``ra`` (DPsim's reduced-order machines have none) is a DPsim resistor
between the machine and its bus: ``V = E'' - (ra + j x'') I`` is weakgrid's stator exactly,
and DPsim's torque ``Vd Id + Vq Iq``, taken inside the resistor, the air-gap torque.

Refused (DataError naming the model or the field): every other machine model (GENROE, GENSAE:
exponential saturation, a model DPsim does not have), ``D != 0`` (DPsim's reduced-order
machines have no damping term), ``psse_shaft = 1``
(DPsim's shaft does not divide by the speed), ``S10 != 0`` (above), and an exciter on a GENCLS
(the classical machine has no field voltage input). Exciters, governors and stabilizers run in
weakgrid (:mod:`weakgrid.sim.emt.machine_controls`).
"""

from __future__ import annotations


from ..errors import DataError

#: weakgrid machine model → DPsim class name (in ``emt.ph3`` and ``dp.ph1``)
MACHINE_MAP = {"GENCLS": "SynchronGenerator4OrderVBR", "GENROU": "SynchronGenerator6bOrderVBR",
               "GENSAL": "SynchronGenerator6bOrderVBR"}

#: models with a field-voltage input (an exciter may drive DPsim's ``Ef``)
FIELD_MODELS = ("GENROU", "GENSAL")


def check_machines(system, drop_saturation: bool = False) -> None:
    """Refuse every machine or control the DPsim engines cannot represent, all in one message.

    Parameters
    ----------
    system : weakgrid.sim.system.System
    drop_saturation : bool
        Run a GENROU/GENSAL with ``S10 != 0`` unsaturated (DPsim has no saturation) instead of
        refusing it.
    """
    bad = []
    field = {}
    for c in system.components.values():
        if c.kind != "machine":
            continue
        if c.type_name not in MACHINE_MAP:
            bad.append(f"{', '.join(c.names)}: machine model {c.type_name} (DPsim mapping exists "
                       f"for {', '.join(MACHINE_MAP)})")
            continue
        why = {"D": "no damping term",
               "psse_shaft": "the shaft 2H dw/dt = Tm - Te, not PSS/E's division by the speed"}
        if c.type_name in FIELD_MODELS and not drop_saturation:
            why["S10"] = ("no saturation; set S10 = 0, or pass drop_saturation=True to run the "
                          "machine unsaturated: in a study, [simulation] drop_saturation = true")
        for fld, reason in why.items():
            nz = [(nm, v) for nm, v in zip(c.names, c.p[fld]) if v != 0]
            if nz:
                fix = "" if fld == "S10" else f"; set {fld} = 0"
                bad.append(f"{', '.join(nm for nm, _ in nz)}: {c.type_name} {fld} = "
                           f"{', '.join(f'{v:g}' for _, v in nz)} (DPsim's machine has {reason}{fix})")
        for nm in c.names:
            field[nm] = c.type_name in FIELD_MODELS
    for c in system.components.values():
        if c.kind == "compensator":
            bad.append(f"{', '.join(c.names)}: {c.kind} {c.type_name} (no DPsim mapping yet)")
        elif c.kind == "exciter":
            for nm, lk in zip(c.names, c.links):
                if not field.get(lk["machine"], True):
                    bad.append(f"{nm}: exciter {c.type_name} on the classical machine "
                               f"'{lk['machine']}' (GENCLS has no field voltage input)")
    if bad:
        raise DataError("simulation", "engine", "dpsim",
                        "models the DPsim engines cannot represent (refused, not substituted): "
                        + "; ".join(bad))


def dpsim_parameters(c, i):
    """DPsim ``set_operational_parameters_per_unit`` arguments after ``(Sn, Vn, fn)`` of
    instance ``i`` of machine component ``c`` (pu on the system base, see the module table):
    ``(H, Ld, Lq, L0, Ld', Lq', Td0', Tq0')`` for the 4th order, then ``(Ld'', Lq'', Td0'',
    Tq0'', Taa = 0)`` for the 6th."""
    p = {k: float(v[i]) for k, v in c.p.items()}
    H = p["M"] / 2.0
    if c.type_name == "GENCLS":
        x = p["xd1"]
        return (H, x, x, 0.1 * x, x, x, 1.0, 1.0)
    L0 = p["xl"] if p["xl"] > 0 else p["xd2"]
    if c.type_name == "GENSAL":          # no q-axis transient winding: Lq' = Lq, E'd stays 0
        return (H, p["xd"], p["xq"], L0, p["xd1"], p["xq"], p["Td10"], 1.0,
                p["xd2"], p["xq2"], p["Td20"], p["Tq20"], 0.0)
    return (H, p["xd"], p["xq"], L0, p["xd1"], p["xq1"], p["Td10"], p["Tq10"],
            p["xd2"], p["xq2"], p["Td20"], p["Tq20"], 0.0)


def build_machines(system, kit, nodes, Vpf, cir=None):
    """DPsim generators for the system's machines, connected to their bus nodes.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        A set-up system (``check_machines`` passed).
    kit : weakgrid.sim.emt.dpsim_module.Kit
        The domain's classes.
    nodes : list
        DPsim node per bus position.
    Vpf : ndarray of complex
        Power-flow bus voltages [V, line-to-line RMS phasors].
    cir : weakgrid.sim.emt.topology.Circuit, optional
        Receives the stator resistors and their internal nodes (needed when a machine has
        ``ra > 0``).

    Returns
    -------
    list of (name, generator)
        Machines in :attr:`System.machine_names` order. Per-unit base of the DPsim data: the
        system base ``Sb`` and the bus's base voltage (weakgrid's parameters after setup).
    """
    net, Sb = system.network, system.Sb
    out = {}
    for c in system.components.values():
        if c.kind != "machine":
            continue
        cls = getattr(kit.ph, MACHINE_MAP[c.type_name])
        S = c.power_share(net.pf)          # pu on Sb
        for i, nm in enumerate(c.names):
            b = int(c.bus[i])
            kv = float(net.base_kv[b])
            g = cls(nm, kit.d.LogLevel.off)
            g.set_operational_parameters_per_unit(Sb * 1e6, kv * 1e3, float(c.p["fn"][i]),
                                                  *dpsim_parameters(c, i))
            node, Vt, s = nodes[b], complex(Vpf[b]), complex(S[i])
            ra = float(c.p["ra"][i])
            if ra > 0:
                node, Vt, s = _stator_resistor(kit, cir, nm, nodes[b], Vt, s, ra, kv, Sb)
            s = s * Sb * 1e6
            g.set_initial_values(s, s.real, Vt)
            g.connect([node])
            out[nm] = g
    return [(nm, out[nm]) for nm in system.machine_names if nm in out]


def _stator_resistor(kit, cir, name, bus_node, Vt, S, ra, kv, Sb):
    """The stator resistance ``ra`` [pu on Sb] as a DPsim resistor from an internal node (the
    machine's own terminal) to its bus: ``V = E'' - (ra + j x'') I`` exactly, and DPsim's
    ``Te = Vd Id + Vq Iq`` at the internal node is the air-gap power weakgrid's ``te`` is.

    Returns the internal node, its power-flow voltage [V] and the air-gap power [pu on Sb].
    """
    if cir is None:
        raise DataError(name, "ra", ra, "a stator resistance needs the circuit (build_machines(..., cir=))")
    Vb = kv * 1e3
    v = Vt / Vb
    i = (S / v).conjugate()
    v_int = v + ra * i
    node = kit.node(f"{name}.int", v_int * Vb)
    cir.extra_nodes.append(node)
    res = kit.ph.Resistor(f"{name}.ra", kit.d.LogLevel.off)
    res.set_parameters(kit.param(ra * kv ** 2 / Sb))
    res.connect([node, bus_node])
    cir.components.append(res)
    return node, v_int * Vb, v_int * i.conjugate()


def machine_bus(system) -> dict:
    """Bus position of each machine by name."""
    return {nm: int(c.bus[i]) for c in system.components.values() if c.kind == "machine"
            for i, nm in enumerate(c.names)}


__all__ = ["MACHINE_MAP", "FIELD_MODELS", "check_machines", "dpsim_parameters", "build_machines",
           "machine_bus"]
