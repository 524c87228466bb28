"""HYGOV: hydro turbine-governor for small units (PSS/E HYGOV structure).

Block diagram (pu, turbine base converted to system base; times in s)::

    e  = pref - wd - R*c                      (wd = omega - wref0, R permanent droop)
    e --[Lag 1/(1+sTf)]--> x1
    c  = xi + x1/r,  dxi/dt = clip(x1/(r*Tr), -VELM, VELM), xi held in GMIN..GMAX
    c --[Lag 1/(1+sTg)]--> g                 (gate servo)
    Tw dq/dt = 1 - h,  h = (q/g)^2            (water column)
    tm = At*h*(q - qNL) - Dt*wd*g

Initialized at ``h = 1``, ``q = g = c = tm0/At + qNL``, ``pref = R*c``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag
from ..control_base import MachineControl
from ..params import Param


class HYGOV(MachineControl):
    """Hydro governor. Parameters: R, r [pu]; Tf, Tr, Tg, Tw [s]; VELM [pu/s]; GMAX, GMIN, At, Dt, qNL [pu]."""

    kind = "governor"
    order = 2
    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: machine Sn)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("R", 0.05, "pu", "permanent droop", "pos"),
        Param("r", 1.0, "pu", "temporary droop", "pos"),
        Param("Tr", 1.0, "s", "governor (reset) time constant", "pos"),
        Param("Tf", 0.05, "s", "filter time constant", "pos"),
        Param("Tg", 0.05, "s", "gate servo time constant", "pos"),
        Param("VELM", 0.3, "pu/s", "gate velocity limit", "pos"),
        Param("GMAX", 1.0, "pu", "maximum gate opening", ""),
        Param("GMIN", 0.0, "pu", "minimum gate opening", ""),
        Param("Tw", 1.0, "s", "water inertia time constant", "pos"),
        Param("At", 1.0, "pu", "turbine gain", "pos"),
        Param("Dt", 0.0, "pu", "turbine damping", "nonneg"),
        Param("qNL", 0.1, "pu", "no-load flow", "nonneg"),
    )
    states = ("x1", "xi", "g", "q")
    outputs = ("gate", "head")

    def setup(self, system):
        super().setup(system)
        self.Sbase = np.where(self.p["Tn"] > 0, self.p["Tn"], self.Sn) / system.Sb
        self.LF = Lag(1.0, self.p["Tf"])
        self.LG = Lag(1.0, self.p["Tg"])

    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"xi": ("GMIN", "GMAX")}

    def limits(self):
        return [(self.idx("xi"), self.p["GMIN"], self.p["GMAX"])]

    def init(self, system, x, sig):
        tm0 = sig["tm0"][self.mach] / self.Sbase          # turbine base
        c0 = tm0 / self.p["At"] + self.p["qNL"]
        self.pref0 = self.p["R"] * c0
        x[self.sl(0)] = 0.0
        x[self.sl(1)] = c0
        x[self.sl(2)] = c0
        x[self.sl(3)] = c0

    def compute(self, ctx):
        p = self.p
        m = self.mach
        x1, xi, g, q = (ctx.x[..., self._sls[k]] for k in range(4))
        wd = ctx.sig["omega"][..., m] - p["wref0"]
        c = xi + x1 / p["r"]
        e = self.pref0 - wd - p["R"] * c
        h = (q / g) ** 2
        f = ctx.f
        f[..., self._sls[0]] = self.LF.deriv(x1, e)
        f[..., self._sls[1]] = np.minimum(np.maximum(x1 / (p["r"] * p["Tr"]), -p["VELM"]), p["VELM"])
        f[..., self._sls[2]] = self.LG.deriv(g, c)
        f[..., self._sls[3]] = (1.0 - h) / p["Tw"]
        tm = (p["At"] * h * (q - p["qNL"]) - p["Dt"] * wd * g) * self.Sbase
        ctx.sig["tm"][..., m] = tm
        ctx.out["HYGOV.gate"], ctx.out["HYGOV.head"] = g, h
