"""IEEEX1: IEEE type 1 DC exciter with voltage-dependent regulator ceiling (PSS/E IEEEX1).

Same block diagram and parameters as :class:`~weakgrid.sim.exciters.exdc2.EXDC2`
(sensing lag TR, lead-lag TC/TB, regulator KA/(1+sTA), DC exciter KE/TE with
quadratic saturation, rate feedback sKF1/(1+sTF1)), except that

* the regulator limits scale with the terminal voltage (non-windup, the limits move
  with ``Vt``)::

      VR_Vt = 1:  VRMIN*Vt <= VR <= VRMAX*Vt      (IEEE / PSS/E)
      VR_Vt = 0:  VRMIN    <= VR <= VRMAX         (ANDES 2.0)

* the field voltage is the exciter voltage itself, ``Efd = vp`` (no speed factor).

Difference from ANDES 2.0 (documented, not copied): ANDES's IEEEX1 defines the
ceiling ``VRMAX*Vt`` but its anti-windup limiter keeps the bounds ``VRMAX``, ``VRMIN``
it was built with (the product is assigned to the block after its limiter exists), so
the regulator is held at the constant ``VRMAX`` (measured: on ``ieee39_full`` faulted
at bus 16, ANDES's regulators stop at exactly 5.0, 6.5 and 9.9 = ``VRMAX`` while
``VRMAX*Vt`` is 2.9-5.9). ``VR_Vt = 0`` reproduces that; the ANDES importer sets it
with ``from_andes(..., conventions="andes")``. They agree while the limits are not
reached.
"""

from __future__ import annotations

import numpy as np

from ..params import Param
from .exdc2 import EXDC2


class IEEEX1(EXDC2):
    """IEEE type 1 DC exciter; parameters as EXDC2 (VRMAX, VRMIN are multiplied by Vt
    unless ``VR_Vt = 0``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = EXDC2.params + (
        Param("VR_Vt", 1.0, "-", "1: regulator limits VRMAX*Vt, VRMIN*Vt (IEEE); "
              "0: constant VRMAX, VRMIN (ANDES 2.0)", "flag"),
    )
    speed_times_vp = False

    def _scale(self, v):
        """Factor of the regulator limits: ``Vt`` (standard) or 1 (``VR_Vt = 0``)."""
        return np.where(self.p["VR_Vt"] > 0, v, 1.0)

    def limits(self):
        k = self._scale(self._vt0)
        return [(self.idx("VR"), self.p["VRMIN"] * k, self.p["VRMAX"] * k)]

    def limit_values(self, ctx):
        """Current regulator limits ``(VRMIN*Vt, VRMAX*Vt)`` (one entry per instance)."""
        k = self._scale(ctx.sig["Ecomp"][self.mach])
        return self.p["VRMIN"] * k, self.p["VRMAX"] * k

    def init(self, system, x, sig):
        super().init(system, x, sig)
        self._vt0 = sig["Ecomp0"][self.mach].copy()
