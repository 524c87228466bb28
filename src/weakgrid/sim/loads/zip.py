"""ZIP load: polynomial (constant power / current / impedance) load (ANDES ``ZIP``).

In the time domain a ZIP replaces the constant-impedance model of the bus load it
represents (its power-flow powers ``P0 + jQ0`` [pu, system base] at voltage ``v0``)::

    P(v) = P0 * (kpp + kpi*v/v0 + kpz*(v/v0)^2) / 100
    Q(v) = Q0 * (kqp + kqi*v/v0 + kqz*(v/v0)^2) / 100
    I = -conj((P + jQ)/V) + conj(P0 + jQ0)/v0^2 * V     (injected; the second term removes
                                                         the bus load's constant impedance)

The percentages must each sum to 100 (else the power flow's operating point is not an
equilibrium; ANDES then reports a failed initialization).
"""

from __future__ import annotations

import numpy as np

from ..component import Component
from ..errors import DataError
from ..namespace import add_at, take
from ..network import PD, QD
from ..params import Param


class ZIP(Component):
    """Polynomial loads, one per bus load share; add with :meth:`add_zip`."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    #: the power-flow voltage magnitude and the admittance it gives the share (from the operating
    #: point, read only when evaluating): per batch member; the share ``P0``, ``Q0`` is the grid's
    batch_params = ("v0", "y0")
    order = 0
    params = (
        Param("kpp", None, "%", "constant-power share of P", ""),
        Param("kpi", None, "%", "constant-current share of P", ""),
        Param("kpz", None, "%", "constant-impedance share of P", ""),
        Param("kqp", None, "%", "constant-power share of Q", ""),
        Param("kqi", None, "%", "constant-current share of Q", ""),
        Param("kqz", None, "%", "constant-impedance share of Q", ""),
    )
    outputs = ("P", "Q")
    units = {"P": "power", "Q": "power"}

    @classmethod
    def andes_link(cls, m, k, pos, ss, Sb, **_):
        """Link of ANDES ZIP ``k``: the bus and powers of the PQ load it replaces (None if off)."""
        pq = ss.PQ
        j = list(pq.idx.v).index(m.pq.v[k])
        if pq.u.v[j] <= 0 or pq.bus.v[j] not in pos:   # off, or on an out-of-service bus
            return None
        # ``vin`` (input values) exists only after ANDES's setup; before it, ``v`` holds them
        p0 = float(pq.p0.v[j] if getattr(pq.p0, "vin", None) is None else pq.p0.vin[j])
        q0 = float(pq.q0.v[j] if getattr(pq.q0, "vin", None) is None else pq.q0.vin[j])
        return {"bus": int(pos[pq.bus.v[j]]), "P0": p0, "Q0": q0}

    def add_zip(self, name, bus, P0, Q0, **params):
        """Add a ZIP load at bus position ``bus`` (0-based) replacing ``P0 + jQ0`` [pu] of its load."""
        self.add(name, {"bus": bus, "P0": P0, "Q0": Q0}, params)
        return name

    def setup(self, system):
        super().setup(system)
        p = self.p
        net = system.network
        self.bus = np.array([lk["bus"] for lk in self.links], int)
        self.P0 = np.array([lk["P0"] for lk in self.links], float)
        self.Q0 = np.array([lk["Q0"] for lk in self.links], float)
        for a, b, c, what in (("kpp", "kpi", "kpz", "P"), ("kqp", "kqi", "kqz", "Q")):
            tot = p[a] + p[b] + p[c]
            for i in np.nonzero(np.abs(tot - 100.0) > 1e-9)[0]:
                raise DataError(self.element(i), a, p[a][i],
                                f"{a} + {b} + {c} = {tot[i]:g} %; the shares of {what} must sum to 100")
        for b in set(self.bus.tolist()):
            on = self.bus == b
            have = net.bus[b, [PD, QD]] / system.Sb
            want = np.array([self.P0[on].sum(), self.Q0[on].sum()])
            if np.any(np.abs(want) > np.abs(have) + 1e-9):
                i = int(np.nonzero(on)[0][0])
                raise DataError(self.element(i), "P0", float(want[0]),
                                f"the ZIP loads at bus {net.bus_ids[b]} exceed its load {have} pu")
        self._uniq = len(set(self.bus.tolist())) == self.n

    def pattern(self, system):
        return [(system.bus_vars(b), system.bus_vars(b)) for b in self.bus]

    def init(self, system, x, sig):
        p = self.p
        V0 = system.network.pf.V[self.bus]
        self.v0 = np.abs(V0)
        self.y0 = np.conj(self.P0 + 1j * self.Q0) / self.v0 ** 2
        self.cp = self.P0 * np.array([p["kpp"], p["kpi"], p["kpz"]]) / 100.0
        self.cq = self.Q0 * np.array([p["kqp"], p["kqi"], p["kqz"]]) / 100.0

    def compute(self, ctx):
        xp = self.xp
        V = take(xp, ctx.V, self.bus)
        v = xp.abs(V)
        r = v / self.v0
        cp, cq = self.cp, self.cq
        P = cp[0, ...] + cp[1, ...] * r + cp[2, ...] * r * r
        Q = cq[0, ...] + cq[1, ...] * r + cq[2, ...] * r * r
        Vs = xp.where(xp.abs(V) > 1e-6, V, 1e-6)
        I = -xp.conj((P + 1j * Q) / Vs) + self.y0 * V
        add_at(xp, ctx.I, self.bus, I, self._uniq)
        ctx.out["ZIP.P"], ctx.out["ZIP.Q"] = P, Q
