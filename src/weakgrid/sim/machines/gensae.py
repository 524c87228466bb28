"""GENSAE: salient-pole machine with exponential saturation on both axes (PSS/E GENSAE).

GENSAL's windings (:mod:`~weakgrid.sim.machines.gensal`), with PSS/E's GENSAE saturation:
the exponential curve ``Se(x) = B*x^A`` through ``(1.0, S10)`` and ``(1.2, S12)``
(:func:`weakgrid.sim.blocks.exp_saturation_coeffs`; ``S10 = 0`` disables it), of the
sub-transient flux magnitude ``psi2 = |psi2d + j psi2q|`` and on both axes::

    XadIfd = e1q + (xd-xd1)*(gd1*Id + gd2*(e1q - e2d)) + Se(psi2)*psi2d
    Tq20 dpsi2q/dt = -psi2q + (xq-xq2)*Iq - Se(psi2)*(xq-xl)/(xd-xl)*psi2q

(GENSAL: ``Se(e1q)*e1q`` on the d axis only). The q-axis term moves the rotor angle of the
operating point: on PSID's PSS/E benchmark PSS/E gives 33.4912 deg for GENSAE where the same
data in GENSAL give 35.4891 deg; weakgrid's GENSAE starts at PSS/E's 33.4912 deg.
The initialization solves ``psi2q*(1 + Se*(xq-xl)/(xd-xl)) = (xq-xq2)*Iq`` with ``Se`` of
``|V + (ra + j xd2) It|`` (:func:`~weakgrid.sim.machines.base.saturated_rotor_angle`).
"""

from __future__ import annotations

from ..blocks import exp_saturation, exp_saturation_coeffs
from ..namespace import on_arrays_of
from .gensal import GENSAL


class GENSAE(GENSAL):
    """Salient-pole synchronous machine with exponential saturation on both axes (PSS/E GENSAE).

    Notes
    -----
    Parameters, states, shaft and PSS/E record as :class:`~weakgrid.sim.machines.gensal.GENSAL`.
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    saturation = "exponential"
    q_saturation = True

    @staticmethod
    def _sat_coeffs(S10, S12):
        return exp_saturation_coeffs(1.0, S10, 1.2, S12)

    def _sat(self, x):
        return on_arrays_of(exp_saturation, self.xp)(x, self.SA, self.SB)
