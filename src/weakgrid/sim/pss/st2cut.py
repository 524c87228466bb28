"""ST2CUT: dual-input stabilizer with output cut-off (PSS/E ST2CUT; input modes 0, 1, 3, 4, 5).

Block diagram (pu, times in s)::

    sig  --[Lag K1/(1+sT1)]--+
                             +--> IN --[WashoutOrLag sT3/(1+sT4)]--[LeadLag (1+sT5)/(1+sT6)]
    sig2 --[Lag K2/(1+sT2)]--+       --[LeadLag (1+sT7)/(1+sT8)]--[LeadLag (1+sT9)/(1+sT10)]
                                     --> clip(LSMIN, LSMAX) = VSS
    vs = VSS  if  v0 + VCL < v < v0 + VCU  else 0          (output cut-off around the initial voltage)

Inputs by ``MODE`` / ``MODE2``: 0 none; 1 speed deviation ``omega - 1``; 3
electrical power on the machine base (``Pe*Sb/Sn``; equal to PSS/E's air-gap
torque when the armature resistance is zero); 4 accelerating power ``tm - tm0``
[system base]; 5 terminal voltage. Conventions as ANDES: ``T3 = 0`` turns the
washout into the lag ``1/(1+sT4)``; ``VCU = 0`` / ``VCL = 0`` mean no cut-off on
that side. Modes 2 (bus frequency) and 6 (voltage derivative) and remote buses
are not implemented (refused with a clear error).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag, WashoutOrLag, hard_limit
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param

_MODES = (0, 1, 3, 4, 5)


class ST2CUT(MachineControl):
    """Dual-input PSS with cut-off. Parameters: MODE, MODE2; K1, K2 [pu]; T1..T10 [s];
    LSMAX, LSMIN, VCU, VCL [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "pss"
    order = 1
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("MODE", "_BUSR", "MODE2", "_BUSR2", "K1", "K2", "T1", "T2", "T3", "T4", "T5",
                   "T6", "T7", "T8", "T9", "T10", "LSMAX", "LSMIN", "VCU", "VCL")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E ST2CUT: ICONs input codes and remote buses of its two inputs; remote bus 0 =
        the machine's own bus (the only one this model measures)."""
        from ..io.psse.conventions import local_bus

        local_bus(values, "_BUSR", ctx)
        local_bus(values, "_BUSR2", ctx)
        return dict(values)

    params = (
        Param("MODE", 1.0, "-", "input signal 1 (0 none, 1 speed, 3 Pe, 4 accelerating power, 5 voltage)", "nonneg"),
        Param("MODE2", 0.0, "-", "input signal 2 (same codes)", "nonneg"),
        Param("K1", 1.0, "pu", "transducer 1 gain", ""),
        Param("K2", 1.0, "pu", "transducer 2 gain", ""),
        Param("T1", 1.0, "s", "transducer 1 time constant", "nonneg"),
        Param("T2", 1.0, "s", "transducer 2 time constant", "nonneg"),
        Param("T3", 1.0, "s", "washout numerator time constant (0: lag)", "nonneg"),
        Param("T4", 0.2, "s", "washout time constant", "pos"),
        Param("T5", 1.0, "s", "lead-lag 1 lead", "nonneg"),
        Param("T6", 0.5, "s", "lead-lag 1 lag", "nonneg"),
        Param("T7", 1.0, "s", "lead-lag 2 lead", "nonneg"),
        Param("T8", 1.0, "s", "lead-lag 2 lag", "nonneg"),
        Param("T9", 1.0, "s", "lead-lag 3 lead", "nonneg"),
        Param("T10", 0.2, "s", "lead-lag 3 lag", "nonneg"),
        Param("LSMAX", 0.3, "pu", "output upper limit", ""),
        Param("LSMIN", -0.3, "pu", "output lower limit", ""),
        Param("VCU", 999.0, "pu", "cut-off above v0 + VCU (0: none)", ""),
        Param("VCL", -999.0, "pu", "cut-off below v0 + VCL (0: none)", ""),
    )
    states = ("L1", "L2", "WO", "LL1", "LL2", "LL3")
    outputs = ("sig", "sig2", "vss")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for fld in ("MODE", "MODE2"):
            for i, mode in enumerate(p[fld]):
                if mode not in _MODES:
                    raise DataError(self.element(i), fld, mode,
                                    "supported input modes are 0 (none), 1, 3, 4 and 5 "
                                    "(2 bus frequency and 6 dV/dt are not implemented)")
        self.L1 = Lag(p["K1"], p["T1"])
        self.L2 = Lag(p["K2"], p["T2"])
        self.WO = WashoutOrLag(p["T3"], p["T4"])
        self.LL1 = LeadLag(p["T5"], p["T6"])
        self.LL2 = LeadLag(p["T7"], p["T8"])
        self.LL3 = LeadLag(p["T9"], p["T10"])
        self.VCU = np.where(p["VCU"] == 0, 999.0, p["VCU"])
        self.VCL = np.where(p["VCL"] == 0, -999.0, p["VCL"])

    def _signal(self, mode, s, Sb):
        xp, m = self.xp, self._mi     # numpy.select's choice in its order, 0 for none
        return xp.where(mode == 1, take(xp, s["omega"], m) - 1.0,
                        xp.where(mode == 3, take(xp, s["Pe"], m) * Sb / self.Sn,
                                 xp.where(mode == 4, take(xp, s["tm"], m) - take(xp, s["tm0"], m),
                                          xp.where(mode == 5, take(xp, s["Vt"], m), 0.0))))

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        init_sig = {"omega": np.ones_like(sig["tm0"]), "Pe": sig["Pe0"], "tm": sig["tm0"],
                    "tm0": sig["tm0"], "Vt": sig["Vt0"]}
        u1 = self._signal(p["MODE"], init_sig, system.Sb)
        u2 = self._signal(p["MODE2"], init_sig, system.Sb)
        self.v0 = sig["Vt0"][m].copy()
        IN = self.L1.init(u1) + self.L2.init(u2)
        wo = self.WO.output(IN, IN)
        x[self.sl(0)] = self.L1.init(u1)
        x[self.sl(1)] = self.L2.init(u2)
        x[self.sl(2)] = IN
        x[self.sl(3)] = wo
        x[self.sl(4)] = wo
        x[self.sl(5)] = wo

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        s = ctx.sig
        l1, l2, wo, x1, x2, x3 = (ctx.x[..., k] for k in self._sls)
        Sb = ctx.system.Sb
        u1 = self._signal(p["MODE"], s, Sb)
        u2 = self._signal(p["MODE2"], s, Sb)
        IN = self.L1.output(l1, u1) + self.L2.output(l2, u2)
        y0 = self.WO.output(wo, IN)
        y1 = self.LL1.output(x1, y0)
        y2 = self.LL2.output(x2, y1)
        y3 = self.LL3.output(x3, y2)
        f = ctx.f
        f[..., self._sls[0]] = self.L1.deriv(l1, u1)
        f[..., self._sls[1]] = self.L2.deriv(l2, u2)
        f[..., self._sls[2]] = self.WO.deriv(wo, IN)
        f[..., self._sls[3]] = self.LL1.deriv(x1, y0)
        f[..., self._sls[4]] = self.LL2.deriv(x2, y1)
        f[..., self._sls[5]] = self.LL3.deriv(x3, y2)
        vss = hard_limit(y3, p["LSMIN"], p["LSMAX"], xp)
        v = take(xp, s["Vt"], m)
        vs = xp.where((v > self.v0 + self.VCL) & (v < self.v0 + self.VCU), vss, 0.0)
        put(xp, s["vs"], m, vs)
        o = ctx.out
        o["ST2CUT.sig"], o["ST2CUT.sig2"], o["ST2CUT.vss"] = u1, u2, vss
