"""EXAC4: IEEE type AC4 alternator-supplied controlled-rectifier exciter (PSS/E EXAC4).

Block diagram (pu on the machine base, times in s; ANDES parameter names)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG + vs                                   (vs: PSS output)
    vil = clip(vi, VIMIN, VIMAX)
    vil --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL  --[Lag KA/(1+sTA)]--> VR
    Efd = clip(VR, VRMIN - KC*XadIfd, VRMAX - KC*XadIfd)   (thyristor bridge ceiling, loaded)

The output limits are a limiter on the regulator output (the lag state is not held), as in
the PSS/E diagram and ANDES 2.0; ``XadIfd`` stands for the field current ``IFD``. The exciter
alternator's own regulation is not modelled (IEEE 421.5). ``vref`` is set at initialization
so that ``Efd = vf0``; the initial input ``vf0/KA`` must lie within ``VIMIN..VIMAX`` and
``vf0`` within the output limits, else setup refuses (``initial_bounds``).
"""

from __future__ import annotations

from ..blocks import Lag, LeadLag, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class EXAC4(MachineControl):
    """IEEE AC4 exciter. Times [s]: TR, TC, TB, TA; gains [pu]: KA, KC;
    limits VIMAX, VIMIN, VRMAX, VRMIN [pu, machine base]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "VIMAX", "VIMIN", "TC", "TB", "KA", "TA", "VRMAX", "VRMIN", "KC")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("VIMAX", 5.0, "pu", "maximum input error", ""),
        Param("VIMIN", -0.1, "pu", "minimum input error", ""),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant", "pos"),
        Param("VRMAX", 8.0, "pu", "maximum output (at zero field current)", ""),
        Param("VRMIN", 0.0, "pu", "minimum output (at zero field current)", ""),
        Param("KC", 0.0, "pu", "rectifier loading factor", "nonneg"),
    )
    states = ("LG", "LL", "VR")
    outputs = ("vi", "vout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LR = Lag(p["KA"], p["TA"])

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
        vi0 = vf0 / p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(vi0)
        x[self.sl(2)] = self.LR.init(vi0)
        self.initial_bounds = [
            ("vi", vi0, p["VIMIN"], p["VIMAX"], "VIMIN", "VIMAX"),
            ("Efd", vf0, p["VRMIN"] - p["KC"] * xad, p["VRMAX"] - p["KC"] * xad,
             "VRMIN - KC*XadIfd", "VRMAX - KC*XadIfd")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, ll, vr = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        vil = hard_limit(vi, p["VIMIN"], p["VIMAX"], xp)
        y = self.LL.output(ll, vil)
        efd = hard_limit(self.LR.output(vr, y), p["VRMIN"] - p["KC"] * xad, p["VRMAX"] - p["KC"] * xad,
                         xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vil)
        f[..., self._sls[2]] = self.LR.deriv(vr, y)
        put(xp, s["vf"], m, efd)
        ctx.out["EXAC4.vi"], ctx.out["EXAC4.vout"] = vi, efd
