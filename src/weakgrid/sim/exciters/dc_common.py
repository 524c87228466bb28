"""Pieces shared by the IEEE DC-type exciters (IEEET1, ESDC2A): the DC exciter with saturation."""

from __future__ import annotations

import numpy as np

from ..blocks import Block, quad_saturation, quad_saturation_coeffs
from ..params import Param

SATURATION_PARAMS = (
    Param("E1", 0.0, "pu", "first saturation point", "nonneg"),
    Param("SE1", 0.0, "pu", "saturation at E1", "nonneg"),
    Param("E2", 1.0, "pu", "second saturation point", "nonneg"),
    Param("SE2", 1.0, "pu", "saturation at E2", "nonneg"),
)


class DCExciter(Block):
    r"""DC exciter :math:`T_E \dot E_{fd} = V_R - V_{FE}`, :math:`V_{FE} = K_E E_{fd} + E_{fd} S_E(E_{fd})`.

    The saturation product :math:`E_{fd} S_E(E_{fd}) = B (E_{fd} - A)^2` for :math:`E_{fd} \ge A`
    (quadratic curve through ``(E1, SE1)``, ``(E2, SE2)``; ``SE1 = 0`` or ``SE2 = 0`` disables it).
    A block (:class:`~weakgrid.sim.blocks.Block`): its arrays and namespace follow the grid's.
    """

    def __init__(self, KE, TE, E1, SE1, E2, SE2):
        self.KE = np.asarray(KE, float)
        self.TE = np.asarray(TE, float)
        self.A, self.B = quad_saturation_coeffs(E1, SE1, E2, SE2)

    def vfe(self, efd):
        """Exciter feedback ``KE*Efd + Efd*SE(Efd)`` [pu]."""
        return self.KE * efd + quad_saturation(efd, self.A, self.B, self.xp)

    def deriv(self, efd, vr):
        return (vr - self.vfe(efd)) / self.TE

    def vr0(self, efd0):
        """Regulator output that holds ``Efd = efd0`` in steady state."""
        return self.KE * efd0 + np.where(efd0 > self.A, self.B * (self.A - efd0) ** 2, 0.0)


def vrmax_or_unlimited(VRMAX):
    """``VRMAX = 0`` means "no upper regulator limit" (PSS/E/ANDES convention): +999."""
    VRMAX = np.asarray(VRMAX, float)
    return np.where(VRMAX == 0, 999.0, VRMAX)
