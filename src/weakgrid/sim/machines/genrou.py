"""GENROU: round-rotor machine with quadratic saturation (PSS/E GENROU as in ANDES).

Equations on the system base (ANDES ``GENROU`` with ``Flux0``; sub-transient
reactances must be equal, ``xd2 == xq2``)::

    gd1 = (xd2-xl)/(xd1-xl)      gq1 = (xq2-xl)/(xq1-xl)
    gd2 = (xd1-xd2)/(xd1-xl)^2   gq2 = (xq1-xq2)/(xq1-xl)^2   gqd = (xq-xl)/(xd-xl)
    psi2d = gd1*e1q + gd2*(xd1-xl)*e2d          (d-axis air-gap flux)
    psi2q = gq1*e1d + (1-gq1)*e2q               (q-axis air-gap flux)
    psi2  = |psi2d + j psi2q|,  Se = B*(psi2-A)^2/psi2 for psi2 >= A
    stator: xd2*Id + ra*Iq = psi2d - vq,  -ra*Id + xq2*Iq = vd - psi2q
    XadIfd = e1q + (xd-xd1)*(gd1*Id - gd2*e2d + gd2*e1q) + Se*psi2d
    XaqI1q = e1d + (xq-xq1)*(gq2*e1d - gq2*e2q - gq1*Iq) + Se*gqd*psi2q
    Td10 de1q/dt = vf - XadIfd
    Tq10 de1d/dt = -XaqI1q
    Td20 de2d/dt = -e2d + e1q - (xd1-xl)*Id
    Tq20 de2q/dt = -e2q + e1d + (xq1-xl)*Iq
    te = psid*Iq - psiq*Id, psid = ra*Iq + vq, psiq = -(ra*Id + vd)

Saturation coefficients ``A, B`` come from ``(1.0, S10)`` and ``(1.2, S12)``
through :func:`weakgrid.sim.blocks.quad_saturation_coeffs` (``S10 = 0`` disables it).
The steady-state initialization follows the OpenIPSL/ANDES procedure.
Shaft: ANDES's by default; ``psse_shaft = 1`` gives PSS/E's (mechanical input as power,
divided by the speed; :mod:`~weakgrid.sim.machines.shaft`), as a PSS/E case means it.

Data checks: ``xd2 <= xd1 <= xd`` and ``xq2 <= xq1 <= xq`` (``xq1 = xq``, no q-axis
transient effect, occurs in ANDES's wecc data; ``xd2 = xd1``, no sub-transient effect, in a PSS/E
case of PowerSimulationsDynamics.jl), ``xl < xd1, xq1``; ``xl >= xd2`` (ANDES's
ieee39 data) is unusual but well defined and is accepted with a warning, as ANDES does.
"""

from __future__ import annotations

import numpy as np

from ..blocks import exp_saturation, quad_saturation_coeffs
from ..errors import DataError
from ..kernels import Kernel, constants
from ..namespace import take
from ..params import Param
from .base import BASE_PARAMS, SyncMachine, psse_subtransient_params
from .shaft import swing


