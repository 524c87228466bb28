"""Transfer two-port from a source's internal voltage to the UPQC's series node ``V' = Vr + Vu``.

The simulator's UPQC adds ``Vu`` at the shunt-bus (r) end of its series branch, so the branch
current is ``(Vr + Vu − V1)/Zu``. A source (GTI internal voltage ``Es`` behind its coupling
reactance, or an SG's ``E'`` behind ``x'd``) on the machine side of that branch drives current
into ``V'`` through the *machine side* of the network: every bus reachable from the source's bus
without crossing the UPQC branch. Kron-reducing the admittance matrix of
``[E, machine-side buses, V']`` to its two external nodes gives::

    I_E = Y11·E + Y12·V'

and the design model (9)/(10) uses ``B = |Y12|`` (the transfer susceptance of the whole path),
up to the loss angle ``ε = ∠Y12 − π/2`` (zero for a lossless path).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..game.errors import ParameterError
from ..sim.network import BR_B, BR_R, BR_X, F_BUS, T_BUS

PD, QD, GS, BS = 2, 3, 4, 5  # MATPOWER bus-table columns

__all__ = ["TwoPort", "machine_side_buses", "source_twoport"]


@dataclass
class TwoPort:
    """Kron-reduced two-port ``[[Y11, Y12], [Y21, Y22]]`` (pu, system base) and its path.

    Attributes
    ----------
    Y11, Y12 : complex
    buses : list of int
        External numbers of the machine-side buses that were eliminated.
    branches : list of int
        0-based rows of the machine-side branches in the path.
    lossless : bool
        Whether resistances and line charging were dropped (reactances only).
    Y22 : complex
        Driving-point admittance at ``V'`` (pu), used to add the grid's Thevenin impedance behind
        ``V'`` (:meth:`through`).
    """

    Y11: complex
    Y12: complex
    buses: list
    branches: list
    lossless: bool
    Y22: complex = complex("nan")

    def through(self, z: complex) -> complex:
        """Transfer admittance ``Y12·y/(Y22 + y)`` from the source to a node behind ``V'``
        through the series impedance ``z`` (pu), e.g. the grid's Thevenin impedance.

        ``V'`` is eliminated (Kron reduction of ``[E, V', E_th]``); ``z = 0`` returns ``Y12``.
        """
        if z == 0:
            return self.Y12
        y = 1.0 / z
        return self.Y12 * y / (self.Y22 + y)

    @property
    def B(self) -> float:
        """Transfer susceptance ``|Y12|`` (pu)."""
        return float(abs(self.Y12))

    @property
    def loss_angle(self) -> float:
        """ε = ∠Y12 − π/2 (rad): zero for a lossless path."""
        return float(np.angle(self.Y12) - np.pi / 2)


def machine_side_buses(network, source_bus: int, upqc_branch: int):
    """Bus positions reachable from ``source_bus`` (position) without the UPQC branch.

    Returns ``(buses, branches)`` (positions, branch rows). Raises if the shunt bus r is reached
    (the UPQC branch is then not the only path between the source and the grid).
    """
    net = network
    f = np.array([net.index_of(int(b)) for b in net.branch[:, F_BUS]])
    t = np.array([net.index_of(int(b)) for b in net.branch[:, T_BUS]])
    on = net.branch[:, 10] > 0
    r = int(f[upqc_branch])
    seen, stack, rows = {source_bus}, [source_bus], set()
    while stack:
        b = stack.pop()
        for k in np.nonzero(on & ((f == b) | (t == b)))[0]:
            if k == upqc_branch:
                continue
            rows.add(int(k))
            o = int(t[k]) if f[k] == b else int(f[k])
            if o not in seen:
                seen.add(o)
                stack.append(o)
    if r in seen:
        raise ParameterError("upqc.branch", upqc_branch,
                             "the controlled machine reaches the UPQC shunt bus without crossing "
                             "the UPQC branch: put the UPQC in the branch that joins the machine "
                             "to the rest of the grid")
    return sorted(seen), sorted(rows)


def source_twoport(system, source_bus: int, source_y: complex, upqc_branch: int,
                   lossless: bool = False, allow_loads: bool = False) -> TwoPort:
    """Two-port from a source's internal voltage to ``V'`` of UPQC branch ``upqc_branch``.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up (its network's power flow solved).
    source_bus : int
        Position (0-based) of the bus the source is connected to.
    source_y : complex
        Admittance between the internal voltage and ``source_bus`` (pu, system base), e.g.
        ``−j·B_gti`` or ``1/(ra + j·x'd)``.
    upqc_branch : int
        0-based branch row of the UPQC series branch (from-bus = shunt bus r).
    lossless : bool
        Keep reactances only (resistances and line charging dropped), as the classical design
        model (9) does.
    allow_loads : bool
        Machine-side buses normally must carry no load or shunt (checked); with True, their
        load admittances at the power-flow voltage are included.
    """
    net = system.network
    buses, rows = machine_side_buses(net, source_bus, upqc_branch)
    b1 = net.index_of(int(net.branch[upqc_branch, T_BUS]))
    for b in buses:
        if any(net.bus[b, c] != 0 for c in (PD, QD, GS, BS)) and not allow_loads:
            raise ParameterError("loads", int(net.bus_ids[b]),
                                 "the path from the controlled machine to the UPQC must carry no "
                                 "load or shunt (the design model (9) has none)")
    # node order: 0 = internal voltage, 1..m = machine-side buses, m+1 = V'
    m = len(buses)
    loc = {b: i + 1 for i, b in enumerate(buses)}
    Y = np.zeros((m + 2, m + 2), complex)

    def series(i, j, y):
        Y[i, i] += y; Y[j, j] += y; Y[i, j] -= y; Y[j, i] -= y  # noqa: E702

    ys = complex(0, source_y.imag) if lossless else source_y
    series(0, loc[source_bus], ys)
    ff, tt, Yff, Yft, Ytf, Ytt = net.branch_admittances()
    for k in rows:
        i, j = loc[int(ff[k])], loc[int(tt[k])]
        if lossless:
            series(i, j, 1.0 / complex(0.0, net.branch[k, BR_X]))
        else:
            Y[i, i] += Yff[k]; Y[i, j] += Yft[k]; Y[j, i] += Ytf[k]; Y[j, j] += Ytt[k]  # noqa: E702
    if allow_loads:
        yl = net.load_admittance(net.pf.V)
        for b in buses:
            Y[loc[b], loc[b]] += yl[b]
    row = net.branch[upqc_branch]
    yu = 1.0 / complex(0.0 if lossless else row[BR_R], row[BR_X])
    if row[BR_B] != 0:
        raise ParameterError("upqc.branch", upqc_branch, "the UPQC branch must have no charging")
    series(loc[b1], m + 1, yu)
    ext, inn = [0, m + 1], list(range(1, m + 1))
    Yr = Y[np.ix_(ext, ext)] - Y[np.ix_(ext, inn)] @ np.linalg.solve(Y[np.ix_(inn, inn)],
                                                                      Y[np.ix_(inn, ext)])
    return TwoPort(Yr[0, 0], Yr[0, 1], [int(net.bus_ids[b]) for b in buses], rows, lossless,
                   Yr[1, 1])
