"""GAST: gas-turbine governor (PSS/E GAST, ANDES parameter names).

Block diagram (pu on the system base after conversion; times in s)::

    wd   = omega - wref0
    pd   = pref0 + (paux - wd)/R                              (speed governor)
    plim = AT + KT*(AT - LT)                                  (exhaust-temperature load limit)
    vin  = min(pd, plim)                                      (low-value gate)
    vin --[Lag 1/(1+sT1), non-windup VMIN..VMAX]--> LAG       (fuel valve)
    LAG --[Lag 1/(1+sT2)]--> LG2                              (turbine)
    LG2 --[Lag 1/(1+sT3)]--> LT                               (load-limit feedback)
    tm  = LG2 - Dt*wd

``R`` is on the turbine base (``ipower``); ``VMAX``, ``VMIN``, ``AT``, ``Dt`` on the turbine
base (``power``); ``KT`` is a ratio. The turbine base is ``Tn`` if > 0 else the machine ``Sn``.
``pref0`` is the initial mechanical torque. At t = 0 the speed governor must pass the low-value
gate (``tm0 <= plim0 = AT + KT*(AT - tm0)``, i.e. ``tm0 <= AT``): if the temperature limit
were already the smaller input, the valve demand would not be ``tm0`` and the turbine would
drift, so setup refuses (``initial_bounds``).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class GAST(MachineControl):
    """Gas turbine-governor GAST. Parameters: R, VMAX, VMIN, AT, Dt [pu, turbine base];
    KT [pu/pu]; T1, T2, T3 [s]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("R", "T1", "T2", "T3", "AT", "KT", "VMAX", "VMIN", "Dt")
    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: machine Sn)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("R", 0.05, "pu (turbine base)", "droop", "pos", "ipower"),
        Param("VMAX", 1.2, "pu (turbine base)", "maximum valve position", "", "power"),
        Param("VMIN", 0.0, "pu (turbine base)", "minimum valve position", "", "power"),
        Param("KT", 5.0, "pu", "temperature limiter gain", "nonneg"),
        Param("AT", 1.0, "pu (turbine base)", "ambient temperature load limit", "", "power"),
        Param("T1", 0.1, "s", "fuel valve time constant", "pos"),
        Param("T2", 0.2, "s", "turbine time constant", "pos"),
        Param("T3", 10.0, "s", "load-limit time constant", "pos"),
        Param("Dt", 0.0, "pu (turbine base)", "turbine damping", "", "power"),
    )
    states = ("LAG", "LG2", "LT")
    outputs = ("pd", "plim", "pout")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"LAG": ("VMIN", "VMAX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LAG = LagNonWindup(1.0, p["T1"], p["VMIN"], p["VMAX"])
        self.LG2 = Lag(1.0, p["T2"])
        self.LT = Lag(1.0, p["T3"])
        self.paux = np.zeros(self.n)

    def limits(self):
        return [(self.idx("LAG"), self.p["VMIN"], self.p["VMAX"])]

    def init(self, system, x, sig):
        p = self.p
        tm0 = sig["tm0"][self.mach]
        self.pref0 = tm0.copy()
        x[self.sl(0)] = tm0
        x[self.sl(1)] = self.LG2.init(tm0)
        x[self.sl(2)] = self.LT.init(tm0)
        plim0 = p["AT"] + p["KT"] * (p["AT"] - tm0)
        self.initial_bounds = [("the governor demand (tm0, system base)", tm0, -np.inf, plim0,
                                "lower limit", "AT + KT*(AT - tm0)")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lag, lg2, lt = (ctx.x[..., s] for s in self._sls)
        wd = take(xp, ctx.sig["omega"], m) - p["wref0"]
        pd = self.pref0 + (self.paux - wd) / p["R"]
        plim = p["AT"] + p["KT"] * (p["AT"] - self.LT.output(lt, lg2))
        vin = xp.minimum(pd, plim)                           # low-value gate
        y2 = self.LG2.output(lg2, lag)
        f = ctx.f
        f[..., self._sls[0]] = self.LAG.deriv(lag, vin)
        f[..., self._sls[1]] = self.LG2.deriv(lg2, lag)
        f[..., self._sls[2]] = self.LT.deriv(lt, y2)
        pout = y2 - p["Dt"] * wd
        put(xp, ctx.sig["tm"], m, pout)
        ctx.out["GAST.pd"], ctx.out["GAST.plim"], ctx.out["GAST.pout"] = pd, plim, pout
