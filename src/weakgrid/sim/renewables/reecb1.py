"""REECB1: WECC generic renewable electrical control model B (PSS/E REECB1, PSLF REEC_B).

REECA1 without its voltage-dependent current limits (VDL1, VDL2), its post-dip state machine
(Thld, Thld2, Iqfrz), the speed dependency (PFLAG) and the voltage reference ``Vref1``
(see :mod:`.reeca1` for the block diagram). What changes, as in ANDES 2.0:

* ``Iqinj = clip(Kqv * deadband(Vref0 - s0; dbd1, dbd2), Iql1, Iqh1)`` at all times (the dead
  band keeps it at 0 in normal operation), not only in a dip;
* current limits from ``Imax`` alone: P priority ``Ipmax = Imax``, ``Iqmax = sqrt(Imax^2 -
  Ipcmd^2)``; Q priority ``Iqmax = Imax``, ``Ipmax = sqrt(Imax^2 - Iqcmd^2)``;
* ``Vsel = clip(PIQ, VMIN, VMAX)`` with VFLAG = 1, 0 with VFLAG = 0; the voltage PI's input is
  ``Vsel`` (QFLAG = 1); the initial Q reference is ``q0``.

The voltage-dip freeze of ``s4``, ``s5`` and the PI controllers is REECA1's: in a dip the PI
outputs are held at their value at the last accepted point before it. ANDES 2.0 holds them at
their value in the Newton iterate at which its dip flag switched, which after a network event
is neither: on ANDES's ``ieee14_reecb1`` (census fault) its held ``PIV_y`` is 0.110 pu in the
fault and 0.089 pu from the clearing to the end of the dip, against 0.072 pu before it. That
value depends on ANDES's Newton path, so no model flag reproduces it; it alone makes the
2.1e-5 pu gap on that case (4.5e-6 pu with ANDES's held values imposed,
:mod:`weakgrid.sim.peer.andes_dip_hold`, ``tests/sim/test_reecb1_peer.py``).
"""

from __future__ import annotations

import numpy as np

from ..component import Component
from .reeca1 import REECA1

_ONLY_A = {"PFLAG", "Vref1", "Iqfrz", "Thld", "Thld2", "vdl_np"} | {
    f"{a}{k}" for a in ("Vq", "Iq", "Vp", "Ip") for k in (1, 2, 3, 4)}


class REECB1(REECA1):
    """Renewable energy electrical control model B (WECC); drives one REGCA1."""

    params = tuple(p for p in REECA1.params if p.name not in _ONLY_A)

    def setup(self, system):
        Component.setup(self, system)
        for prm in REECA1.params:        # the parts of REECA1 that B lacks: switched off
            if prm.name in _ONLY_A:
                self.p[prm.name] = np.full(self.n, 0.0 if prm.name != "Vref1" else 1.0)
        self._setup_links(system)

    def _vdl(self, s0):
        shape = np.shape(s0)
        return np.broadcast_to(self.Imaxr, shape), np.broadcast_to(self.Imaxr, shape)

    def _qref0(self, v, vp):
        return self.q0.copy()

    def _vsel(self, piq, pfsel):
        p = self.p
        return np.clip(np.where(p["VFLAG"] > 0, piq, 0.0), p["VMIN"], p["VMAX"])

    def _piv_input(self, vsel, s0y):
        return np.where(self.p["QFLAG"] > 0, vsel, 0.0)

    def _iqinj(self, iqv, dip, t):
        return np.clip(iqv, self.p["Iql1"], self.p["Iqh1"])
