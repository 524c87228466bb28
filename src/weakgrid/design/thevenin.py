"""The grid seen from the UPQC shunt bus r: its Thevenin equivalent and the inertia behind it.

The paper's design model (9)/(10) puts an infinite bus at r (``Vr`` stiff). In a grid whose
other machines are of comparable size, the controlled machine swings against them through the
grid's impedance, and its mode is higher than the design model's or lower depending on both. The
"thevenin" design option (:func:`weakgrid.design.derive_design` with ``grid_model="thevenin"``)
replaces the stiff ``Vr`` by

* the grid's Thevenin equivalent at r, ``E_th`` behind ``Z_th``: the network with the UPQC branch
  open (so the controlled machine and its side are removed), every load as its constant
  impedance at the power-flow voltage, every other synchronous machine with an exciter as a
  voltage source at its terminal (its voltage regulator holds it), one without as ``E'``
  behind ``ra + j·x'd`` (the classical model), every other GTI as its internal voltage behind
  ``1/(j·B)``; the sources shorted for ``Z_th``::

      Z_th = [Y_grid⁻¹]_rr ,   E_th = Vr + Z_th·I       (I: current of the UPQC branch r → b1)

* and the two-machine inertia factor: the controlled machine (inertia ``M1``) swings against the
  centre of inertia of the other machines (``M2 = Σ M``), so the relative angle obeys
  ``d²δ/dt² = (1/M1 + 1/M2)·(Pm − Pe)``: the input gain ``a`` is multiplied by ``1 + M1/M2``.

References: Kundur, *Power System Stability and Control*, §12.3 (two-machine system; the
equivalent of the rest of the grid at a bus).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..game.errors import ParameterError
from ..sim.network import BR_R, BR_X, F_BUS, T_BUS
from .twoport import machine_side_buses

__all__ = ["GridThevenin", "SOURCES", "grid_thevenin", "two_machine_factor"]


@dataclass
class GridThevenin:
    """The grid seen from the shunt bus r (pu on the system base).

    Attributes
    ----------
    Z : complex
        Thevenin impedance ``Z_th`` at r, pu.
    E : complex
        Thevenin voltage ``E_th`` (power-flow angle reference), pu.
    M_behind : float
        Sum of the inertia ``M = 2H`` (s, system base) of the synchronous machines behind r
        (``inf`` if there is none; an infinite bus's large M gives a factor close to 1).
    sources : list of str
        The machines and GTIs kept as sources, each with how (at its terminal, behind x'd …).
    """

    Z: complex
    E: complex
    M_behind: float
    sources: list


def two_machine_factor(M1: float, M2: float) -> float:
    """Inertia factor ``1 + M1/M2`` of a machine (M1) swinging against another (M2).

    ``M2 = inf`` (an infinite bus) gives 1: the paper's model.
    """
    if not (M1 > 0) or not (M2 > 0):
        raise ParameterError("M", (M1, M2), "inertias must be positive (M = 2H, s)")
    return 1.0 + (0.0 if math.isinf(M2) else M1 / M2)


SOURCES = ("auto", "terminal", "transient")


def grid_thevenin(system, upqc_branch: int, controlled_bus: int,
                  sources: str = "auto") -> GridThevenin:
    """Thevenin equivalent of the grid at the shunt bus r of ``upqc_branch``.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up (power flow solved, components initialized).
    upqc_branch : int
        0-based row of the UPQC series branch (from-bus = shunt bus r).
    controlled_bus : int
        Position (0-based) of the controlled machine's bus: its side of the UPQC branch is
        removed from the grid.
    sources : {"auto", "terminal", "transient"}
        How the other synchronous machines enter: ``"terminal"`` — as voltage sources at their
        terminal buses (their voltage regulators hold the terminal voltage at the swing
        frequency; the grid's impedance is the network's only); ``"transient"`` — as ``E'``
        behind ``ra + j·x'd`` (constant field: the classical model); ``"auto"`` — terminal for
        a machine with an exciter, transient for one without. Other GTIs are always their
        internal voltage behind ``1/(j·B)``.
    """
    if sources not in SOURCES:
        raise ParameterError("sources", sources, f"choose one of {SOURCES}")
    net = system.network
    V = net.pf.V
    r = net.index_of(int(net.branch[upqc_branch, F_BUS]))
    b1 = net.index_of(int(net.branch[upqc_branch, T_BUS]))
    side, _ = machine_side_buses(net, controlled_bus, upqc_branch)
    side = set(side)
    status = net.branch[:, 10] > 0
    status[upqc_branch] = False
    shunt = net.load_admittance(V).astype(complex)
    names, M2, held = [], 0.0, set()
    gti = system.components.get("GTI")
    for c in system.components.values():
        if c is not gti and c.kind != "machine":
            continue
        for i, name in enumerate(c.names):
            b = int(c.bus[i])
            if b in side:
                continue
            if c is gti:
                shunt[b] += -1j * float(c.p["B"][i])
                names.append(f"{name} behind 1/(jB)")
                continue
            M2 += float(c.p["M"][i])
            avr = bool(system.controls_of(name, "exciter")) if sources == "auto" else False
            if sources == "terminal" or avr:
                held.add(b)
                names.append(f"{name} at its terminal")
            else:
                shunt[b] += 1.0 / complex(float(c.p["ra"][i]), float(c.p["xd1"][i]))
                names.append(f"{name} behind ra + jx'd")
    if not names:
        raise ParameterError("design.grid_model", "thevenin", "the grid behind the UPQC shunt "
                             "bus has no machine or GTI to form a Thevenin source; use "
                             "grid_model = \"paper\"")
    row = net.branch[upqc_branch]
    I = (V[r] - V[b1]) / complex(row[BR_R], row[BR_X])   # r → b1 at the power flow (Vu = 0)
    if r in held:                                          # a held source at r: stiff
        return GridThevenin(0j, complex(V[r]), M2 if M2 > 0 else math.inf, names)
    Y = net.ybus(branch_status=status, shunt=shunt)
    idx = [b for b in range(net.nb) if b not in side and b not in held]
    e = np.zeros(len(idx), complex)
    e[idx.index(r)] = 1.0
    try:
        z = np.linalg.solve(Y[np.ix_(idx, idx)], e)
    except np.linalg.LinAlgError:
        raise ParameterError("design.grid_model", "thevenin", "the grid seen from the shunt "
                             "bus is singular (no source path to ground); use "
                             "grid_model = \"paper\"") from None
    Z = complex(z[idx.index(r)])
    return GridThevenin(Z, complex(V[r] + Z * I), M2 if M2 > 0 else math.inf, names)
