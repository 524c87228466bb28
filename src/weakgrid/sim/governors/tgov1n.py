"""TGOV1N: TGOV1 with the reference and auxiliary inputs added after the droop (ANDES TGOV1N).

Block diagram as :class:`~weakgrid.sim.governors.tgov1.TGOV1` except the valve demand::

    pd = pref0 + paux - wd/R

so that a power set-point or AGC signal ``paux`` [pu] is not multiplied by ``1/R``.
With ``paux = 0`` it behaves exactly as TGOV1.
"""

from __future__ import annotations

from .tgov1 import TGOV1


class TGOV1N(TGOV1):
    """TGOV1 with ``pref``/``paux`` summed after the droop gain; parameters as TGOV1."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    psse_record = None   # an ANDES variant: PSS/E has no TGOV1N

    def _pd(self, wd):
        return self.pref0 + self.paux - wd / self.p["R"]
