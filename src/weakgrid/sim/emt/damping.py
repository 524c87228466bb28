"""The damping resistor in series with the capacitance at a DPsim machine's terminal bus.

The mode. DPsim's reduced-order machines (``SynchronGenerator4OrderVBR`` for GENCLS,
``6bOrderVBR`` for GENROU/GENSAL; :mod:`weakgrid.sim.emt.machines`) have an algebraic stator:
no ``dψ/dt`` terms, the stator reactance enters the network as a constant "resistance"
matrix in the rotor's ``dq`` frame (DPsim 1.4 ``ReducedOrderSynchronGeneratorVBR``:
``mResistanceMatrixDq = [[0, mA], [mB, 0]]``). To the network the machine is the impedance
``z_m = ra + j x`` (``x = xd1`` for GENCLS, ``xd2`` for GENROU/GENSAL) at *every* frequency,
not an inductance. With a capacitance ``b`` [pu] at the machine's node (line charging, a
capacitive shunt), the node has a first-order mode of its own (DP frame, the line's inductors
and ``g`` the bus's shunt conductance aside)::

    (b/ω0) dV/dt = −(g + 1/z_m) V    →    λ = −ω0 (g + 1/z_m) / b,   |Im λ| ≈ ω0 / (x b)

which is undamped when ``ra = g = 0``; the trapezoidal rule keeps it undamped and warps its
frequency to ``(2/dt) atan(ω0 dt / (2 x b))``. A real stator's inductance ``x/ω0`` would give
``ω0/√(x b)`` instead (the mode is the quasi-static stator's artefact). Measured
(``tests/sim/test_emt_terminal_damping.py``, docs/engines.md): a GENCLS (``xd1 = 0.25`` pu) on
two lines with ``b = 0.1`` pu each, ``b = 0.1`` pu at its node, a fault cleared after 50 ms:
2.08 kHz at ``dt`` = 1e-4 s (warped ``ω0/(x b)`` = 2.40 kHz: 2.06 kHz), 1.58 kHz at 2e-4 s
(1.57), 2.41 kHz at 2.5e-5 s (2.37); its frequency scales as ``1/b``, not ``1/√b``.

The remedy. A resistor ``R_d`` in series with every capacitor at the node (a capacitor's
series resistance) turns the mode into ``λ = −ω0 / (b (R_d + z_m))``, of damping ratio
``Re(R_d + z_m)/|R_d + z_m|``: ``R_d`` is sized so that the ratio is :data:`ZETA` (at least),
independent of ``b``. At the fundamental, each capacitor ``j b_k`` becomes
``j b_k / (1 + j b_k R_d)`` ≈ ``j b_k + b_k² R_d``: a conductance ``b_k² R_d`` (2.5e-4 pu in
all on the test grid, 0.03 % of the machine's power; the speed excursion moves by 0.02 %) and
a relative susceptance change ``(b_k R_d)²``. Only buses whose mode's own damping (from ``ra`` and the bus's load conductance ``g``) is below
:data:`ZETA` get it. When ``b R_d`` would exceed :data:`MAX_SHIFT` (a large capacitance at the
machine, the mode near the network's own frequencies) the bus is refused, naming the bus, the
machines and the fixes.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from ..network import BR_B, BR_STATUS, F_BUS, T_BUS, TAP

#: damping ratio the terminal node's mode is given
ZETA = 0.2
#: largest ``b · R_d`` [–] (the relative change of the bus's capacitor admittance at the
#: fundamental) accepted; beyond it the bus is refused
MAX_SHIFT = 0.01


def machine_reactance(c, i) -> float:
    """The reactance [pu on Sb] DPsim's VBR machine presents to the network: ``xd1`` (GENCLS),
    ``xd2`` (GENROU, GENSAL)."""
    return float(c.p["xd1" if c.type_name == "GENCLS" else "xd2"][i])


def node_capacitance(system, skip_rows=()) -> np.ndarray:
    """Per bus position, the capacitance the DPsim circuit puts at the bus node [pu susceptance
    on Sb]: half the charging of every in-service branch end (``BR_B / (2 TAP²)`` at a
    transformer's from end), branches in ``skip_rows`` left out (a UPQC's)."""
    net = system.network
    out = np.zeros(net.nb)
    for k, row in enumerate(net.branch):
        if row[BR_STATUS] <= 0 or k in skip_rows or row[BR_B] <= 0:
            continue
        tap = float(row[TAP]) if row[TAP] != 0 else 1.0
        out[net.index_of(int(row[F_BUS]))] += 0.5 * row[BR_B] / tap ** 2
        out[net.index_of(int(row[T_BUS]))] += 0.5 * row[BR_B]
    return out


def terminal_damping(system, y_shunt, skip_rows=()) -> np.ndarray:
    """Per bus position, the damping resistance ``R_d`` [pu on Sb] in series with each
    capacitor at the bus (0: none needed). Raises :class:`DataError` for a bus where the
    resistor would shift the capacitors' fundamental admittance by more than
    :data:`MAX_SHIFT`.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up.
    y_shunt : ndarray of complex
        Per bus position, the constant shunt admittance [pu] the circuit builds
        (:func:`weakgrid.sim.emt.topology._shunt_admittance`).
    skip_rows : iterable of int
        Branch rows built elsewhere (a UPQC's).
    """
    net = system.network
    b_node = node_capacitance(system, skip_rows) + np.maximum(np.imag(y_shunt), 0.0)
    y_m = np.zeros(net.nb, complex)
    names = {}
    for c in system.components.values():
        if c.kind != "machine":
            continue
        for i, nm in enumerate(c.names):
            b = int(c.bus[i])
            y_m[b] += 1.0 / complex(float(c.p["ra"][i]), machine_reactance(c, i))
            names.setdefault(b, []).append(f"{nm} ({c.type_name})")
    out = np.zeros(net.nb)
    bad = []
    for b, who in names.items():
        if b_node[b] <= 0:
            continue
        lam = -(np.real(y_shunt[b]) + y_m[b])            # × ω0 / b: only its angle matters
        if -lam.real >= ZETA * abs(lam):
            continue
        z = 1.0 / y_m[b]
        r = ZETA * z.imag / math.sqrt(1.0 - ZETA ** 2)
        Rd = max(r - z.real, 0.0)
        if b_node[b] * Rd > MAX_SHIFT:
            bad.append(f"bus {net.bus_ids[b]} ({', '.join(who)}; capacitance {b_node[b]:.4g} pu "
                       f"at the machine's node, its mode at ≈ {net.f_hz / (z.imag * b_node[b]):.4g} Hz "
                       f"needs a damping resistor of {Rd:.4g} pu, which would change the "
                       f"capacitance's admittance by {100 * b_node[b] * Rd:.3g} % > "
                       f"{100 * MAX_SHIFT:g} %)")
            continue
        out[b] = Rd
    if bad:
        raise DataError("simulation", "engine", "dpsim",
                        "a DPsim machine with large capacitance at its own node rings undamped "
                        "after any current interruption (its algebraic stator is a reactance at "
                        "every frequency; weakgrid.sim.emt.damping): " + "; ".join(bad)
                        + ". Fix: put the capacitance behind the machine's step-up transformer or "
                          "an inductive tie, give the machine its stator resistance ra, or run "
                          "the phasor engine")
    return out


__all__ = ["ZETA", "MAX_SHIFT", "machine_reactance", "node_capacitance", "terminal_damping"]
