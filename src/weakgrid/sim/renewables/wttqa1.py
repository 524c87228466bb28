"""WTTQA1: WECC generic wind-turbine torque controller (PSS/E WTTQA1, PSLF WTGQ_A).

Sets the active power reference of the electrical control (:class:`~.reeca1.REECA1`) from a
torque PI controller (system per unit; times in s; speeds in pu)::

    Pe --[Lag 1/(1+sTp)]--> s1 --> fPe(s1) --[Lag 1/(1+sTwref)]--> s2 = wref
        fPe: piecewise linear through (p1, sp1) .. (p4, sp4), flat outside
    Tsel = wg - wref                       (Tflag = 0, speed error)
         = (s1 - Pref0) / wg                (Tflag = 1, power error)
    Tsel --[PI Kpp + Kip/s, non-windup Temin..Temax]--> Te
    Pref = Te wg                           (to REECA1; wref to the pitch controller WTPTA1)

``wg`` is the generator speed of the drive train (:class:`~.wtdta1.WTDTA1`), ``Pe`` the
converter's power. The chain starts at rest: ``wg = wt = wref = fPe(Pe0)`` (the torque
controller sets the drive train's initial speed), ``Te = Pref0/wg``. ``Temax``, ``Temin``,
``p1..p4`` are on the turbine rating ``Tn`` (the converter's ``Sn`` when ``Tn = 0``), and so
are the PI gains (with ``Tflag = 0`` they turn a speed into a torque on that base).

Departures of ANDES 2.0 from the WECC model, reproduced by flags (set by the ANDES importer with
``conventions="andes"``, :data:`weakgrid.sim.io.andes.ANDES_CONVENTIONS`):

* ``speed_err = 0``: ANDES's speed error is ``wref - wg`` (``speed_err = 1``, WECC:
  ``wg - wref``, a generator above its reference speed raises its torque);
* ``Pe_filt = 0``: ANDES's power error takes the unfiltered ``Pe`` (WECC: ``s1``);
* ``wg_reset = 1``: ANDES feeds REECA1 the speed ``1 + wg - fPe(s1)`` (its "reset of wg to 1",
  which makes REECA1's ``PFLAG`` act only on the speed deviation) instead of ``wg``; it
  matters only with ``PFLAG = 1``;
* ``adjust_lim = 1``: an initial torque beyond ``[Temin, Temax]`` widens that limit to it, as
  ANDES's ``allow_adjust`` does (with a warning in its log); ``adjust_lim = 0`` refuses it.
* The PI gains act on the system base in ANDES (the importer converts them); the WECC PI is
  frozen in a voltage dip, which ANDES does not implement (neither does this model).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, PINonWindup, piecewise_linear
from ..component import Component
from ..errors import DataError
from ..namespace import take
from ..params import Param
from ._wind import andes_link, chain_pattern, held, publish, resolve


class WTTQA1(Component):
    """Torque (Pref) controller of a type-3 wind turbine (WECC); linked to one WTPTA1 (``rep``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 1.4          # after WTDTA1 (wg), before REECA1 (reads Pref)
    params = (
        Param("Kip", 0.1, "pu/(pu s) (Tn)", "torque PI integral gain"),
        Param("Kpp", 0.0, "pu/pu (Tn)", "torque PI proportional gain"),
        Param("Tp", 0.05, "s", "Pe filter time constant (0: none)", "nonneg"),
        Param("Twref", 30.0, "s", "speed reference time constant (0: none)", "nonneg"),
        Param("Temax", 1.2, "pu (Tn)", "maximum electric torque"),
        Param("Temin", 0.0, "pu (Tn)", "minimum electric torque"),
        Param("Tflag", None, "-", "1 power error, 0 speed error", "flag"),
        Param("p1", 0.2, "pu (Tn)", "power point 1"), Param("sp1", 0.58, "pu", "speed at p1"),
        Param("p2", 0.4, "pu (Tn)", "power point 2"), Param("sp2", 0.72, "pu", "speed at p2"),
        Param("p3", 0.6, "pu (Tn)", "power point 3"), Param("sp3", 0.86, "pu", "speed at p3"),
        Param("p4", 0.8, "pu (Tn)", "power point 4"), Param("sp4", 1.0, "pu", "speed at p4"),
        Param("Tn", 0.0, "MVA", "turbine rating (0: the converter's Sn)", "nonneg"),
        Param("speed_err", 1.0, "-", "speed error: 1 wg - wref (WECC), 0 wref - wg (ANDES 2.0)", "flag"),
        Param("Pe_filt", 1.0, "-", "power error on: 1 filtered Pe (WECC), 0 Pe (ANDES 2.0)", "flag"),
        Param("wg_reset", 0.0, "-", "speed to REECA1: 0 wg (WECC), 1 1 + wg - fPe (ANDES 2.0)", "flag"),
        Param("adjust_lim", 0.0, "-", "initial torque beyond a limit: 0 refuse, 1 widen it (ANDES 2.0)",
              "flag"),
    )
    states = ("s1", "s2", "PI")
    outputs = ("Pref", "Te", "Tsel", "fPe", "wref")
    limit_fields = {"PI": ("Temin", "Temax")}

    @classmethod
    def andes_link(cls, m, k, dev_name, **_):
        """Link of ANDES device ``k``: the weakgrid name of its pitch controller (``rep``)."""
        return andes_link(m, k, dev_name, "rep", "WTPTA1", "")

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """``Tn`` missing -> 0 (the converter's Sn); PI gains from ANDES's system base."""
        if not np.isfinite(values.get("Tn", 0.0)):
            values["Tn"] = 0.0
        Tn = values["Tn"]
        if Tn <= 0:
            pt = ss.WTPTA1
            rea = pt.rea.v[list(pt.idx.v).index(m.rep.v[k])]
            rego = ss.WTARA1.rego.v[list(ss.WTARA1.idx.v).index(rea)]
            ree = ss.WTDTA1.ree.v[list(ss.WTDTA1.idx.v).index(rego)]
            reg = ss.REECA1.reg.v[list(ss.REECA1.idx.v).index(ree)]
            Tn = float(ss.REGCA1.Sn.v[list(ss.REGCA1.idx.v).index(reg)])
        if values["Tflag"] == 0:        # a speed error -> torque: ANDES's gains are on Sb
            for f in ("Kpp", "Kip"):
                values[f] = values[f] * ss.config.mva / Tn
        return values

    def add_wttqa1(self, name, rep, **params):
        """Add the torque controller of the pitch controller named ``rep``."""
        self.add(name, {"rep": rep}, params)
        return name

    def setup(self, system):
        super().setup(system)
        p = self.p
        for a, b in (("p1", "p2"), ("p2", "p3"), ("p3", "p4")):
            for i in np.nonzero(p[a] >= p[b])[0]:
                raise DataError(self.element(int(i)), b, p[b][i], f"the power points must increase: give {b} > {a}")
        for i in np.nonzero(p["Temin"] > p["Temax"])[0]:
            raise DataError(self.element(int(i)), "Temin", p["Temin"][i], "give Temin <= Temax")
        self.ree = None

    def init(self, system, x, sig):
        p = self.p
        self.pt, self.rep = resolve(self, system, "rep", "WTPTA1")
        k = np.full(self.pt.n, -1)
        k[self.rep] = np.arange(self.n)
        self.pt.tq = (self, k)
        self.dt, self.rego = self.pt.dt, self.pt.rego[self.rep]
        self.ree_comp, self.ree = self.dt.ree_comp, self.dt.ree[self.rego]
        Sn = np.where(p["Tn"] > 0, p["Tn"], self.dt.Sn[self.rego])
        c = Sn / system.Sb
        for f in ("Temax", "Temin", "p1", "p2", "p3", "p4"):
            p[f] = p[f] * c
        for f in ("Kpp", "Kip"):
            p[f] = p[f] * np.where(p["Tflag"] > 0, 1.0, c)
        pflag = self.ree_comp.p["PFLAG"][self.ree] > 0
        for i in np.nonzero(pflag & (p["wg_reset"] <= 0))[0]:
            raise DataError(self.element(int(i)), "PFLAG", 1.0,
                            "its REECA1 has PFLAG = 1: the torque controller's Pref = Te wg would be "
                            "multiplied by the speed again; set PFLAG = 0 in the REECA1")
        self.Pref0 = self.dt.Pe0[self.rego]
        w = self._fpe(self.Pref0)
        self.dt.set_speed(x, w, self.rego)
        te0 = self.Pref0 / w
        if np.any(p["adjust_lim"] > 0):
            adj = p["adjust_lim"] > 0
            p["Temax"] = np.where(adj, np.maximum(p["Temax"], te0), p["Temax"])
            p["Temin"] = np.where(adj, np.minimum(p["Temin"], te0), p["Temin"])
        self.s1b = Lag(1.0, p["Tp"])
        self.s2b = Lag(1.0, p["Twref"])
        self.PIb = PINonWindup(p["Kpp"], p["Kip"], p["Temin"], p["Temax"])
        x[self.sl(0)] = self.Pref0
        x[self.sl(1)] = w
        x[self.sl(2)] = te0

    def limits(self):
        return [(self.idx("PI"), self.p["Temin"], self.p["Temax"])]

    def _fpe(self, s1):
        p = self.p
        return piecewise_linear(s1, [p["p1"], p["p2"], p["p3"], p["p4"]], [p["sp1"], p["sp2"], p["sp3"], p["sp4"]],
                                self.xp)

    def wref(self, x):
        """Speed reference [pu] (``s2``; with ``Twref = 0`` the map of the filtered power)."""
        s1, s2 = x[..., self.sl(0)], x[..., self.sl(1)]
        return self.xp.where(self.p["Twref"] > 0, s2, self._fpe(s1))

    def pattern(self, system):
        return [chain_pattern(system, self.ree_comp, int(self.ree[i]), self.instance_states(i)) for i in range(self.n)]

    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        s1, s2, xi = x[..., sl[0]], x[..., sl[1]], x[..., sl[2]]
        pe = take(xp, ctx.sig["REGCA1.Pe"], take(xp, self.dt.reg, self.rego))
        wg = take(xp, x[..., self.dt.sl(1)], self.rego)
        s1y = self.s1b.output(s1, pe)
        fpe = self._fpe(s1y)
        wref = self.s2b.output(s2, fpe)
        sign = xp.where(p["speed_err"] > 0, xp.asarray(1.0, dtype=xp.float64), -1.0)
        pe_sel = xp.where(p["Pe_filt"] > 0, s1y, pe)
        tsel = xp.where(p["Tflag"] > 0, (pe_sel - self.Pref0) / wg, sign * (wg - wref))
        te = self.PIb.output(xi, tsel)
        pref = te * wg
        n = self.ree_comp.n
        publish(ctx, "REECA1.Pref", n, self.ree, pref, self.ree_comp.Pref0, xp)
        if xp.any(p["wg_reset"] > 0):
            wg_r = xp.where(p["wg_reset"] > 0, 1.0 + wg - fpe, wg)
            publish(ctx, "REECA1.wg", n, self.ree, wg_r, 1.0, xp)
        f = ctx.f
        f[..., sl[0]] = self.s1b.deriv(s1, pe)
        f[..., sl[1]] = self.s2b.deriv(s2, fpe)
        f[..., sl[2]] = held(self.PIb.deriv(xi, tsel), xi, p["Temin"], p["Temax"], xp)
        o = ctx.out
        o["WTTQA1.Pref"], o["WTTQA1.Te"], o["WTTQA1.Tsel"] = pref, te, tsel
        o["WTTQA1.fPe"], o["WTTQA1.wref"] = fpe, wref + 0.0