class GENROU(SyncMachine):
    """Round-rotor synchronous machine with quadratic saturation.

    Notes
    -----
    Parameters, on the machine base unless stated:
    Sn, Vn, fn, M, D, ra, xd1 as in :class:`~weakgrid.sim.machines.gencls.GENCLS`;
    xl, xd, xq, xd2, xq1, xq2 [pu]; Td10, Td20, Tq10, Tq20 [s]; S10, S12 [pu].
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    #: the last evaluation's values (read by ``finish``)
    scratch = ("_te", "_XadIfd")
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("Td10", "Td20", "Tq10", "Tq20", "H", "D", "xd", "xq", "xd1", "xq1", "xd2",
                   "xl", "S10", "S12")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E GENROU (and GENROE): :func:`~weakgrid.sim.machines.base.psse_subtransient_params`."""
        return psse_subtransient_params(values, ctx)

    params = BASE_PARAMS + (
        Param("xl", 0.0, "pu (machine base)", "leakage reactance", "nonneg", "z"),
        Param("xd", 1.9, "pu (machine base)", "d-axis synchronous reactance", "pos", "z"),
        Param("xq", 1.7, "pu (machine base)", "q-axis synchronous reactance", "pos", "z"),
        Param("xd2", 0.3, "pu (machine base)", "d-axis sub-transient reactance x''d", "pos", "z"),
        Param("xq1", 0.5, "pu (machine base)", "q-axis transient reactance x'q", "pos", "z"),
        Param("xq2", 0.3, "pu (machine base)", "q-axis sub-transient reactance x''q", "pos", "z"),
        Param("Td10", 8.0, "s", "d-axis transient open-circuit time constant T'd0", "pos"),
        Param("Td20", 0.04, "s", "d-axis sub-transient open-circuit time constant T''d0", "pos"),
        Param("Tq10", 0.8, "s", "q-axis transient open-circuit time constant T'q0", "pos"),
        Param("Tq20", 0.02, "s", "q-axis sub-transient open-circuit time constant T''q0", "pos"),
        Param("S10", 0.0, "pu", "saturation factor at 1.0 pu flux", "nonneg"),
        Param("S12", 1.0, "pu", "saturation factor at 1.2 pu flux", "nonneg"),
    )
    states = ("delta", "omega", "e1q", "e1d", "e2d", "e2q")
    outputs = ("Pe", "Qe", "te", "Id", "Iq", "XadIfd", "psi2", "Se", "vf")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in range(self.n):
            if abs(p["xd2"][i] - p["xq2"][i]) > 1e-12 * max(1.0, abs(p["xd2"][i])):
                raise DataError(self.element(i), "xq2", self._values[i]["xq2"],
                                f"{self.type_name} needs xq2 == xd2 (round rotor, as in PSS/E and ANDES); "
                                "set xq2 = xd2")
            if not p["xl"][i] < min(p["xd1"][i], p["xq1"][i]):
                raise DataError(self.element(i), "xl", self._values[i]["xl"],
                                "leakage reactance must be < xd1 and < xq1")
            # xq1 = xq (no q-axis transient effect, ANDES's wecc data) is well defined, and so is
            # xd2 = xd1 / xq2 = xq1 (no sub-transient effect: gd2 = gq2 = 0, the damper states
            # drop out of the flux; PSS/E runs such data, e.g. PSID's STAB1 case)
            if not (p["xd2"][i] <= p["xd1"][i] <= p["xd"][i]) or not (p["xq2"][i] <= p["xq1"][i] <= p["xq"][i]):
                raise DataError(self.element(i), "xd1", self._values[i]["xd1"],
                                "need xd2 <= xd1 <= xd and xq2 <= xq1 <= xq")
        # unusual but well defined (ANDES's ieee39 data): said once for the model, as ANDES accepts it
        self.warn_instances(np.nonzero(~(p["xl"] < p["xd2"]))[0],
                            "leakage reactance xl >= xd2 (normally xl < xd2); accepted, as in ANDES",
                            lambda i: f"xl = {p['xl'][i]:g} >= xd2 = {p['xd2'][i]:g}")
        xl = p["xl"]
        self.gd1 = (p["xd2"] - xl) / (p["xd1"] - xl)
        self.gq1 = (p["xq2"] - xl) / (p["xq1"] - xl)
        self.gd2 = (p["xd1"] - p["xd2"]) / (p["xd1"] - xl) ** 2
        self.gq2 = (p["xq1"] - p["xq2"]) / (p["xq1"] - xl) ** 2
        self.gqd = (p["xq"] - xl) / (p["xd"] - xl)
        self.SA, self.SB = self._sat_coeffs(p["S10"], p["S12"])
        self._pre = f"{self.type_name}."
        # folded constants of the core (same equations, fewer operations), genrou_core's p
        det = p["xd2"] * p["xq2"] + p["ra"] * p["ra"]
        xdd1, xqq1 = p["xd"] - p["xd1"], p["xq"] - p["xq1"]
        iTd20, iTq20 = 1.0 / p["Td20"], 1.0 / p["Tq20"]
        self._P = constants(self.n, (
            self.gd1, self.gd2 * (p["xd1"] - xl), self.gq1, 1 - self.gq1,
            p["xq2"] / det, p["ra"] / det, p["xd2"] / det,
            xdd1 * self.gd1, xdd1 * self.gd2, xqq1 * self.gq1, xqq1 * self.gq2,
            -1.0 / p["Tq10"], iTd20, iTq20, (p["xd1"] - xl) * iTd20, (p["xq1"] - xl) * iTq20,
            self.gqd, p["ra"], self.SA, self.SB))
        self._iTd10 = 1.0 / p["Td10"]
        # the core's branches: the stator with or without ra, the saturation curve (0 none,
        # 1 GENROU's quadratic, 2 GENROE's exponential); compiled (weakgrid.sim.kernels)
        # except the exponential, whose power function does not round as NumPy's
        nosat = bool(np.all(self.SB == 0))
        sat = 0 if nosat else (1 if self._curve is quad_sat else 2)
        self._flags = (bool(np.all(p["ra"] == 0)), sat)
        self._compiled_flags = self._flags if sat < 2 else None

    @staticmethod
    def _sat_coeffs(S10, S12):
        """``(A, B)`` of the saturation curve through ``(1.0, S10)``, ``(1.2, S12)``."""
        return quad_saturation_coeffs(1.0, S10, 1.2, S12)

    def _sat(self, psi2):
        """The saturation factor ``Se(psi2)`` of this model's curve (:attr:`_curve`)."""
        return self._curve(psi2, self.SA, self.SB)

    def init(self, system, x, sig):
        p = self.p
        pf = system.network.pf
        V = pf.V[self.bus]
        S = self.power_share(pf)
        It = np.conj(S / V)
        ra, xd2, xq2, xq, xd, xl = p["ra"], p["xd2"], p["xq2"], p["xq"], p["xd"], p["xl"]
        psi20 = V + It * (ra + 1j * xd2)          # sub-transient flux in the network frame
        a20 = np.abs(psi20)
        Se0 = self._sat(a20)
        ang = np.angle(psi20) - np.angle(It)
        ap = a20 * (1 + Se0 * self.gqd)
        bp = np.abs(It) * (xq2 - xq)
        delta = np.arctan(bp * np.cos(ang) / (bp * np.sin(ang) - ap)) + np.angle(psi20)
        rot = np.exp(-1j * delta)
        psi_dq = psi20 * rot
        It_dq = np.conj(It * rot)
        psi2d, psi2q = psi_dq.real, -psi_dq.imag
        Id, Iq = It_dq.imag, It_dq.real
        vf0 = (Se0 + 1) * psi2d + (xd - xd2) * Id
        tm0 = (V * np.conj(It)).real + ra * np.abs(It) ** 2
        x[self.sl(0)] = delta
        x[self.sl(1)] = 1.0
        x[self.sl(2)] = Id * (p["xd1"] - xd) - Se0 * psi2d + vf0
        x[self.sl(3)] = Iq * (xq - p["xq1"]) - Se0 * self.gqd * psi2q
        x[self.sl(4)] = Id * (xl - xd) - Se0 * psi2d + vf0
        x[self.sl(5)] = -Iq * (xl - xq) - Se0 * self.gqd * psi2q
        system.set_machine_initial(self.m, vf0=vf0, tm0=tm0, XadIfd=vf0, Pe=S.real, Qe=S.imag,
                                   delta=delta, V=V)

    def compute(self, ctx):
        xp, x, sl = self.xp, ctx.x, self._sls
        delta, omega = x[..., sl[0]], x[..., sl[1]]
        V = take(xp, ctx.V, self._bi)
        sd, cd = xp.sin(delta), xp.cos(delta)
        (Ire, Iim, Id, Iq, XadIfd, Se, psi2, te, Pe, Qe, f3, f4, f5) = _KERNEL(
            (x[..., sl[2]], x[..., sl[3]], x[..., sl[4]], x[..., sl[5]], sd, cd, xp.real(V),
             xp.imag(V)), self._P, self._flags, self._compiled_flags)
        # injected current (Id + j Iq) exp(j(delta - pi/2))
        self.inject(ctx, Ire + 1j * Iim)
        self._te = te
        self._XadIfd = XadIfd
        self.publish(ctx, omega, delta, Pe, Qe, V, XadIfd)
        f = ctx.f
        f[..., sl[3]] = f3
        f[..., sl[4]] = f4
        f[..., sl[5]] = f5
        o, k = ctx.out, self._pre
        o[k + "Pe"], o[k + "Qe"], o[k + "te"] = Pe, Qe, te
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
        f[..., sl[2]] = (vf - self._XadIfd) * self._iTd10


