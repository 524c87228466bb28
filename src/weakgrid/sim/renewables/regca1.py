"""REGCA1: WECC generic renewable generator/converter model A (PSS/E REGCA1, PSLF REGC_A).

The converter is a controlled current source aligned with its terminal voltage
(no PLL, as ANDES 2.0). Block diagram (system per unit; times in s)::

    Ipcmd --[LagRate 1/(1+sTg), T*dx/dt <= Rrpwr; non-windup upper LVPL(S2)]--> S0
    Ipout = S0 * LVG(v)                       low-voltage active current management
    -Iqcmd --[LagRate 1/(1+sTg), Iqrmin..Iqrmax (only in the direction of q0)]--> S1
    Iqout = clip(S1 - HVG(v), Iolim, 9999),  HVG = max(Khv*(v - Volim), 0)
    v --[Lag 1/(1+sTfltr)]--> S2
    LVG(v)   = 0 below Lvpnt0, linear to 1 at Lvpnt1, 1 above
    LVPL(S2) = 0 below Zerox, Lvpl1*(S2 - Zerox)/(Brkpt - Zerox) up to Brkpt, then no limit
               (no limit at all when Lvplsw = 0)
    P = Ipout*v,  Q = Iqout*v,  I = (Ipout - j Iqout) * V/|V|   (injected; v -> Vest: PSS/E, below)

Without an electrical control (REECA1) the commands are held at their initial values
``Ipcmd = p0/(v LVG(v))``, ``Iqcmd = -q0/v`` (as ANDES). Parameter names and per-unit
conventions are ANDES's: ``Iolim``, ``Iqrmax``, ``Iqrmin`` are currents on the device
base ``Sn`` (converted by ``Sn/Sb``).

Rate limits: ANDES 2.0 applies ``Rrpwr``, ``Iqrmax``, ``Iqrmin`` to ``Tg dx/dt`` (``Rrpwr`` on
the system base), so that with PSS/E's data (``Tg`` = 0.02 s) its current ramps 1/Tg = 50 times
faster than PSS/E's, whose limits bound ``dIp/dt`` and ``dIq/dt`` in pu/s on MBASE (PSS/E Model
Library, REGCA1: "Rrpwr: LVPL ramp rate limit (pu/s)", "Iqrmax/Iqrmin: upper/lower limit on rate
of change for reactive current (pu/s)"; WECC's REGC_A specification alike, typical Rrpwr = 10 pu/s:
a 0.1-s recovery of the active current). ``rates_per_s = 1`` gives PSS/E's meaning (set by the
PSS/E reader, :meth:`psse_params`); the default 0 keeps ANDES's, as imported from ANDES. (PSID
clamps ``Ipcmd - Ip`` before dividing by ``Tg`` too; its PSS/E benchmark cases, with Rrpwr = 10
and Iqrmax = 100, never reach the limits, so they do not tell the two readings apart.)

PSS/E's converter interface (``psse_interface``): by default (ANDES, PSID, the continuous model)
the converter's power is ``P = Ipout*|V|``, ``Q = Iqout*|V|`` at every instant. PSS/E computes the
converter's P and Q (the ones it reports; here also the ones its electrical and plant controls
see -- PSS/E's results cannot tell that apart: the largest P difference moves by < 4e-7 pu)
with a voltage estimate ``Vest`` relaxed towards ``|V|`` once per integration step,
``Vest_k = (Vest_(k-1) + |V_k|)/2`` at the network solution of step ``k``: ``P = Ipout*Vest``,
``Q = Iqout*Vest``, while the network receives the current ``(Ipout - j Iqout) V/|V|``. At a
steady state ``Vest = |V|`` and nothing changes; after a voltage step P and Q move half-way with
the voltage at the step and the rest follows by halves, step by step. Measured on PSS/E's own
RENA results (REGCA1 + REECB1 + REPCA1, 5-ms step, line trip at 1 s; ``tests/psse/
test_rena_interface.py``, ``tests/sim/test_regca1_psse_interface.py``): PSS/E's P and Q are short
of the continuous converter's by one common factor, 0.47 % at the event sample (half the
0.95 % voltage step), 0.21 %, 0.11 %, 0.05 % at the next three steps -- ``Vest/|V|`` sample by
sample -- while PSS/E's bus voltage is that of the unscaled current (4e-6 pu from weakgrid's
continuous run at +5 ms; scaling the injected current instead moves it 2.5e-5 pu away). It is a
property of PSS/E's step (a discrete state, not a time constant: the data have none below
20 ms, and a lag would show the whole step, not half of it, at the event) and is reproduced as
such: ``Vest_(k-1)`` is discrete memory updated at each accepted point (``accept``, after
every step and after an event's network re-solution), and the point being solved uses
``(Vest_(k-1) + |V|)/2``; it matches PSS/E's time course when weakgrid steps at PSS/E's step.
The factor 1/2 is the measured one (REGCA1's CON ``Accel`` is 0 in those files and does not
enter it; the shipped results show nothing of other ``Accel`` values, so ``Accel`` stays
unused). ``psse_interface = 1`` is set by the PSS/E reader (:meth:`psse_params`), as
``psse_shaft`` for machines; 0 (the default) keeps the continuous form for every other route.

Limits follow ANDES: the rate limits bound ``T dx/dt``; the upper limit LVPL of ``S0`` is
an anti-windup limit that moves with ``S2``: a state that crosses it is *reset* to it and held
there while its input pushes up (the integrator's non-windup limits, refreshed at every Newton
iterate through :meth:`limit_values`), as ANDES's ``AntiWindup`` resets the state. The output
is the state, so it never exceeds LVPL. ANDES 2.0's ``AntiWindup`` resets only a state whose
derivative is >= 0 (at every Newton iterate: ``x >= upper and dx/dt >= 0``): a state above a
falling LVPL that decreases towards a smaller Ipcmd stays above the limit there, e.g. 5.4 pu
against LVPL = 0.34 pu in ``tests/sim/test_reeca1_peer.py``'s limit case. The flag
``LVPL_strict = 0`` reproduces that (the integrator then holds S0 at LVPL only when it
crosses the limit with dS0/dt >= 0; a held S0 is released when dS0/dt < 0, as always);
``from_andes(..., conventions="andes")`` sets it. (Holding the state where it was when the limit first bound, and clipping only
the output, leaves the state far above a limit that fell in a fault; when LVPL switches off
at ``Brkpt`` the output then jumps back to the state, and the step cannot converge.)
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagRate, piecewise_linear
from ..component import Component
from ..errors import DataError
from ..namespace import add_at, take
from ..params import Param


class REGCA1(Component):
    """Renewable generator/converter model A (WECC) on a static generator row (or its share of it:
    ``gammap``, ``gammaq``).

    PSS/E reader interface (REGCA1, REECA1, REECB1, REPCA1 alike): ``psse_record`` (ICONs first;
    names starting with ``_`` are ICONs consumed by ``psse_params``/``psse_link``),
    ``psse_params(values, ctx)`` -> parameters and ``psse_link(values, ctx)`` -> the link dict of
    :meth:`Component.add`, with ``values`` the record's fields by ``psse_record`` name (numbers;
    REPCA1's circuit id ``_CKT`` a string) and ``ctx`` the contract's context (``bus``, ``id``,
    ``mbase``, ``sbase``, ``where``) plus ``gen_row`` (0-based gen-table row of the generator
    (IBUS, ID)), ``names`` (model -> weakgrid name of the records already built at that generator,
    e.g. ``{"REGCA1": "REGCA1_103_1"}``: the reader builds REGCA1 before REECA1/REECB1 and those
    before REPCA1) and, for REPCA1 with a monitored branch, ``branch_row(from_bus, to_bus, ckt)`` ->
    0-based branch row (PSS/E bus numbers, stripped circuit id).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    gen_shared = True        # with machines or other converters, by the shares gammap, gammaq
    order = 0
    params = (
        Param("Sn", 100.0, "MVA", "device rating", "pos"),
        Param("Tg", 0.1, "s", "converter time constant", "pos"),
        Param("Rrpwr", 10.0, "pu", "LVPL ramp limit (on Tg*dIp/dt)", "pos"),
        Param("Brkpt", 1.0, "pu", "LVPL breakpoint voltage", ""),
        Param("Zerox", 0.5, "pu", "LVPL zero-crossing voltage", ""),
        Param("Lvplsw", 1.0, "-", "LVPL switch (1 on, 0 off)", "nonneg"),
        Param("Lvpl1", 1.0, "pu", "LVPL gain at Brkpt", ""),
        Param("Volim", 1.2, "pu", "voltage limit of high-voltage reactive current management", ""),
        Param("Lvpnt1", 0.8, "pu", "high point of low-voltage active current management", ""),
        Param("Lvpnt0", 0.4, "pu", "low point of low-voltage active current management", ""),
        Param("Iolim", -1.5, "pu (Sn)", "lower limit of the reactive current output", "", "current"),
        Param("Tfltr", 0.1, "s", "voltage filter time constant of LVPL", "pos"),
        Param("Khv", 0.7, "pu/pu", "overvoltage compensation gain", ""),
        Param("Iqrmax", 1.0, "pu (Sn)", "upper rate limit of reactive current (on Tg*dIq/dt)", "", "current"),
        Param("Iqrmin", -1.0, "pu (Sn)", "lower rate limit of reactive current (on Tg*dIq/dt)", "", "current"),
        Param("Accel", 0.0, "-", "acceleration factor (unused, as ANDES)", ""),
        Param("gammap", 1.0, "-", "share of the static generator's P", "pos"),
        Param("gammaq", 1.0, "-", "share of the static generator's Q", "pos"),
        Param("LVPL_strict", 1.0, "-", "1: S0 never exceeds LVPL (reset whenever it crosses it); "
              "0: reset only while dS0/dt >= 0 (ANDES 2.0)", "flag"),
        Param("psse_interface", 0.0, "-", "1: P, Q = (Ipout, Iqout)*Vest, Vest relaxed by halves towards "
              "|V| once per step (PSS/E); 0: P, Q = (Ipout, Iqout)*|V| (ANDES, continuous)", "flag"),
        Param("rates_per_s", 0.0, "-", "1: Rrpwr, Iqrmax, Iqrmin bound dIp/dt, dIq/dt [pu/s on Sn] (PSS/E, "
              "WECC); 0: they bound Tg*dIp/dt, Tg*dIq/dt, Rrpwr on the system base (ANDES 2.0)", "flag"),
    )

    #: PSS/E .dyr record after ``IBUS 'REGCA1' ID``: ICON Lvplsw, then the 14 CONs (PSS/E Model
    #: Library, REGCA1; the layout of PSID's RENA and the WECC 240-bus files).
    psse_record = ("Lvplsw", "Tg", "Rrpwr", "Brkpt", "Zerox", "Lvpl1", "Volim", "Lvpnt1", "Lvpnt0",
                   "Iolim", "Tfltr", "Khv", "Iqrmax", "Iqrmin", "Accel")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E record -> parameters: ``Sn`` = the generator's MBASE; the rate limits ``Rrpwr``,
        ``Iqrmax``, ``Iqrmin`` keep their PSS/E meaning (pu/s on MBASE: ``rates_per_s = 1``);
        the converter's P and Q are PSS/E's, with the per-step voltage estimate
        (``psse_interface = 1``, see the module docstring); the record's CONs are otherwise the parameters (``Accel`` has no
        effect on the model)."""
        v = dict(values)
        v["Sn"] = float(ctx.mbase)
        v["rates_per_s"] = 1.0
        v["psse_interface"] = 1.0
        return v

    @classmethod
    def psse_link(cls, values, ctx):
        """Link of a PSS/E record: the gen-table row ``ctx.gen_row`` of its generator (IBUS, ID)."""
        return {"gen": int(ctx.gen_row)}
    states = ("S0", "S1", "S2")
    outputs = ("Ipout", "Iqout", "Pe", "Qe", "LVG", "LVPL", "Ipcmd", "Iqcmd")
    disconnectable = True    # a generator trip removes its current (compute)
    injection_outputs = ("Ipout", "Iqout", "Pe", "Qe")
    units = {"Pe": "power", "Qe": "power"}

    @classmethod
    def andes_link(cls, m, k, gen_row, **_):
        """Link of ANDES device ``k`` of model ``m``: the gen-table row of its static generator."""
        return {"gen": gen_row[m.gen.v[k]]}

    def add_regca1(self, name, gen, **params):
        """Add one converter replacing gen-table row ``gen`` (0-based)."""
        self.add(name, {"gen": gen}, params)
        return name

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.resolve_gen_rows(system)
        c = p["Sn"] / system.Sb
        for prm in self.params:
            if prm.base == "current":
                p[prm.name] = p[prm.name] * c
        self._uniq = len(set(self.bus.tolist())) == self.n
        # PSS/E's interface: Vest is discrete memory, updated at accepted points (accept); only
        # then is this component one "with discrete memory" (which keeps it out of batches)
        self._psse_if = p["psse_interface"] > 0
        if self._psse_if.any():
            self.accept = self._accept_vest
        else:
            self.__dict__.pop("accept", None)

    def pattern(self, system):
        groups = []
        for i in range(self.n):
            v = self.instance_states(i) + system.bus_vars(self.bus[i])
            groups.append((v, v))
        return groups

    # ---------------------------------------------------------------- algebra
    def _lvg(self, v):
        p = self.p
        return piecewise_linear(v, [p["Lvpnt0"], p["Lvpnt1"]], [0.0, 1.0], self.xp)

    def _lvpl(self, s2):
        xp, p = self.xp, self.p
        on = p["Lvplsw"] > 0
        seg = (s2 - p["Zerox"]) * p["Lvpl1"] / (p["Brkpt"] - p["Zerox"])
        lim = xp.where(s2 <= p["Zerox"], 0.0, xp.where(s2 <= p["Brkpt"], seg, 9999.0))
        return xp.where(on, lim, 9999.0)

    limit_fields = {"S0": ("lower limit", "LVPL (Brkpt, Zerox, Lvpl1)")}

    def limits(self):
        """``S0`` below LVPL(S2) (anti-windup, reset to the limit when it crosses it)."""
        return [(self.idx("S0"), np.full(self.n, -np.inf), self._lvpl_limit(self._v0))]

    def limits_reset_if_pushing(self):
        """``LVPL_strict = 0`` (ANDES 2.0): S0 is reset to LVPL only while dS0/dt >= 0."""
        return [self.p["LVPL_strict"] <= 0]

    def _lvpl_limit(self, s2):
        lim = self._lvpl(s2)
        return np.where(lim >= 9999.0, np.inf, lim)     # off: no limit (releases a held state)

    def limit_values(self, ctx):
        """Current LVPL limit of ``S0`` from the filtered voltage ``S2`` in ``ctx``."""
        return np.full(self.n, -np.inf), self._lvpl_limit(ctx.x[self.sl(2)])

    def init(self, system, x, sig):
        pf = system.network.pf
        p = self.p
        V = pf.V[self.bus]
        v = np.abs(V)
        self.p0 = pf.Pg[self.gen] * p["gammap"]
        self.q0 = pf.Qg[self.gen] * p["gammaq"]
        self._v0 = v.copy()
        self._vest = v.copy()         # PSS/E interface: Vest at the last accepted point
        lvg = self._lvg(v)
        for i in np.nonzero(lvg <= 0)[0]:
            raise DataError(self.element(i), "Lvpnt0", p["Lvpnt0"][i],
                            f"the initial voltage {v[i]:.4g} pu is at or below Lvpnt0: no active current "
                            "can flow; lower Lvpnt0")
        hv = p["Khv"] * (v - p["Volim"])
        for i in np.nonzero(hv > 0)[0]:
            raise DataError(self.element(i), "Volim", p["Volim"][i],
                            f"the initial voltage {v[i]:.4g} pu exceeds Volim; raise Volim above it")
        self.Ipcmd0 = self.p0 / v / lvg
        self.Iqcmd0 = -self.q0 / v
        iq = -self.Iqcmd0
        for i in np.nonzero(iq < p["Iolim"])[0]:
            raise DataError(self.element(i), "Iolim", p["Iolim"][i],
                            f"the initial reactive current {iq[i]:.4g} pu is below Iolim; lower Iolim")
        lvpl = self._lvpl(v)
        for i in np.nonzero(self.Ipcmd0 > lvpl)[0]:
            raise DataError(self.element(i), "Brkpt", p["Brkpt"][i],
                            f"the initial active current {self.Ipcmd0[i]:.4g} pu exceeds the LVPL limit "
                            f"{lvpl[i]:.4g} pu at {v[i]:.4g} pu; lower Brkpt or raise Lvpl1")
        # rate limits on Tg*dx/dt (the LagRate convention): PSS/E's dx/dt limits times Tg, and
        # PSS/E's Rrpwr (pu/s on Sn) on the system base of S0
        per_s = p["rates_per_s"] > 0
        rrpwr = np.where(per_s, p["Rrpwr"] * p["Tg"] * p["Sn"] / system.Sb, p["Rrpwr"])
        iqrmax = np.where(per_s, p["Iqrmax"] * p["Tg"], p["Iqrmax"])
        iqrmin = np.where(per_s, p["Iqrmin"] * p["Tg"], p["Iqrmin"])
        self.S0 = LagRate(1.0, p["Tg"], -np.inf, rrpwr)
        self.S1 = LagRate(-1.0, p["Tg"], np.where(self.q0 < 0, iqrmin, -np.inf),
                          np.where(self.q0 > 0, iqrmax, np.inf))
        self.S2 = Lag(1.0, p["Tfltr"])
        x[self.sl(0)] = self.Ipcmd0
        x[self.sl(1)] = self.S1.init(self.Iqcmd0)
        x[self.sl(2)] = v

    # -------------------------------------------------------------- equations
    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        s0, s1, s2 = x[..., sl[0]], x[..., sl[1]], x[..., sl[2]]
        V = take(xp, ctx.V, self.bus)
        v = xp.abs(V)
        lvpl = self._lvpl(s2)
        self._lvpl_v = lvpl
        ip = s0                       # held at/below LVPL by the integrator (anti-windup reset)
        lvg = self._lvg(v)
        ipout = ip * lvg
        hvg = xp.maximum(p["Khv"] * (v - p["Volim"]), 0.0)
        iqout = xp.clip(s1 - hvg, p["Iolim"], 9999.0)
        vs = xp.where(v > 1e-6, v, 1e-6)
        I = (ipout - 1j * iqout) * V / vs
        add_at(xp, ctx.I, self.bus, self.connected(I), self._uniq)
        # the converter's P and Q: with |V|, or with PSS/E's per-step estimate Vest
        vp = xp.where(self._psse_if, 0.5 * (self._vest + v), v)
        # commands: constant unless an electrical control (REECA1) publishes them
        shape = x.shape[:-1] + (self.n,)
        ctx.sig["REGCA1.Ipcmd"] = xp.asarray(xp.broadcast_to(self.Ipcmd0, shape), copy=True)
        ctx.sig["REGCA1.Iqcmd"] = xp.asarray(xp.broadcast_to(self.Iqcmd0, shape), copy=True)
        ctx.sig["REGCA1.v"] = v
        ctx.sig["REGCA1.Pe"] = ipout * vp
        ctx.sig["REGCA1.Qe"] = iqout * vp
        self._o = (ipout, iqout, lvg, lvpl, v, vp)

    def finish(self, ctx):
        x = ctx.x
        sl = self._sls
        s0, s1, s2 = x[..., sl[0]], x[..., sl[1]], x[..., sl[2]]
        ipcmd, iqcmd = ctx.sig["REGCA1.Ipcmd"], ctx.sig["REGCA1.Iqcmd"]
        ipout, iqout, lvg, lvpl, v, vp = self._o
        ctx.f[..., sl[0]] = self.S0.deriv(s0, ipcmd)   # upper limit LVPL: see limits()
        ctx.f[..., sl[1]] = self.S1.deriv(s1, iqcmd)
        ctx.f[..., sl[2]] = self.S2.deriv(s2, v)
        o = ctx.out
        o["REGCA1.Ipout"], o["REGCA1.Iqout"] = ipout, iqout
        o["REGCA1.Pe"], o["REGCA1.Qe"] = ipout * vp, iqout * vp
        o["REGCA1.LVG"], o["REGCA1.LVPL"] = lvg, lvpl
        o["REGCA1.Ipcmd"], o["REGCA1.Iqcmd"] = ipcmd + 0.0, iqcmd + 0.0

    def _accept_vest(self, t, ctx):
        """PSS/E's interface (``psse_interface = 1``): keep ``Vest`` of the accepted point ``t``,
        ``(Vest_prev + |V|)/2``, for the next step's network solutions."""
        xp = self.xp
        v = xp.abs(take(xp, ctx.V, self.bus))
        self._vest = xp.where(self._psse_if, 0.5 * (self._vest + v), self._vest)
