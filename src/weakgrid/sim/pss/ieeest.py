"""IEEEST: IEEE standard PSS (PSS/E IEEEST; input modes 1, 3, 4, 5).

Block diagram (PSS/E's Model Library; IEEE 421.5 PSS1A's filter)::

    sig --[(1 + A5 s + A6 s^2) / ((1 + A1 s + A2 s^2)(1 + A3 s + A4 s^2))]
        --[(1+sT1)/(1+sT2)]--[(1+sT3)/(1+sT4)]--[KS]--[sT5/(1+sT6)]--> clip(LSMIN, LSMAX) = vs

Input ``sig`` by ``MODE``: 1 speed deviation ``omega - 1`` [pu]; 3 electrical
power on the machine base [pu]; 4 accelerating power ``tm - tm0`` [pu, system
base]; 5 terminal voltage [pu]. The output is added to the exciter's summing
junction. The output is cut (set to 0) when the terminal voltage leaves ``[VCL, VCU]``.

The filter is one transfer function: its numerator is realized over whichever denominator
factor has at least its order (``(A3, A4)`` first, else ``(A1, A2)``, else their product when
both are first order), the other factor is a plain second-order lag. So PSS/E's usual data
``A1 = 1.013, A2 = 0.013, A3 = A4 = 0, A5 = 1.013, A6 = 0.113`` (PSID's MultiGen and IEEEST
benchmarks, the WECC 240-bus case) filter as ``(1 + A5 s + A6 s^2)/(1 + A1 s + A2 s^2)``, as PSS/E
and PowerSimulationsDynamics.jl compute it. ANDES 2.0 pairs the numerator with ``(A3, A4)`` only
and bypasses that factor when ``A4 = 0`` (numerator dropped); ``F2_bypass = 1`` reproduces it
(``from_andes(..., conventions="andes")``). A numerator of higher order than the whole
denominator (improper) is refused naming A5/A6.

Zero-parameter conventions (as PSS/E and ANDES): ``VCU = 0`` / ``VCL = 0`` means no
upper / lower cut-off; ``T5 = 0`` turns the washout ``sT5/(1+sT6)`` into the lag
``1/(1+sT6)``; a filter with all its coefficients zero, or a lead-lag with both time
constants zero, passes its input.
"""

from __future__ import annotations

import numpy as np

from ..blocks import LeadLag, Washout
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param


