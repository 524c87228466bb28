"""IEEEG1: IEEE type 1 steam turbine-governor, optionally cross-compound (PSS/E IEEEG1).

Block diagram (pu on the system base after conversion; times in s)::

    wd = wref0 - omega                                   (speed of machine ``syn``)
    wd --[LeadLag K(1+sT2)/(1+sT1)]--> LL
    vs = clip((LL + P0 + paux - GV)/T3, UC, UO)          (valve speed, rate limits)
    vs --[Integrator, non-windup PMIN..PMAX]--> GV       (valve/gate position)
    GV --[Lag 1/(1+sT4)]--> L4 --[1/(1+sT5)]--> L5 --[1/(1+sT6)]--> L6 --[1/(1+sT7)]--> L7
    PHP = K1*L4 + K3*L5 + K5*L6 + K7*L7                  -> tm of ``syn`` (high pressure)
    PLP = K2*L4 + K4*L5 + K6*L6 + K8*L7                  -> tm of ``syn2`` (low pressure, optional)

``K1..K8`` are normalized to sum to 1. The turbine base is ``Tn`` if > 0, else
the sum of the ratings of the connected machines; ``K``, ``PMAX``, ``PMIN`` are
on it (``power``: multiplied by base/Sb). ``P0`` is the initial total turbine
power. With two machines the initial split must match ``K``: if
``tm0(syn)*(K2+K4+K6+K8) != tm0(syn2)*(K1+K3+K5+K7)`` the initial point is not
steady; a warning names the device (as ANDES).
"""

from __future__ import annotations

import numpy as np

from ..blocks import IntegratorNonWindup, Lag, LeadLag, hard_limit
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param