def genrou_core(s, p, ra0, sat):
    """GENROU's flux, stator and rotor equations, elementwise (:class:`~weakgrid.sim.kernels.Kernel`:
    arrays or scalars, the same floats).

    ``s = (e1q, e1d, e2d, e2q, sin delta, cos delta, Re V, Im V)`` (states and terminal voltage,
    pu on the system base); ``p``: the constants :meth:`GENROU.setup` packs (``_P``); ``ra0``:
    every ``ra`` is 0 (the stator's solution without it); ``sat``: the saturation factor
    ``Se(psi2)``, 0 none, 1 quadratic (:func:`quad_sat`), 2 exponential
    (:func:`~weakgrid.sim.blocks.exp_saturation`, GENROE). Returns
    ``(Re I, Im I, Id, Iq, XadIfd, Se, psi2, te, Pe, Qe, de1d/dt, de2d/dt, de2q/dt)``: the
    network current injected, the outputs and three of the derivatives (pu, pu/s).
    """
    e1q, e1d, e2d, e2q, sd, cd, Vre, Vim = s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]
    gd1, c_e2d, gq1, c_e2q, cIda, cIdb, cIqb = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    kd1, kd2, kq1, kq2, iTq10, iTd20, iTq20 = p[7], p[8], p[9], p[10], p[11], p[12], p[13]
    xd1l_iTd20, xq1l_iTq20, gqd, ra, SA, SB = p[14], p[15], p[16], p[17], p[18], p[19]
    psi2d = gd1 * e1q + c_e2d * e2d          # d-axis air-gap flux
    psi2q = gq1 * e1d + c_e2q * e2q          # q-axis air-gap flux
    psi2 = np.sqrt(psi2d * psi2d + psi2q * psi2q)
    vd = Vre * sd - Vim * cd
    vq = Vre * cd + Vim * sd
    # stator: xd2*Id + ra*Iq = psi2d - vq,  -ra*Id + xq2*Iq = vd - psi2q
    a = psi2d - vq
    b = vd - psi2q
    if ra0:
        Id = cIda * a
        Iq = cIqb * b
        psid, psiq = vq, -vd
    else:
        Id = cIda * a - cIdb * b
        Iq = cIqb * b + cIdb * a
        psid = ra * Iq + vq
        psiq = -(ra * Id + vd)
    # injected current (Id + j Iq) exp(j(delta - pi/2))
    Ire = Id * sd + Iq * cd
    Iim = Iq * sd - Id * cd
    dq, dd = e1q - e2d, e1d - e2q       # each once: the flux and the damper equations read them
    XadIfd = e1q + kd1 * Id + kd2 * dq
    XaqI1q = e1d + kq2 * dd - kq1 * Iq
    if sat == 0:
        Se = psi2 * 0.0
    else:
        Se = quad_sat(psi2, SA, SB) if sat == 1 else exp_saturation(psi2, SA, SB)
        XadIfd = XadIfd + Se * psi2d
        XaqI1q = XaqI1q + (Se * gqd) * psi2q
    te = psid * Iq - psiq * Id
    Pe = vd * Id + vq * Iq
    Qe = vq * Id - vd * Iq
    return (Ire, Iim, Id, Iq, XadIfd, Se, psi2, te, Pe, Qe,
            XaqI1q * iTq10, dq * iTd20 - xd1l_iTd20 * Id, dd * iTq20 + xq1l_iTq20 * Iq)


