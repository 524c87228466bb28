"""GENSAL: salient-pole machine, quadratic saturation on the d axis (PSS/E GENSAL).

Three rotor windings: the field (``e1q`` = E'q), one d-axis damper (``e2d`` = psi_kd)
and one q-axis damper whose flux is the q-axis sub-transient flux itself (``psi2q`` =
psi''_q; no q-axis transient winding: X'q = Xq). Equations on the system base, in the
sign convention of :mod:`~weakgrid.sim.machines.genrou` (PSS/E's block diagram, speed
effects on the stator neglected as PSS/E does)::

    gd1 = (xd2-xl)/(xd1-xl),  gd2 = (xd1-xd2)/(xd1-xl)^2
    psi2d = gd1*e1q + (1-gd1)*e2d                      (d-axis sub-transient flux)
    stator: xd2*Id + ra*Iq = psi2d - vq,  -ra*Id + xq2*Iq = vd - psi2q      (xq2 = xd2)
    XadIfd = e1q + (xd-xd1)*(gd1*Id + gd2*(e1q - e2d)) + Se(e1q)*e1q
    Td10 de1q/dt  = vf - XadIfd
    Td20 de2d/dt  = -e2d + e1q - (xd1-xl)*Id
    Tq20 dpsi2q/dt = -psi2q + (xq-xq2)*Iq
    te = psid*Iq - psiq*Id,  psid = ra*Iq + vq,  psiq = -(ra*Id + vd)

Saturation acts on the d axis only, as a function of E'q: ``Se(x) = B*(x-A)^2/x`` for
``x > A`` through ``(1.0, S10)`` and ``(1.2, S12)``
(:func:`weakgrid.sim.blocks.quad_saturation_coeffs`, PSS/E's quadratic curve; ``S10 = 0``
disables it). This is PSS/E's GENSAL: on PSID's PSS/E benchmark weakgrid's GENSAL is
0.0015 deg from PSS/E's rotor angle; the same machine with GENROU-like ``Se(|psi''|)*psi2d``
instead is 0.5 deg off (on a 1.3 deg swing). Unsaturated, GENSAL is GENROU with ``xq1 = xq`` (no q-axis transient
winding): ``psi2q`` is GENROU's ``(1-gq1)*e2q`` and GENROU's ``e1d`` stays 0.

Data checks (PSS/E's GENSAL rules): one sub-transient reactance ``xq2 == xd2`` (PSS/E has
only X''d); ``xd2 <= xd1 <= xd``; ``xl < xd1``; ``xq2 <= xq``; ``S12 >= S10``.
``xd1 == xd2`` (no d-axis damper effect) is well defined: the damper flux ``e2d`` then
enters nothing (``gd1 = 1``, ``gd2 = 0``) and the machine is a one-winding d axis; it is
accepted. ``xl >= xd2`` is unusual but well defined and accepted with a warning, as for
GENROU.

Shaft: PSS/E's, ``M dw/dt = (Pm - D dw)/omega - te`` (``psse_shaft = 1``, the default of
the PSS/E-only models GENSAL, GENSAE, GENROE; ``psse_shaft = 0`` gives ANDES's
``M dw/dt = tm - te - D dw`` of GENROU and GENCLS).
"""

from __future__ import annotations

import numpy as np

from ..blocks import quad_saturation_coeffs
from ..errors import DataError
from ..namespace import take
from ..params import Param
from .base import (BASE_PARAMS, SyncMachine, psse_subtransient_params, saturated_rotor_angle,
                   with_default)
from .shaft import swing


