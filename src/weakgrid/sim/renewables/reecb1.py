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

PSS/E's REECB1 (``wecc = 1``, set by the PSS/E reader): the current commands are the orders
divided by the *filtered* voltage ``s0`` (``Ipcmd = Pord/s0``, ``Iqcmd = Q/s0`` with QFLAG = 0),
not by the terminal voltage ``v`` as in ANDES 2.0; the voltage PI regulates the terminal
voltage, its input is ``Vsel - s0`` (QFLAG = 1), with ``Vsel`` the Q PI's output (VFLAG = 1;
limited to ``[VMIN, VMAX]``: a voltage reference, e.g. 0.9..1.05 pu in PSID's RENA and the WECC
240-bus data; the Q PI starts at ``v0``) or the Q reference itself (VFLAG = 0: REPCA1 then sends
a voltage reference; it starts at ``v0``). This is the structure PSID implements and matches to
PSS/E's own results on its RENA cases. ANDES 2.0's ``Vsel`` without ``- s0`` cannot start in
steady state with such ``VMIN > 0`` data (the V PI integrates ``Vsel >= VMIN``).

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
from ..params import Param
from .reeca1 import REECA1

_ONLY_A = {"PFLAG", "Vref1", "Iqfrz", "Thld", "Thld2", "vdl_np"} | {
    f"{a}{k}" for a in ("Vq", "Iq", "Vp", "Ip") for k in (1, 2, 3, 4)}


class REECB1(REECA1):
    """Renewable energy electrical control model B (WECC); drives one REGCA1."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = tuple(p for p in REECA1.params if p.name not in _ONLY_A) + (
        Param("wecc", 0.0, "-", "1 PSS/E's REECB1 (the V PI regulates Vsel - s0; Vsel = PIQ, or the Q "
              "reference with VFLAG = 0; currents = orders / s0), 0 ANDES 2.0 (V PI input Vsel = clip(PIQ "
              "or 0); currents = orders / v)", "flag"),)

    #: PSS/E .dyr record after ``IBUS 'REECB1' ID`` (PSS/E Model Library, REECB1; PSID's RENA and
    #: the WECC 240-bus files): ICONs BUSR (0 = local), PFFLAG, VFLAG, QFLAG, PQFLAG — no PFLAG —
    #: and 25 CONs. :meth:`REECA1.psse_params` / :meth:`REECA1.psse_link` apply.
    psse_record = ("_BUSR", "PFFLAG", "VFLAG", "QFLAG", "PQFLAG",
                   "Vdip", "Vup", "Trv", "dbd1", "dbd2", "Kqv", "Iqh1", "Iql1", "Vref0", "Tp", "QMax",
                   "QMin", "VMAX", "VMIN", "Kqp", "Kqi", "Kvp", "Kvi", "Tiq", "dPmax", "dPmin", "PMAX",
                   "PMIN", "Imax", "Tpord")

    def setup(self, system):
        Component.setup(self, system)
        for prm in REECA1.params:        # the parts of REECA1 that B lacks: switched off
            if prm.name in _ONLY_A:
                self.p[prm.name] = np.full(self.n, 0.0 if prm.name != "Vref1" else 1.0)
        self._setup_links(system)

    def _vdl(self, s0):
        xp, shape = self.xp, tuple(s0.shape)
        return xp.broadcast_to(self.Imaxr, shape), xp.broadcast_to(self.Imaxr, shape)

    @classmethod
    def psse_params(cls, values, ctx):
        """As :meth:`REECA1.psse_params`, with PSS/E's reactive path (``wecc = 1``)."""
        v = super().psse_params(values, ctx)
        v["wecc"] = 1.0
        return v

    def _std(self):
        return self.p["wecc"] > 0

    def _vdiv(self, v, s0y):
        # PSS/E: Ipcmd = Pord / Vt_filt, Iqcmd = Q / Vt_filt (the Trv-filtered voltage s0)
        xp = self.xp
        return xp.where(self._std(), xp.maximum(s0y, 0.01), super()._vdiv(v, s0y))

    def _piq0(self, v):
        p = self.p
        # PSS/E: the Q PI's output is the voltage reference of the V PI: it starts at v0
        return np.where(self._std(), np.clip(v, p["VMIN"], p["VMAX"]), super()._piq0(v))

    def _qref0(self, v, vp):
        p = self.p
        # PSS/E with VFLAG = 0, QFLAG = 1: the reference (plus REPCA1's Qext) is a voltage
        return np.where(self._std() & (p["VFLAG"] <= 0) & (p["QFLAG"] > 0), v, self.q0)

    def _vsel(self, piq, pfsel):
        xp, p = self.xp, self.p
        ands = xp.clip(xp.where(p["VFLAG"] > 0, piq, 0.0), p["VMIN"], p["VMAX"])
        return xp.where(self._std(), xp.where(p["VFLAG"] > 0, piq, pfsel), ands)

    def _piv_input(self, vsel, s0y):
        xp = self.xp
        return xp.where(self.p["QFLAG"] > 0, vsel - xp.where(self._std(), s0y, 0.0), 0.0)

    def _iqinj(self, iqv, dip, t):
        return self.xp.clip(iqv, self.p["Iql1"], self.p["Iqh1"])
