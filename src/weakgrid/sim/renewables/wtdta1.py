"""WTDTA1: WECC generic wind-turbine drive train, two-mass shaft (PSS/E WTDTA1, PSLF WTGT_A).

The turbine and the generator are two inertias coupled by a shaft (system per unit; times in
s; speeds in pu of the synchronous speed)::

    Ht2 = 2 H Htfrac,   Hg2 = 2 H (1 - Htfrac),   Kshaft = Ht2 Hg2 Freq1^2 / (2 H)
    Ht2 dwt/dt = Pm/wt - Tsh - Pd                          (turbine speed wt)
    Hg2 dwg/dt = -Pe/wg + Tsh + Pd - DAMP (wg - w0)        (generator speed wg)
    dTsh/dt    = Kshaft (wt - wg)                          (shaft torque Tsh)
    Pd         = Dshaft (wt - wg)                          (shaft damping)

``Pm`` is the aerodynamic power of :class:`~.wtara1.WTARA1` (constant ``Pe0`` without one),
``Pe`` the converter's active power (:class:`~.regca1.REGCA1`). The generator speed ``wg``
goes to the electrical control (:class:`~.reeca1.REECA1`, used with ``PFLAG = 1``) and to the
torque control (:class:`~.wttqa1.WTTQA1`). ``H``, ``DAMP`` and ``Dshaft`` are on the
converter's rating ``Sn`` (converted by ``Sn/Sb``).

Initialization: both speeds at ``w0`` (or, with a torque controller, at its speed reference
``fPe(Pe0)``, which it sets), ``Tsh = Pe0/wg0``, ``Pm0 = Pe0``.

``Freq1`` is read as ANDES reads it: ``Kshaft`` above makes the undamped torsional mode
``Freq1`` rad/s. PSS/E's documentation gives ``Freq1`` in Hz, which would multiply ``Kshaft``
by ``(2 pi)^2``; its exported data use per unit (ANDES's note). ``Htfrac = 0`` is a single mass
(the turbine's inertia is then 0: not supported here, give ``Htfrac > 0``).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Integrator
from ..component import Component
from ..errors import DataError
from ..namespace import take
from ..params import Param
from ._wind import andes_link, chain_pattern, publish, resolve


class WTDTA1(Component):
    """Two-mass drive train of a type-3 wind turbine (WECC); linked to one REECA1 (``ree``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 1.1          # before WTTQA1 and REECA1 (which read wg)
    params = (
        Param("H", 3.0, "MWs/MVA (Sn)", "total inertia constant", "pos", "power"),
        Param("DAMP", 0.0, "pu (Sn)", "generator damping coefficient", "", "power"),
        Param("Htfrac", 0.5, "-", "turbine inertia fraction Hturb/H (0 < Htfrac < 1)", "pos"),
        Param("Freq1", 1.0, "pu", "first shaft torsional resonant frequency (rad/s, as ANDES)", "pos"),
        Param("Dshaft", 1.0, "pu (Sn)", "shaft damping coefficient", "", "power"),
        Param("w0", 1.0, "pu", "initial speed without a torque controller", "pos"),
    )
    states = ("wt", "wg", "Tsh")
    outputs = ("Pm", "Pd", "Pe")

    @classmethod
    def andes_link(cls, m, k, dev_name, **_):
        """Link of ANDES device ``k``: the weakgrid name of its REECA1 (``ree``)."""
        return andes_link(m, k, dev_name, "ree", "REECA1", " (the only electrical control supported for WTDTA1)")

    def add_wtdta1(self, name, ree, **params):
        """Add one drive train linked to the REECA1 named ``ree``."""
        self.add(name, {"ree": ree}, params)
        return name

    def setup(self, system):
        super().setup(system)
        for i in np.nonzero(self.p["Htfrac"] >= 1)[0]:
            raise DataError(self.element(int(i)), "Htfrac", self.p["Htfrac"][i],
                            "give 0 < Htfrac < 1 (both masses need inertia)")
        self.ree = None
        self.aero = None     # (WTARA1 component, its index per instance or -1), set by WTARA1.init

    def init(self, system, x, sig):
        p = self.p
        self.ree_comp, self.ree = resolve(self, system, "ree", "REECA1")
        rc = self.ree_comp.regc
        self.reg = self.ree_comp.reg[self.ree]
        self.Sn = rc.p["Sn"][self.reg]
        c = self.Sn / system.Sb
        for prm in self.params:
            if prm.base == "power":
                p[prm.name] = p[prm.name] * c
        self.Ht2 = 2 * p["H"] * p["Htfrac"]
        self.Hg2 = 2 * p["H"] * (1 - p["Htfrac"])
        self.Kshaft = self.Ht2 * self.Hg2 * 0.5 * p["Freq1"] ** 2 / p["H"]
        self.Pe0 = rc.p0[self.reg]
        self.Pm0 = self.Pe0.copy()
        self.set_speed(x, p["w0"])
        pflag = self.ree_comp.p["PFLAG"][self.ree] > 0
        for i in np.nonzero(pflag & (p["w0"] != 1))[0]:
            raise DataError(self.element(int(i)), "w0", p["w0"][i],
                            "with PFLAG = 1 its REECA1 multiplies the power reference by the generator "
                            "speed, which must then start at 1; set w0 = 1 or PFLAG = 0")
        self.wtb = Integrator(1.0 / self.Ht2)
        self.wgb = Integrator(1.0 / self.Hg2)
        self.Tshb = Integrator(self.Kshaft)

    def set_speed(self, x, w, rows=None):
        """Initial speeds ``w`` (both masses) and shaft torque ``Pe0/w`` of instances ``rows``."""
        rows = np.arange(self.n) if rows is None else rows
        if not hasattr(self, "w_init"):
            self.w_init = np.zeros(self.n)
        self.w_init[rows] = w
        for k, v in ((0, w), (1, w), (2, self.Pe0[rows] / w)):
            s = self.sl(k)
            x[s.start + rows] = v
        bad = (self.p["DAMP"] != 0) & (np.abs(self.w_init - self.p["w0"]) > 1e-12)
        for i in np.nonzero(bad)[0]:
            raise DataError(self.element(int(i)), "DAMP", self.p["DAMP"][i],
                            f"the initial generator speed {self.w_init[i]:.4g} pu differs from w0 = "
                            f"{self.p['w0'][i]:g}: the damping DAMP (wg - w0) would not start at rest; "
                            "set DAMP = 0 or w0 to the initial speed")

    def pattern(self, system):
        return [chain_pattern(system, self.ree_comp, int(self.ree[i]), self.instance_states(i)) for i in range(self.n)]

    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        wt, wg, tsh = x[..., sl[0]], x[..., sl[1]], x[..., sl[2]]
        pe = take(xp, ctx.sig["REGCA1.Pe"], self.reg)
        pm = self.Pm0
        if self.aero is not None:
            ac, k = self.aero
            pm = xp.where(k >= 0, take(xp, ac.pm(x), xp.maximum(k, 0)), pm)
        pd = p["Dshaft"] * (wt - wg)
        f = ctx.f
        f[..., sl[0]] = self.wtb.deriv(wt, pm / wt - tsh - pd)
        f[..., sl[1]] = self.wgb.deriv(wg, -pe / wg + tsh + pd - p["DAMP"] * (wg - p["w0"]))
        f[..., sl[2]] = self.Tshb.deriv(tsh, wt - wg)
        publish(ctx, "REECA1.wg", self.ree_comp.n, self.ree, wg, 1.0, xp)
        o = ctx.out
        o["WTDTA1.Pm"] = xp.broadcast_to(pm, wt.shape) + 0.0
        o["WTDTA1.Pd"], o["WTDTA1.Pe"] = pd, pe + 0.0
