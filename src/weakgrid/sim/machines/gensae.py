"""GENSAE: salient-pole machine with exponential saturation (PSS/E GENSAE).

GENSAL's windings and equations (:mod:`~weakgrid.sim.machines.gensal`) with PSS/E's
exponential saturation curve ``Se(x) = B*x^A`` through ``(1.0, S10)`` and ``(1.2, S12)``
(:func:`weakgrid.sim.blocks.exp_saturation_coeffs`; ``S10 = 0`` disables it).
"""

from __future__ import annotations

from ..blocks import exp_saturation, exp_saturation_coeffs
from .gensal import GENSAL


class GENSAE(GENSAL):
    """Salient-pole synchronous machine with exponential saturation (PSS/E GENSAE).

    Notes
    -----
    Parameters, states and PSS/E record as :class:`~weakgrid.sim.machines.gensal.GENSAL`.
    """

    saturation = "exponential"
    q_saturation = True

    @staticmethod
    def _sat_coeffs(S10, S12):
        return exp_saturation_coeffs(1.0, S10, 1.2, S12)

    def _sat(self, x):
        return exp_saturation(x, self.SA, self.SB)
