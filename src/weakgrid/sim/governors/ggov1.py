"""GGOV1: GE general-purpose turbine-governor (PSS/E GGOV1; WECC / IEEE PES-TR1 GGOV1).

Block diagram (pu on the turbine base ``Trate`` MW, or the machine base ``Sn`` when
``Trate = 0``; times in s)::

    dw    = omega - 1
    PELF  = Pe/(1+sTpelec)                                     (measured electrical power)
    PMW   = Kimw/s (Pmwset - PELF), non-windup -1.1R..1.1R     (supervisory load controller)
    fb    = PELF (Rselect = 1) | 0 (0, isochronous) | FSR (-1, governor output) | VAL (-2, valve stroke)
    e     = clip(deadband(Pref + PMW - R*fb - dw, -db, db), minerr, maxerr)
    FSRN  = Kpgov*e + GI + Kdgov*s/(1+sTdgov)*e                (governor PID; GI integral, GD filter)
    TEXM  = [(1+sTsa)/(1+sTsb)] [1/(1+sTfload)] (wf*(1+dw))    (exhaust temperature, states TX1, TX2)
    FSRT  = min(Kpload*(TLIM - TEXM) + LI, 1),  TLIM = Wfnl + Ldref/Kturb    (load limiter, LI integral)
    FSRA  = XA,  dXA/dt = Ka*(Aset - s/(1+sTa)*dw) + tracking   (acceleration limiter; ACD filter)
    FSR   = clip(min(FSRN, FSRT, FSRA), Vmin, Vmax)             (low-value gate)
    dVAL/dt = clip((FSR - VAL)/Tact, Rclose, Ropen), VAL non-windup Vmin..Vmax   (actuator)
    wf    = VAL*(1+dw) (Flag = 1) | VAL (Flag = 0)              (fuel flow)
    Kturb*(wf - Wfnl) --[ e^{-sTeng} ]--[ (1+sTc)/(1+sTb) ]--> S4   (engine dead time, turbine; LL)
    PMECH = S4 - Dm*(1+dw),   tm = PMECH                        (Dm >= 0)

Low-value gate in continuous time. PSS/E evaluates the gate with the previous step's output:
its acceleration limiter is ``FSRA = FSR(t-DELT) + Ka*DELT*(Aset - accel)``, and the integrators
of the controllers that the gate does not select follow its output. Here each controller's
integrator tracks the gate output with the time constant ``Ttrack`` (back-calculation,
``(FSR - y)/Ttrack`` added to its derivative, ``y`` its unlimited output): zero for the selected
controller (``y = FSR``), so that one is an exact PI/PID; the others sit just above ``FSR``
(``Ki*e*Ttrack``) and cannot wind up; the acceleration limiter is the integrator ``XA`` that
PSS/E's update is in the limit ``DELT -> 0``: ``FSR`` rises at most at ``Ka*(Aset - accel)``.
``Ttrack`` (default 0.01 s, of the order of PSS/E's DELT) is not a PSS/E parameter.

``Dm >= 0`` as OpenIPSL's PSS/E-verified GGOV1: the damping term ``Dm*(1+dw)`` and the exhaust
temperature input ``wf*(1+dw)``. ``Dm < 0`` (fuel flow falling with speed, ``(1+dw)^Dm``) is
refused (not implemented). ``Rup``/``Rdown`` (load-limit rate limits) are read and not
represented (as in OpenIPSL's GGOV1); tighter than +-10 pu/s they raise a warning.
Rselect = -1 closes an algebraic loop (the gate output enters the governor error): it is solved
in each evaluation (Newton on the piecewise-linear loop, slope ``1 + (Kpgov + Kdgov/Tdgov)*R``).

Output: ``tm`` is PSS/E's PMECH converted from the turbine base to the system base; as PSS/E's
machine models, the machine's PSS/E shaft (``psse_shaft = 1``, set for every machine read from a PSS/E file) divides it by the speed.

Initialized at rest at the machine's initial torque ``tm0``: ``PMECH0 = tm0`` (turbine base),
``VAL = FSR = FSRN = GI = fsr0 = (PMECH0 + Dm)/Kturb + Wfnl``, ``Pmwset = PELF = Pe0``,
``Pref = R*fb0``, the temperature at ``fsr0``, ``LI`` and ``XA`` where their tracking balances.
Refused at setup (naming the limit): ``fsr0`` beyond ``Vmax``/``Vmin``, an initial exhaust
temperature above the load limit (``fsr0 > TLIM``: the load limiter, not the governor, would be
in control; field ``Ldref``), ``fsr0 > 1`` (the load limiter's cap).

PSS/E record: ICONs ``Rselect Flag``; CONs ``R Tpelec maxerr minerr Kpgov Kigov Kdgov Tdgov Vmax
Vmin Tact Kturb Wfnl Tb Tc Teng Tfload Kpload Kiload Ldref Dm Ropen Rclose Kimw Aset Ka Ta Trate
db Tsa Tsb Rup Rdown``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import IntegratorNonWindup, Lag, LeadLag, TransportDelay, Washout, deadband
from ..control_base import MachineControl
from ..errors import DataError
from ..params import Param


class GGOV1(MachineControl):
    """GE general governor/turbine (PSS/E GGOV1). ICONs Rselect (1, 0, -1, -2), Flag (0, 1); CONs as
    PSS/E (module docstring); Ttrack [s] (low-value-gate tracking, not PSS/E)."""

    kind = "governor"
    order = 2
    params = (
        Param("Rselect", 1.0, "-", "droop feedback: 1 Pe, 0 none, -1 governor output, -2 valve stroke", ""),
        Param("Flag", 1.0, "-", "fuel flow: 0 independent of speed, 1 proportional to speed", "flag"),
        Param("R", 0.04, "pu (turbine base)", "permanent droop", "nonneg"),
        Param("Tpelec", 1.0, "s", "electrical power transducer time constant", "nonneg"),
        Param("maxerr", 0.05, "pu", "maximum governor error", ""),
        Param("minerr", -0.05, "pu", "minimum governor error", ""),
        Param("Kpgov", 10.0, "pu", "governor proportional gain", ""),
        Param("Kigov", 2.0, "1/s", "governor integral gain", "nonneg"),
        Param("Kdgov", 0.0, "s", "governor derivative gain", ""),
        Param("Tdgov", 1.0, "s", "governor derivative time constant", "nonneg"),
        Param("Vmax", 1.0, "pu (turbine base)", "maximum valve position", ""),
        Param("Vmin", 0.15, "pu (turbine base)", "minimum valve position", ""),
        Param("Tact", 0.5, "s", "actuator time constant", "pos"),
        Param("Kturb", 1.5, "pu", "turbine gain", "pos"),
        Param("Wfnl", 0.2, "pu (turbine base)", "no-load fuel flow", ""),
        Param("Tb", 0.1, "s", "turbine lag time constant", "nonneg"),
        Param("Tc", 0.0, "s", "turbine lead time constant", "nonneg"),
        Param("Teng", 0.0, "s", "engine transport delay", "nonneg"),
        Param("Tfload", 3.0, "s", "load limiter (temperature) time constant", "nonneg"),
        Param("Kpload", 2.0, "pu", "load limiter proportional gain", ""),
        Param("Kiload", 0.67, "1/s", "load limiter integral gain", "nonneg"),
        Param("Ldref", 1.0, "pu (turbine base)", "load limiter reference", ""),
        Param("Dm", 0.0, "pu (turbine base)", "mechanical damping (speed sensitivity)", ""),
        Param("Ropen", 0.1, "pu/s", "maximum valve opening rate", ""),
        Param("Rclose", -0.1, "pu/s", "maximum valve closing rate", ""),
        Param("Kimw", 0.0, "1/s", "supervisory load controller gain", "nonneg"),
        Param("Aset", 0.1, "pu/s", "acceleration limiter set point", ""),
        Param("Ka", 10.0, "pu", "acceleration limiter gain", "nonneg"),
        Param("Ta", 0.1, "s", "acceleration limiter (derivative) time constant", "pos"),
        Param("Trate", 0.0, "MW", "turbine rating (0: the machine base)", "nonneg"),
        Param("db", 0.0, "pu", "governor dead band", "nonneg"),
        Param("Tsa", 4.0, "s", "temperature detection lead time constant", "nonneg"),
        Param("Tsb", 5.0, "s", "temperature detection lag time constant", "nonneg"),
        Param("Rup", 99.0, "pu/s", "maximum rate of load limit increase (not represented)", ""),
        Param("Rdown", -99.0, "pu/s", "maximum rate of load limit decrease (not represented)", ""),
        Param("Ttrack", 0.01, "s", "low-value-gate tracking time constant (not PSS/E)", "pos"),
    )
    states = ("PELF", "PMW", "GI", "GD", "VAL", "LL", "TX1", "TX2", "LI", "ACD", "XA")
    outputs = ("ERR", "ACC", "FSRN", "FSRT", "FSRA", "FSR", "TEXM", "PMECH")

    #: PSS/E .dyr record after ``IBUS 'GGOV1' ID``: ICONs Rselect, Flag, then the 33 CONs
    psse_record = ("Rselect", "Flag", "R", "Tpelec", "maxerr", "minerr", "Kpgov", "Kigov", "Kdgov",
                   "Tdgov", "Vmax", "Vmin", "Tact", "Kturb", "Wfnl", "Tb", "Tc", "Teng", "Tfload",
                   "Kpload", "Kiload", "Ldref", "Dm", "Ropen", "Rclose", "Kimw", "Aset", "Ka", "Ta",
                   "Trate", "db", "Tsa", "Tsb", "Rup", "Rdown")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"VAL": ("Vmin", "Vmax"), "PMW": ("-1.1*R", "1.1*R")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in range(self.n):
            el = self.element(i)
            if p["Rselect"][i] not in (1.0, 0.0, -1.0, -2.0):
                raise DataError(el, "Rselect", float(p["Rselect"][i]),
                                "give 1 (electrical power), 0 (isochronous), -1 (governor output) "
                                "or -2 (valve stroke)")
            for hi, lo in (("Vmax", "Vmin"), ("maxerr", "minerr"), ("Ropen", "Rclose")):
                if p[hi][i] < p[lo][i]:
                    raise DataError(el, hi, float(p[hi][i]), f"below {lo} = {p[lo][i]:g}; give {hi} >= {lo}")
            if p["Dm"][i] < 0:
                raise DataError(el, "Dm", float(p["Dm"][i]),
                                "Dm < 0 (fuel flow decreasing with speed) is not implemented; give Dm >= 0")
            for lead, lag in (("Tc", "Tb"), ("Tsa", "Tsb"), ("Kdgov", "Tdgov")):
                if p[lead][i] != 0 and p[lag][i] == 0:
                    raise DataError(el, lead, float(p[lead][i]),
                                    f"a lead/derivative without its lag ({lag} = 0) is improper; "
                                    f"give {lag} > 0 or {lead} = 0")
        self.warn_instances(np.nonzero((p["Rup"] < 10) | (p["Rdown"] > -10))[0],
                            "load-limit rate limits Rup, Rdown are not represented",
                            lambda i: f"Rup = {p['Rup'][i]:g}, Rdown = {p['Rdown'][i]:g}")
        Tbase = np.where(p["Trate"] > 0, p["Trate"], self.Sn)
        self.kT = Tbase / system.Sb                          # turbine base -> system base
        self.PELF = Lag(1.0, p["Tpelec"])
        self.PMW = IntegratorNonWindup(p["Kimw"], -1.1 * p["R"], 1.1 * p["R"])
        self.GD = Washout(p["Kdgov"], p["Tdgov"])
        self.VAL = IntegratorNonWindup(1.0, p["Vmin"], p["Vmax"])
        self.LL = LeadLag(p["Tc"], p["Tb"])
        self.TX1 = LeadLag(p["Tsa"], p["Tsb"])
        self.TX2 = Lag(1.0, p["Tfload"])
        self.ACD = Washout(1.0, p["Ta"])
        self.DELAY = TransportDelay(p["Teng"])
        self.TLIM = p["Wfnl"] + p["Ldref"] / p["Kturb"]
        self.kspd = (p["Flag"] > 0).astype(float)             # fuel flow proportional to speed
        self._loop = p["Rselect"] == -1.0
        self._any_loop = bool(np.any(self._loop))

    def limits(self):
        p = self.p
        return [(self.idx("PMW"), -1.1 * p["R"], 1.1 * p["R"]),
                (self.idx("VAL"), p["Vmin"], p["Vmax"])]

    # ------------------------------------------------------------------ pieces
    def _fsrn(self, fb, pmw, gi, gd, dw):
        """Governor error and PID output for the droop feedback ``fb``."""
        p = self.p
        e = np.clip(deadband(self.pref0 + pmw - p["R"] * fb - dw, -p["db"], p["db"]),
                    p["minerr"], p["maxerr"])
        return e, p["Kpgov"] * e + gi + self.GD.output(gd, e)

    def _turbine_input(self, val, dw):
        wf = val * (1.0 + self.kspd * dw)
        return wf, self.p["Kturb"] * (wf - self.p["Wfnl"])

    def init(self, system, x, sig):
        p = self.p
        pm0 = sig["tm0"][self.mach] / self.kT
        pe0 = sig["Pe0"][self.mach] / self.kT
        s40 = pm0 + p["Dm"]
        fsr0 = s40 / p["Kturb"] + p["Wfnl"]
        self.pmwset = pe0.copy()
        fb0 = np.select([p["Rselect"] == 1, p["Rselect"] == 0], [pe0, 0.0], fsr0)
        self.pref0 = p["R"] * fb0
        diff0 = self.TLIM - fsr0
        Tt = p["Ttrack"]
        z = np.zeros(self.n)
        vals = dict(PELF=pe0, PMW=z, GI=fsr0, GD=z, VAL=fsr0, LL=self.LL.init(s40),
                    TX1=self.TX1.init(fsr0), TX2=fsr0,
                    LI=fsr0 + p["Kiload"] * diff0 * Tt - p["Kpload"] * diff0,
                    ACD=z, XA=fsr0 + p["Ka"] * p["Aset"] * Tt)
        for k, st in enumerate(self.states):
            x[self.sl(k)] = vals[st]
        self.DELAY.reset(0.0, s40)
        self.initial_bounds = [
            ("the initial fuel demand fsr0 (turbine base)", fsr0, -np.inf, self.TLIM,
             "lower limit", "Ldref"),
            ("the initial fuel demand fsr0 (turbine base)", fsr0, -np.inf, 1.0,
             "lower limit", "1 (load limiter output cap)")]

    def accept(self, t, ctx):
        if self.DELAY.any:
            m = self._mi
            dw = ctx.sig["omega"][m] - 1.0
            self.DELAY.record(t, self._turbine_input(ctx.x[self._sls[4]], dw)[1])

    def compute(self, ctx):
        p = self.p
        m = self._mi
        pelf_x, pmw, gi, gd, val, ll, tx1, tx2, li, acd, xa = (ctx.x[..., s] for s in self._sls)
        omega = ctx.sig["omega"][..., m]
        dw = omega - 1.0
        pe = ctx.sig["Pe"][..., m] / self.kT
        pelf = self.PELF.output(pelf_x, pe)
        wf, ut = self._turbine_input(val, dw)
        # load limiter
        tin = wf * (1.0 + dw)
        y1 = self.TX1.output(tx1, tin)
        texm = self.TX2.output(tx2, y1)
        diff = self.TLIM - texm
        yT = p["Kpload"] * diff + li
        fsrt = np.minimum(yT, 1.0)
        fsra = xa
        other = np.minimum(fsrt, fsra)
        # governor (the droop feedback may be the gate output itself: Rselect = -1)
        fb = np.select([p["Rselect"] == 1, p["Rselect"] == 0, p["Rselect"] == -2], [pelf, 0.0, val], 0.0)
        e, fsrn = self._fsrn(fb, pmw, gi, gd, dw)
        fsr = np.clip(np.minimum(fsrn, other), p["Vmin"], p["Vmax"])
        if self._any_loop:
            F = fsr
            kd = np.where(p["Tdgov"] > 0, p["Kdgov"], 0.0) / np.where(p["Tdgov"] > 0, p["Tdgov"], 1.0)
            slope = 1.0 + (p["Kpgov"] + kd) * p["R"]          # dh/dF with the governor in control
            for _ in range(30):
                fbF = np.where(self._loop, F, fb)
                e, fsrn = self._fsrn(fbF, pmw, gi, gd, dw)
                G = np.clip(np.minimum(fsrn, other), p["Vmin"], p["Vmax"])
                h = F - G
                if np.all(np.abs(np.where(self._loop, h, 0.0)) < 1e-13):
                    break
                active = (fsrn < other) & (G > p["Vmin"]) & (G < p["Vmax"])
                F = F - h / np.where(active & self._loop, slope, 1.0)
            fsr = G
        Tt = p["Ttrack"]
        f = ctx.f
        d = {}
        d["PELF"] = self.PELF.deriv(pelf_x, pe)
        d["PMW"] = p["Kimw"] * (self.pmwset - pelf)
        d["GI"] = p["Kigov"] * e + (fsr - fsrn) / Tt
        d["GD"] = self.GD.deriv(gd, e)
        d["VAL"] = np.clip((fsr - val) / p["Tact"], p["Rclose"], p["Ropen"])
        utd = self.DELAY.output(ctx.t, ut)
        d["LL"] = self.LL.deriv(ll, utd)
        d["TX1"] = self.TX1.deriv(tx1, tin)
        d["TX2"] = self.TX2.deriv(tx2, y1)
        d["LI"] = p["Kiload"] * diff + (fsr - yT) / Tt
        accel = self.ACD.output(acd, dw)
        d["ACD"] = self.ACD.deriv(acd, dw)
        d["XA"] = p["Ka"] * (p["Aset"] - accel) + (fsr - xa) / Tt
        for k, st in enumerate(self.states):
            f[..., self._sls[k]] = d[st]
        s4 = self.LL.output(ll, utd)
        pm = s4 - p["Dm"] * (1.0 + dw)
        ctx.sig["tm"][..., m] = pm * self.kT   # PMECH: the PSS/E shaft divides by omega
        o = ctx.out
        o["GGOV1.ERR"], o["GGOV1.ACC"] = e, accel
        o["GGOV1.FSRN"], o["GGOV1.FSRT"], o["GGOV1.FSRA"] = fsrn, fsrt, fsra
        o["GGOV1.FSR"], o["GGOV1.TEXM"], o["GGOV1.PMECH"] = fsr, texm, pm
