"""UPQC series branch: an ideal series voltage source inside a network branch.

The UPQC sits in branch ``branch`` of the case (from-bus = shunt bus ``r``,
to-bus = bus 1, series impedance ``Zu = R + jX`` of that branch = the series
transformer leakage). The network keeps the branch impedance; the source adds::

    Vu = (Vuq + j*Vup) * exp(j*theta_r),   |Vu| <= Vmax  (scaled down on the limit)
    I  = (Vr + Vu - V1)/Zu                   branch current r -> 1
    injections: +Vu/Zu at bus 1, -Vu/Zu at bus r           (Norton equivalent of Vu)
    P_series = Re(Vu * conj(I)),  Q_series = Im(Vu * conj(I))

``Vuq`` is in phase with the shunt-bus voltage, ``Vup`` in quadrature (the
paper's u = [u1, u2] = [Vup, Vuq]). Where the series real power comes from:

* ``structure="conventional"``: drawn from bus r by the shunt converter
  (a constant-power injection ``-P_series`` at bus r);
* ``structure="reduced"``: drawn from the dc link of GTI ``gti``, entering its
  balance ``C*Vc*dVc/dt = Pin - Pe - P_series``.

The inputs ``Vup``, ``Vuq`` [pu] are held values set by a digital controller
(:mod:`weakgrid.sim.controllers`) or directly via :meth:`set_input`.
"""

from __future__ import annotations

import numpy as np

from .component import Component, scatter_add
from .errors import DataError
from .network import BR_B, BR_R, BR_X, F_BUS, SHIFT, T_BUS, TAP
from .params import Param


def rating_clip(u, Vmax):
    """``u = [Vup, Vuq]`` [pu] (or rows of them) scaled down to ``|u| <= Vmax`` as the UPQC
    applies it: ``u·min(1, Vmax/|u|)`` with ``|u| = hypot(Vup, Vuq)`` (``Vmax = inf``: u).

    This is the rating clip of the exported digital controller
    (:mod:`weakgrid.models.export_digital`, same operations).
    """
    u = np.asarray(u, float)
    mag = np.hypot(u[..., 0], u[..., 1])
    return u * np.minimum(1.0, Vmax / np.where(mag > 0, mag, 1.0))[..., None]


