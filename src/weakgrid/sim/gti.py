"""Grid-tie inverter (GTI) of a renewable generator with dc-link capacitor dynamics.

Model (per unit on the system base; time in s)::

    C*Vc*dVc/dt = Pin - Pe - P_series          (P_series: reduced-UPQC draw, else 0)
    Pe = (1 + chi) * P_ac,  P_ac = Re(Es * conj(I))
    Vs = ks*Vc, ks = min(Vs_ref/Vc, ks_max)    (ideal inner loop holding Vs at Vs_ref; modulation limit)
    Es = Vs * exp(j*(theta_r + phi_s)),  I = -j*B*(Es - V)   (coupling susceptance B to its bus)
    phi_s = phi_s0 + phi_hat                    (angle w.r.t. the UPQC shunt bus r, ideal PLL)

Phase control, ``mode="energy"`` (the paper's eq. (4)-(5))::

    d(phi_hat)/dt = upsilon,  upsilon = tau*(Vc^2 - Vc0^2)/2

``mode="pq"`` (conventional baseline): PID loops (derivative filtered by ``Td``)::

    phi_s  = phi_s0 + PID_P(P_ref - Pm),   P_ref = Pin/(1+chi) + PI_dc(Vc - Vc0)
    Vs_ref = Vs0    + PID_Q(Q_ref - Qm),   Q_ref = initial Q
    Td dPm/dt = P_ac - Pm,  Td dQm/dt = Q - Qm   (measurement filters)

The outer dc-voltage loop ``PI_dc = kp_v + ki_v/s`` is how a real PQ-controlled GTI
keeps its dc link at its set-point (a surplus of dc energy raises the power
reference); with ``kp_v = ki_v = 0`` (the default) ``P_ref`` is fixed and the dc link
is left to drift after a disturbance.

The GTI replaces row ``gen`` of the gen table; ``Pin``, ``Vs0`` and ``phi_s0``
follow from the power flow. Energy base: ``C*Vc^2/2`` in pu·s on ``Sb``.
"""

from __future__ import annotations

import numpy as np

from .blocks import PID
from .component import Component, fast_index
from .errors import DataError
from .namespace import add_at, take
from .params import Param


