"""GENCLS: classical machine, constant voltage behind the transient reactance.

Equations (system base, ANDES ``GENCLS`` with ``Flux0``)::

    vd = v sin(delta - theta),  vq = v cos(delta - theta)
    0 = xd1*Id + ra*Iq - (vf - vq)          (d axis, internal emf E' = vf)
    0 = -ra*Id + xd1*Iq - vd                (q axis)
    te = (vq + ra*Iq)*Iq + (vd + ra*Id)*Id
    shaft: see :mod:`weakgrid.sim.machines.shaft`

PSS/E's GENCLS (``psse_shaft = 1``, set by the PSS/E reader): the electrical torque is the air-gap
power over the speed, ``te/omega`` (the constant EMF E' is not scaled by the speed, unlike the
sub-transient EMF of PSS/E's GENROU family), so the shaft is
``M dw/dt = (Pm - D dw)/omega - te/omega``: its speed damping is ``D`` alone, as PSS/E's
results show (PSID's OMIB benchmark, ``Test01``: the rotor-angle oscillation decays at
-0.159 1/s in PSS/E, -0.159 1/s here; with ``te`` undivided it decays at -0.199 1/s, the extra
``Pm/omega`` damping, and is 4.9 % of PSS/E's swing off) and as OpenIPSL's PSS/E GENCLS
(``(P0 - P - D dw)/2H``, verified against PSS/E) has it.

``vf`` is held at its initial value unless an exciter is attached.
"""

from __future__ import annotations

import numpy as np

from ..kernels import Kernel, constants
from ..namespace import take
from .base import BASE_PARAMS, SyncMachine
from .shaft import swing


class GENCLS(SyncMachine):
    """Classical machine model (PSS/E and ANDES ``GENCLS``).

    Notes
    -----
    Parameters, on the machine base unless stated:
    Sn [MVA], Vn [kV], fn [Hz], M = 2H [s], D [pu], ra [pu], xd1 = x'd [pu].
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("H", "D")
    #: the last evaluation's value (read by ``finish``)
    scratch = ("_te",)

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E GENCLS: ``M = 2H``; the source impedance is ``ZSORCE`` (``ra + j xd1``, pu on
        MBASE). ``H = 0`` (PSS/E's infinite bus) gives ``M = 0``, which the reader turns into an
        infinite bus."""
        from ..errors import DataError

        v = {"M": 2.0 * values["H"], "D": values["D"], "ra": ctx.zsorce.real, "xd1": ctx.zsorce.imag}
        if not v["xd1"] > 0:
            raise DataError(ctx.where, "ZSORCE", ctx.zsorce,
                            "GENCLS takes its reactance from the generator record's ZX (> 0 pu on MBASE)")
        return v

    params = BASE_PARAMS
    states = ("delta", "omega")
    outputs = ("Pe", "Qe", "te", "Id", "Iq", "vf")

    def init(self, system, x, sig):
        pf = system.network.pf
        V = pf.V[self.bus]
        S = self.power_share(pf)
        I = np.conj(S / V)
        ra, xq = self.p["ra"], self.p["xd1"]
        E = V + I * (ra + 1j * xq)
        delta = np.angle(E)
        vd, vq = self.dq_voltage(V, delta)
        Idq = I * np.exp(1j * (0.5 * np.pi - delta))
        Id, Iq = Idq.real, Idq.imag
        vf0 = vq + ra * Iq + xq * Id
        tm0 = (vq + ra * Iq) * Iq + (vd + ra * Id) * Id
        x[self.sl(0)] = delta
        x[self.sl(1)] = 1.0
        system.set_machine_initial(self.m, vf0=vf0, tm0=tm0, XadIfd=vf0, Pe=S.real, Qe=S.imag,
                                   delta=delta, V=V)

    def setup(self, system):
        super().setup(system)
        ra, xq = self.p["ra"], self.p["xd1"]
        det = xq * xq + ra * ra
        # folded constants of the stator equations (module docstring): det = xd1^2 + ra^2
        self._P = constants(self.n, (xq / det, ra / det, ra))

    def compute(self, ctx):
        xp, x = self.xp, ctx.x
        delta, omega = x[..., self._sls[0]], x[..., self._sls[1]]
        V = take(xp, ctx.V, self._bi)
        vf = take(xp, ctx.sig["vf"], self._mi)
        Ire, Iim, Id, Iq, Pe, Qe, te = _KERNEL(
            (xp.sin(delta), xp.cos(delta), xp.real(V), xp.imag(V), vf), self._P, (), ())
        self.inject(ctx, Ire + 1j * Iim)
        self._te = te
        self.publish(ctx, omega, delta, Pe, Qe, V, vf)
        o = ctx.out
        o["GENCLS.Pe"], o["GENCLS.Qe"], o["GENCLS.te"] = Pe, Qe, te
        o["GENCLS.Id"], o["GENCLS.Iq"] = Id, Iq

    def finish(self, ctx):
        xp = self.xp
        omega = ctx.x[..., self._sls[1]]
        tm = take(xp, ctx.sig["tm"], self._mi)
        ctx.out["GENCLS.vf"] = take(xp, ctx.sig["vf"], self._mi)
        te = self._te
        if self._psse_shaft is not None:   # PSS/E: the air-gap power over the speed (docstring)
            te = xp.where(self._psse_shaft, te / omega, te)
        d_delta, d_omega = swing(omega, tm, te, self.p["M"], self.p["D"], self.wb,
                                 self._psse_shaft, xp)
        ctx.f[..., self._sls[0]] = d_delta
        ctx.f[..., self._sls[1]] = d_omega


def gencls_core(s, p):
    """GENCLS's stator and air-gap power, elementwise (:class:`~weakgrid.sim.kernels.Kernel`:
    arrays or scalars, the same floats).

    ``s = (sin delta, cos delta, Re V, Im V, vf)`` (pu, system base); ``p = (xd1/det, ra/det,
    ra)``, ``det = xd1^2 + ra^2``. Returns ``(Re I, Im I, Id, Iq, Pe, Qe, te)``: the network
    current injected and the outputs.
    """
    sd, cd, Vre, Vim, vf = s[0], s[1], s[2], s[3], s[4]
    cIa, cIb, ra = p[0], p[1], p[2]
    vd = Vre * sd - Vim * cd               # dq_voltage
    vq = Vre * cd + Vim * sd
    a, b = vf - vq, vd                     # xd1*Id + ra*Iq = a,  -ra*Id + xd1*Iq = b
    Id = cIa * a - cIb * b
    Iq = cIa * b + cIb * a
    Pe = vd * Id + vq * Iq
    Qe = vq * Id - vd * Iq
    # injected current (Id + j Iq) exp(j(delta - pi/2)), as network_current
    return (Id * sd + Iq * cd, Iq * sd - Id * cd, Id, Iq, Pe, Qe,
            Pe + ra * (Iq * Iq + Id * Id))   # te = (vq + ra Iq) Iq + (vd + ra Id) Id


_KERNEL = Kernel(gencls_core, 7)
