"""DEGOV1: Woodward diesel governor with droop (PSS/E DEGOV1).

Block diagram (pu on the machine base ``Sn`` = PSS/E MBASE; times in s)::

    dw  = omega - 1                                     (speed deviation, PSS/E SPEED)
    fb  = THR              (M = 0: throttle feedback)
        | Pe/(1+sTE)       (M = 1: electrical power feedback, state PEF)
    e   = pref - dw - DROOP*fb
    e --[ (1+sT3)/(1+sT1+s^2 T1 T2) ]--> y1                        (electric control box ECB1, ECB2)
    y1 --[ (1+sT4)/((1+sT5)(1+sT6)) ]--> y2                        (actuator dynamics ACT1, ACT2)
    y2 --[ K/s, non-windup TMIN..TMAX ]--> THR                     (actuator position = throttle)
    THR --[ e^{-sTD} ]--> THRD                                     (engine dead time)
    PMECH = THRD*(1 + dw),  tm = PMECH                 (the PSS/E shaft divides it by omega)

``TE`` filters the electrical power only; the throttle feedback (M = 0) is direct, as in
PowerSimulationsDynamics.jl's DEGOV1 (whose eigenvalues this reproduces, below).

The actuator ``K(1+sT4)/(s(1+sT5)(1+sT6))`` of the PSS/E diagram, with its output limits
``TMAX``/``TMIN``, is realized with the integrator last, so that the limits act without windup
on the actuator output itself (the transfer function is the same).

Output: PSS/E's diesel model multiplies the delayed throttle by the speed to give the
mechanical *power* PMECH, and the PSS/E machine models divide PMECH by the speed to get the
mechanical torque: ``tm = PMECH`` (system base: ``*Sn/Sb``), and the machine's PSS/E shaft
(``psse_shaft = 1``, set for every machine read from a PSS/E file) divides it by the speed.

Engine dead time: represented exactly by a stored history of ``THR`` at the integrator's
accepted points, linearly interpolated at ``t - TD`` (:class:`~weakgrid.sim.blocks.TransportDelay`),
not by a Padé approximation: a Padé approximant of order n adds n states and its all-pass
phase is right only for ``omega*TD`` below about n (for a 1 s delay and the 1-2 Hz
electromechanical swings that needs n > 10), while the history is exact to the step's
interpolation error and costs no state (against PSS/E's own DEGOV run with TD = 1 s the speed
agrees within 3.05e-5 pu, see :mod:`~weakgrid.sim.governors.degov`). The delayed value is an
input known from the past whenever ``TD`` exceeds the step.

Initialized at rest at the machine's initial torque ``tm0``: ``THR = THRD = tm0`` (machine
base), the filters at their steady inputs, ``pref = DROOP*fb0`` (``fb0 = tm0`` with M = 0,
``Pe0`` with M = 1). A ``tm0`` beyond ``TMAX`` / ``TMIN`` is refused at setup naming the limit.

Small-signal check: on PSID's case 63 (GENROU + DEGOV1, M = 0 and 1) the eigenvalues of the
initial point equal PowerSimulationsDynamics.jl's within 5.1e-4 (norm 7.3e-4).

PSS/E record: ICON ``M``; CONs ``T1 T2 T3 K T4 T5 T6 TD TMAX TMIN DROOP TE``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import IntegratorNonWindup, Lag, LeadLag2, TransportDelay
from ..control_base import MachineControl
from ..errors import DataError
from ..params import Param


class DEGOV1(MachineControl):
    """Woodward diesel governor with droop (PSS/E DEGOV1). Parameters: M [flag]; T1..T6, TD, TE [s];
    K [pu]; TMAX, TMIN [pu, machine base]; DROOP [pu speed / pu power]."""

    kind = "governor"
    order = 2
    params = (
        Param("M", 0.0, "-", "droop feedback: 0 throttle, 1 electrical power", "flag"),
        Param("T1", 0.0, "s", "electric control box time constant 1", "nonneg"),
        Param("T2", 0.0, "s", "electric control box time constant 2", "nonneg"),
        Param("T3", 0.0, "s", "electric control box lead time constant", "nonneg"),
        Param("K", 1.0, "pu", "actuator gain", "pos"),
        Param("T4", 0.0, "s", "actuator lead time constant", "nonneg"),
        Param("T5", 0.0, "s", "actuator lag time constant 1", "nonneg"),
        Param("T6", 0.0, "s", "actuator lag time constant 2", "nonneg"),
        Param("TD", 0.0, "s", "engine dead time", "nonneg"),
        Param("TMAX", 1.1, "pu (machine base)", "maximum throttle (actuator output)", ""),
        Param("TMIN", 0.0, "pu (machine base)", "minimum throttle (actuator output)", ""),
        Param("DROOP", 0.05, "pu/pu (machine base)", "speed droop", "nonneg"),
        Param("TE", 0.0, "s", "electrical power transducer time constant (M = 1)", "nonneg"),
    )
    states = ("ECB1", "ECB2", "ACT1", "ACT2", "THR", "PEF")
    outputs = ("THRD", "PMECH")

    #: PSS/E .dyr record after ``IBUS 'DEGOV1' ID``: ICON M, then the CONs
    psse_record = ("M", "T1", "T2", "T3", "K", "T4", "T5", "T6", "TD", "TMAX", "TMIN", "DROOP", "TE")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"THR": ("TMIN", "TMAX")}
    droop_flag = True

    def setup(self, system):
        super().setup(system)
        p = self.p
        for k in ("M", "DROOP", "TE"):                     # absent from DEGOV (no droop)
            p.setdefault(k, np.zeros(self.n))
        for i in range(self.n):
            if p["TMAX"][i] < p["TMIN"][i]:
                raise DataError(self.element(i), "TMAX", float(p["TMAX"][i]),
                                f"below TMIN = {p['TMIN'][i]:g}; give TMAX >= TMIN")
        self.ECB = LeadLag2(p["T3"], p["T1"], p["T1"] * p["T2"])
        self.ACT = LeadLag2(p["T4"], p["T5"] + p["T6"], p["T5"] * p["T6"])
        for blk, lead, lags in ((self.ECB, "T3", "T1"), (self.ACT, "T4", "T5 and T6")):
            bad = np.nonzero(blk.improper())[0]
            if len(bad):
                i = int(bad[0])
                raise DataError(self.element(i), lead, float(p[lead][i]),
                                f"a lead without a lag ({lags} = 0) is improper; give {lags} > 0 "
                                f"or {lead} = 0")
        self.THR = IntegratorNonWindup(p["K"], p["TMIN"], p["TMAX"])
        self.kpe = self.droop_flag * (p["M"] > 0)          # 1: electrical power feedback
        self.PEF = Lag(1.0, np.where(self.kpe > 0, p["TE"], 0.0))
        self.DELAY = TransportDelay(p["TD"])
        self.k = self.Sn / system.Sb                       # machine base -> system base

    def limits(self):
        return [(self.idx("THR"), self.p["TMIN"], self.p["TMAX"])]

    def init(self, system, x, sig):
        p = self.p
        tm0 = sig["tm0"][self.mach] / self.k
        pe0 = sig["Pe0"][self.mach] / self.k
        fb0 = np.where(self.kpe > 0, pe0, tm0)
        self.pref0 = p["DROOP"] * fb0 * self.droop_flag
        x[self.sl(0)], x[self.sl(1)] = self.ECB.init(np.zeros(self.n))
        x[self.sl(2)], x[self.sl(3)] = self.ACT.init(np.zeros(self.n))
        x[self.sl(4)] = tm0
        x[self.sl(5)] = np.where(self.kpe > 0, pe0, 0.0)
        self.DELAY.reset(0.0, tm0)

    def accept(self, t, ctx):
        self.DELAY.record(t, ctx.x[self._sls[4]])

    def compute(self, ctx):
        p = self.p
        m = self._mi
        e1, e2, a1, a2, thr, pef = (ctx.x[..., s] for s in self._sls)
        omega = ctx.sig["omega"][..., m]
        dw = omega - 1.0
        pe = ctx.sig["Pe"][..., m] / self.k
        fb = np.where(self.kpe > 0, self.PEF.output(pef, pe), thr)
        e = self.pref0 - dw - self.droop_flag * p["DROOP"] * fb
        y1 = self.ECB.output(e1, e2, e)
        y2 = self.ACT.output(a1, a2, y1)
        f = ctx.f
        f[..., self._sls[0]], f[..., self._sls[1]] = self.ECB.deriv(e1, e2, e)
        f[..., self._sls[2]], f[..., self._sls[3]] = self.ACT.deriv(a1, a2, y1)
        f[..., self._sls[4]] = self.THR.deriv(thr, y2)
        f[..., self._sls[5]] = np.where(self.kpe > 0, self.PEF.deriv(pef, pe), 0.0)
        thrd = self.DELAY.output(ctx.t, thr)
        ctx.sig["tm"][..., m] = thrd * omega * self.k   # PMECH: the PSS/E shaft divides by omega
        o = ctx.out
        o[f"{self.type_name}.THRD"], o[f"{self.type_name}.PMECH"] = thrd, thrd * omega
