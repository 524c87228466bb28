"""weakgrid machine models → DPsim synchronous-generator models (the one mapping table).

=================  ============================================  =================================
weakgrid model     DPsim model (EMT ``emt.ph3``, DP ``dp.ph1``)  how
=================  ============================================  =================================
``GENCLS``         ``SynchronGenerator4OrderVBR``                ``Ld = Lq = Ld_t = Lq_t = xd1``
=================  ============================================  =================================

Why the 4th-order model is the classical machine exactly: its transient EMFs obey
``Td0' dE'q/dt = Ef - E'q - (Ld - Ld') Id`` and ``Tq0' dE'd/dt = -E'd + (Lq - Lq') Iq``;
with ``Ld = Ld'`` and ``Lq = Lq'`` and the field voltage held at its initial value
``Ef = E'q(0)`` (no exciter), ``E'q`` stays constant and ``E'd`` stays at its initial zero:
a constant EMF behind ``xd1``, the classical model, for any time constants. DPsim has no
classical machine in its EMT domain (``SynchronGeneratorTrStab`` is DP/SP only), so the same
4th-order model is used in both domains.

Residual differences to weakgrid's GENCLS (stated, not hidden):

* the shaft: both integrate ``2H dw/dt = Tm - Te`` (weakgrid's default ``psse_shaft = 0``; a
  GENCLS read from PSS/E with ``psse_shaft = 1`` divides by the speed, DPsim does not), DPsim by
  forward Euler at its step, weakgrid by the trapezoid;
* the network: DPsim's EMT and DP domains keep the inductors' and capacitors' dynamics (the
  machine is a voltage behind the inductance ``xd1``), the phasor engine makes the network
  algebraic. On the SMIB of ``tests/sim/test_emt_dpsim.py`` (bolted fault cleared after 0.1 s)
  the network transients, damped by the line resistance, take 1.5-4.3 % off the post-clearing
  speed excursion for ``BR_R`` from 0.003 to 0.1 pu; EMT and DP agree to 0.02 %.

Refused (DataError naming the model or the field): every other machine model (GENROU, GENSAL,
... : DPsim's 6th-order models are not the PSS/E ones, mapping them would substitute a model),
a machine with exciter, governor or stabilizer attached (DPsim's controls are other models),
``D != 0`` (DPsim's reduced-order machines have no damping term), ``ra != 0`` (no stator
resistance parameter) and ``psse_shaft = 1`` (DPsim's shaft does not divide by the speed).
"""

from __future__ import annotations


from ..errors import DataError

#: weakgrid machine model → DPsim class name (in ``emt.ph3`` and ``dp.ph1``)
MACHINE_MAP = {"GENCLS": "SynchronGenerator4OrderVBR"}


def check_machines(system) -> None:
    """Refuse every machine or control the DPsim engines cannot represent, all in one message."""
    bad = []
    for c in system.components.values():
        if c.kind == "machine":
            if c.type_name not in MACHINE_MAP:
                bad.append(f"{', '.join(c.names)}: machine model {c.type_name} (DPsim mapping exists "
                           f"for {', '.join(MACHINE_MAP)})")
                continue
            why = {"D": "no damping term", "ra": "no stator resistance",
                   "psse_shaft": "the shaft 2H dw/dt = Tm - Te, not PSS/E's division by the speed"}
            for fld, reason in why.items():
                nz = [(nm, v) for nm, v in zip(c.names, c.p[fld]) if v != 0]
                if nz:
                    bad.append(f"{', '.join(nm for nm, _ in nz)}: {c.type_name} {fld} = "
                               f"{', '.join(f'{v:g}' for _, v in nz)} (DPsim's 4th-order machine has "
                               f"{reason}; set {fld} = 0)")
        elif c.kind in ("exciter", "governor", "pss", "compensator"):
            bad.append(f"{', '.join(c.names)}: {c.kind} {c.type_name} (no DPsim mapping yet)")
    if bad:
        raise DataError("simulation", "engine", "dpsim",
                        "models the DPsim engines cannot represent (refused, not substituted): "
                        + "; ".join(bad))


def build_machines(system, kit, nodes, Vpf):
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
            x = float(c.p["xd1"][i])
            H = float(c.p["M"][i]) / 2.0
            g = cls(nm, kit.d.LogLevel.off)
            # (Sn, Vn, fn, H, Ld, Lq, L0, Ld_t, Lq_t, Td0_t, Tq0_t): Ld = Lq = Ld_t = Lq_t (see module)
            g.set_operational_parameters_per_unit(Sb * 1e6, kv * 1e3, float(c.p["fn"][i]), H,
                                                  x, x, 0.1 * x, x, x, 1.0, 1.0)
            s = complex(S[i]) * Sb * 1e6
            g.set_initial_values(s, s.real, complex(Vpf[b]))
            g.connect([nodes[b]])
            out[nm] = g
    return [(nm, out[nm]) for nm in system.machine_names if nm in out]


def machine_bus(system) -> dict:
    """Bus position of each machine by name."""
    return {nm: int(c.bus[i]) for c in system.components.values() if c.kind == "machine"
            for i, nm in enumerate(c.names)}


__all__ = ["MACHINE_MAP", "check_machines", "build_machines", "machine_bus"]
