"""WTARA1: WECC generic wind-turbine aerodynamics (PSS/E WTARA1, PSLF WTGA_A).

The mechanical power falls quadratically with the pitch angle (no wind-speed detail)::

    Pm = Pm0 - Ka theta (theta - theta0)                  [pu, system base]

``theta`` [deg] is the pitch angle of :class:`~.wtpta1.WTPTA1` (held at ``theta0`` without a
pitch controller), ``Pm0`` the initial power of the drive train (:class:`~.wtdta1.WTDTA1`,
``= Pe0``), to which ``Pm`` goes. ``Ka`` [pu/deg^2] is on the converter's rating ``Sn``
(converted by ``Sn/Sb``); ANDES reads it on the system base, and its importer converts.
"""

from __future__ import annotations

import numpy as np

from ..component import Component
from ..errors import DataError
from ..namespace import take
from ..params import Param
from ._wind import andes_link, resolve


class WTARA1(Component):
    """Aerodynamics of a type-3 wind turbine (WECC); linked to one WTDTA1 (``rego``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 1.2          # after WTDTA1 (initialized first); WTDTA1 reads Pm from pm()
    params = (
        Param("Ka", 1.0, "pu/deg^2 (Sn)", "aerodynamic gain", "nonneg", "power"),
        Param("theta0", 0.0, "deg", "initial pitch angle"),
    )
    states = ()
    outputs = ("Pm", "theta")

    @classmethod
    def andes_link(cls, m, k, dev_name, **_):
        """Link of ANDES device ``k``: the weakgrid name of its drive train (``rego``)."""
        return andes_link(m, k, dev_name, "rego", "WTDTA1", " (the only drive train supported)")

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """``Ka`` from ANDES's system base to the converter's base; refuse ``theta0 != 0`` with a
        pitch controller (ANDES then adds ``rad(theta0) - theta0`` to the pitch angle)."""
        dt = ss.WTDTA1
        kd = list(dt.idx.v).index(m.rego.v[k])
        ree = dt.ree.v[kd]
        reg = ss.REECA1.reg.v[list(ss.REECA1.idx.v).index(ree)]
        Sn = float(ss.REGCA1.Sn.v[list(ss.REGCA1.idx.v).index(reg)])
        values["Ka"] = values["Ka"] * ss.config.mva / Sn
        pitched = "WTPTA1" in ss.models and m.idx.v[k] in list(ss.WTPTA1.rea.v)
        if pitched and values.get("theta0", 0.0) != 0:
            raise DataError(f"ANDES WTARA1 {m.idx.v[k]}", "theta0", values["theta0"],
                            "with a pitch controller ANDES 2.0 mixes radians and degrees in the pitch "
                            "angle (theta = rad(theta0) - theta0 + LG); give theta0 = 0")
        return values

    def add_wtara1(self, name, rego, **params):
        """Add the aerodynamics of the drive train named ``rego``."""
        self.add(name, {"rego": rego}, params)
        return name

    def setup(self, system):
        super().setup(system)
        self.pitch = None      # (WTPTA1 component, its index per instance or -1), set by WTPTA1.init

    def init(self, system, x, sig):
        self.dt, self.rego = resolve(self, system, "rego", "WTDTA1")
        c = self.dt.Sn[self.rego] / system.Sb
        self.p["Ka"] = self.p["Ka"] * c
        self.ree_comp, self.ree = self.dt.ree_comp, self.dt.ree[self.rego]
        k = np.full(self.dt.n, -1)
        k[self.rego] = np.arange(self.n)
        self.dt.aero = (self, k)

    def theta(self, x):
        """Pitch angle [deg]: the pitch controller's output, or ``theta0``."""
        xp, th0 = self.xp, self.p["theta0"]
        if self.pitch is None:
            return xp.broadcast_to(th0, tuple(x.shape[:-1]) + (self.n,))
        pc, k = self.pitch
        th = pc.theta(x)
        return xp.where(k >= 0, take(xp, th, xp.maximum(k, 0)), th0)

    def pm(self, x):
        """Mechanical power [pu, system base] of each instance."""
        th = self.theta(x)
        return take(self.xp, self.dt.Pm0, self.rego) - self.p["Ka"] * th * (th - self.p["theta0"])

    def compute(self, ctx):
        th = self.theta(ctx.x)
        ctx.out["WTARA1.Pm"], ctx.out["WTARA1.theta"] = self.pm(ctx.x), th + 0.0
