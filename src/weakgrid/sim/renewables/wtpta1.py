"""WTPTA1: WECC generic wind-turbine pitch controller (PSS/E WTPTA1, PSLF WTGP_A).

Two PI controllers act on the pitch angle [deg] (system per unit; times in s)::

    e     = Pord - Pref                       (REECA1's power order and reference)
    PIc   = PI(Kpc, Kic) on e,                              output and state in [thmin, thmax]
    PIw   = PI(Kpw, Kiw) on Kcc e + wt - wref,              output and state in [thmin, thmax]
    PIc + PIw --[Lag 1/(1+sTp), non-windup thmin..thmax, rate dthmin..dthmax]--> theta

``wt`` is the turbine speed of the drive train (:class:`~.wtdta1.WTDTA1`), ``wref`` the speed
reference of the torque controller (:class:`~.wttqa1.WTTQA1`, its filtered ``fPe``; held at
the drive train's ``w0`` without one). ``theta`` goes to the aerodynamics
(:class:`~.wtara1.WTARA1`). At the initial point the turbine runs at its reference with
``Pord = Pref``: ``PIw`` holds ``theta0``, ``PIc`` 0. ``Kpc``, ``Kic``, ``Kcc`` act on a power
on the converter's rating ``Sn`` (converted by ``Sb/Sn``); ANDES applies them to the power on
the system base and its importer converts.

Departures of ANDES 2.0 from the WECC model, reproduced by flags (set by the ANDES importer with
``conventions="andes"``, :data:`weakgrid.sim.io.andes.ANDES_CONVENTIONS`):

* ``wref_tq = 0``: ANDES holds ``wref`` at the drive train's ``w0`` (its initial speed before
  the torque controller resets it to ``fPe(Pe0)``), instead of the torque controller's speed
  reference (``wref_tq = 1``, WECC). A turbine that starts below ``w0`` then starts with its
  speed PI pushed against ``thmin`` (held there);
* ``rate_T = 1``: ANDES's rate limiter bounds ``Tp dtheta/dt`` by ``dthmin..dthmax`` (its
  ``LagAntiWindupRate``), not ``dtheta/dt`` (``rate_T = 0``, WECC: the limits are in deg/s).
"""

from __future__ import annotations

import numpy as np

from ..blocks import LagRate, PINonWindup
from ..component import Component
from ..errors import DataError
from ..namespace import take
from ..params import Param
from ._wind import andes_link, chain_pattern, held, resolve


