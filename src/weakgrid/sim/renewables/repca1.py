"""REPCA1: WECC generic renewable plant control model A (PSS/E REPCA1, PSLF REPC_A).

Adds a plant-level reactive and active power correction (``Qext``, ``Pext``) to the references
of one electrical control (:class:`~.reeca1.REECA1`). Block diagram (system per unit, times in
s; ``V`` is the voltage of the converter's bus, the line is the monitored branch)::

    Iline = Isign (V1 - V2) / (r + jx),  Pline + jQline = Isign V1 conj(Iline)/Isign^2
            (Isign = +1 when the converter is at the line's bus1, -1 at bus2; 0 without a line)
    VCsel = |V - (Rc + jXc) Iline|  (VCFlag = 1)   or   Kc Qline + |V|  (VCFlag = 0)
    VCsel --[Lag 1/(1+sTfltr)]--> s0,       Qline --[Lag 1/(1+sTfltr)]--> s1
    Refsel = Vref0 - s0 (RefFlag = 1)   or   Qline0 - s1 (RefFlag = 0)
    e = clip(deadband(Refsel; dbd1, dbd2), emin, emax), held while |V| < Vfrz
    e --[PI Kp, Ki (tracking anti-windup), Qmin..Qmax]--> s2 --[LeadLag (1+sTft)/(1+sTfv)]--> Qext
    Pline --[Lag 1/(1+sTp)]--> s4
    ferr = 1 - f;   droop = Ddn * fdb if fdb < 0 else Dup * fdb,   fdb = deadband(ferr; fdbd1, fdbd2)
    Perr = droop + PLflag (Pline0 - s4),   fe = clip(Perr, femin, femax)
    fe --[PI Kpg, Kig (tracking anti-windup), Pmin - P0..Pmax - P0]--> s5 --[Lag 1/(1+sTg)]--> s6
    Pext = Fflag * s6

``Pext`` is an increment on the converter's initial power ``P0`` (ANDES's form), so the plant's
power reference is ``P0 + s5``. ``Pmin``, ``Pmax`` bound that *total* reference, as in the WECC
REPC_A diagram and PSS/E's REPCA1, whose PI output is the electrical control's ``Pref`` itself
(started at ``P0``): the PI's limits are ``Pmin - P0``, ``Pmax - P0``. ANDES 2.0 applies them to
the increment ``s5`` (its default ``Pmin = -999``); ``P_total = 0`` reproduces that (the ANDES
importer sets it). With PSS/E data (``Pmin = 0``) ANDES's form pins ``s5`` at 0 from below: the
plant cannot lower its power, and PSS/E's RENA frequency-flag case (``Fflag = 1``, ``Kpg = 1``,
``Tp = 0.25``) showed no undershoot where PSS/E's power dips 2.6e-4 pu below P0 (0.39974 at
1.21 s).

Without a monitored line, ANDES 2.0 (and an ANDES import) takes ``Pline = Qline = 0``: the
plant's Q/V and P loops then see no power at all. PSS/E's REPCA1 without a monitored branch
(branch ICONs 0) regulates the generator's own output: the link ``terminal=True`` (set by the
PSS/E reader, :meth:`psse_link`) takes ``Pline + jQline`` = the converter's ``Pe + jQe`` and
``Iline`` = its current (as PSID does on its PSS/E benchmark cases, which it matches).

The frequency ``f`` [pu] is measured at the converter's bus as ANDES's ``BusFreq`` does
(angle lag ``Tf``, washout ``Tw``; the constants of the BusFreq named in ``busf`` or found at
the bus, ANDES's defaults 0.02 s and 0.1 s otherwise). ``Rc``, ``Xc`` default to the monitored
line's ``r``, ``x`` (system base) on import, as ANDES. The PI tracking gains are ANDES's
configuration ``kqs = ksg = 2``, and the hold of ``e`` its ``freeze = 1``. ``Pmax``, ``Pmin`` are
powers on the converter's rating ``Sn``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag, PITrackAW, Washout, deadband
from ..component import Component
from ..errors import DataError
from ..namespace import put, take
from ..params import Param

_EC = ("REECA1", "REECB1")     # electrical controls a plant control may drive


def _flag(name, info, default=None):
    return Param(name, default, "-", info, "nonneg")


class REPCA1(Component):
    """Renewable plant control model A (WECC); drives one REECA1 or REECB1."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 1            # before REECA1/REECB1, which read Pext and Qext
    params = (
        _flag("VCFlag", "1 line drop compensation, 0 droop (Kc Qline)"),
        _flag("RefFlag", "1 voltage control, 0 Q control"),
        _flag("Fflag", "frequency control on (1) or off (0)"),
        _flag("PLflag", "line power control on (1) or off (0)", 1.0),
        Param("Tfltr", 0.02, "s", "voltage and Q filter time constant (0: none)", "nonneg"),
        Param("Kp", 1.0, "pu/pu", "Q PI proportional gain"),
        Param("Ki", 0.1, "1/s", "Q PI integral gain"),
        Param("Tft", 1.0, "s", "lead time constant", "nonneg"),
        Param("Tfv", 1.0, "s", "lag time constant (0: none)", "nonneg"),
        Param("Vfrz", 0.8, "pu", "voltage below which e is held"),
        Param("Rc", 0.0, "pu", "line drop compensation resistance (system base)"),
        Param("Xc", 0.0, "pu", "line drop compensation reactance (system base)"),
        Param("Kc", 0.0, "pu/pu", "reactive droop gain"),
        Param("emax", 999.0, "pu", "upper limit of the deadband output"),
        Param("emin", -999.0, "pu", "lower limit of the deadband output"),
        Param("dbd1", -0.1, "pu", "lower edge of the voltage/Q dead band"),
        Param("dbd2", 0.1, "pu", "upper edge of the voltage/Q dead band"),
        Param("Qmax", 999.0, "pu", "upper limit of the Q PI output"),
        Param("Qmin", -999.0, "pu", "lower limit of the Q PI output"),
        Param("Kpg", 1.0, "pu/pu", "P PI proportional gain"),
        Param("Kig", 0.1, "1/s", "P PI integral gain"),
        Param("Tp", 0.02, "s", "line power filter time constant (0: none)", "nonneg"),
        Param("fdbd1", -0.0002833, "pu", "lower edge of the frequency dead band"),
        Param("fdbd2", 0.0002833, "pu", "upper edge of the frequency dead band"),
        Param("femax", 0.05, "pu", "upper limit of the power error"),
        Param("femin", -0.05, "pu", "lower limit of the power error"),
        Param("Pmax", 999.0, "pu (Sn)", "upper limit of the P PI output", "", "power"),
        Param("Pmin", -999.0, "pu (Sn)", "lower limit of the P PI output", "", "power"),
        Param("Tg", 0.02, "s", "Pext lag time constant (0: none)", "nonneg"),
        _flag("P_total", "1: Pmin, Pmax bound the total power reference P0 + s5 (WECC, PSS/E); "
              "0: the increment s5 (ANDES 2.0)", 1.0),
        Param("Ddn", 10.0, "pu/pu", "down-regulation droop gain (over-frequency)"),
        Param("Dup", 10.0, "pu/pu", "up-regulation droop gain (under-frequency)"),
        Param("fn", 60.0, "Hz", "nominal frequency", "pos"),
        Param("Tf", 0.02, "s", "frequency measurement: angle filter", "pos"),
        Param("Tw", 0.1, "s", "frequency measurement: washout", "pos"),
        Param("kqs", 2.0, "pu/pu", "Q PI tracking gain (ANDES config)", "nonneg"),
        Param("ksg", 2.0, "pu/pu", "P PI tracking gain (ANDES config)", "nonneg"),
    )
    #: PSS/E .dyr record after ``IBUS 'REPCA1' ID`` (PSS/E Model Library, REPCA1; PSID's RENA and
    #: the WECC 240-bus files): ICONs IREG (regulated bus, 0 = local), monitored branch FROM bus, TO
    #: bus and circuit id (a quoted string), VCFlag, RefFlag, Fflag; 27 CONs (PSS/E's ``Tlag`` is
    #: ``Tg``).
    psse_record = ("_IREG", "_BUS1", "_BUS2", "_CKT", "VCFlag", "RefFlag", "Fflag",
                   "Tfltr", "Kp", "Ki", "Tft", "Tfv", "Vfrz", "Rc", "Xc", "Kc", "emax", "emin", "dbd1",
                   "dbd2", "Qmax", "Qmin", "Kpg", "Kig", "Tp", "fdbd1", "fdbd2", "femax", "femin", "Pmax",
                   "Pmin", "Tg", "Ddn", "Dup")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E record -> parameters: the ICONs of the link are dropped (see :meth:`psse_link`),
        ``IREG`` must be 0 or the converter's bus (a remote regulated bus is not implemented);
        ``PLflag = 1`` (PSS/E's REPCA1 always closes the plant power loop; it acts with
        ``Fflag = 1``)."""
        v = dict(values)
        ireg = v.pop("_IREG")
        if ireg not in (0, ctx.bus):
            raise DataError(ctx.where, "IREG", ireg, "a remote regulated bus (ICON 1) is not implemented; "
                            "give 0 (the converter's terminal bus)")
        for f in ("_BUS1", "_BUS2", "_CKT"):
            v.pop(f)
        v["PLflag"] = 1.0
        return v

    @classmethod
    def psse_link(cls, values, ctx):
        """Link of a PSS/E record: the REECA1 or REECB1 of the same generator
        (``ctx.names[...]``), and the monitored branch: none (``terminal=True``: the
        converter's own output) when its FROM and TO buses are 0, else the 0-based branch row
        ``ctx.branch_row(from_bus, to_bus, ckt)`` (the measured end is the converter's bus)."""
        names = getattr(ctx, "names", {})
        ree = names.get("REECA1") or names.get("REECB1")
        if ree is None:
            raise DataError(ctx.where, "ID", ctx.id, "a REPCA1 drives the REECA1 or REECB1 of its "
                            f"generator: give one for bus {ctx.bus} id '{ctx.id}'")
        b1, b2 = values["_BUS1"], values["_BUS2"]
        if b1 == 0 and b2 == 0:
            return {"ree": ree, "line": None, "terminal": True}
        if b1 == 0 or b2 == 0:
            raise DataError(ctx.where, "BUS1" if b1 == 0 else "BUS2", 0,
                            "give both buses of the monitored branch (ICONs 2, 3), or 0 for both")
        return {"ree": ree, "line": int(ctx.branch_row(int(b1), int(b2), str(values["_CKT"]).strip())),
                "zline": False}

    states = ("s0", "s1", "s2", "s3", "s4", "s5", "s6", "L", "WO")
    outputs = ("Pext", "Qext", "f", "Pline", "Qline", "eHld", "fe", "s5_y")

    # ------------------------------------------------------------------ import
    @classmethod
    def andes_link(cls, m, k, dev_name, ss, **_):
        """Link of ANDES device ``k``: its REECA1 and the 0-based row of its monitored line."""
        name = dev_name.get(("REECA1", m.ree.v[k])) or dev_name.get(("REECB1", m.ree.v[k]))
        dev = f"ANDES REPCA1 {m.idx.v[k]}"
        if name is None:
            if any(e in ss.models and m.ree.v[k] in list(ss.models[e].idx.v) for e in _EC):
                return None
            raise DataError(dev, "ree", m.ree.v[k], "no REECA1 or REECB1 with this idx (the only "
                            "electrical controls supported)")
        if m.busr.v[k] not in (None, ""):
            raise DataError(dev, "busr", m.busr.v[k], "remote measurement is not supported; leave it empty")
        line = m.line.v[k]
        row = None
        if line not in (None, ""):
            lines = list(ss.Line.idx.v)
            if line not in lines:
                raise DataError(dev, "line", line, "no Line with this idx")
            row = lines.index(line)
        rc, xc = m.Rc.v[k], m.Xc.v[k]
        return {"ree": name, "line": row, "zline": rc is None or xc is None}

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """Rc, Xc from the line when missing; BusFreq constants; ANDES configuration."""
        for f in ("Rc", "Xc"):
            if not np.isfinite(values.get(f, 0.0)):
                values.pop(f, None)
        bf = m.busf.v[k]
        bfm = ss.models.get("BusFreq")
        if bfm is not None and bfm.n:
            ids = list(bfm.idx.v)
            j = ids.index(bf) if bf in ids else None
            if j is None:   # ANDES finds the BusFreq at the converter's bus (DeviceFinder)
                ec = next(ss.models[e] for e in _EC if m.ree.v[k] in list(ss.models[e].idx.v))
                reg = ec.reg.v[list(ec.idx.v).index(m.ree.v[k])]
                bus = ss.REGCA1.bus.v[list(ss.REGCA1.idx.v).index(reg)]
                on = [i for i, b in enumerate(bfm.bus.v) if b == bus]
                j = on[0] if on else None
            if j is not None:
                values["Tf"], values["Tw"] = float(bfm.Tf.v[j]), float(bfm.Tw.v[j])
                values["fn"] = float(bfm.fn.v[j])
        for f in ("kqs", "ksg"):
            if hasattr(m.config, f):
                values[f] = float(getattr(m.config, f))
        return values

    def add_repca1(self, name, ree, line=None, **params):
        """Add one plant control driving the REECA1 named ``ree``, monitoring branch row ``line``."""
        self.add(name, {"ree": ree, "line": line}, params)
        return name

    # ------------------------------------------------------------------- setup
    def setup(self, system):
        super().setup(system)
        p = self.p
        regc = system.components.get("REGCA1")
        ecs = [system.components[e] for e in _EC if e in system.components]
        net = system.network
        self.ree = np.zeros(self.n, int)
        self.ree_comps = [None] * self.n
        self.bus = np.zeros(self.n, int)
        self.b1 = np.zeros(self.n, int)
        self.b2 = np.zeros(self.n, int)
        self.isign = np.zeros(self.n)
        self.zl = np.ones(self.n, complex)
        self.term = np.array([bool(lk.get("terminal")) for lk in self.links], bool)
        self._any_term = bool(self.term.any())
        self.r = np.zeros(self.n, int)        # REGCA1 of each plant control
        Sn = np.zeros(self.n)
        for i, lk in enumerate(self.links):
            ree = next((c for c in ecs if lk.get("ree") in c.names), None)
            if ree is None:
                raise DataError(self.element(i), "ree", lk.get("ree"),
                                "give the name of a REECA1 or REECB1 of the system")
            j = ree.names.index(lk["ree"])
            self.ree[i] = j
            self.ree_comps[i] = ree
            r = regc.names.index(ree.links[j]["reg"])
            self.r[i] = r
            self.bus[i] = regc.bus[r]
            Sn[i] = regc.p["Sn"][r]
            row = lk.get("line")
            if row is None:
                self.b1[i] = self.b2[i] = self.bus[i]
                continue
            if self.term[i]:
                raise DataError(self.element(i), "terminal", True,
                                "a plant control measures either a line or its converter's terminal")
            if not (0 <= int(row) < net.branch.shape[0]):
                raise DataError(self.element(i), "line", row, "give a 0-based row of the branch table")
            br = net.branch[int(row)]
            self.b1[i] = net.index_of(int(br[0]), self.element(i), "line bus1")
            self.b2[i] = net.index_of(int(br[1]), self.element(i), "line bus2")
            self.zl[i] = br[2] + 1j * br[3]
            self.isign[i] = 1.0 if self.b1[i] == self.bus[i] else (-1.0 if self.b2[i] == self.bus[i] else 0.0)
            if self.isign[i] == 0:
                raise DataError(self.element(i), "line", row, "the monitored line must end at the converter's bus")
            if lk.get("zline"):
                p["Rc"][i], p["Xc"][i] = br[2], br[3]
        c = Sn / system.Sb
        for prm in self.params:
            if prm.base == "power":
                p[prm.name] = p[prm.name] * c
        self.regc = regc
        # per electrical-control type: (rows of this model, their indices in that type)
        self._targets = {}
        for c in ecs:
            rows = np.array([i for i in range(self.n) if self.ree_comps[i] is c], int)
            if len(rows):
                self._targets[c.type_name] = (c.n, rows, self.ree[rows])
        self.s0b = Lag(1.0, p["Tfltr"])
        self.s1b = Lag(1.0, p["Tfltr"])
        self.s2b = PITrackAW(p["Kp"], p["Ki"], p["kqs"])
        self.s3b = LeadLag(p["Tft"], p["Tfv"])
        self.s4b = Lag(1.0, p["Tp"])
        self.s5b = PITrackAW(p["Kpg"], p["Kig"], p["ksg"])
        self.s6b = Lag(1.0, p["Tg"])
        self.iwn = 1.0 / (2 * np.pi * p["fn"])
        self.WOb = Washout(self.iwn, p["Tw"])

    def pattern(self, system):
        rc = self.regc
        out = []
        for i in range(self.n):
            j, ree = self.ree[i], self.ree_comps[i]
            r = rc.names.index(ree.links[j]["reg"])
            v = (self.instance_states(i) + ree.instance_states(j) + rc.instance_states(r)
                 + system.bus_vars(self.bus[i]) + system.bus_vars(self.b1[i]) + system.bus_vars(self.b2[i]))
            out.append((v, v))
        return out

    # ---------------------------------------------------------------- algebra
    def _line(self, V, PQ=None):
        """Pline, Qline, VCsel, |V|; ``PQ`` = the converters' ``Pe + jQe`` (terminal measurement)."""
        xp = self.xp
        V1, V2 = take(xp, V, self.b1), take(xp, V, self.b2)
        Vb = take(xp, V, self.bus)
        I = self.isign * (V1 - V2) / self.zl
        S = self.isign * V1 * xp.conj((V1 - V2) / self.zl)
        if PQ is not None and self._any_term:
            S = xp.where(self.term, PQ, S)
            I = xp.where(self.term, xp.conj(PQ / xp.where(xp.abs(Vb) > 1e-6, Vb, 1e-6)), I)
        Vc = xp.abs(Vb - (self.p["Rc"] + 1j * self.p["Xc"]) * I)
        v = xp.abs(Vb)
        vcsel = xp.where(self.p["VCFlag"] > 0, Vc, xp.imag(S) * self.p["Kc"] + v)
        return xp.real(S), xp.imag(S), vcsel, v

    def init(self, system, x, sig):
        V = system.network.pf.V
        self.V0 = V[self.bus].copy()
        P, Q, vcsel, v = self._line(V, self.regc.p0[self.r] + 1j * self.regc.q0[self.r])
        self.Pline0, self.Qline0, self.Vref0 = P, Q, vcsel
        # the P PI's limits: on the total reference P0 + s5 (P_total = 1) or on s5 (ANDES)
        p0 = np.where(self.p["P_total"] > 0, self.regc.p0[self.r], 0.0)
        self.Plo, self.Phi = self.p["Pmin"] - p0, self.p["Pmax"] - p0
        self.initial_bounds = [("s5 (plant power reference - P0)", np.zeros(self.n), self.Plo, self.Phi,
                                "Pmin - P0", "Pmax - P0")]
        for i in np.nonzero(v < self.p["Vfrz"])[0]:
            raise DataError(self.element(i), "Vfrz", self.p["Vfrz"][i],
                            f"the initial voltage {v[i]:.4g} pu is below Vfrz: the control would start held")
        x[self.sl(0)] = vcsel
        x[self.sl(1)] = Q
        x[self.sl(4)] = P
        for k in (2, 3, 5, 6, 7, 8):
            x[self.sl(k)] = 0.0
        self._ehold = np.zeros(self.n)

    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        s0, s1, s2, s3, s4, s5, s6, L, wo = (x[..., sl[k]] for k in range(9))
        r = self.r
        P, Q, vcsel, v = self._line(ctx.V, take(xp, ctx.sig["REGCA1.Pe"], r) + 1j * take(xp, ctx.sig["REGCA1.Qe"], r))
        # frequency at the bus (ANDES BusFreq): angle lag and washout
        Vb = take(xp, ctx.V, self.bus)
        z = Vb * xp.conj(self.V0) * xp.exp(-1j * L)
        err = xp.atan2(xp.imag(z), xp.real(z))      # numpy.angle
        f = 1.0 + self.WOb.output(wo, L)
        # reactive power / voltage
        s0y, s1y = self.s0b.output(s0, vcsel), self.s1b.output(s1, Q)
        refsel = xp.where(p["RefFlag"] > 0, self.Vref0 - s0y, self.Qline0 - s1y)
        enf = xp.clip(deadband(refsel, p["dbd1"], p["dbd2"], xp), p["emin"], p["emax"])
        held = v < p["Vfrz"]
        ehld = xp.where(held, self._ehold, enf)
        s2y = self.s2b.output(s2, ehld, p["Qmin"], p["Qmax"])
        qext = self.s3b.output(s3, s2y)
        # active power / frequency
        s4y = self.s4b.output(s4, P)
        fdb = deadband(1.0 - f, p["fdbd1"], p["fdbd2"], xp)
        droop = xp.where(fdb < 0, fdb * p["Ddn"], fdb * p["Dup"])
        perr = droop + xp.where(p["PLflag"] > 0, self.Pline0 - s4y, 0.0)
        fe = xp.clip(perr, p["femin"], p["femax"])
        s5y = self.s5b.output(s5, fe, self.Plo, self.Phi)
        s6y = self.s6b.output(s6, s5y)
        pext = xp.where(p["Fflag"] > 0, s6y, 0.0)
        for tn, (n, rows, idx) in self._targets.items():
            for key, val in (("Pext", pext), ("Qext", qext)):
                arr = xp.zeros(x.shape[:-1] + (n,), dtype=xp.float64)
                put(xp, arr, idx, take(xp, val, rows))
                ctx.sig[f"{tn}.{key}"] = arr
        fd = ctx.f
        fd[..., sl[0]] = self.s0b.deriv(s0, vcsel)
        fd[..., sl[1]] = self.s1b.deriv(s1, Q)
        fd[..., sl[2]] = self.s2b.deriv(s2, ehld, p["Qmin"], p["Qmax"])
        fd[..., sl[3]] = self.s3b.deriv(s3, s2y)
        fd[..., sl[4]] = self.s4b.deriv(s4, P)
        fd[..., sl[5]] = self.s5b.deriv(s5, fe, self.Plo, self.Phi)
        fd[..., sl[6]] = self.s6b.deriv(s6, s5y)
        fd[..., sl[7]] = err / p["Tf"]
        fd[..., sl[8]] = self.WOb.deriv(wo, L)
        o = ctx.out
        o["REPCA1.Pext"], o["REPCA1.Qext"], o["REPCA1.f"] = pext, qext, f
        o["REPCA1.Pline"], o["REPCA1.Qline"], o["REPCA1.eHld"] = P, Q, ehld
        o["REPCA1.fe"], o["REPCA1.s5_y"] = fe, s5y
        o["REPCA1.held"] = xp.astype(held, xp.float64)
        o["REPCA1.enf"] = enf

    def accept(self, t, ctx):
        """Hold memory of ``e``: its last value while the voltage was above Vfrz."""
        xp = self.xp
        held = ctx.out["REPCA1.held"] > 0.5
        self._ehold = xp.where(held, self._ehold, ctx.out["REPCA1.enf"])
