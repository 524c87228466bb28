"""IEEEVC: voltage compensator (load compensation) of an exciter's input.

The exciter regulates the magnitude of a voltage behind the compensating impedance
``rc + j xc`` instead of the terminal voltage itself (IEEE 421.5, the compensator
``|Vt + (RC + j XC) It|``; PSS/E IEEEVC)::

    Ecomp = | Vt + (rc + j xc) * It |

``Vt``, ``It`` are the machine's terminal voltage and stator current phasors (generator
convention: the current leaves the machine). ``xc < 0`` regulates a point inside the step-up
transformer (line-drop compensation), ``xc > 0`` shares reactive power between machines on one
bus (reactive droop). ``Ecomp`` replaces ``Vt`` wherever the machine's exciter reads its input
voltage (its sensing, and a ceiling proportional to ``Vt``); the PSS and everything else keep
the uncompensated ``Vt``.

Per-unit bases: ``rc``, ``xc`` on the machine base (``Sn``, ``Vn``) as PSS/E. ANDES 2.0 declares
them as impedances but its IEEEVC has no ``Sn``, so they stay on the system base; ``on_Sb = 1``
reproduces that (the ANDES importer sets it with ``conventions="andes"``). The two coincide for
machines rated at the system base.
"""

from __future__ import annotations

import numpy as np

from ..control_base import MachineControl
from ..namespace import NUMPY, put, take
from ..params import Param


class IEEEVC(MachineControl):
    """Voltage compensator. Parameters: rc, xc [pu, machine base; system base if ``on_Sb``]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "compensator"
    order = 1.5          # after the machines (reads Vt, Pe, Qe), before the exciters (read Ecomp)
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("rc", "xc")
    params = (
        Param("rc", 0.0, "pu (machine base)", "active (resistive) compensation", ""),
        Param("xc", 0.0, "pu (machine base)", "reactive compensation", ""),
        Param("on_Sb", 0.0, "-", "1: rc, xc on the system base (ANDES 2.0); 0: machine base", "flag"),
    )
    outputs = ("Ecomp",)

    def setup(self, system):
        super().setup(system)
        Vb = system.network.base_kv[self.bus]
        Vn = np.zeros(self.n)
        for i, m in enumerate(self.mach):
            mtype, mname = system._machines[m]
            mc = system.components[mtype]
            Vn[i] = mc.p["Vn"][mc.names.index(mname)]
        Vn = np.where(Vn > 0, Vn, Vb)               # Vn = 0: the bus base
        to_sys = (Vn ** 2 / self.Sn) / (Vb ** 2 / system.Sb)
        k = np.where(self.p["on_Sb"] > 0, 1.0, to_sys)
        self.Zc = (self.p["rc"] + 1j * self.p["xc"]) * k      # system base

    def _ecomp(self, Vt, theta, Pe, Qe, xp=NUMPY):
        V = Vt * xp.exp(1j * theta)
        It = xp.conj((Pe + 1j * Qe) / V)           # stator current, system base
        return xp.abs(V + self.Zc * It)

    def init(self, system, x, sig):
        m = self.mach
        e = self._ecomp(sig["Vt0"][m], sig["theta0"][m], sig["Pe0"][m], sig["Qe0"][m])
        sig["Ecomp"][m] = sig["Ecomp0"][m] = e

    def compute(self, ctx):
        xp, s = self.xp, ctx.sig
        m = self._mi
        e = self._ecomp(take(xp, s["Vt"], m), take(xp, s["theta"], m), take(xp, s["Pe"], m),
                        take(xp, s["Qe"], m), xp)
        put(xp, s["Ecomp"], m, e)
        ctx.out["IEEEVC.Ecomp"] = e
