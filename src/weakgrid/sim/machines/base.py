"""Common part of synchronous machine models: links, per-unit bases, terminal quantities."""

from __future__ import annotations

import numpy as np

from ..component import Component, fast_index
from ..namespace import add_at, put
from ..params import Param

BASE_PARAMS = (
    Param("Sn", 100.0, "MVA", "machine power rating", "pos"),
    Param("Vn", 0.0, "kV", "machine voltage rating (0: bus base kV)", "nonneg"),
    Param("fn", 60.0, "Hz", "rated frequency", "pos"),
    Param("M", 6.0, "s (machine base)", "inertia constant M = 2H", "pos", "power"),
    Param("D", 0.0, "pu (machine base)", "damping coefficient", "nonneg", "power"),
    Param("ra", 0.0, "pu (machine base)", "armature resistance", "nonneg", "z"),
    Param("xd1", 0.302, "pu (machine base)", "d-axis transient reactance x'd", "pos", "z"),
    Param("gammap", 1.0, "-", "share of its static generator's P (devices on one row sum to 1)", "nonneg"),
    Param("gammaq", 1.0, "-", "share of its static generator's Q (devices on one row sum to 1)", "nonneg"),
    Param("psse_shaft", 0.0, "-", "1: PSS/E's shaft, M dw/dt = (Pm - D dw)/omega - te (mechanical input "
          "is power); 0: ANDES's, M dw/dt = tm - te - D dw (see machines.shaft)", "flag"),
)


def with_default(params, name, default):
    """``params`` with the default of ``name`` replaced (a model's own convention)."""
    return tuple(Param(p.name, default, p.unit, p.info, p.rule, p.base) if p.name == name else p
                 for p in params)


def psse_subtransient_params(values, ctx):
    """A PSS/E GENROU, GENROE, GENSAL or GENSAE record as parameters: ``M = 2H``, ``xq2 = xd2``
    (PSS/E's single X''), ``ra = Re(ZSORCE)`` (pu on MBASE; the record has no armature
    resistance)."""
    v = dict(values)
    v["M"] = 2.0 * v.pop("H")
    v["xq2"] = v["xd2"]
    v["ra"] = float(ctx.zsorce.real)
    return v


class SyncMachine(Component):
    """Base of synchronous machines.

    Each instance is linked to one row ``gen`` of the network's gen table and
    replaces that static generator in the time domain. Parameters are on the
    machine base (``Sn``, ``Vn``) and converted to the system base on setup.

    Signals published (machine-indexed): ``omega``, ``delta``, ``Pe``, ``Qe``,
    ``Vt`` (terminal voltage magnitude), ``theta`` (terminal voltage angle),
    ``XadIfd``, ``Ecomp`` (the exciters' input voltage: ``Vt`` unless a compensator such
    as IEEEVC changes it); defaults for ``vf`` and ``tm`` are the initial values (used when
    no exciter/governor is attached).
    """

    kind = "machine"
    order = 0
    gen_shared = True        # with converters or other machines, by the shares gammap, gammaq
    disconnectable = True    # a generator trip removes its current (inject)
    injection_outputs = ("Pe", "Qe", "te", "Id", "Iq")
    units = {"delta": "angle", "omega": "speed", "Pe": "power", "Qe": "power", "te": "power",
             "tm": "power", "Id": "current", "Iq": "current"}

    def setup(self, system):
        super().setup(system)
        net = system.network
        self.resolve_gen_rows(system)
        Sb = system.Sb
        Vb = net.base_kv[self.bus]
        Vn = np.where(self.p["Vn"] > 0, self.p["Vn"], Vb)
        Sn = self.p["Sn"]
        coeff = {"z": (Vn ** 2 / Sn) / (Vb ** 2 / Sb), "power": Sn / Sb, "ipower": Sb / Sn}
        for prm in self.params:
            if prm.base:
                self.p[prm.name] = self.p[prm.name] * coeff[prm.base]
        self.wb = 2 * np.pi * self.p["fn"]
        self.m = np.array([system.machine_number(nm) for nm in self.names], dtype=int)
        self._mi = fast_index(self.m)
        # two machines on one bus: their currents must accumulate (add_at with unique=False)
        self._uniq = len(set(self.bus.tolist())) == self.n
        self._bi = fast_index(self.bus) if self._uniq else self.bus
        psse = self.p["psse_shaft"] > 0
        self._psse_shaft = psse if psse.any() else None    # None: ANDES's shaft everywhere (fast path)

    def pattern(self, system):
        return None  # grouped with its controls by the system

    def power_share(self, pf):
        """Complex power of the power flow this machine takes: ``gammap Pg + j gammaq Qg`` [pu]."""
        return pf.Pg[self.gen] * self.p["gammap"] + 1j * pf.Qg[self.gen] * self.p["gammaq"]

    @staticmethod
    def dq_voltage(V, delta):
        """d/q components of the terminal voltage: ``vd = v sin(delta-theta)``, ``vq = v cos(delta-theta)``."""
        s, c = np.sin(delta), np.cos(delta)
        return V.real * s - V.imag * c, V.real * c + V.imag * s

    @staticmethod
    def network_current(Id, Iq, delta):
        """Current phasor injected into the bus: ``(Id + j Iq) * exp(j(delta - pi/2))``."""
        return (Id + 1j * Iq) * (np.sin(delta) - 1j * np.cos(delta))

    def inject(self, ctx, I):
        """Add the machines' network currents ``I`` to ``ctx.I`` (accumulating on shared buses)."""
        add_at(self.xp, ctx.I, self._bi, self.connected(I), self._uniq)

    def publish(self, ctx, omega, delta, Pe, Qe, V, XadIfd):
        xp, m, sig = self.xp, self._mi, ctx.sig
        vt = xp.abs(V)
        put(xp, sig["omega"], m, omega)
        put(xp, sig["delta"], m, delta)
        put(xp, sig["Pe"], m, Pe)
        put(xp, sig["Qe"], m, Qe)
        put(xp, sig["Vt"], m, vt)
        put(xp, sig["Ecomp"], m, vt)
        put(xp, sig["theta"], m, xp.atan2(xp.imag(V), xp.real(V)))   # np.angle's arithmetic
        put(xp, sig["XadIfd"], m, XadIfd)


def saturated_rotor_angle(psi2, It, k, xq, xq2):
    r"""Steady-state rotor angle [rad] of a machine whose q-axis sub-transient flux obeys
    :math:`\psi''_q (1 + k) = (x_q - x''_q) I_q` (``k = Se * (xq-xl)/(xd-xl)`` with q-axis
    saturation as in GENROU, ``k = 0`` without it, GENSAL).

    ``psi2 = V + (ra + j x'') It`` is the sub-transient flux phasor and ``It`` the terminal
    current phasor (network frame, system base). With ``x = delta - angle(psi2)`` and
    ``ang = angle(psi2) - angle(It)`` the condition reads
    ``tan x = b cos(ang) / (b sin(ang) - a)``, ``a = |psi2| (1 + k)``, ``b = |It| (x''q - xq)``
    (the OpenIPSL / ANDES GENROU initialization). For ``k = 0`` it is the angle of
    ``V + (ra + j xq) It``.
    """
    ang = np.angle(psi2) - np.angle(It)
    a = np.abs(psi2) * (1 + k)
    b = np.abs(It) * (xq2 - xq)
    return np.arctan(b * np.cos(ang) / (b * np.sin(ang) - a)) + np.angle(psi2)