class IEEEG1(MachineControl):
    """IEEE type 1 turbine-governor. Link ``machine`` (speed, HP power) and optional ``machine2``
    (LP power). Parameters: K [pu], T1..T7 [s], UO, UC [pu/s], PMAX, PMIN [pu], K1..K8 [-]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the initial gate/power reference computed at init (from the operating point): per batch member
    batch_params = ("P0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("_JBUS", "_M", "K", "T1", "T2", "T3", "UO", "UC", "PMAX", "PMIN", "T4", "K1",
                   "K2", "T5", "K3", "K4", "T6", "K5", "K6", "T7", "K7", "K8")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E IEEEG1: ICONs JBUS, M name the low-pressure machine of a cross-compound unit;
        only JBUS = 0 (single shaft) is read from a .dyr."""
        from ..errors import DataError

        if values["_JBUS"] != 0:
            raise DataError(ctx.where, "JBUS", values["_JBUS"],
                            "cross-compound IEEEG1 (JBUS != 0) is not read from PSS/E files; use 0")
        return dict(values)

    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: sum of machine ratings)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("K", 20.0, "pu (turbine base)", "gain 1/R", "nonneg"),
        Param("T1", 1.0, "s", "governor lag", "nonneg"),
        Param("T2", 1.0, "s", "governor lead", "nonneg"),
        Param("T3", 0.1, "s", "valve controller time constant", "pos"),
        Param("UO", 0.1, "pu/s", "maximum valve opening rate", ""),
        Param("UC", -0.1, "pu/s", "maximum valve closing rate", ""),
        Param("PMAX", 5.0, "pu (turbine base)", "maximum turbine power", ""),
        Param("PMIN", 0.0, "pu (turbine base)", "minimum turbine power", ""),
        Param("T4", 0.4, "s", "inlet piping/steam bowl time constant", "nonneg"),
        Param("K1", 0.5, "-", "HP fraction after T4", ""),
        Param("K2", 0.0, "-", "LP fraction after T4", ""),
        Param("T5", 8.0, "s", "second boiler pass time constant", "nonneg"),
        Param("K3", 0.5, "-", "HP fraction after T5", ""),
        Param("K4", 0.0, "-", "LP fraction after T5", ""),
        Param("T6", 0.5, "s", "third boiler pass time constant", "nonneg"),
        Param("K5", 0.0, "-", "HP fraction after T6", ""),
        Param("K6", 0.0, "-", "LP fraction after T6", ""),
        Param("T7", 0.05, "s", "fourth boiler pass time constant", "nonneg"),
        Param("K7", 0.0, "-", "HP fraction after T7", ""),
        Param("K8", 0.0, "-", "LP fraction after T7", ""),
    )
    states = ("LL", "GV", "L4", "L5", "L6", "L7")
    outputs = ("vs", "PHP", "PLP")

    def setup(self, system):
        super().setup(system)
        p = self.p
        n = self.n
        # second (low-pressure) machine, -1 if none
        self.mach2 = np.array([system.machine_number(lk["machine2"]) if lk.get("machine2") is not None else -1
                               for lk in self.links], dtype=int)
        self.has2 = self.mach2 >= 0
        self._any2 = bool(self.has2.any())
        self._i2 = np.nonzero(self.has2)[0]          # the instances with an LP machine
        self._m2 = self.mach2[self._i2]              # and their LP machines
        Sn2 = np.zeros(n)
        for i in np.nonzero(self.has2)[0]:
            mtype, mname = system._machines[self.mach2[i]]
            mc = system.components[mtype]
            Sn2[i] = mc.p["Sn"][mc.names.index(mname)]
        base = np.where(p["Tn"] > 0, p["Tn"], self.Sn + Sn2) / system.Sb
        for k in ("K", "PMAX", "PMIN"):
            p[k] = p[k] * base
        Ks = np.array([p[f"K{j}"] for j in range(1, 9)])
        tot = Ks.sum(axis=0)
        for i in np.nonzero(tot == 0)[0]:
            raise DataError(self.element(i), "K1", p["K1"][i], "K1..K8 sum to 0; give the turbine power fractions")
        self.Kn = Ks / tot
        self.LL = LeadLag(p["T2"], p["T1"], p["K"])
        self.GV = IntegratorNonWindup(1.0, p["PMIN"], p["PMAX"])
        self.L = [Lag(1.0, p[f"T{j}"]) for j in (4, 5, 6, 7)]
        self.paux = np.zeros(n)

    def limits(self):
        return [(self.idx("GV"), self.p["PMIN"], self.p["PMAX"])]

    def pattern(self, system):
        """The LP output drives the shaft of ``machine2``: its states depend on this governor's."""
        groups = []
        for i in np.nonzero(self.has2)[0]:
            mtype, mname = system._machines[self.mach2[i]]
            mc = system.components[mtype]
            groups.append((mc.instance_states(mc.names.index(mname)), self.instance_states(i)))
        return groups

    def init(self, system, x, sig):
        m = self.mach
        tm0 = sig["tm0"][m]
        tm02 = np.where(self.has2, sig["tm0"][np.maximum(self.mach2, 0)], 0.0)
        hp, lp = self.Kn[0::2].sum(axis=0), self.Kn[1::2].sum(axis=0)
        self.warn_instances(np.nonzero(self.has2 & (np.abs(tm0 * lp - tm02 * hp) > 1e-6))[0],
                            "the initial powers of the two machines do not split as K1..K8; the "
                            "initial point is not steady",
                            lambda i: f"({tm0[i]:.6g}, {tm02[i]:.6g} pu vs {hp[i]:.3g}/{lp[i]:.3g})")
        self.P0 = tm0 + tm02
        self.tm02 = tm02
        x[self.sl(0)] = self.LL.init(np.zeros(self.n))
        for k in range(1, 6):
            x[self.sl(k)] = self.P0

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        ll, gv, l4, l5, l6, l7 = (ctx.x[..., s] for s in self._sls)
        wd = p["wref0"] - take(xp, ctx.sig["omega"], m)
        y = self.LL.output(ll, wd)
        vs = hard_limit((y + self.P0 + self.paux - gv) / p["T3"], p["UC"], p["UO"], xp)
        y4 = self.L[0].output(l4, gv)
        y5 = self.L[1].output(l5, y4)
        y6 = self.L[2].output(l6, y5)
        y7 = self.L[3].output(l7, y6)
        f = ctx.f
        f[..., self._sls[0]] = self.LL.deriv(ll, wd)
        f[..., self._sls[1]] = self.GV.deriv(gv, vs)
        f[..., self._sls[2]] = self.L[0].deriv(l4, gv)
        f[..., self._sls[3]] = self.L[1].deriv(l5, y4)
        f[..., self._sls[4]] = self.L[2].deriv(l6, y5)
        f[..., self._sls[5]] = self.L[3].deriv(l7, y6)
        K = [self.Kn[j, ...] for j in range(8)]
        php = K[0] * y4 + K[2] * y5 + K[4] * y6 + K[6] * y7
        plp = K[1] * y4 + K[3] * y5 + K[5] * y6 + K[7] * y7
        put(xp, ctx.sig["tm"], m, php)
        if self._any2:
            put(xp, ctx.sig["tm"], self._m2, take(xp, plp, self._i2))
        o = ctx.out
        o["IEEEG1.vs"], o["IEEEG1.PHP"], o["IEEEG1.PLP"] = vs, php, plp