class GENSAL(SyncMachine):
    """Salient-pole synchronous machine, quadratic saturation of E'q on the d axis (PSS/E GENSAL).

    Notes
    -----
    Parameters, on the machine base unless stated:
    Sn, Vn, fn, M = 2H, D, ra, xd1 as in :class:`~weakgrid.sim.machines.gencls.GENCLS`;
    xl, xd, xq, xd2, xq2 [pu]; Td10 = T'do, Td20 = T''do, Tq20 = T''qo [s]; S10, S12 [pu].
    States: ``delta`` [rad], ``omega`` [pu], ``e1q`` (E'q), ``e2d`` (psi_kd), ``psi2q``
    (psi''_q) [pu]. The shaft is PSS/E's by default (``psse_shaft = 1``: the mechanical
    input is power, divided by the speed; :mod:`~weakgrid.sim.machines.shaft`).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    #: the last evaluation's values (read by ``finish``)
    scratch = ("_te", "_XadIfd")
    params = with_default(BASE_PARAMS, "psse_shaft", 1.0) + (
        Param("xl", 0.0, "pu (machine base)", "leakage reactance", "nonneg", "z"),
        Param("xd", 1.9, "pu (machine base)", "d-axis synchronous reactance", "pos", "z"),
        Param("xq", 1.7, "pu (machine base)", "q-axis synchronous reactance", "pos", "z"),
        Param("xd2", 0.3, "pu (machine base)", "d-axis sub-transient reactance x''d", "pos", "z"),
        Param("xq2", 0.3, "pu (machine base)", "q-axis sub-transient reactance x''q (= x''d)", "pos", "z"),
        Param("Td10", 8.0, "s", "d-axis transient open-circuit time constant T'd0", "pos"),
        Param("Td20", 0.04, "s", "d-axis sub-transient open-circuit time constant T''d0", "pos"),
        Param("Tq20", 0.02, "s", "q-axis sub-transient open-circuit time constant T''q0", "pos"),
        Param("S10", 0.0, "pu", "saturation factor at 1.0 pu flux", "nonneg"),
        Param("S12", 1.0, "pu", "saturation factor at 1.2 pu flux", "nonneg"),
    )
    states = ("delta", "omega", "e1q", "e2d", "psi2q")
    outputs = ("Pe", "Qe", "te", "Id", "Iq", "XadIfd", "psi2", "Se", "vf")

    #: PSS/E .dyr record (Program Application Guide): T'do, T''do, T''qo, H, D, Xd, Xq, X'd,
    #: X''d, Xl, S(1.0), S(1.2)
    psse_record = ("Td10", "Td20", "Tq20", "H", "D", "xd", "xq", "xd1", "xd2", "xl", "S10", "S12")

    #: saturation curve through (1.0, S10), (1.2, S12): "quadratic" or "exponential"
    saturation = "quadratic"
    #: saturation also on the q axis (GENSAE), as a function of ``|psi''|`` instead of E'q
    q_saturation = False

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E GENSAL (and GENSAE): :func:`~weakgrid.sim.machines.base.psse_subtransient_params`."""
        return psse_subtransient_params(values, ctx)

    # ------------------------------------------------------------------ setup
    def setup(self, system):
        super().setup(system)
        p = self.p
        name = self.type_name
        for i in range(self.n):
            val = self._values[i]
            if abs(p["xd2"][i] - p["xq2"][i]) > 1e-12 * max(1.0, abs(p["xd2"][i])):
                raise DataError(self.element(i), "xq2", val["xq2"],
                                f"{name} has one sub-transient reactance (PSS/E's X''d = X''q); "
                                f"set xq2 = xd2 = {val['xd2']:g}")
            if not p["xd1"][i] <= p["xd"][i]:
                raise DataError(self.element(i), "xd1", val["xd1"],
                                f"{name} needs X'd <= Xd (xd = {val['xd']:g})")
            if not p["xd2"][i] <= p["xd1"][i]:
                raise DataError(self.element(i), "xd2", val["xd2"],
                                f"{name} needs X''d <= X'd (xd1 = {val['xd1']:g}); X''d = X'd "
                                "(no d-axis damper effect) is accepted")
            if not p["xl"][i] < p["xd1"][i]:
                raise DataError(self.element(i), "xl", val["xl"],
                                f"{name} needs the leakage reactance Xl < X'd (xd1 = {val['xd1']:g})")
            if not p["xq2"][i] <= p["xq"][i]:
                raise DataError(self.element(i), "xq", val["xq"],
                                f"{name} needs Xq >= X''q (xq2 = {val['xq2']:g})")
            if p["S10"][i] > 0 and not p["S12"][i] >= p["S10"][i]:
                raise DataError(self.element(i), "S12", val["S12"],
                                f"{name} needs S(1.2) >= S(1.0) = {val['S10']:g} (saturation grows "
                                "with flux); S10 = 0 disables saturation")
        self.warn_instances(np.nonzero(~(p["xl"] < p["xd2"]))[0],
                            "leakage reactance xl >= xd2 (normally xl < xd2); accepted",
                            lambda i: f"xl = {p['xl'][i]:g} >= xd2 = {p['xd2'][i]:g}")
        xl = p["xl"]
        self.gd1 = (p["xd2"] - xl) / (p["xd1"] - xl)
        self.gd2 = (p["xd1"] - p["xd2"]) / (p["xd1"] - xl) ** 2
        self.gqd = (p["xq"] - xl) / (p["xd"] - xl)
        self.SA, self.SB = self._sat_coeffs(p["S10"], p["S12"])
        self._nosat = bool(np.all(self.SB == 0))
        self._det = p["xd2"] * p["xq2"] + p["ra"] * p["ra"]
        self._ra0 = bool(np.all(p["ra"] == 0))
        self._pre = f"{name}."

    @staticmethod
    def _sat_coeffs(S10, S12):
        return quad_saturation_coeffs(1.0, S10, 1.2, S12)

    def _sat(self, x):
        """Saturation factor ``Se(x)`` (quadratic: ``B (x-A)^2 / x`` for ``x > A``, else 0)."""
        xp = self.xp
        # x kept off 0 where x <= 0 (there the result is 0 anyway)
        Se = xp.where(x > self.SA, self.SB * (x - self.SA) ** 2 / xp.where(x > 0, x, 1.0), 0.0)
        return xp.where(xp.isfinite(Se) & (x > 0), Se, 0.0)

    # ------------------------------------------------------------------- init
    def init(self, system, x, sig):
        p = self.p
        pf = system.network.pf
        V = pf.V[self.bus]
        S = self.power_share(pf)
        It = np.conj(S / V)
        ra, xd2, xq, xd, xl, xd1 = p["ra"], p["xd2"], p["xq"], p["xd"], p["xl"], p["xd1"]
        psi20 = V + It * (ra + 1j * xd2)          # sub-transient flux in the network frame
        Seq = self._sat(np.abs(psi20)) if self.q_saturation else np.zeros(self.n)
        delta = saturated_rotor_angle(psi20, It, Seq * self.gqd, xq, p["xq2"])
        rot = np.exp(-1j * delta)
        psi_dq = psi20 * rot
        It_dq = np.conj(It * rot)
        psi2d, psi2q = psi_dq.real, -psi_dq.imag
        Id = It_dq.imag
        e1q = psi2d + (xd1 - xd2) * Id
        e2d = e1q - (xd1 - xl) * Id
        sat_d = Seq * psi2d if self.q_saturation else self._sat(e1q) * e1q
        vf0 = e1q + (xd - xd1) * Id + sat_d
        tm0 = (V * np.conj(It)).real + ra * np.abs(It) ** 2
        x[self.sl(0)] = delta
        x[self.sl(1)] = 1.0
        x[self.sl(2)] = e1q
        x[self.sl(3)] = e2d
        x[self.sl(4)] = psi2q
        system.set_machine_initial(self.m, vf0=vf0, tm0=tm0, XadIfd=vf0, Pe=S.real, Qe=S.imag,
                                   delta=delta, V=V)

    # ---------------------------------------------------------------- equations
    def compute(self, ctx):
        xp, p = self.xp, self.p
        x = ctx.x
        sl = self._sls
        delta, omega = x[..., sl[0]], x[..., sl[1]]
        e1q, e2d, psi2q = x[..., sl[2]], x[..., sl[3]], x[..., sl[4]]
        psi2d = self.gd1 * e1q + (1.0 - self.gd1) * e2d
        V = take(xp, ctx.V, self._bi)
        sd, cd = xp.sin(delta), xp.cos(delta)
        Vre, Vim = xp.real(V), xp.imag(V)
        vd = Vre * sd - Vim * cd
        vq = Vre * cd + Vim * sd
        # stator: xd2*Id + ra*Iq = a,  -ra*Id + xq2*Iq = b
        a = psi2d - vq
        b = vd - psi2q
        ra = p["ra"]
        Id = (p["xq2"] * a - ra * b) / self._det
        Iq = (p["xd2"] * b + ra * a) / self._det
        psid = ra * Iq + vq
        psiq = -(ra * Id + vd)
        self.inject(ctx, (Id * sd + Iq * cd) + 1j * (Iq * sd - Id * cd))
        psi2 = xp.sqrt(psi2d * psi2d + psi2q * psi2q)
        XadIfd = e1q + (p["xd"] - p["xd1"]) * (self.gd1 * Id + self.gd2 * (e1q - e2d))
        dpsi2q = -psi2q + (p["xq"] - p["xq2"]) * Iq
        if self._nosat:
            Se = xp.zeros_like(psi2)
        elif self.q_saturation:
            Se = self._sat(psi2)
            XadIfd = XadIfd + Se * psi2d
            dpsi2q = dpsi2q - (Se * self.gqd) * psi2q
        else:
            Se = self._sat(e1q)
            XadIfd = XadIfd + Se * e1q
        self._te = psid * Iq - psiq * Id
        self._XadIfd = XadIfd
        Pe = vd * Id + vq * Iq
        Qe = vq * Id - vd * Iq
        self.publish(ctx, omega, delta, Pe, Qe, V, XadIfd)
        f = ctx.f
        f[..., sl[3]] = (e1q - e2d - (p["xd1"] - p["xl"]) * Id) / p["Td20"]
        f[..., sl[4]] = dpsi2q / p["Tq20"]
        o, k = ctx.out, self._pre
        o[k + "Pe"], o[k + "Qe"], o[k + "te"] = Pe, Qe, self._te
        o[k + "Id"], o[k + "Iq"], o[k + "XadIfd"] = Id, Iq, XadIfd
        o[k + "psi2"], o[k + "Se"] = psi2, Se

    def finish(self, ctx):
        p = self.p
        xp, m, sl = self.xp, self._mi, self._sls
        omega = ctx.x[..., sl[1]]
        vf = take(xp, ctx.sig["vf"], m)
        tm = take(xp, ctx.sig["tm"], m)
        ctx.out[self._pre + "vf"] = vf
        d_delta, d_omega = swing(omega, tm, self._te, p["M"], p["D"], self.wb, self._psse_shaft, xp)
        f = ctx.f
        f[..., sl[0]] = d_delta
        f[..., sl[1]] = d_omega
        f[..., sl[2]] = (vf - self._XadIfd) / p["Td10"]
