"""Gate-to-power characteristic of the PSS/E hydro PID governors (PIDGOV, WPIDHY).

The turbine's steady power against gate opening is the broken line through
``(G0, 0), (G1, P1), (G2, P2), (1, P3)``: zero below ``G0`` (no-load gate), the last segment
continued beyond full gate. It must increase (``G0 < G1 < G2 < 1``, ``0 < P1 < P2 < P3``) so
that the initial gate is the inverse of the initial power.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError


def check_gate_table(comp):
    """Refuse a non-increasing gate-power table, naming the first field out of order."""
    p = comp.p
    for i in range(comp.n):
        g = [p["G0"][i], p["G1"][i], p["G2"][i], 1.0]
        w = [0.0, p["P1"][i], p["P2"][i], p["P3"][i]]
        for k, (gf, pf) in enumerate((("G1", "P1"), ("G2", "P2"), (None, "P3")), start=1):
            if not g[k] > g[k - 1]:
                fld = gf or "G2"
                raise DataError(comp.element(i), fld, float(p[fld][i]),
                                "gate openings must increase: G0 < G1 < G2 < 1")
            if not w[k] > w[k - 1]:
                raise DataError(comp.element(i), pf, float(p[pf][i]),
                                "powers of the gate characteristic must increase: 0 < P1 < P2 < P3")


def gate_power(comp, g):
    """Turbine power [pu] at gate ``g`` (broken line, zero below G0, extrapolated beyond 1)."""
    xp, p = comp.xp, comp.p
    G0, G1, G2, P1, P2, P3 = (p[k] for k in ("G0", "G1", "G2", "P1", "P2", "P3"))
    s1 = P1 / (G1 - G0)
    s2 = (P2 - P1) / (G2 - G1)
    s3 = (P3 - P2) / (1.0 - G2)
    return xp.where(g <= G0, 0.0,
                    xp.where(g <= G1, s1 * (g - G0),
                             xp.where(g <= G2, P1 + s2 * (g - G1), P2 + s3 * (g - G2))))


def power_gate(comp, P):
    """Inverse of :func:`gate_power` for ``P >= 0`` (``P = 0`` gives the no-load gate ``G0``)."""
    p = comp.p
    G0, G1, G2, P1, P2, P3 = (p[k] for k in ("G0", "G1", "G2", "P1", "P2", "P3"))
    return np.where(P <= P1, G0 + P * (G1 - G0) / P1,
                    np.where(P <= P2, G1 + (P - P1) * (G2 - G1) / (P2 - P1),
                             G2 + (P - P2) * (1.0 - G2) / (P3 - P2)))