class UPQC(Component):
    """Vectorized UPQC series branches; add instances with :meth:`add_upqc`."""

    #: the series-voltage commands [pu] a controller holds: per member in a batch
    batch_inputs = ("u_p", "u_q")

    kind = "device"
    order = 3
    params = (Param("Vmax", 0.2, "pu", "series voltage rating |Vu|max", "pos"),)
    states = ()
    outputs = ("Vup", "Vuq", "Vu", "I", "P_series", "Q_series", "P_shunt", "P_line")
    units = {"P_series": "power", "Q_series": "power", "P_shunt": "power", "P_line": "power", "I": "current"}

    def add_upqc(self, name, branch, structure="conventional", gti=None, **params):
        """Add a UPQC in 0-based branch row ``branch`` (from-bus = shunt bus r).

        Parameters
        ----------
        structure : {"conventional", "reduced"}
        gti : str, optional
            Name of the GTI whose dc link feeds the series converter (reduced structure).
        """
        el = f"UPQC '{name}'"
        if structure not in ("conventional", "reduced"):
            raise DataError(el, "structure", structure, "use 'conventional' or 'reduced'")
        if structure == "reduced" and gti is None:
            raise DataError(el, "gti", None, "the reduced structure needs the name of the GTI feeding it")
        self.add(name, {"branch": branch, "structure": structure, "gti": gti}, params)
        return name

    def setup(self, system):
        super().setup(system)
        net = system.network
        n = self.n
        self.branch = np.zeros(n, int)
        self.r = np.zeros(n, int)
        self.b1 = np.zeros(n, int)
        self.yu = np.zeros(n, complex)
        self.reduced = np.zeros(n, bool)
        self.gti_i = np.zeros(n, int)
        for i, lk in enumerate(self.links):
            k = lk["branch"]
            if not (isinstance(k, (int, np.integer)) and 0 <= k < net.nl):
                raise DataError(self.element(i), "branch", k, f"give a branch row 0..{net.nl - 1}")
            row = net.branch[k]
            if row[BR_B] != 0 or row[TAP] not in (0, 1) or row[SHIFT] != 0:
                raise DataError(self.element(i), "branch", k,
                                "the UPQC branch must be a plain series impedance (B = 0, TAP = 0/1, SHIFT = 0)")
            self.branch[i] = k
            self.r[i] = net.index_of(int(row[F_BUS]))
            self.b1[i] = net.index_of(int(row[T_BUS]))
            self.yu[i] = 1.0 / complex(row[BR_R], row[BR_X])
            if lk["structure"] == "reduced":
                gti = system.components.get("GTI")
                if gti is None or lk["gti"] not in gti.names:
                    raise DataError(self.element(i), "gti", lk["gti"], "no GTI with that name in the system")
                self.reduced[i] = True
                self.gti_i[i] = gti.names.index(lk["gti"])
        self.u_p = np.zeros(n)
        self.u_q = np.zeros(n)
        self._conv = ~self.reduced
        self._any_conv = bool(self._conv.any())
        self._any_red = bool(self.reduced.any())
        self._uniq = len(set(self.r.tolist()) | set(self.b1.tolist())) == 2 * n
        self._uniq_g = len(set(self.gti_i[self.reduced].tolist())) == int(self.reduced.sum())

    def set_input(self, name, Vup, Vuq):
        """Hold series-voltage commands ``Vup`` (quadrature) and ``Vuq`` (in phase) [pu] for UPQC ``name``."""
        i = self.names.index(name)
        self.u_p[i] = Vup
        self.u_q[i] = Vuq

    def pattern(self, system):
        groups = []
        gti = system.components.get("GTI")
        for i in range(self.n):
            cols = system.bus_vars(self.r[i]) + system.bus_vars(self.b1[i])
            rows = list(cols)
            if self.reduced[i]:
                rows.append(gti.idx("Vc")[self.gti_i[i]])
            groups.append((rows, cols))
        return groups

    def compute(self, ctx):
        on = ctx.system.branch_status[self.branch]
        Vr = ctx.V[..., self.r]
        V1 = ctx.V[..., self.b1]
        vr_abs = np.abs(Vr)
        if (vr_abs > 1e-6).all():      # fast path (same values as the guarded expressions)
            ur = Vr / vr_abs
            Vr_safe = Vr
        else:
            ur = np.where(vr_abs > 1e-9, Vr / np.where(vr_abs > 1e-9, vr_abs, 1.0), 1.0)
            Vr_safe = np.where(vr_abs > 1e-6, Vr, 1e-6)
        Vu = (self.u_q + 1j * self.u_p) * ur
        mag = np.abs(Vu)
        Vmax = self.p["Vmax"]
        if (mag > Vmax).any():
            Vu = Vu * np.where(mag > Vmax, Vmax / np.where(mag > 0, mag, 1.0), 1.0)
        if not on.all():
            Vu = np.where(on, Vu, 0.0)
        Isrc = self.yu * Vu
        scatter_add(ctx.I, self.b1, Isrc, self._uniq)
        scatter_add(ctx.I, self.r, -Isrc, self._uniq)
        I = self.yu * (Vr + Vu - V1) * on
        S = Vu * np.conj(I)
        P = S.real
        conv = self._conv
        if self._any_conv:
            scatter_add(ctx.I, self.r[conv], -(P[..., conv] / np.conj(Vr_safe[..., conv])), self._uniq)
        if self._any_red:
            red = self.reduced
            scatter_add(ctx.sig["gti_p_series"], self.gti_i[red], P[..., red], self._uniq_g)
        rot = Vu * np.conj(ur)
        o = ctx.out
        o["UPQC.Vuq"], o["UPQC.Vup"], o["UPQC.Vu"] = rot.real, rot.imag, np.abs(Vu)
        o["UPQC.I"], o["UPQC.P_series"], o["UPQC.Q_series"] = np.abs(I), P, S.imag
        o["UPQC.P_shunt"] = np.where(conv, P, 0.0)
        o["UPQC.P_line"] = ((Vr + Vu) * np.conj(I)).real