class IEEEST(MachineControl):
    """IEEE standard PSS. Parameters: MODE; A1..A6, T1..T6 [s]; KS [pu]; LSMAX, LSMIN, VCU, VCL [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "pss"
    order = 1
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("MODE", "_BUSR", "A1", "A2", "A3", "A4", "A5", "A6", "T1", "T2", "T3", "T4",
                   "T5", "T6", "KS", "LSMAX", "LSMIN", "VCU", "VCL")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E IEEEST: ICONs input code (MODE) and remote bus; remote bus 0 = the machine's own
        bus (the only one this model measures)."""
        from ..io.psse.conventions import local_bus

        local_bus(values, "_BUSR", ctx)
        return dict(values)

    params = (
        Param("MODE", 1.0, "-", "input signal (1 speed, 3 Pe, 4 accelerating power, 5 voltage)", "pos"),
        Param("A1", 0.0, "s", "filter pole coefficient (s)", "nonneg"),
        Param("A2", 0.0, "s^2", "filter pole coefficient (s^2)", "nonneg"),
        Param("A3", 0.0, "s", "filter pole coefficient (s)", "nonneg"),
        Param("A4", 0.0, "s^2", "filter pole coefficient (s^2)", "nonneg"),
        Param("A5", 0.0, "s", "filter zero coefficient (s)", "nonneg"),
        Param("A6", 0.0, "s^2", "filter zero coefficient (s^2)", "nonneg"),
        Param("T1", 1.0, "s", "first lead", "nonneg"),
        Param("T2", 1.0, "s", "first lag", "nonneg"),
        Param("T3", 1.0, "s", "second lead", "nonneg"),
        Param("T4", 1.0, "s", "second lag", "nonneg"),
        Param("T5", 1.0, "s", "washout numerator", "nonneg"),
        Param("T6", 1.0, "s", "washout denominator", "pos"),
        Param("KS", 1.0, "pu", "gain", ""),
        Param("LSMAX", 0.3, "pu", "output upper limit", ""),
        Param("LSMIN", -0.3, "pu", "output lower limit", ""),
        Param("VCU", 999.0, "pu", "voltage cutoff upper", ""),
        Param("VCL", -999.0, "pu", "voltage cutoff lower", ""),
        Param("F2_bypass", 0.0, "-", "1: ANDES 2.0's filter, (1 + A5 s + A6 s^2)/(1 + A3 s + A4 s^2) "
              "bypassed when A4 = 0; 0: PSS/E's (the numerator over the whole denominator)", "flag"),
    )
    states = ("F1a", "F1b", "F2a", "F2b", "LL1", "LL2", "WO")
    outputs = ("sig", "vss")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i, mode in enumerate(p["MODE"]):
            if mode not in (1, 3, 4, 5):
                raise DataError(self.element(i), "MODE", mode, "supported input modes are 1, 3, 4 and 5")
        self.LL1 = LeadLag(p["T1"], p["T2"])
        self.LL2 = LeadLag(p["T3"], p["T4"])
        self.WO = Washout(p["T5"], p["T6"])
        self._wo_lag = p["T5"] <= 0          # T5 = 0: the washout degenerates into a lag 1/(1+sT6)
        self._any_wo_lag = bool(self._wo_lag.any())
        # VCU = 0 / VCL = 0: no cut-off on that side
        self.VCU = np.where(p["VCU"] == 0, 999.0, p["VCU"])
        self.VCL = np.where(p["VCL"] == 0, -999.0, p["VCL"])
        # constant structure flags (fast paths of compute)
        # one input mode for all instances (the usual case): that signal alone, no select
        self._mode = int(p["MODE"][0]) if np.all(p["MODE"] == p["MODE"][0]) else None
        self._pe_scale = system.Sb / self.Sn   # Pe on the machine base (MODE 3)
        self._pair_filter()
        self._filt1 = bool(np.any((self._lp[0] > 0) | (self._lp[1] > 0)))
        self._filt2 = bool(np.any((self._ll[0] > 0) | (self._ll[1] > 0)))
        self._no_cut = bool(np.all(self.VCL <= -999.0) and np.all(self.VCU >= 999.0))

    def _pair_filter(self):
        """Split the filter into a lag ``1/(1 + a1 s + a2 s^2)`` (``self._lp``) and a lead-lag
        ``(1 + A5 s + A6 s^2)/(1 + b1 s + b2 s^2)`` (``self._ll``, ``self._num``) whose
        denominator has at least the numerator's order (see the module docstring)."""
        p = self.p
        A1, A2, A3, A4, A5, A6 = (p[k].copy() for k in ("A1", "A2", "A3", "A4", "A5", "A6"))
        andes = (p["F2_bypass"] > 0) & (A4 <= 0)     # ANDES 2.0: the second factor bypassed
        A3[andes] = A5[andes] = A6[andes] = 0.0

        def order(a, b):
            return np.where(b > 0, 2, np.where(a > 0, 1, 0))

        n, o12, o34 = order(A5, A6), order(A1, A2), order(A3, A4)
        on34 = o34 >= n
        on12 = ~on34 & (o12 >= n)
        both = ~on34 & ~on12 & (o12 + o34 >= n)       # two first-order factors, A6 > 0
        for i in np.nonzero(~(on34 | on12 | both))[0]:
            raise DataError(self.element(i), "A6" if A6[i] > 0 else "A5", float(A6[i] or A5[i]),
                            "the filter (1 + A5 s + A6 s^2)/((1 + A1 s + A2 s^2)(1 + A3 s + A4 s^2)) "
                            "has a numerator of higher order than its denominator: set A5/A6 to 0 "
                            "or give the denominator (A1..A4) at least that order")
        b1 = np.where(on34, A3, np.where(on12, A1, A1 + A3))
        b2 = np.where(on34, A4, np.where(on12, A2, A1 * A3))
        a1 = np.where(on34, A1, np.where(on12, A3, 0.0))
        a2 = np.where(on34, A2, np.where(on12, A4, 0.0))
        self._lp, self._ll, self._num = (a1, a2), (b1, b2), (A5, A6)

    def _signal(self, ctx):
        xp, s, mi = self.xp, ctx.sig, self._mi
        if self._mode is not None:               # one input mode for all (the usual case)
            if self._mode == 1:
                return take(xp, s["omega"], mi) - 1.0
            if self._mode == 3:
                return take(xp, s["Pe"], mi) * self._pe_scale
            if self._mode == 4:
                return take(xp, s["tm"], mi) - take(xp, s["tm0"], mi)
            return take(xp, s["Vt"], mi)
        mode = self.p["MODE"]      # per instance: numpy.select's choice, 0 for none
        return xp.where(mode == 1, take(xp, s["omega"], mi) - 1.0,
                        xp.where(mode == 3, take(xp, s["Pe"], mi) * self._pe_scale,
                                 xp.where(mode == 4, take(xp, s["tm"], mi) - take(xp, s["tm0"], mi),
                                          xp.where(mode == 5, take(xp, s["Vt"], mi), 0.0))))

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        mode = p["MODE"]
        u0 = np.select([mode == 1, mode == 3, mode == 4, mode == 5],
                       [0.0 * m, sig["Pe0"][m] * self._pe_scale, 0.0 * m, sig["Vt0"][m]])
        x[self.sl(0)] = u0
        x[self.sl(1)] = 0.0
        x[self.sl(2)] = u0
        x[self.sl(3)] = 0.0
        x[self.sl(4)] = u0
        x[self.sl(5)] = u0
        x[self.sl(6)] = p["KS"] * u0

    def _second_order(self, xa, xb, u, a1, a2):
        """States of 1/(1 + a1 s + a2 s^2) (xa = output, xb = its derivative); a2 = 0 reduces order."""
        xp = self.xp
        on2 = a2 > 0
        on1 = a1 > 0
        a2s = xp.where(on2, a2, 1.0)
        a1s = xp.where(on1, a1, 1.0)
        dxa = xp.where(on2, xb, xp.where(on1, (u - xa) / a1s, 0.0))
        dxb = xp.where(on2, (u - xa - a1 * xb) / a2s, 0.0)
        y = xp.where(on2 | on1, xa, u)
        return y, dxa, dxb

    def compute(self, ctx):
        xp, p, x, f, sl = self.xp, self.p, ctx.x, ctx.f, self._sls
        u = self._signal(ctx)
        if self._filt1:
            y1, f[..., sl[0]], f[..., sl[1]] = self._second_order(x[..., sl[0]], x[..., sl[1]], u, *self._lp)
        else:   # no lag: output = input, derivatives 0
            y1 = u
        if self._filt2:
            # (1 + A5 s + A6 s^2)/(1 + b1 s + b2 s^2): w = y1/(den), output = w + A5 w' + A6 w''
            b1, b2 = self._ll
            A5, A6 = self._num
            w, f[..., sl[2]], f[..., sl[3]] = self._second_order(x[..., sl[2]], x[..., sl[3]], y1, b1, b2)
            wdot = xp.where(b2 > 0, x[..., sl[3]], xp.where(b1 > 0, f[..., sl[2]], 0.0))
            wdd = xp.where(b2 > 0, f[..., sl[3]], 0.0)
            y2 = w + A5 * wdot + A6 * wdd
        else:
            y2 = y1
        x4, x5, x6 = x[..., sl[4]], x[..., sl[5]], x[..., sl[6]]
        y3, f[..., sl[4]] = self.LL1.output_deriv(x4, y2)
        y4, f[..., sl[5]] = self.LL2.output_deriv(x5, y3)
        vks = p["KS"] * y4
        vss, f[..., sl[6]] = self.WO.output_deriv(x6, vks)
        if self._any_wo_lag:
            vss = xp.where(self._wo_lag, x6, vss)
        vs = xp.minimum(xp.maximum(vss, p["LSMIN"]), p["LSMAX"])
        if not self._no_cut:
            vt = take(xp, ctx.sig["Vt"], self._mi)
            vs = xp.where((vt > self.VCL) & (vt < self.VCU), vs, 0.0)
        put(xp, ctx.sig["vs"], self._mi, vs)
        ctx.out["IEEEST.sig"], ctx.out["IEEEST.vss"] = u, vss
