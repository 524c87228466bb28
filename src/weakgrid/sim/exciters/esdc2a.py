"""ESDC2A: IEEE 421.5-2005 type DC2A exciter (PSS/E ESDC2A).

The DC1A diagram (:mod:`weakgrid.sim.exciters.esdc1a`, whose class this one extends) with
the regulator limits scaled by the terminal voltage (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vsen = LG if TR_used else v                          (sensed voltage; TR_used = 0: ANDES 2.0)
    vi = vref - vsen - WF + vs                           (vs: PSS output)
    vi --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL --[Lag KA/(1+sTA), non-windup VRMIN*Vt..VRMAX*Vt]--> VR   (ceiling scales with Vt)
    TE dEfd/dt = VR - (KE*Efd + Efd*SE(Efd))             (DC exciter, quadratic saturation)
    Efd --[Washout s*KF/(1+sTF1)]--> WF                  (rate feedback)

``VRMAX = 0`` means no upper limit. No under-excitation limiter (its HV gate is
absent, as in ANDES); ``Switch`` is accepted and unused (as in PSS/E).

Difference from ANDES 2.0 (documented, not copied): ANDES feeds the unfiltered
bus voltage to the summing junction (its ``TR`` lag is computed but unused);
here the sensed voltage passes through ``TR`` as in the standard. They agree
for ``TR = 0``. The flag ``TR_used = 0`` reproduces ANDES (the lag state stays, its
output unused); the ANDES importer sets it with ``from_andes(..., conventions="andes")``.
Effect on ANDES's ``kundur_esdc2a`` (census fault): 9.5e-5 pu of speed with the
standard, 1.4e-5 pu with ``TR_used = 0``. ANDES's ceiling ``VRMAX*Vt`` does follow ``Vt``
(a ``VarService`` re-evaluated at every Newton iteration; in that case its regulators sit
on ``7.3*Vt`` during the fault), as here.
"""

from __future__ import annotations

from ..params import Param
from .esdc1a import ESDC1A


class ESDC2A(ESDC1A):
    """IEEE DC2A exciter. Times [s]: TR, TA, TB, TC, TE, TF1; gains [pu]: KA, KE, KF;
    VRMAX, VRMIN [pu, times Vt]; E1, SE1, E2, SE2 (saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = tuple(
        Param("VRMAX", 7.3, "pu", "maximum regulator output at Vt = 1 (0: unlimited)", "") if p.name == "VRMAX"
        else Param("VRMIN", -7.3, "pu", "minimum regulator output at Vt = 1", "") if p.name == "VRMIN"
        else p for p in ESDC1A.params)
    limit_fields = {"VR": ("VRMIN*Vt", "VRMAX*Vt")}

    def limits(self):
        v0 = self._vt0
        return [(self.idx("VR"), self.p["VRMIN"] * v0, self._vrmax * v0)]

    def limit_values(self, ctx):
        """Current regulator limits ``(VRMIN*Vt, VRMAX*Vt)``."""
        v = ctx.sig["Ecomp"][self.mach]
        return self.p["VRMIN"] * v, self._vrmax * v
