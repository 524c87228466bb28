"""PVD1: WECC distributed photovoltaic model (PSS/E PVD1, ANDES ``PVD1``).

A current source aligned with its bus voltage (system per unit; frequencies in Hz; times in s)::

    frequency measurement (as ANDES BusFreq at the bus):
        (a - a0) --[Lag 1/(1+sTf)]--> L --[Washout (1/wn) s/(1+sTw)]--> df,  fHz = fn (1 + df)
    trip (recovery) factors, 1 inside the normal band, linear to 0 at the trip points:
        Ffl(fHz; ft0, ft1), Ffh(fHz; ft2, ft3), Fvl(v; vt0, vt1), Fvh(v; vt2, vt3)
        R = Fvl Fvh Ffl Ffh if recflag else 1
    active power: Psum = pref0 + Pext0 + ddn * deadband(fn - fHz; fdbd, 999)
        Ipul = clip(Psum, 0, pmx) / vp       (the lower clip gives 0, as ANDES: Psum < 0 -> 0)
    reactive power: Qsum = qref0 + Qdrp(Vcomp), Q-V droop dqdv outside [v0, v1] bounded by qmn..qmx,
        Vcomp = |V + j xc (Ipout + j Iqout)|,    Iqul = Qsum / vp,   vp = max(v, 0.01)
    current limit ialim, P priority (pqflag = 1) or Q priority (0):
        Ipcmd = R clip(Ipul, 0, Ipmax),  Iqcmd = R clip(Iqul, -Iqmax, Iqmax)
    Ipout = Lag(Ipcmd, tip),  Iqout = Lag(Iqcmd, tiq);   P = Ipout v,  Q = Iqout v

Several PVD1 may share one static generator (``gammap``, ``gammaq``: shares of its P and Q,
which must sum to 1 over the devices of one generator). ``qmx``, ``qmn``, ``pmx``, ``dqdv``,
``ddn`` are powers and ``ialim`` a current on the device base ``Sn`` (converted by ``Sn/Sb``, as
ANDES). The frequency-measurement constants ``Tf``, ``Tw`` are those of the ANDES ``BusFreq``
device the PVD1 names in ``busf`` (ANDES defaults 0.02 s and 0.1 s otherwise). The lag's
input error ``(a - a0) - L`` is formed as the angle of ``V conj(V0) exp(-jL)``, so the
measurement stays right when the bus angle drifts past +-pi (ANDES's angle is unwrapped).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, Washout
from ..component import Component
from ..errors import DataError
from ..namespace import NUMPY, add_at, take
from ..params import Param


def _band_lo(u, p0, p1, xp=NUMPY):
    """0 at or below p0, linear to 1 at p1, 1 above (ANDES Limiter zones)."""
    return xp.where(u <= p0, 0.0, xp.where(u >= p1, 1.0, (u - p0) / (p1 - p0)))


def _band_hi(u, p2, p3, xp=NUMPY):
    """1 at or below p2, linear to 0 at p3, 0 above."""
    return xp.where(u <= p2, 1.0, xp.where(u >= p3, 0.0, 1.0 + (p2 - u) / (p3 - p2)))


class PVD1(Component):
    """Distributed PV (WECC PVD1); several devices may share one static generator row."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    #: the power-flow voltage and power references computed at init: per batch member
    batch_params = ("V0", "pref0", "qref0", "Vqu", "Vql")
    order = 0
    gen_shared = True
    params = (
        Param("Sn", 100.0, "MVA", "device rating", "pos"),
        Param("fn", 60.0, "Hz", "nominal frequency", "pos"),
        Param("xc", 0.0, "pu", "coupling reactance of the compensated voltage", ""),
        Param("pqflag", 1.0, "-", "current priority: 1 P, 0 Q", "nonneg"),
        Param("qmx", 0.33, "pu (Sn)", "maximum reactive power command", "", "power"),
        Param("qmn", -0.33, "pu (Sn)", "minimum reactive power command", "", "power"),
        Param("pmx", 9999.0, "pu (Sn)", "maximum active power", "", "power"),
        Param("v0", 0.8, "pu", "lower voltage of the Q-V droop deadband", ""),
        Param("v1", 1.1, "pu", "upper voltage of the Q-V droop deadband", ""),
        Param("dqdv", -1.0, "pu (Sn)/pu", "Q-V droop (negative)", "", "power"),
        Param("fdbd", -0.017, "Hz", "frequency deadband (lower edge)", ""),
        Param("ddn", 0.0, "pu (Sn)/Hz", "frequency droop gain outside the deadband", "", "power"),
        Param("ialim", 1.3, "pu (Sn)", "apparent current limit", "pos", "current"),
        Param("vt0", 0.88, "pu", "voltage trip point 0", ""),
        Param("vt1", 0.90, "pu", "voltage trip point 1", ""),
        Param("vt2", 1.1, "pu", "voltage trip point 2", ""),
        Param("vt3", 1.2, "pu", "voltage trip point 3", ""),
        Param("vrflag", 0.0, "-", "voltage-trip latching (unused, as ANDES)", ""),
        Param("ft0", 59.5, "Hz", "frequency trip point 0", ""),
        Param("ft1", 59.7, "Hz", "frequency trip point 1", ""),
        Param("ft2", 60.3, "Hz", "frequency trip point 2", ""),
        Param("ft3", 60.5, "Hz", "frequency trip point 3", ""),
        Param("frflag", 0.0, "-", "frequency-trip latching (unused, as ANDES)", ""),
        Param("tip", 0.02, "s", "active current lag", "pos"),
        Param("tiq", 0.02, "s", "reactive current lag", "pos"),
        Param("gammap", 1.0, "-", "share of the static generator's P", "nonneg"),
        Param("gammaq", 1.0, "-", "share of the static generator's Q", "nonneg"),
        Param("recflag", 1.0, "-", "voltage/frequency recovery factors on (1) or off (0)", "nonneg"),
        Param("Tf", 0.02, "s", "frequency measurement: angle filter", "pos"),
        Param("Tw", 0.1, "s", "frequency measurement: washout", "pos"),
    )
    states = ("L", "WO", "Ipout", "Iqout")
    outputs = ("fHz", "R", "Ipul", "Ipcmd", "Iqcmd", "Pe", "Qe")
    disconnectable = True    # a generator trip removes its current (compute)
    injection_outputs = ("Pe", "Qe")
    units = {"Pe": "power", "Qe": "power"}

    @classmethod
    def andes_link(cls, m, k, gen_row, ss, **_):
        """Link of ANDES PVD1 ``k``: its static generator row, with its BusFreq constants."""
        return {"gen": gen_row[m.gen.v[k]], "busf": m.busf.v[k]}

    #: names of the frequency-measurement constants (the BusFreq's ``Tf``, ``Tw``)
    freq_params = ("Tf", "Tw")

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """Add ``Tf``, ``Tw`` of the BusFreq device named in ``busf`` (ANDES defaults otherwise)."""
        bf = m.busf.v[k]
        tf, tw = cls.freq_params
        if bf is not None and "BusFreq" in ss.models and bf in list(ss.BusFreq.idx.v):
            j = list(ss.BusFreq.idx.v).index(bf)
            values[tf] = float(ss.BusFreq.Tf.v[j])
            values[tw] = float(ss.BusFreq.Tw.v[j])
        return values

    def add_pvd1(self, name, gen, **params):
        """Add one device on gen-table row ``gen`` (0-based)."""
        self.add(name, {"gen": gen}, params)
        return name

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.resolve_gen_rows(system)     # the shares on a row must sum to 1: System.setup checks
        c = p["Sn"] / system.Sb
        for prm in self.params:
            if prm.base in ("power", "current"):
                p[prm.name] = p[prm.name] * c
        self._uniq = len(set(self.bus.tolist())) == self.n
        self.iwn = 1.0 / (2 * np.pi * p["fn"])
        self.Lb = Lag(1.0, p[self.freq_params[0]])
        self.WOb = Washout(self.iwn, p[self.freq_params[1]])
        self._key = {o: f"{self.type_name}.{o}" for o in self.outputs}
        self.Ipb = Lag(1.0, p["tip"])
        self.Iqb = Lag(1.0, p["tiq"])

    def pattern(self, system):
        return [(self.instance_states(i) + system.bus_vars(self.bus[i]),) * 2 for i in range(self.n)]

    # ---------------------------------------------------------------- algebra
    #: lower bound of the active-power command, as a fraction of ``pmx`` (PV: no absorption)
    pmin_frac = 0.0

    def _ip_gates(self, x):
        """Factors ``(lo, hi)`` of the active-current limits: ``lo*Ipmax <= Ipcmd <= hi*Ipmax``."""
        return 0.0, 1.0

    def _commands(self, v, V, fHz, ipout, iqout, gates):
        xp, p = self.xp, self.p
        vp = xp.maximum(v, 0.01)
        R = _band_lo(v, p["vt0"], p["vt1"], xp) * _band_hi(v, p["vt2"], p["vt3"], xp) \
            * _band_lo(fHz, p["ft0"], p["ft1"], xp) * _band_hi(fHz, p["ft2"], p["ft3"], xp)
        R = xp.where(p["recflag"] > 0, R, 1.0)
        fdev = p["fn"] - fHz
        pdrp = p["ddn"] * (xp.where(fdev >= 999.0, fdev - 999.0, 0.0)
                           + xp.where(fdev <= p["fdbd"], fdev - p["fdbd"], 0.0))
        psum = self.pref0 + pdrp
        pmin = self.pmin_frac * p["pmx"]
        ipul = xp.where(psum >= p["pmx"], p["pmx"], xp.where(psum <= pmin, pmin, psum)) / vp
        vcomp = xp.abs(V + 1j * p["xc"] * (ipout + 1j * iqout))
        qdrp = xp.where(vcomp <= self.Vql, p["qmx"], 0.0) + xp.where(vcomp >= self.Vqu, p["qmn"], 0.0) \
            + xp.where((vcomp > self.Vql) & (vcomp < p["v0"]), p["qmx"] + p["dqdv"] * (self.Vqu - vcomp), 0.0) \
            + xp.where((vcomp > p["v1"]) & (vcomp < self.Vqu), p["dqdv"] * (p["v1"] - vcomp), 0.0)
        iqul = (self.qref0 + qdrp) / vp
        pri = p["pqflag"] > 0
        lim = p["ialim"]
        # P priority: Ip limited by ialim, Iq by what is left; Q priority the other way round
        glo, ghi = gates
        ipcmd_p = R * xp.clip(ipul, glo * lim, ghi * lim)
        iqmax_p = xp.sqrt(xp.maximum(lim ** 2 - ipcmd_p ** 2, 0.0))
        iqcmd_p = R * xp.clip(iqul, -iqmax_p, iqmax_p)
        iqcmd_q = R * xp.clip(iqul, -lim, lim)
        ipmax_q = xp.sqrt(xp.maximum(lim ** 2 - iqcmd_q ** 2, 0.0))
        ipcmd_q = R * xp.clip(ipul, glo * ipmax_q, ghi * ipmax_q)
        return xp.where(pri, ipcmd_p, ipcmd_q), xp.where(pri, iqcmd_p, iqcmd_q), R, qdrp, ipul

    def init(self, system, x, sig):
        pf = system.network.pf
        p = self.p
        V = pf.V[self.bus]
        v = np.abs(V)
        self.V0 = V.copy()
        self.pref0 = pf.Pg[self.gen] * p["gammap"]
        self.qref0 = pf.Qg[self.gen] * p["gammaq"]
        with np.errstate(divide="ignore"):
            self.Vqu = p["v1"] - (self.qref0 - p["qmn"]) / p["dqdv"]
            self.Vql = p["v0"] + (p["qmx"] - self.qref0) / p["dqdv"]
        ip0, iq0 = self.pref0 / v, self.qref0 / v
        ipc, iqc, R, qdrp, _ = self._commands(v, V, p["fn"], ip0, iq0, self._init_gates())
        bad = (np.abs(ipc - ip0) > 1e-9) | (np.abs(iqc - iq0) > 1e-9)
        for i in np.nonzero(bad)[0]:
            why = ("the voltage or frequency is in a trip band" if R[i] < 1 else
                   "the Q-V droop is active" if qdrp[i] != 0 else "the current limit ialim binds")
            raise DataError(self.element(i), "ialim" if R[i] == 1 and qdrp[i] == 0 else "v0",
                            float(p["ialim"][i] if R[i] == 1 and qdrp[i] == 0 else p["v0"][i]),
                            f"the power-flow point ({self.pref0[i]:.4g} + j{self.qref0[i]:.4g} pu at "
                            f"{v[i]:.4g} pu) is not a steady state: {why}; correct the limits")
        x[self.sl(0)] = 0.0
        x[self.sl(1)] = 0.0
        x[self.sl(2)] = ip0
        x[self.sl(3)] = iq0

    def _init_gates(self):
        return 0.0, 1.0

    # -------------------------------------------------------------- equations
    def compute(self, ctx):
        xp, x, sl = self.xp, ctx.x, self._sls
        L, wo, ipout, iqout = (x[..., sl[k]] for k in range(4))
        V = take(xp, ctx.V, self.bus)
        v = xp.abs(V)
        # (a - a0) - L, wrapped: L stays a continuous (unwrapped) angle even when the grid
        # frequency drifts for long (the bus angle itself is only known modulo 2 pi)
        z = V * xp.conj(self.V0) * xp.exp(-1j * L)
        err = xp.atan2(xp.imag(z), xp.real(z))      # numpy.angle
        df = self.WOb.output(wo, L)
        fHz = self.p["fn"] * (1.0 + df)
        ipcmd, iqcmd, R, _, ipul = self._commands(v, V, fHz, ipout, iqout, self._ip_gates(x))
        vs = xp.where(v > 1e-6, v, 1e-6)
        add_at(xp, ctx.I, self.bus, self.connected((ipout - 1j * iqout) * V / vs), self._uniq)
        f = ctx.f
        f[..., sl[0]] = err / self.Lb._Ts
        f[..., sl[1]] = self.WOb.deriv(wo, L)
        f[..., sl[2]] = self.Ipb.deriv(ipout, ipcmd)
        f[..., sl[3]] = self.Iqb.deriv(iqout, iqcmd)
        o, k = ctx.out, self._key
        o[k["fHz"]], o[k["R"]], o[k["Ipcmd"]], o[k["Iqcmd"]] = fHz, R, ipcmd, iqcmd
        o[k["Pe"]], o[k["Qe"]], o[k["Ipul"]] = ipout * v, iqout * v, ipul
        return ipout, v
