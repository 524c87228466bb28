"""SCRX: bus-fed or solid-fed static exciter (PSS/E SCRX).

Block diagram (pu on the machine base, times in s; PSS/E SCRX names)::

    vi = vref - v + vs                                    (v: regulated voltage, vs: PSS output)
    vi --[LeadLag (1+sTA)/(1+sTB), TA = TATB*TB]--> LL
    LL --[Lag K/(1+sTE), non-windup EMIN..EMAX]--> VR
    EX = VR * Vt   if CSWITCH = 0 (bus fed: the bridge is supplied from the terminals)
    EX = VR        if CSWITCH = 1 (solid fed)
    Efd = EX                         if rc_rfd = 0 (the bridge conducts negative field current)
    Efd = EX if XadIfd > 0, else -rc_rfd * XadIfd      (rc_rfd > 0: crowbar, no negative current)

``Vt`` is the terminal-voltage magnitude (unfiltered) and ``XadIfd`` the field current in pu of
the machine. ``rc_rfd`` is the ratio of the crowbar (discharge) resistance to the field
resistance. ``TE = 0`` makes the lag the static gain ``clip(K*LL, EMIN, EMAX)``.

At initialization ``VR = vf0 / Vt`` (bus fed) or ``vf0`` (solid fed) and ``vref = v + VR/K``. A
crowbar (``rc_rfd > 0``) at a negative initial field current would make ``Efd`` independent of
the regulator (no steady state): refused, naming ``rc_rfd``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param


class SCRX(MachineControl):
    """Bus-fed or solid-fed static exciter. Parameters: TATB [-], TB, TE [s], K [pu], EMIN, EMAX
    [pu, machine base], CSWITCH (0 bus fed, 1 solid fed), rc_rfd [-] (0: negative field current
    allowed; > 0: crowbar resistance / field resistance)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("TATB", 0.1, "-", "ratio TA/TB of the lead-lag", "nonneg"),
        Param("TB", 10.0, "s", "lag time constant of the lead-lag", "nonneg"),
        Param("K", 200.0, "pu", "gain", "pos"),
        Param("TE", 0.05, "s", "bridge time constant (0: static gain)", "nonneg"),
        Param("EMIN", 0.0, "pu", "minimum regulator output (times Vt when bus fed)", ""),
        Param("EMAX", 5.0, "pu", "maximum regulator output (times Vt when bus fed)", ""),
        Param("CSWITCH", 1.0, "-", "0: bus fed (output times Vt), 1: solid fed", "flag"),
        Param("rc_rfd", 0.0, "-", "crowbar / field resistance ratio (0: negative field current allowed)",
              "nonneg"),
    )
    states = ("LL", "VR")
    outputs = ("vi", "EX", "vout")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"VR": ("EMIN", "EMAX")}
    #: PSS/E .dyr record after ``IBUS 'SCRX' ID`` (PSS/E Model Library: 8 CONs, no ICON)
    psse_record = ("TATB", "TB", "K", "TE", "EMIN", "EMAX", "CSWITCH", "rc_rfd")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E CONs -> parameters (the same names; CSWITCH must be 0 or 1, as PSS/E reads it)."""
        v = dict(values)
        if v.get("CSWITCH") not in (0.0, 1.0):
            raise DataError(ctx.where, "CSWITCH", v.get("CSWITCH"), "0 (bus fed) or 1 (solid fed)")
        return v

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LL = LeadLag(p["TATB"] * p["TB"], p["TB"])
        self.LA = Lag(p["K"], p["TE"])
        self._bus_fed = p["CSWITCH"] == 0
        self._crowbar = p["rc_rfd"] > 0

    def limits(self):
        on = self.p["TE"] > 0
        return [(self.idx("VR")[on], self.p["EMIN"][on], self.p["EMAX"][on])]

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, vt = sig["vf0"][m], sig["Ecomp0"][m], sig["Vt0"][m]
        xad = sig["XadIfd"][m]
        bad = self._crowbar & (xad <= 0)
        if np.any(bad):
            k = int(np.nonzero(bad)[0][0])
            raise DataError(self.element(k), "rc_rfd", float(p["rc_rfd"][k]),
                            f"the initial field current XadIfd = {float(xad[k]):.6g} pu is not positive, "
                            "so the crowbar sets Efd = -rc_rfd*XadIfd whatever the regulator does: no "
                            "steady state; give rc_rfd = 0 (negative field current allowed) or change the "
                            "operating point")
        VR0 = np.where(self._bus_fed, vf0 / vt, vf0)
        self.vref0 = v + VR0 / p["K"]
        x[self.sl(0)] = self.LL.init(VR0 / p["K"])
        x[self.sl(1)] = VR0
        # TE = 0: the static gain is clipped (no state holds it): its initial value is checked here
        big = np.where(p["TE"] > 0, np.inf, 0.0)
        self.initial_bounds = [("VR", VR0, p["EMIN"] - big, p["EMAX"] + big, "EMIN", "EMAX")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        ll, vr = ctx.x[..., self._sls[0]], ctx.x[..., self._sls[1]]
        s = ctx.sig
        vi = self.vref0 - take(xp, s["Ecomp"], m) + take(xp, s["vs"], m)
        y = self.LL.output(ll, vi)
        VR = xp.minimum(xp.maximum(self.LA.output(vr, y), p["EMIN"]), p["EMAX"])
        EX = xp.where(self._bus_fed, VR * take(xp, s["Vt"], m), VR)
        xad = take(xp, s["XadIfd"], m)
        efd = xp.where(self._crowbar & (xad <= 0), -p["rc_rfd"] * xad, EX)
        ctx.f[..., self._sls[0]] = self.LL.deriv(ll, vi)
        ctx.f[..., self._sls[1]] = self.LA.deriv(vr, y)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["SCRX.vi"], o["SCRX.EX"], o["SCRX.vout"] = vi, EX, efd
