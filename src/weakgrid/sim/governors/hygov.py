"""HYGOV: hydro turbine-governor for small units (PSS/E HYGOV structure).

Block diagram (pu on the turbine base ``Tn`` (or the machine's ``Sn``), converted to the
system base at the output; times in s)::

    e  = pref - wd - R*c                      (wd = omega - wref0, R permanent droop)
    e --[Lag 1/(1+sTf)]--> x1
    c  = xi + x1/r                            (desired gate; r temporary droop)
    dxi/dt = clip(Ki*x1, lo, hi),  xi held in GMIN..GMAX (non-windup)
        Ki = 1/(r*Tr)             (Tr_used = 1, PSS/E)      | Sb/Sn  (Tr_used = 0, ANDES 2.0)
        lo, hi = -VELM, VELM      (VELM_offset = 0)         | -VELM - x1/r, VELM - x1/r (= 1)
    c --[Lag 1/(1+sTg)]--> g                  (gate servo)
    Tw' dq/dt = 1 - h,  h = (q/g)^2           (water column)
        Tw' = Tw                  (Tw_sysbase = 0, PSS/E)   | Tw*Sn/Sb (Tw_sysbase = 1, ANDES 2.0)
    tm = At*h*(q - qNL) - Dt'*wd*g            (turbine; Dt' = Dt, or Dt*Sn/Sb with Dt_sysbase = 1)

Initialized at ``h = 1``, ``q = g = c = tm0/At + qNL``, ``pref = R*c``.

Where ANDES 2.0 departs (its ``models/governor/hygov.py``; flags, default = PSS/E)
-------------------------------------------------------------------------------------
ANDES converts ``R``, ``r`` (inverse power) and ``GMAX``, ``GMIN``, ``VELM``, ``qNL``, ``Dt``
(power) to the system base and computes the flow ``q``, the gate and the power in
system-base per unit. With ``k = Sn/Sb`` (``Sn`` = ``Tn`` or the machine rating) and its
variables rewritten on the turbine base, its diagram is the one above except:

* ``Tr_used = 0``: its gate integrator has unit gain on the system base (``Tr`` is read but
  unused): ``Ki = 1/k = Sb/Sn`` [1/s] on the turbine base instead of ``1/(r*Tr)``. Equal to
  PSS/E when ``r*Tr = Sn/Sb`` (e.g. 100-MVA units with ``r*Tr = 1`` s on a 100-MVA base).
* ``Tw_sysbase = 1``: it integrates the water column in system-base flow
  (``Tw d(q*k)/dt = 1 - h``), so its water time constant is in effect ``Tw*Sn/Sb`` [s].
* ``Dt_sysbase = 1``: its damping term takes ``Dt`` and the gate both on the system base,
  so on the turbine base it is ``Dt*Sn/Sb`` (no effect with ``Dt = 0``).
* ``VELM_offset = 1``: its gate-velocity limiter bounds the integrator's rate by
  ``±VELM - x1/r`` (pu/s, turbine base) instead of ``±VELM`` (it subtracts the
  proportional path's value, not its rate, from the velocity limit).

``from_andes(..., conventions="andes")`` sets all four (``io.andes.ANDES_CONVENTIONS``).
The position limits ``GMIN``, ``GMAX`` act alike in both (on the integrator ``xi``, as
ANDES's anti-windup limiter on its ``gtpos``). Measured (``tests/sim/test_andes_hygov.py``,
speed difference to ANDES, standard -> ANDES's conventions): kundur with a 900-MVA HYGOV,
100-ms fault, 1/120 s: 5.0e-4 -> 9.9e-5 pu (the rest is ANDES's step error at its exciters'
ceiling: 1.5e-5 pu at 1/960 s, 3.0e-6 pu at 1/120 s with the ceilings out of reach); with
GMIN, GMAX and the rate bounds acting: 9.0e-4 -> 3.0e-6 pu; ANDES's nordic44 (50 HYGOV):
6.6e-5 -> 2.1e-6 pu.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class HYGOV(MachineControl):
    """Hydro governor. Parameters: R, r [pu]; Tf, Tr, Tg, Tw [s]; VELM [pu/s]; GMAX, GMIN, At, Dt, qNL [pu];
    flags Tr_used, Tw_sysbase, Dt_sysbase, VELM_offset (module docstring)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("R", "r", "Tr", "Tf", "Tg", "VELM", "GMAX", "GMIN", "Tw", "At", "Dt", "qNL")
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
        Param("Tr_used", 1.0, "-", "1: gate integrator gain 1/(r*Tr) (PSS/E); "
              "0: unit gain on the system base, Sb/Sn on the turbine base (ANDES 2.0)", "flag"),
        Param("Tw_sysbase", 0.0, "-", "0: water column on the turbine base (PSS/E); "
              "1: in system-base flow, time constant Tw*Sn/Sb (ANDES 2.0)", "flag"),
        Param("Dt_sysbase", 0.0, "-", "0: damping Dt on the turbine base (PSS/E); "
              "1: Dt*Sn/Sb on the turbine base (ANDES 2.0)", "flag"),
        Param("VELM_offset", 0.0, "-", "0: gate integrator rate within +-VELM; "
              "1: within +-VELM - x1/r (ANDES 2.0)", "flag"),
    )
    states = ("x1", "xi", "g", "q")
    outputs = ("gate", "head")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.Sbase = np.where(p["Tn"] > 0, p["Tn"], self.Sn) / system.Sb     # k = Sn/Sb
        self.LF = Lag(1.0, p["Tf"])
        self.LG = Lag(1.0, p["Tg"])
        self.Ki = np.where(p["Tr_used"] > 0, 1.0 / (p["r"] * p["Tr"]), 1.0 / self.Sbase)
        self.Tw_eff = np.where(p["Tw_sysbase"] > 0, p["Tw"] * self.Sbase, p["Tw"])
        self.Dt_eff = np.where(p["Dt_sysbase"] > 0, p["Dt"] * self.Sbase, p["Dt"])
        self.v_off = np.where(p["VELM_offset"] > 0, 1.0 / p["r"], 0.0)

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
        xp, p = self.xp, self.p
        m = self._mi    # a slice when the machines are contiguous (a view, no gather)
        x1, xi, g, q = (ctx.x[..., self._sls[k]] for k in range(4))
        wd = take(xp, ctx.sig["omega"], m) - p["wref0"]
        c = xi + x1 / p["r"]
        e = self.pref0 - wd - p["R"] * c
        h = (q / g) ** 2
        f = ctx.f
        f[..., self._sls[0]] = self.LF.deriv(x1, e)
        off = self.v_off * x1
        f[..., self._sls[1]] = xp.minimum(xp.maximum(self.Ki * x1, -p["VELM"] - off), p["VELM"] - off)
        f[..., self._sls[2]] = self.LG.deriv(g, c)
        f[..., self._sls[3]] = (1.0 - h) / self.Tw_eff
        tm = (p["At"] * h * (q - p["qNL"]) - self.Dt_eff * wd * g) * self.Sbase
        put(xp, ctx.sig["tm"], m, tm)
        ctx.out["HYGOV.gate"], ctx.out["HYGOV.head"] = g, h