def quad_sat(psi2, A, B):
    """GENROU's saturation factor ``Se = B (psi2 - A)^2 / psi2`` for ``psi2 >= A``, else 0, and
    0 where that is not finite (arrays; :func:`quad_sat_scalar` is its compiled form)."""
    ok = (psi2 > 0) & (psi2 < np.inf)
    if np.all(ok):   # fast path: same values as below there
        return B * np.maximum(psi2 - A, 0.0) ** 2 / psi2
    # elsewhere 0: where psi2 is 0 or not finite (divided by 1 there, nothing to warn of)
    Se = B * np.maximum(psi2 - A, 0.0) ** 2 / np.where(ok, psi2, 1.0)
    return np.where(ok & np.isfinite(Se), Se, 0.0)


def quad_sat_scalar(psi2, A, B):
    """:func:`quad_sat` for one element (the same floats)."""
    if 0.0 < psi2 < np.inf:        # _sat's fast path
        m = psi2 - A
        if not m > 0.0:
            m = 0.0
        return B * (m * m) / psi2
    if psi2 >= A:
        Se = B * ((psi2 - A) * (psi2 - A)) / psi2
        if Se - Se == 0.0:         # finite
            return Se
    return 0.0


def exp_saturation_scalar(x, A, B):
    """:func:`~weakgrid.sim.blocks.exp_saturation` for one element, for the compiler's typing
    of :func:`genrou_core` only: GENROE, which uses it, runs on NumPy (a power function need not
    round as NumPy's)."""
    return B * abs(x) ** A if x > 0 else 0.0


#: the saturation curve ``Se(psi2, A, B)`` (GENROE's: the exponential one)
GENROU._curve = staticmethod(quad_sat)

_KERNEL = Kernel(genrou_core, 13, ((quad_sat, quad_sat_scalar),
                                   (exp_saturation, exp_saturation_scalar)))
