"""WPIDHY: Woodward PID hydro governor (PSS/E WPIDHY).

Block diagram (pu on the machine base ``Sn`` = PSS/E MBASE; times in s)::

    dw = omega - 1
    (Pe - pref) --[ REG/(1+sTREG) ]--> XREG          (droop on electrical power; REG < 0 in
                                                      PSS/E data: the droop is -REG)
    u = XREG - dw
    u --[ (KD s^2 + KP s + KI) / (s (1+sTA)^2) ]--> XA                (PID, states PI, XD, XA)
        realized as (KP' + KI/s + KD' s/(1+sTA)) / (1+sTA),
        KP' = KP - TA*KI,  KD' = KD - TA*KP + TA^2*KI
    XA --[ 1/(1+sTB) ]--> XB
    v = clip(XB, VELMN, VELMX)                                         (gate velocity limits)
    v --[ 1/s, non-windup GATMN..GATMX ]--> GATE
    Pg = gate characteristic (G0, 0), (G1, P1), (G2, P2), (1, P3) at GATE
    Pg --[ (1 - sTW)/(1 + sTW/2) ]--> XW-output --clip(PMIN, PMAX)--> PT   (water column)
    PMECH = PT - D*dw,   tm = PMECH

The PID output is the gate velocity demand: the gate integrates it, so from speed to gate
``KD`` acts as the proportional gain, ``KP`` as the integral gain and ``KI`` integrates twice.
This is PowerSimulationsDynamics.jl's reading of the PSS/E diagram. OpenIPSL's WPIDHY reads it
as a gate *position* demand (a derivative-lag ``s/(1+sTB)`` before the velocity limits and
the integrator); with the data of PSID's PSS/E benchmark case (KD = 3, KP = 3, KI = 0.5,
TW = 3.25 s; 70 MW, gate 0.742) that reading has two unstable eigenvalues (+2.7 and +15.8 1/s)
at the initial point, while this one is stable and its eigenvalues equal PSID's (test case 60)
within 5e-4. ``tm`` is PSS/E's PMECH (system base ``*Sn/Sb``); as PSS/E's machine models,
the machine's PSS/E shaft (``psse_shaft = 1``, set for every machine read from a PSS/E file) divides it by the speed.

Initialized at rest at the machine's initial torque ``tm0``: ``GATE`` = the gate at which the
characteristic gives ``tm0`` (machine base), every controller state 0 except the water column
(``tm0``), ``pref = Pe0``. In the steady state the PID input is zero, so the speed settles at
``dw = REG*(Pe - pref)``. An initial gate beyond ``GATMX``/``GATMN`` or a ``tm0`` beyond
``PMAX``/``PMIN`` is refused at setup naming the limit.

PSS/E record (CONs only): ``TREG REG KP KI KD TA TB VELMX VELMN GATMX GATMN TW PMAX PMIN D G0 G1
P1 G2 P2 P3``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import IntegratorNonWindup, Lag, LeadLag, Washout
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param
from ._gate import check_gate_table, gate_power, power_gate


class WPIDHY(MachineControl):
    """Woodward PID hydro governor (PSS/E WPIDHY). Parameters: TREG, TA, TB, TW [s]; REG [pu]; KP [pu],
    KI [1/s], KD [s]; VELMX, VELMN [pu/s]; GATMX, GATMN, PMAX, PMIN, D [pu]; gate table G0..P3."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    params = (
        Param("TREG", 0.0, "s", "droop (power measurement) time constant", "nonneg"),
        Param("REG", -0.05, "pu (machine base)", "droop gain on electrical power (negative: droop -REG)", ""),
        Param("KP", 1.0, "pu", "proportional gain", ""),
        Param("KI", 1.0, "1/s", "integral gain", "pos"),
        Param("KD", 0.0, "s", "derivative gain", ""),
        Param("TA", 0.02, "s", "controller time constant", "nonneg"),
        Param("TB", 0.01, "s", "gate servo time constant", "nonneg"),
        Param("VELMX", 0.1, "pu/s", "maximum gate opening velocity", ""),
        Param("VELMN", -0.1, "pu/s", "maximum gate closing velocity (< 0)", ""),
        Param("GATMX", 1.0, "pu", "maximum gate opening", ""),
        Param("GATMN", 0.0, "pu", "minimum gate opening", ""),
        Param("TW", 1.0, "s", "water inertia time constant", "nonneg"),
        Param("PMAX", 1.0, "pu (machine base)", "maximum turbine power", ""),
        Param("PMIN", 0.0, "pu (machine base)", "minimum turbine power", ""),
        Param("D", 0.0, "pu (machine base)", "turbine damping", ""),
        Param("G0", 0.0, "pu", "gate opening at zero power", ""),
        Param("G1", 0.4, "pu", "gate opening, point 1", ""),
        Param("P1", 0.4, "pu (machine base)", "power at G1", ""),
        Param("G2", 0.8, "pu", "gate opening, point 2", ""),
        Param("P2", 0.8, "pu (machine base)", "power at G2", ""),
        Param("P3", 1.0, "pu (machine base)", "power at full gate (1 pu)", ""),
    )
    states = ("XREG", "PI", "XD", "XA", "XB", "GATE", "XW")
    outputs = ("Pg", "PMECH")

    #: PSS/E .dyr record after ``IBUS 'WPIDHY' ID`` (CONs only)
    psse_record = ("TREG", "REG", "KP", "KI", "KD", "TA", "TB", "VELMX", "VELMN", "GATMX", "GATMN",
                   "TW", "PMAX", "PMIN", "D", "G0", "G1", "P1", "G2", "P2", "P3")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"GATE": ("GATMN", "GATMX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in range(self.n):
            for hi, lo in (("GATMX", "GATMN"), ("VELMX", "VELMN"), ("PMAX", "PMIN")):
                if p[hi][i] < p[lo][i]:
                    raise DataError(self.element(i), hi, float(p[hi][i]),
                                    f"below {lo} = {p[lo][i]:g}; give {hi} >= {lo}")
            if p["TA"][i] == 0 and p["KD"][i] != 0:
                raise DataError(self.element(i), "KD", float(p["KD"][i]),
                                "a derivative gain needs TA > 0 (its filter); give TA > 0 or KD = 0")
        check_gate_table(self)
        TA = p["TA"]
        self.kp = p["KP"] - TA * p["KI"]
        self.REGL = Lag(p["REG"], p["TREG"])
        self.D = Washout(p["KD"] - TA * p["KP"] + TA * TA * p["KI"], TA)
        self.LA = Lag(1.0, TA)
        self.LB = Lag(1.0, p["TB"])
        self.GATE = IntegratorNonWindup(1.0, p["GATMN"], p["GATMX"])
        self.WATER = LeadLag(-p["TW"], p["TW"] / 2.0)
        self.k = self.Sn / system.Sb

    def limits(self):
        return [(self.idx("GATE"), self.p["GATMN"], self.p["GATMX"])]

    def init(self, system, x, sig):
        p = self.p
        tm0 = sig["tm0"][self.mach] / self.k
        self.pref0 = sig["Pe0"][self.mach] / self.k
        g0 = power_gate(self, tm0)
        z = np.zeros(self.n)
        for k, v in enumerate((z, z, z, z, z, g0, self.WATER.init(tm0))):
            x[self.sl(k)] = v
        self.initial_bounds = [("the turbine power (tm0, machine base)", tm0, p["PMIN"], p["PMAX"],
                                "PMIN", "PMAX")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        xreg, xpi, xd, xa, xb, gate, xw = (ctx.x[..., s] for s in self._sls)
        omega = take(xp, ctx.sig["omega"], m)
        dw = omega - 1.0
        ein = take(xp, ctx.sig["Pe"], m) / self.k - self.pref0
        u = self.REGL.output(xreg, ein) - dw
        ypid = self.kp * u + xpi + self.D.output(xd, u)
        ya = self.LA.output(xa, ypid)
        yb = self.LB.output(xb, ya)
        v = xp.clip(yb, p["VELMN"], p["VELMX"])
        pg = gate_power(self, gate)
        pt = xp.clip(self.WATER.output(xw, pg), p["PMIN"], p["PMAX"])
        pm = pt - p["D"] * dw
        f = ctx.f
        f[..., self._sls[0]] = self.REGL.deriv(xreg, ein)
        f[..., self._sls[1]] = p["KI"] * u
        f[..., self._sls[2]] = self.D.deriv(xd, u)
        f[..., self._sls[3]] = self.LA.deriv(xa, ypid)
        f[..., self._sls[4]] = self.LB.deriv(xb, ya)
        f[..., self._sls[5]] = v
        f[..., self._sls[6]] = self.WATER.deriv(xw, pg)
        put(xp, ctx.sig["tm"], m, pm * self.k)   # PMECH: the PSS/E shaft divides by omega
        ctx.out["WPIDHY.Pg"], ctx.out["WPIDHY.PMECH"] = pg, pm
