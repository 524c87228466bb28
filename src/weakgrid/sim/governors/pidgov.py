"""PIDGOV: hydro turbine-governor with a PID governor (PSS/E PIDGOV).

Block diagram (pu on the machine base ``Sn`` = PSS/E MBASE; times in s)::

    dw = omega - 1
    fb = Pe                  (Flag = 0: electrical power feedback)
       | GATE                (Flag = 1: gate position feedback)
    (pref - fb) --[ Rperm/(1+sTreg) ]--> XREG                     (permanent droop)
    u  = XREG - dw
    u --[ Kp + Ki/s ]--> ypi   (state PI)        u --[ sKd/(1+sTa) ]--> yd   (state XD)
    ypi --[ 1/(1+sTa) ]--> XA                                      (state XA)
    XA + yd --[ 1/(1+sTa) ]--> XB                                  (state XB)
    v = clip((XB - GATE)/Tb, Velmin, Velmax)                       (gate servo, rate limits)
    v --[ 1/s, non-windup Gmin..Gmax ]--> GATE
    Pg = gate characteristic (G0, 0), (G1, P1), (G2, P2), (1, P3) at GATE
    Pg --[ (1 - sTz)/(1 + sTz/2) ]--> PT,   Tz = Atw*Tw            (water column, state XW)
    PMECH = PT - Dturb*dw,   tm = PMECH

``tm`` is PSS/E's mechanical power PMECH (system base: ``*Sn/Sb``); as PSS/E's machine models,
the machine's PSS/E shaft (``psse_shaft = 1``, set for every machine read from a PSS/E file) divides it by the speed.

Initialized at rest at the machine's initial torque ``tm0``: ``GATE`` = the gate at which the
characteristic gives ``tm0`` (machine base), ``XA = XB = PI = GATE``, ``XREG = XD = 0`` and
``pref = Pe0`` (Flag 0) or ``GATE0`` (Flag 1). In the steady state the PI input is zero, so
the speed settles at ``dw = -Rperm*(fb - pref)``: droop ``Rperm`` on power or on gate. An
initial gate beyond ``Gmax``/``Gmin`` is refused at setup naming the limit (PSID's table, P3 =
0.9 at full gate, cannot carry 100 MW: gate 1.025 > Gmax = 1; its cases run the unit at 70 MW,
gate 0.95).

Small-signal check: on PSID's cases 58 (GENROU + SEXS + PIDGOV, Flag 0 and 1, 70 MW) the
eigenvalues of the initial point equal PowerSimulationsDynamics.jl's within 4.4e-4.

PSS/E record: ICON ``Flag``; CONs ``Rperm Treg Kp Ki Kd Ta Tb Dturb G0 G1 P1 G2 P2 P3 Gmax Gmin
Atw Tw Velmax Velmin``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import IntegratorNonWindup, Lag, LeadLag, Washout
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param
from ._gate import check_gate_table, gate_power, power_gate


class PIDGOV(MachineControl):
    """Hydro PID governor (PSS/E PIDGOV). Parameters: Flag; Rperm [pu]; Treg, Ta, Tb, Tw [s]; Kp [pu],
    Ki [1/s], Kd [s]; Dturb [pu]; gate table G0, G1, P1, G2, P2, P3; Gmax, Gmin [pu]; Atw [-];
    Velmax, Velmin [pu/s]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    params = (
        Param("Flag", 0.0, "-", "feedback: 0 electrical power, 1 gate position", "flag"),
        Param("Rperm", 0.05, "pu (machine base)", "permanent droop", "nonneg"),
        Param("Treg", 0.0, "s", "droop (speed detector) time constant", "nonneg"),
        Param("Kp", 1.0, "pu", "proportional gain", ""),
        Param("Ki", 1.0, "1/s", "integral gain", "pos"),
        Param("Kd", 0.0, "s", "derivative gain", ""),
        Param("Ta", 0.1, "s", "controller time constant", "nonneg"),
        Param("Tb", 0.5, "s", "gate servo time constant", "pos"),
        Param("Dturb", 0.0, "pu (machine base)", "turbine damping", ""),
        Param("G0", 0.0, "pu", "gate opening at zero power", ""),
        Param("G1", 0.4, "pu", "gate opening, point 1", ""),
        Param("P1", 0.4, "pu (machine base)", "power at G1", ""),
        Param("G2", 0.8, "pu", "gate opening, point 2", ""),
        Param("P2", 0.8, "pu (machine base)", "power at G2", ""),
        Param("P3", 1.0, "pu (machine base)", "power at full gate (1 pu)", ""),
        Param("Gmax", 1.0, "pu", "maximum gate opening", ""),
        Param("Gmin", 0.0, "pu", "minimum gate opening", ""),
        Param("Atw", 1.0, "-", "factor on the water time constant (Tz = Atw*Tw)", "nonneg"),
        Param("Tw", 1.0, "s", "water inertia time constant", "nonneg"),
        Param("Velmax", 0.2, "pu/s", "maximum gate opening velocity", ""),
        Param("Velmin", -0.2, "pu/s", "maximum gate closing velocity (< 0)", ""),
    )
    states = ("XREG", "PI", "XA", "XD", "XB", "GATE", "XW")
    outputs = ("Pg", "PMECH")

    #: PSS/E .dyr record after ``IBUS 'PIDGOV' ID``: ICON Flag, then the CONs
    psse_record = ("Flag", "Rperm", "Treg", "Kp", "Ki", "Kd", "Ta", "Tb", "Dturb", "G0", "G1", "P1",
                   "G2", "P2", "P3", "Gmax", "Gmin", "Atw", "Tw", "Velmax", "Velmin")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"GATE": ("Gmin", "Gmax")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in range(self.n):
            for hi, lo in (("Gmax", "Gmin"), ("Velmax", "Velmin")):
                if p[hi][i] < p[lo][i]:
                    raise DataError(self.element(i), hi, float(p[hi][i]),
                                    f"below {lo} = {p[lo][i]:g}; give {hi} >= {lo}")
        check_gate_table(self)
        self.REG = Lag(p["Rperm"], p["Treg"])
        self.LA = Lag(1.0, p["Ta"])
        self.D = Washout(p["Kd"], p["Ta"])
        self.GATE = IntegratorNonWindup(1.0, p["Gmin"], p["Gmax"])
        Tz = p["Atw"] * p["Tw"]
        self.WATER = LeadLag(-Tz, Tz / 2.0)
        self.k = self.Sn / system.Sb

    def limits(self):
        return [(self.idx("GATE"), self.p["Gmin"], self.p["Gmax"])]

    def init(self, system, x, sig):
        p = self.p
        tm0 = sig["tm0"][self.mach] / self.k
        pe0 = sig["Pe0"][self.mach] / self.k
        g0 = power_gate(self, tm0)
        self.pref0 = np.where(p["Flag"] > 0, g0, pe0)
        z = np.zeros(self.n)
        for k, v in enumerate((z, g0, g0, z, g0, g0, self.WATER.init(tm0))):
            x[self.sl(k)] = v

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        xreg, xpi, xa, xd, xb, gate, xw = (ctx.x[..., s] for s in self._sls)
        omega = take(xp, ctx.sig["omega"], m)
        dw = omega - 1.0
        pe = take(xp, ctx.sig["Pe"], m) / self.k
        fb = xp.where(p["Flag"] > 0, gate, pe)
        ein = self.pref0 - fb
        u = self.REG.output(xreg, ein) - dw
        ypi = p["Kp"] * u + xpi
        yd = self.D.output(xd, u)
        ya = self.LA.output(xa, ypi)
        yb_in = ya + yd
        yb = self.LA.output(xb, yb_in)
        v = xp.clip((yb - gate) / p["Tb"], p["Velmin"], p["Velmax"])
        pg = gate_power(self, gate)
        pt = self.WATER.output(xw, pg)
        pm = pt - p["Dturb"] * dw
        f = ctx.f
        f[..., self._sls[0]] = self.REG.deriv(xreg, ein)
        f[..., self._sls[1]] = p["Ki"] * u
        f[..., self._sls[2]] = self.LA.deriv(xa, ypi)
        f[..., self._sls[3]] = self.D.deriv(xd, u)
        f[..., self._sls[4]] = self.LA.deriv(xb, yb_in)
        f[..., self._sls[5]] = v
        f[..., self._sls[6]] = self.WATER.deriv(xw, pg)
        put(xp, ctx.sig["tm"], m, pm * self.k)   # PMECH: the PSS/E shaft divides by omega
        ctx.out["PIDGOV.Pg"], ctx.out["PIDGOV.PMECH"] = pg, pm
