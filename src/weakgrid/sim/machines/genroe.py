"""GENROE: round-rotor machine with exponential saturation (PSS/E GENROE).

GENROU's windings, equations and initialization (:mod:`~weakgrid.sim.machines.genrou`:
saturation of the air-gap flux magnitude ``psi2 = |psi''|``, ``Se(psi2)*psi2d`` on the
d axis and ``Se(psi2)*(xq-xl)/(xd-xl)*psi2q`` on the q axis) with PSS/E's exponential
curve ``Se(x) = B*x^A`` through ``(1.0, S10)`` and ``(1.2, S12)``
(:func:`weakgrid.sim.blocks.exp_saturation_coeffs`: ``B = S10``,
``A = ln(S12/S10)/ln 1.2``; ``S10 = 0`` disables it).

Shaft: PSS/E's by default (``psse_shaft = 1``, :mod:`~weakgrid.sim.machines.shaft`);
GENROU's default is ANDES's (``psse_shaft = 0``).

Data checks: GENROU's, and ``S12 >= S10`` when ``S10 > 0`` (an exponential through
both points that grows with flux; ``S12 = 0`` has none).
"""

from __future__ import annotations

from ..blocks import exp_saturation, exp_saturation_coeffs
from ..errors import DataError
from .base import with_default
from .genrou import GENROU


class GENROE(GENROU):
    """Round-rotor synchronous machine with exponential saturation (PSS/E GENROE).

    Notes
    -----
    Parameters and states as :class:`~weakgrid.sim.machines.genrou.GENROU`.
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = with_default(GENROU.params, "psse_shaft", 1.0)

    #: PSS/E .dyr record (Program Application Guide, as GENROU): T'do, T''do, T'qo, T''qo,
    #: H, D, Xd, Xq, X'd, X'q, X''d, Xl, S(1.0), S(1.2)
    psse_record = ("Td10", "Td20", "Tq10", "Tq20", "H", "D", "xd", "xq", "xd1", "xq1", "xd2",
                   "xl", "S10", "S12")

    def setup(self, system):
        p0 = {k: [v[k] for v in self._values] for k in ("S10", "S12")}
        for i, (s10, s12) in enumerate(zip(p0["S10"], p0["S12"])):
            if s10 > 0 and not s12 >= s10:
                raise DataError(self.element(i), "S12", s12,
                                f"GENROE needs S(1.2) >= S(1.0) = {s10:g} (an exponential saturation "
                                "curve growing with flux); S10 = 0 disables saturation")
        super().setup(system)

    @staticmethod
    def _sat_coeffs(S10, S12):
        return exp_saturation_coeffs(1.0, S10, 1.2, S12)

    #: GENROU's core with the exponential curve (it runs on NumPy: weakgrid.sim.kernels)
    _curve = staticmethod(exp_saturation)