class GTI(Component):
    """Vectorized grid-tie inverters; add instances with :meth:`add_gti`."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    #: set-points computed at init (from the operating point): per batch member
    batch_params = ("Pin", "phi0", "Vs0", "Q0", "Pac0")
    #: the last evaluation's values (read by ``finish``)
    scratch = ("_Pac", "_Q", "_Vs", "_ks", "_phis")
    order = 0
    params = (
        Param("C", 0.01, "pu·s (Sb)", "dc-link capacitance (energy C*Vc^2/2 in pu·s)", "pos"),
        Param("Vc0", 1.0, "pu", "steady-state dc-link voltage", "pos"),
        Param("chi", 0.0, "pu", "inverter loss factor chi (Pe = (1+chi)*P_ac)", "nonneg"),
        Param("B", 10.0, "pu (Sb)", "coupling susceptance inverter-bus", "pos"),
        Param("ks_max", 2.0, "-", "modulation-index limit", "pos"),
        Param("tau", 1.0, "1/(pu·s)", "phase-control gain tau", "nonneg"),
        Param("kp_p", 1.163, "rad/pu", "P-loop proportional gain (pq mode)", ""),
        Param("ki_p", 0.105, "rad/(pu·s)", "P-loop integral gain (pq mode)", ""),
        Param("kd_p", 0.0, "rad·s/pu", "P-loop derivative gain (pq mode)", ""),
        Param("kp_q", 0.0001, "pu/pu", "Q-loop proportional gain (pq mode)", ""),
        Param("ki_q", 0.001, "1/s", "Q-loop integral gain (pq mode)", ""),
        Param("kd_q", 0.001, "s", "Q-loop derivative gain (pq mode)", ""),
        Param("Td", 0.01, "s", "derivative filter time constant", "pos"),
        Param("kp_v", 0.0, "pu/pu", "dc-voltage loop proportional gain (pq mode): P_ref per "
              "pu of Vc - Vc0", "nonneg"),
        Param("ki_v", 0.0, "pu/(pu·s)", "dc-voltage loop integral gain (pq mode)", "nonneg"),
    )
    states = ("Vc", "phi_hat", "Pm", "Qm", "xi_p", "xd_p", "xi_q", "xd_q", "xi_v")
    outputs = ("Vs", "ks", "phi_s", "P_ac", "Q", "Pe", "upsilon", "P_series", "dVc")
    units = {"P_ac": "power", "Q": "power", "Pe": "power", "P_series": "power", "phi_s": "angle",
             "phi_hat": "angle"}

    def add_gti(self, name, gen, ref_bus, mode="energy", **params):
        """Add one inverter.

        Parameters
        ----------
        name : str
        gen : int
            0-based gen-table row it replaces (its bus is the inverter's bus).
        ref_bus : int
            External number of the UPQC shunt bus r (angle reference of ``phi_s``).
        mode : {"energy", "pq"}
            Phase control law (see module docstring).
        """
        if mode not in ("energy", "pq"):
            raise DataError(f"GTI '{name}'", "mode", mode, "use 'energy' or 'pq'")
        self.add(name, {"gen": gen, "ref_bus": ref_bus, "mode": mode}, params)
        return name

    def setup(self, system):
        super().setup(system)
        net = system.network
        self.resolve_gen_rows(system)
        self.ref = np.zeros(self.n, int)
        for i, lk in enumerate(self.links):
            self.ref[i] = net.index_of(lk["ref_bus"], self.element(i), "ref_bus")
        self.pq = np.array([lk["mode"] == "pq" for lk in self.links])
        p = self.p
        self.pidP = PID(p["kp_p"], p["ki_p"], p["kd_p"], p["Td"])
        self.pidQ = PID(p["kp_q"], p["ki_q"], p["kd_q"], p["Td"])
        self.p_series = np.zeros(self.n)
        self._any_pq = bool(self.pq.any())
        self._uniq = len(set(self.bus.tolist())) == self.n
        # the buses as slices where they can be (basic indexing: no gather per evaluation)
        self._bi = fast_index(self.bus) if self._uniq else self.bus
        self._refi = fast_index(self.ref)

    def pattern(self, system):
        groups = []
        for i in range(self.n):
            v = self.instance_states(i) + system.bus_vars(self.bus[i]) + system.bus_vars(self.ref[i])
            rows = self.instance_states(i) + system.bus_vars(self.bus[i])
            groups.append((rows, v))
        return groups

    def init(self, system, x, sig):
        pf = system.network.pf
        p = self.p
        V = pf.V[self.bus]
        S = pf.Pg[self.gen] + 1j * pf.Qg[self.gen]
        I = np.conj(S / V)
        Es = V + 1j * I / p["B"]
        self.Vs0 = np.abs(Es)
        self.phi0 = np.angle(Es) - np.angle(pf.V[self.ref])
        self.Pac0 = (Es * np.conj(I)).real
        self.Q0 = S.imag
        self.Pin = (1 + p["chi"]) * self.Pac0
        ks0 = self.Vs0 / p["Vc0"]
        for i in np.nonzero(ks0 > p["ks_max"])[0]:
            raise DataError(self.element(i), "ks_max", p["ks_max"][i],
                            f"initial modulation index Vs0/Vc0 = {ks0[i]:.4g} exceeds it; raise ks_max or Vc0")
        x[self.sl(0)] = p["Vc0"]
        for k in range(1, 9):
            x[self.sl(k)] = 0.0
        x[self.sl(2)] = self.Pac0
        x[self.sl(3)] = self.Q0

    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        Vc, ph = x[..., sl[0]], x[..., sl[1]]
        V = take(xp, ctx.V, self._bi)
        Vref = take(xp, ctx.V, self._refi)
        th_r = xp.atan2(xp.imag(Vref), xp.real(Vref))     # np.angle's arithmetic
        phi_s = self.phi0 + ph
        Vs_ref = self.Vs0
        if self._any_pq:
            # PID on filtered measurements (states only: no algebraic loop)
            Pref = self.Pin / (1 + p["chi"]) + p["kp_v"] * (Vc - p["Vc0"]) + x[..., sl[8]]
            eP = Pref - x[..., sl[2]]
            eQ = self.Q0 - x[..., sl[3]]
            uP = self.pidP.output(x[..., sl[4]], x[..., sl[5]], eP)
            uQ = self.pidQ.output(x[..., sl[6]], x[..., sl[7]], eQ)
            phi_s = xp.where(self.pq, self.phi0 + uP, phi_s)
            Vs_ref = xp.where(self.pq, self.Vs0 + uQ, Vs_ref)
            self._eP, self._eQ = eP, eQ
        Vcs = Vc if xp.all(Vc > 1e-6) else xp.where(Vc > 1e-6, Vc, 1e-6)
        ks = xp.minimum(Vs_ref / Vcs, p["ks_max"])
        Vs = ks * Vc
        Es = Vs * xp.exp(1j * (th_r + phi_s))
        I = -1j * p["B"] * (Es - V)
        add_at(self.xp, ctx.I, self._bi, I, self._uniq)
        self._Pac = xp.real(Es * xp.conj(I))
        self._Q = xp.imag(V * xp.conj(I))
        self._Vs, self._ks, self._phis = Vs, ks, phi_s
        ctx.sig["gti_p_series"] = xp.zeros(x.shape[:-1] + (self.n,), dtype=xp.float64)

    def finish(self, ctx):
        xp, p, x, f, sl = self.xp, self.p, ctx.x, ctx.f, self._sls
        Vc = x[..., sl[0]]
        ps = ctx.sig["gti_p_series"]
        Pe = (1 + p["chi"]) * self._Pac
        dVc = (self.Pin - Pe - ps) / (p["C"] * Vc)
        ups = p["tau"] * (Vc ** 2 - p["Vc0"] ** 2) / 2
        f[..., sl[0]] = dVc
        if self._any_pq:
            q = self.pq
            f[..., sl[1]] = xp.where(q, 0.0, ups)
            f[..., sl[2]] = xp.where(q, (self._Pac - x[..., sl[2]]) / p["Td"], 0.0)
            f[..., sl[3]] = xp.where(q, (self._Q - x[..., sl[3]]) / p["Td"], 0.0)
            dip, ddp = self.pidP.deriv(x[..., sl[4]], x[..., sl[5]], self._eP)
            diq, ddq = self.pidQ.deriv(x[..., sl[6]], x[..., sl[7]], self._eQ)
            f[..., sl[4]], f[..., sl[5]] = xp.where(q, dip, 0.0), xp.where(q, ddp, 0.0)
            f[..., sl[6]], f[..., sl[7]] = xp.where(q, diq, 0.0), xp.where(q, ddq, 0.0)
            f[..., sl[8]] = xp.where(q, p["ki_v"] * (Vc - p["Vc0"]), 0.0)
        else:   # all energy mode: the pq states are constant (their f stays 0)
            f[..., sl[1]] = ups
        o = ctx.out
        o["GTI.Vs"], o["GTI.ks"], o["GTI.phi_s"] = self._Vs, self._ks, self._phis
        o["GTI.P_ac"], o["GTI.Q"], o["GTI.Pe"] = self._Pac, self._Q, Pe
        o["GTI.upsilon"], o["GTI.P_series"], o["GTI.dVc"] = ups, ps + 0.0, dVc