class WTPTA1(Component):
    """Pitch controller of a type-3 wind turbine (WECC); linked to one WTARA1 (``rea``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 1.3
    params = (
        Param("Kiw", 0.1, "deg/(pu s)", "pitch-control integral gain"),
        Param("Kpw", 0.0, "deg/pu", "pitch-control proportional gain"),
        Param("Kic", 0.1, "deg/(pu s) (Sn)", "pitch-compensation integral gain", "", "ipower"),
        Param("Kpc", 0.0, "deg/pu (Sn)", "pitch-compensation proportional gain", "", "ipower"),
        Param("Kcc", 0.0, "pu/pu (Sn)", "gain of the power difference in the speed loop", "", "ipower"),
        Param("Tp", 0.3, "s", "blade response time constant", "pos"),
        Param("thmax", 30.0, "deg", "maximum pitch angle"),
        Param("thmin", 0.0, "deg", "minimum pitch angle"),
        Param("dthmax", 5.0, "deg/s", "maximum pitch rate"),
        Param("dthmin", -5.0, "deg/s", "minimum pitch rate"),
        Param("wref_tq", 1.0, "-", "speed reference: 1 the torque controller's (WECC), 0 held (ANDES 2.0)",
              "flag"),
        Param("rate_T", 0.0, "-", "rate limits bound: 0 dtheta/dt (WECC), 1 Tp dtheta/dt (ANDES 2.0)", "flag"),
    )
    states = ("PIc", "PIw", "theta")
    outputs = ("theta", "wref", "PIc_y", "PIw_y")
    limit_fields = {"PIc": ("thmin", "thmax"), "PIw": ("thmin", "thmax"), "theta": ("thmin", "thmax")}

    @classmethod
    def andes_link(cls, m, k, dev_name, **_):
        """Link of ANDES device ``k``: the weakgrid name of its aerodynamics (``rea``)."""
        return andes_link(m, k, dev_name, "rea", "WTARA1", "")

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """``Kpc``, ``Kic``, ``Kcc`` from ANDES's system base to the converter's."""
        ara = ss.WTARA1
        rego = ara.rego.v[list(ara.idx.v).index(m.rea.v[k])]
        ree = ss.WTDTA1.ree.v[list(ss.WTDTA1.idx.v).index(rego)]
        reg = ss.REECA1.reg.v[list(ss.REECA1.idx.v).index(ree)]
        Sn = float(ss.REGCA1.Sn.v[list(ss.REGCA1.idx.v).index(reg)])
        for f in ("Kpc", "Kic", "Kcc"):
            values[f] = values[f] * Sn / ss.config.mva
        return values

    def add_wtpta1(self, name, rea, **params):
        """Add the pitch controller of the aerodynamics named ``rea``."""
        self.add(name, {"rea": rea}, params)
        return name

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in np.nonzero(p["thmin"] > p["thmax"])[0]:
            raise DataError(self.element(int(i)), "thmin", p["thmin"][i], "give thmin <= thmax")
        for i in np.nonzero(p["dthmin"] > p["dthmax"])[0]:
            raise DataError(self.element(int(i)), "dthmin", p["dthmin"][i], "give dthmin <= dthmax")
        self.ree = None
        self.tq = None     # (WTTQA1 component, its index per instance or -1), set by WTTQA1.init

    def init(self, system, x, sig):
        p = self.p
        self.ara, self.rea = resolve(self, system, "rea", "WTARA1")
        k = np.full(self.ara.n, -1)
        k[self.rea] = np.arange(self.n)
        self.ara.pitch = (self, k)
        self.dt, self.rego = self.ara.dt, self.ara.rego[self.rea]
        self.ree_comp, self.ree = self.dt.ree_comp, self.dt.ree[self.rego]
        c = system.Sb / self.dt.Sn[self.rego]
        for prm in self.params:
            if prm.base == "ipower":
                p[prm.name] = p[prm.name] * c
        self.wref0 = self.dt.w_init[self.rego].copy()
        th0 = self.ara.p["theta0"][self.rea]
        self.PIcb = PINonWindup(p["Kpc"], p["Kic"], p["thmin"], p["thmax"])
        self.PIwb = PINonWindup(p["Kpw"], p["Kiw"], p["thmin"], p["thmax"])
        r = np.where(p["rate_T"] > 0, 1.0, p["Tp"])
        self.LGb = LagRate(1.0, p["Tp"], p["dthmin"] * r, p["dthmax"] * r)
        x[self.sl(0)] = 0.0
        x[self.sl(1)] = th0
        x[self.sl(2)] = th0

    def limits(self):
        p = self.p
        return [(self.idx(s), p["thmin"], p["thmax"]) for s in self.states]

    def theta(self, x):
        """Pitch angle [deg] (the lag's state)."""
        return x[..., self.sl(2)]

    def _wref(self, x):
        xp = self.xp
        ref = xp.broadcast_to(self.wref0, tuple(x.shape[:-1]) + (self.n,))
        if self.tq is None:
            return ref
        tc, k = self.tq
        w = take(xp, tc.wref(x), xp.maximum(k, 0))
        return xp.where((k >= 0) & (self.p["wref_tq"] > 0), w, ref)

    def pattern(self, system):
        return [chain_pattern(system, self.ree_comp, int(self.ree[i]), self.instance_states(i)) for i in range(self.n)]

    def finish(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        xc, xw, th = x[..., sl[0]], x[..., sl[1]], x[..., sl[2]]
        e = take(xp, ctx.out["REECA1.Pord"], self.ree) - take(xp, ctx.out["REECA1.Pref"], self.ree)
        wt = take(xp, x[..., self.dt.sl(0)], self.rego)
        wref = self._wref(x)
        uw = p["Kcc"] * e + wt - wref
        yc = self.PIcb.output(xc, e)
        yw = self.PIwb.output(xw, uw)
        f = ctx.f
        lo, hi = p["thmin"], p["thmax"]
        f[..., sl[0]] = held(self.PIcb.deriv(xc, e), xc, lo, hi, xp)
        f[..., sl[1]] = held(self.PIwb.deriv(xw, uw), xw, lo, hi, xp)
        f[..., sl[2]] = held(self.LGb.deriv(th, yc + yw), th, lo, hi, xp)
        o = ctx.out
        o["WTPTA1.theta"], o["WTPTA1.wref"] = th + 0.0, wref + 0.0
        o["WTPTA1.PIc_y"], o["WTPTA1.PIw_y"] = yc, yw
