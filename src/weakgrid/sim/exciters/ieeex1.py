"""IEEEX1: IEEE type 1 DC exciter with voltage-dependent regulator ceiling (PSS/E IEEEX1).

Same block diagram and parameters as :class:`~weakgrid.sim.exciters.exdc2.EXDC2`
(sensing lag TR, lead-lag TC/TB, regulator KA/(1+sTA), DC exciter KE/TE with
quadratic saturation, rate feedback sKF1/(1+sTF1)), except that

* the regulator limits scale with the terminal voltage: ``VRMIN*Vt <= VR <= VRMAX*Vt``
  (non-windup, the limits move with ``Vt``), and
* the field voltage is the exciter voltage itself, ``Efd = vp`` (no speed factor).

Difference from ANDES 2.0 (documented, not copied): there the ceiling keeps its
initial value ``VRMAX*Vt0`` (it does not follow ``Vt`` during a fault); here it
follows ``Vt`` as in the standard. They agree while the limits are not reached.
"""

from __future__ import annotations

from .exdc2 import EXDC2


class IEEEX1(EXDC2):
    """IEEE type 1 DC exciter; parameters as EXDC2 (VRMAX, VRMIN are multiplied by Vt)."""

    speed_times_vp = False

    def limits(self):
        v0 = self._vt0
        return [(self.idx("VR"), self.p["VRMIN"] * v0, self.p["VRMAX"] * v0)]

    def limit_values(self, ctx):
        """Current regulator limits ``(VRMIN*Vt, VRMAX*Vt)`` (one entry per instance)."""
        v = ctx.sig["Vt"][self.mach]
        return self.p["VRMIN"] * v, self.p["VRMAX"] * v

    def init(self, system, x, sig):
        super().init(system, x, sig)
        self._vt0 = sig["Vt0"][self.mach].copy()
