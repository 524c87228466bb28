"""REECA1: WECC generic renewable electrical control model A (PSS/E REECA1, PSLF REEC_A).

Drives the current commands of one converter (:class:`~.regca1.REGCA1`) from active and
reactive power references, with the voltage-dip logic and the current limiter. Block
diagram (system per unit, times in s; ``v`` is the converter's terminal voltage)::

    v --[Lag 1/(1+sTrv)]--> s0                       (filtered voltage)
    Pe --[Lag 1/(1+sTp)]--> S1                      (filtered power, power-factor control)
    Volt_dip = v < Vdip or v > Vup                 (freezes s4, s5, PIQ, PIV)
    reactive power:
      PFsel = Qref + Qext (PFFLAG = 0)  or  S1 tan(pfaref0) (PFFLAG = 1)
      Qerr  = clip(PFsel, QMin, QMax) - Qe
      PIQ   = PI(Kqp, Kqi) on Qerr (VFLAG = 1), output in [VMIN, VMAX]
      Vsel  = clip(PIQ if VFLAG else Vref1 + PFsel, VMIN, VMAX)
      PIV   = PI(Kvp, Kvi) on Vsel - (0 if VFLAG else s0), output in [Iqmin, Iqmax]
      PFsel/vp --[Lag 1/(1+sTiq), frozen in a dip]--> s4
      Qsel  = PIV (QFLAG = 1)  or  s4 (QFLAG = 0)
      Iqinj = Kqv * deadband(Vref0 - s0; dbd1, dbd2), clipped to [Iql1, Iqh1], in a dip
              (and for |Thld| s after it if Thld < 0; Iqfrz for Thld s if Thld > 0)
      Iqcmd = clip(Qsel + Iqinj, Iqmin, Iqmax)
    active power:
      Pref + Pext --[LagRate 1/(1+s tpfilt), dPmin..dPmax]--> pfilt
      Psel = wg pfilt (PFLAG = 1) or pfilt (PFLAG = 0)
      Psel --[Lag 1/(1+sTpord), non-windup PMIN..PMAX, frozen in a dip]--> s5 = Pord
      Ipcmd = clip(Pord / vp, 0, Ipmax),        vp = max(v, 0.01)
      (Pref = Pref0 and wg = 1 unless a wind turbine's torque controller WTTQA1 sets Pref and its
      drive train WTDTA1 sets the generator speed wg, see :mod:`.wttqa1`, :mod:`.wtdta1`)
    current limiter (PQFLAG = 1: P priority, 0: Q priority):
      VDL1(s0), VDL2(s0): piecewise-linear through (Vq1, Iq1)..(Vq4, Iq4), (Vp1, Ip1)..(Vp4, Ip4)
      P priority: Ipmax = min(VDL2, Imax),  Iqmax = min(VDL1, sqrt(Imax^2 - Ipcmd^2))
      Q priority: Iqmax = min(VDL1, Imax),  Ipmax = min(VDL2, sqrt(Imax^2 - Iqcmd^2))
      Ipmax is held at its value at the end of a dip for Thld2 s; Iqmin = -Iqmax.

Conventions (those of ANDES 2.0, checked against it in ``tests/sim/test_reeca1_peer.py``):

* ``Imax <= 0`` means no current limit; a VDL table that is not monotone (points or currents
  decreasing) is switched off; ``Vref0 = 0`` means the initial terminal voltage; a time
  constant ``Trv``, ``Tp``, ``Tiq`` or ``Tpord`` of 0 makes its lag a pass-through;
  ``Thld > 0`` holds ``Iqinj`` at ``Iqfrz``, ``Thld < 0`` keeps the voltage-dependent
  ``Iqinj`` for ``|Thld|`` s after a dip; ``p0 = 0`` with ``PFFLAG = 1`` holds the Q
  reference at its initial value (the power-factor angle is undefined).
* In a dip the PI outputs are held at their last value before the dip (their states frozen),
  as ANDES does; so are the outputs of ``s4`` and ``s5`` when their time constant is 0. The
  held value is the one of the last *accepted* point outside a dip (ANDES holds the value of
  the Newton iterate at which its flag switched, which can differ when the voltage jumps from
  below Vdip to above Vup in one step; see ``tests/sim/test_reeca1_peer.py``).
* ``Ipmax`` is held for Thld2 at its value at the end of the dip (WECC). ANDES 2.0 evaluates
  its dip flags at every Newton iterate, and the first iterate after a fault clearing starts
  from the restored pre-fault voltage (inside the normal band): its hold starts there, with
  the pre-fault Ipmax, and stays on while the dip goes on. With P priority this lifts ANDES's
  Ipmax from VDL2 (4.2 pu) to Imax for the first 20 ms after clearing in the peer case. An
  artifact of ANDES's iterates, not reproduced here: the peer harness starts ANDES on the
  network's solution after the clearing (``run_andes_ss(..., configure=solve_network_at_clearing)``), and
  the tools then agree (``test_reeca1_peer.py::test_limits_case_andes_newton_start_at_clearing``).
* The flag combinations follow ANDES's diagram, including its initial references:
  ``Qref0 = q0`` with ``QFLAG = 0``, ``Vref1 - v0`` with ``QFLAG = 1``.
* ANDES adds ``Ipcmd0/LVG0 - Ipcmd0`` to the active current command so that the converter
  starts in steady state when its LVG is below 1 at the initial voltage; done here too.

Differences from ANDES 2.0, where it departs from the WECC diagram (none matters in the
peer cases, whose data keep them out of reach; each is documented, not hidden):

* ANDES does not clip ``Iqinj`` to ``[Iql1, Iqh1]``; here it is clipped, as in the WECC model.
* ANDES takes the non-priority current limit as ``sqrt(Imax^2 - I^2)`` alone, without the VDL
  table of that axis; the WECC model takes the minimum of both. ``vdl_np = 1`` (the default)
  follows WECC, ``vdl_np = 0`` ANDES; the ANDES importer sets 0 so that an ANDES case gives
  ANDES's answer (ANDES's shipped cases reach the VDL tables in a fault).
* ANDES's non-priority limit ``sqrt(Imax^2 - I^2)`` uses ``Imax`` even when it is ``<= 0``
  (which cuts that current to 0); here the "no limit" replacement is used on both axes.

Per-unit bases as ANDES: ``QMax``, ``QMin``, ``dPmax``, ``dPmin``, ``PMAX``, ``PMIN`` are
powers and ``Imax``, ``Iq1..Iq4``, ``Ip1..Ip4`` currents on the converter's rating ``Sn``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagRate, PITrackAW, deadband, piecewise_linear
from ..component import Component
from ..errors import DataError
from ..namespace import put, take
from ..params import Param

BIG = 1e8    # "no limit" (ANDES's replacement value)


def _flag(name, info):
    return Param(name, None, "-", info, "nonneg")


class REECA1(Component):
    """Renewable energy electrical control model A (WECC); drives one REGCA1."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 2            # after REGCA1 (reads its P, Q, v) and REPCA1 (reads Pext, Qext)
    controlled = "REGCA1"
    params = (
        _flag("PFFLAG", "power factor control: 1 PF, 0 Q"),
        _flag("VFLAG", "1 Q control (PIQ), 0 voltage control"),
        _flag("QFLAG", "1 voltage/Q control (PIV), 0 constant PF or Q"),
        _flag("PFLAG", "1 P reference times speed, 0 not (speed is 1 without a drive train)"),
        _flag("PQFLAG", "current priority: 1 P, 0 Q"),
        Param("Vdip", 0.8, "pu", "voltage below which the dip logic acts"),
        Param("Vup", 1.2, "pu", "voltage above which the dip logic acts"),
        Param("Trv", 0.02, "s", "voltage filter time constant (0: none)", "nonneg"),
        Param("dbd1", -0.02, "pu", "lower edge of the voltage dead band (<= 0)"),
        Param("dbd2", 0.02, "pu", "upper edge of the voltage dead band (>= 0)"),
        Param("Kqv", 1.0, "pu/pu", "gain of the dip reactive current injection"),
        Param("Iqh1", 999.0, "pu", "upper limit of Iqinj"),
        Param("Iql1", -999.0, "pu", "lower limit of Iqinj"),
        Param("Vref0", 1.0, "pu", "voltage reference of Iqinj (0: initial voltage)"),
        Param("Iqfrz", 0.0, "pu", "Iqinj held after a dip (Thld > 0)"),
        Param("Thld", 0.0, "s", "hold time of Iqinj after a dip (> 0: at Iqfrz, < 0: as in the dip)"),
        Param("Thld2", 0.0, "s", "hold time of Ipmax after a dip", "nonneg"),
        Param("Tp", 0.02, "s", "electrical power filter time constant (0: none)", "nonneg"),
        Param("QMax", 999.0, "pu (Sn)", "upper limit of the reactive power reference", "", "power"),
        Param("QMin", -999.0, "pu (Sn)", "lower limit of the reactive power reference", "", "power"),
        Param("VMAX", 999.0, "pu", "upper limit of the voltage control"),
        Param("VMIN", -999.0, "pu", "lower limit of the voltage control"),
        Param("Kqp", 1.0, "pu/pu", "reactive power PI: proportional gain"),
        Param("Kqi", 0.1, "1/s", "reactive power PI: integral gain"),
        Param("Kvp", 1.0, "pu/pu", "voltage PI: proportional gain"),
        Param("Kvi", 0.1, "1/s", "voltage PI: integral gain"),
        Param("Vref1", 1.0, "pu", "voltage reference with VFLAG = 0", "nonzero"),
        Param("Tiq", 0.02, "s", "reactive current filter time constant (0: none)", "nonneg"),
        Param("dPmax", 999.0, "pu (Sn)", "upper rate limit of the power reference (on tpfilt dP/dt)", "", "power"),
        Param("dPmin", -999.0, "pu (Sn)", "lower rate limit of the power reference (on tpfilt dP/dt)", "", "power"),
        Param("PMAX", 999.0, "pu (Sn)", "upper limit of the power order", "", "power"),
        Param("PMIN", 0.0, "pu (Sn)", "lower limit of the power order", "", "power"),
        Param("Imax", 999.0, "pu (Sn)", "apparent current limit (<= 0: none)", "", "current"),
        Param("Tpord", 0.02, "s", "power order time constant (0: none)", "nonneg"),
        Param("Vq1", 0.2, "pu", "VDL1 point 1 voltage"), Param("Iq1", 2.0, "pu (Sn)", "VDL1 point 1 current", "", "current"),
        Param("Vq2", 0.4, "pu", "VDL1 point 2 voltage"), Param("Iq2", 4.0, "pu (Sn)", "VDL1 point 2 current", "", "current"),
        Param("Vq3", 0.8, "pu", "VDL1 point 3 voltage"), Param("Iq3", 8.0, "pu (Sn)", "VDL1 point 3 current", "", "current"),
        Param("Vq4", 1.0, "pu", "VDL1 point 4 voltage"), Param("Iq4", 10.0, "pu (Sn)", "VDL1 point 4 current", "", "current"),
        Param("Vp1", 0.2, "pu", "VDL2 point 1 voltage"), Param("Ip1", 2.0, "pu (Sn)", "VDL2 point 1 current", "", "current"),
        Param("Vp2", 0.4, "pu", "VDL2 point 2 voltage"), Param("Ip2", 4.0, "pu (Sn)", "VDL2 point 2 current", "", "current"),
        Param("Vp3", 0.8, "pu", "VDL2 point 3 voltage"), Param("Ip3", 8.0, "pu (Sn)", "VDL2 point 3 current", "", "current"),
        Param("Vp4", 1.0, "pu", "VDL2 point 4 voltage"), Param("Ip4", 12.0, "pu (Sn)", "VDL2 point 4 current", "", "current"),
        Param("tpfilt", 0.02, "s", "power reference filter time constant (ANDES config)", "pos"),
        Param("kqs", 2.0, "pu/pu", "tracking gain of the Q PI (ANDES config)", "nonneg"),
        Param("kvs", 2.0, "pu/pu", "tracking gain of the V PI (ANDES config)", "nonneg"),
        Param("vdl_np", 1.0, "-", "VDL table also limits the non-priority current (1: WECC, 0: ANDES 2.0)",
              "nonneg"),
        Param("rates_per_s", 0.0, "-", "1: dPmax, dPmin bound dPref/dt [pu/s on Sn] (PSS/E, WECC); "
              "0: they bound tpfilt*dPref/dt (ANDES 2.0)", "flag"),
    )

    #: PSS/E .dyr record after ``IBUS 'REECA1' ID`` (PSS/E Model Library, REECA1): ICONs BUSR (bus
    #: of the voltage measurement, 0 = local), PFFLAG, VFLAG, QFLAG, PFLAG, PQFLAG; 45 CONs.
    psse_record = ("_BUSR", "PFFLAG", "VFLAG", "QFLAG", "PFLAG", "PQFLAG",
                   "Vdip", "Vup", "Trv", "dbd1", "dbd2", "Kqv", "Iqh1", "Iql1", "Vref0", "Iqfrz", "Thld",
                   "Thld2", "Tp", "QMax", "QMin", "VMAX", "VMIN", "Kqp", "Kqi", "Kvp", "Kvi", "Vref1", "Tiq",
                   "dPmax", "dPmin", "PMAX", "PMIN", "Imax", "Tpord",
                   "Vq1", "Iq1", "Vq2", "Iq2", "Vq3", "Iq3", "Vq4", "Iq4",
                   "Vp1", "Ip1", "Vp2", "Ip2", "Vp3", "Ip3", "Vp4", "Ip4")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E record -> parameters. ``BUSR = 0`` (or the converter's own bus) is PSS/E's local
        voltage measurement; another bus is refused (remote sensing is not implemented). The ramp
        limits ``dPmax``, ``dPmin`` keep their PSS/E meaning (pu/s on MBASE:
        ``rates_per_s = 1``); the current limiter is WECC's (``vdl_np = 1``, the default)."""
        v = dict(values)
        busr = v.pop("_BUSR")
        if busr not in (0, ctx.bus):
            raise DataError(ctx.where, "BUSR", busr,
                            "remote voltage measurement (ICON 1) is not implemented; give 0 (local: the "
                            "converter's terminal bus)")
        v["rates_per_s"] = 1.0
        return v

    @classmethod
    def psse_link(cls, values, ctx):
        """Link of a PSS/E record: the REGCA1 of the same generator (IBUS, ID), by its weakgrid
        name ``ctx.names["REGCA1"]`` (the records already built at that generator)."""
        name = getattr(ctx, "names", {}).get(cls.controlled)
        if name is None:
            raise DataError(ctx.where, "ID", ctx.id,
                            f"a {cls.__name__} drives the {cls.controlled} of its generator: give a "
                            f"{cls.controlled} record for bus {ctx.bus} id '{ctx.id}'")
        return {"reg": name}
    states = ("s0", "S1", "PIQ", "s4", "pfilt", "s5", "PIV")
    outputs = ("Ipcmd", "Iqcmd", "Ipmax", "Iqmax", "Iqinj", "Pord", "Volt_dip", "Qsel", "PIQ_y", "PIV_y",
               "fThld2", "s4_y", "Pref")

    # ------------------------------------------------------------------ import
    @classmethod
    def andes_link(cls, m, k, dev_name, ss=None, **_):
        """Link of ANDES device ``k``: the weakgrid name of its converter (``reg``).

        ``busr`` empty is local sensing; so is ``busr = 0`` when the case has no bus 0: ANDES's
        PSS/E parser copies the ICON BUSR, whose 0 is PSS/E's "local" (before, such a record was
        refused as remote sensing)."""
        name = dev_name.get((cls.controlled, m.reg.v[k]))
        if name is None:
            if m.reg.v[k] in list(getattr(m.system, cls.controlled).idx.v):
                return None      # its converter is out of service
            raise DataError(f"ANDES {cls.__name__} {m.idx.v[k]}", "reg", m.reg.v[k],
                            f"no {cls.controlled} with this idx; only {cls.controlled} converters are supported")
        busr = m.busr.v[k] if getattr(m, "busr", None) is not None else None
        if busr == 0 and ss is not None and 0 not in list(ss.Bus.idx.v):
            busr = None                              # PSS/E's BUSR = 0: local
        if busr not in (None, ""):
            raise DataError(f"ANDES {cls.__name__} {m.idx.v[k]}", "busr", m.busr.v[k],
                            "remote voltage sensing is not supported; leave it empty")
        return {"reg": name}

    @classmethod
    def andes_params(cls, m, k, ss, values):
        """Add ANDES's configuration constants (``tpfilt``, ``kqs``, ``kvs``)."""
        for f in ("tpfilt", "kqs", "kvs"):
            if f in [p.name for p in cls.params] and hasattr(m.config, f):
                values[f] = float(getattr(m.config, f))
        if "vdl_np" in [p.name for p in cls.params]:
            values["vdl_np"] = 0.0      # ANDES 2.0's current limiter (see the module docstring)
        return values

    def add_reeca1(self, name, reg, **params):
        """Add one electrical control driving the REGCA1 named ``reg``."""
        self.add(name, {"reg": reg}, params)
        return name

    # ------------------------------------------------------------------- setup
    def setup(self, system):
        super().setup(system)
        self._setup_links(system)

    def _setup_links(self, system):
        p = self.p
        regc = system.components.get(self.controlled)
        self.reg = np.zeros(self.n, int)
        for i, lk in enumerate(self.links):
            if regc is None or lk.get("reg") not in regc.names:
                raise DataError(self.element(i), "reg", lk.get("reg"),
                                f"give the name of a {self.controlled} of the system")
            self.reg[i] = regc.names.index(lk["reg"])
        if len(set(self.reg.tolist())) != self.n:
            raise DataError(self.element(0), "reg", [lk["reg"] for lk in self.links],
                            "one electrical control per converter")
        self.regc = regc
        self.bus = regc.bus[self.reg]
        c = regc.p["Sn"][self.reg] / system.Sb
        for prm in self.params:
            if prm.base in ("power", "current"):
                p[prm.name] = p[prm.name] * c
        self.Imaxr = np.where(p["Imax"] <= 0, BIG, p["Imax"])

        def monotone(v, i):
            return np.all([(p[f"{v}{j}"] <= p[f"{v}{j + 1}"]) & (p[f"{i}{j}"] <= p[f"{i}{j + 1}"])
                           for j in (1, 2, 3)], axis=0)

        self.zVDL1 = monotone("Vq", "Iq")
        self.zVDL2 = monotone("Vp", "Ip")
        self.s0b = Lag(1.0, p["Trv"])
        self.S1b = Lag(1.0, p["Tp"])
        self.s4b = Lag(1.0, p["Tiq"])
        per_s = p["rates_per_s"] > 0      # PSS/E's dP/dt limits on the LagRate's tpfilt*dP/dt
        self.pfb = LagRate(1.0, p["tpfilt"], np.where(per_s, p["dPmin"] * p["tpfilt"], p["dPmin"]),
                           np.where(per_s, p["dPmax"] * p["tpfilt"], p["dPmax"]))
        self.s5b = Lag(1.0, p["Tpord"])
        self.PIQb = PITrackAW(p["Kqp"], p["Kqi"], p["kqs"])
        self.PIVb = PITrackAW(p["Kvp"], p["Kvi"], p["kvs"])
        self.Thld_abs = np.abs(p["Thld"])

    def limits(self):
        return [(self.idx("s5"), self.p["PMIN"], self.p["PMAX"])]

    limit_fields = {"s5": ("PMIN", "PMAX")}

    def pattern(self, system):
        rc = self.regc
        out = []
        for i in range(self.n):
            v = self.instance_states(i) + rc.instance_states(self.reg[i]) + system.bus_vars(self.bus[i])
            out.append((v, v))
        return out

    # ------------------------------------------------------------ current limit
    def _vdl(self, s0):
        xp, p = self.xp, self.p
        vdl1 = piecewise_linear(s0, [p["Vq1"], p["Vq2"], p["Vq3"], p["Vq4"]],
                                [p["Iq1"], p["Iq2"], p["Iq3"], p["Iq4"]], xp)
        vdl2 = piecewise_linear(s0, [p["Vp1"], p["Vp2"], p["Vp3"], p["Vp4"]],
                                [p["Ip1"], p["Ip2"], p["Ip3"], p["Ip4"]], xp)
        iq1 = xp.where(self.zVDL1, xp.minimum(vdl1, self.Imaxr), BIG)
        ip1 = xp.where(self.zVDL2, xp.minimum(vdl2, self.Imaxr), BIG)
        return iq1, ip1

    # ------------------------------------------------- variant hooks (REECB1)
    def _vdiv(self, v, s0y):
        """Voltage dividing the power orders into currents: ``max(v, 0.01)``, the terminal
        voltage (ANDES 2.0)."""
        return self.xp.where(v <= 0.01, 0.01, v)

    def _piq0(self, v):
        """Initial state of the Q PI (``Qerr = 0`` there): 0 (ANDES), or the nearest value within
        its output limits ``[VMIN, VMAX]`` when 0 is outside them (a state outside its limits
        is driven by the tracking anti-windup: no steady start)."""
        return np.clip(0.0, self.p["VMIN"], self.p["VMAX"])

    def _qref0(self, v, vp):
        """Initial Q reference (ANDES: ``q0`` with QFLAG = 0, ``Vref1 - v0`` with QFLAG = 1)."""
        p = self.p
        return -np.where(p["QFLAG"] > 0, v - p["Vref1"], self.Iqcmd0 * vp)

    def _vsel(self, piq, pfsel):
        xp, p = self.xp, self.p
        return xp.clip(xp.where(p["VFLAG"] > 0, piq, p["Vref1"] + pfsel), p["VMIN"], p["VMAX"])

    def _piv_input(self, vsel, s0y):
        xp, p = self.xp, self.p
        return xp.where(p["QFLAG"] > 0, vsel - xp.where(p["VFLAG"] > 0, 0.0, s0y), 0.0)

    def _iqinj(self, iqv, dip, t):
        xp, p = self.xp, self.p
        run = ~dip
        ext = run & ((self._dip_prev & (self.Thld_abs > 0)) | (t < self._t_thld))
        iqinj = xp.where(dip, iqv, xp.where(ext, xp.where(p["Thld"] < 0, iqv,
                                                          xp.where(p["Thld"] > 0, p["Iqfrz"], 0.0)), 0.0))
        return xp.clip(iqinj, p["Iql1"], p["Iqh1"])

    # -------------------------------------------------------------------- init
    def init(self, system, x, sig):
        p = self.p
        rc = self.regc
        r = self.reg
        pf = system.network.pf
        v = np.abs(pf.V[self.bus])
        self.p0, self.q0 = rc.p0[r], rc.q0[r]
        vp = np.where(v <= 0.01, 0.01, v)
        self.Ipcmd0 = self.p0 / v
        self.Iqcmd0 = -self.q0 / v
        self.Ip_offset = rc.Ipcmd0[r] - self.Ipcmd0      # 0 unless LVG(v0) < 1 (see module doc)
        self.pfaref0 = np.arctan2(self.q0, self.p0)
        self.zp = self.p0 == 0
        qflag = p["QFLAG"] > 0
        self.Qref0 = self._qref0(v, vp)
        self.Vref0r = np.where(p["Vref0"] == 0, v, p["Vref0"])
        self.Pref0 = self.p0
        for i in np.nonzero((v < p["Vdip"]) | (v > p["Vup"]))[0]:
            raise DataError(self.element(i), "Vdip", p["Vdip"][i],
                            f"the initial voltage {v[i]:.4g} pu is outside [Vdip, Vup] = "
                            f"[{p['Vdip'][i]:g}, {p['Vup'][i]:g}]: the control would start frozen in a "
                            "voltage dip; widen the band")
        x[self.sl(0)] = v
        x[self.sl(1)] = self.p0
        x[self.sl(2)] = self._piq0(v)
        qcpf = np.where(self.zp, self.q0, self.p0 * np.tan(self.pfaref0))
        pfsel = np.where(p["PFFLAG"] > 0, qcpf, self.Qref0)
        x[self.sl(3)] = pfsel / vp
        x[self.sl(4)] = self.Pref0
        x[self.sl(5)] = self.Pref0
        x[self.sl(6)] = np.where(qflag, -self.Iqcmd0, 0.0)
        # the limits at the initial point (held values start there)
        iq1, ip1 = self._vdl(v)
        pri = p["PQFLAG"] > 0
        np_ = p["vdl_np"] > 0
        ipmax = np.where(pri, ip1, np.minimum(np.where(np_, ip1, BIG),
                                              np.sqrt(np.maximum(self.Imaxr ** 2 - self.Iqcmd0 ** 2, 0))))
        iqmax = np.where(pri, np.minimum(np.where(np_, iq1, BIG),
                                         np.sqrt(np.maximum(self.Imaxr ** 2 - self.Ipcmd0 ** 2, 0))), iq1)
        qsel0 = np.where(qflag, -self.Iqcmd0, pfsel / vp)
        bad = (self.Ipcmd0 > ipmax + 1e-9) | (np.abs(qsel0) > iqmax + 1e-9)
        for i in np.nonzero(bad)[0]:
            raise DataError(self.element(i), "Imax", float(p["Imax"][i]),
                            f"the initial currents (Ip = {self.Ipcmd0[i]:.4g}, Iq = {-self.Iqcmd0[i]:.4g} pu) "
                            f"exceed the current limits (Ipmax = {ipmax[i]:.4g}, Iqmax = {iqmax[i]:.4g} pu); "
                            "raise Imax or the VDL tables")
        # discrete memory (updated at accepted steps, see accept())
        self._dip_prev = np.zeros(self.n, bool)
        self._t_thld = np.full(self.n, -np.inf)
        self._t_thld2 = np.full(self.n, -np.inf)
        self._piq_hold = x[self.sl(2)].copy()
        self._piv_hold = x[self.sl(6)].copy()
        self._ipmax_hold = ipmax.copy()
        self._s4_hold = pfsel / vp
        self._pord_hold = self.Pref0.copy()
        self._fthld2_prev = np.zeros(self.n, bool)
        self._dip_start_t = np.full(self.n, -np.inf)

    # --------------------------------------------------------------- equations
    def compute(self, ctx):
        xp, p, x, sl = self.xp, self.p, ctx.x, self._sls
        s0, S1, xq, s4, pfl, s5, xv = (x[..., sl[k]] for k in range(7))
        r = self.reg
        v = take(xp, ctx.sig["REGCA1.v"], r)
        Pe = take(xp, ctx.sig["REGCA1.Pe"], r)
        Qe = take(xp, ctx.sig["REGCA1.Qe"], r)
        pext = ctx.sig.get(f"{self.type_name}.Pext", 0.0)
        qext = ctx.sig.get(f"{self.type_name}.Qext", 0.0)
        t = ctx.t
        dip = (v < p["Vdip"]) | (v > p["Vup"])
        run = ~dip
        s0y = self.s0b.output(s0, v)
        vp = self._vdiv(v, s0y)
        S1y = self.S1b.output(S1, Pe)
        # reactive power
        qref = self.Qref0 + qext
        qcpf = xp.where(self.zp, self.q0, S1y * xp.tan(self.pfaref0))
        pfsel = xp.where(p["PFFLAG"] > 0, qcpf, qref)
        qerr = xp.clip(pfsel, p["QMin"], p["QMax"]) - Qe
        vflag, qflag = p["VFLAG"] > 0, p["QFLAG"] > 0
        uq = xp.where(vflag, qerr, 0.0)
        piq = xp.where(dip, self._piq_hold, self.PIQb.output(xq, uq, p["VMIN"], p["VMAX"]))
        vsel = self._vsel(piq, pfsel)
        s4y = self.s4b.output(s4, pfsel / vp)
        s4y = xp.where(dip & (p["Tiq"] <= 0), self._s4_hold, s4y)     # a frozen pass-through holds
        # voltage-dip reactive current injection
        iqv = p["Kqv"] * deadband(self.Vref0r - s0y, p["dbd1"], p["dbd2"], xp)
        iqinj = self._iqinj(iqv, dip, t)
        # active power: Pref from a torque controller (WTTQA1) if any, wg from a drive train
        pref = ctx.sig.get(f"{self.type_name}.Pref", self.Pref0) + pext
        pfy = pfl                      # LagRate: output = state (tpfilt > 0)
        pfy = xp.where(p["PFLAG"] > 0, ctx.sig.get(f"{self.type_name}.wg", 1.0) * pfy, pfy)   # Psel
        # Tpord = 0: the limiter only (held in a dip, as a frozen state)
        pord = xp.where(p["Tpord"] > 0, s5, xp.where(dip, self._pord_hold, xp.clip(pfy, p["PMIN"], p["PMAX"])))
        # current limiter
        iq1, ip1 = self._vdl(s0y)
        fthld2 = run & ((self._dip_prev & (p["Thld2"] > 0)) | (t < self._t_thld2))
        pri = p["PQFLAG"] > 0
        I2 = self.Imaxr ** 2
        uv = self._piv_input(vsel, s0y)
        # Q priority: Iq first
        iqmax_q = iq1
        piv_q = xp.where(dip, self._piv_hold, self.PIVb.output(xv, uv, -iqmax_q, iqmax_q))
        iqcmd_q = xp.clip(xp.where(qflag, piv_q, s4y) + iqinj, -iqmax_q, iqmax_q)
        np_ = p["vdl_np"] > 0
        ipmax_q = xp.minimum(xp.where(np_, ip1, BIG), xp.sqrt(xp.maximum(I2 - iqcmd_q ** 2, 0.0)))
        # P priority: Ip first
        ipmax_p = ip1
        ipmax = xp.where(pri, ipmax_p, ipmax_q)
        ipmax = xp.where(fthld2, self._ipmax_hold, ipmax)
        ipcmd = xp.clip(pord / vp, 0.0, ipmax)
        iqmax_p = xp.minimum(xp.where(np_, iq1, BIG), xp.sqrt(xp.maximum(I2 - ipcmd ** 2, 0.0)))
        piv_p = xp.where(dip, self._piv_hold, self.PIVb.output(xv, uv, -iqmax_p, iqmax_p))
        iqcmd_p = xp.clip(xp.where(qflag, piv_p, s4y) + iqinj, -iqmax_p, iqmax_p)
        iqmax = xp.where(pri, iqmax_p, iqmax_q)
        iqcmd = xp.where(pri, iqcmd_p, iqcmd_q)
        piv = xp.where(pri, piv_p, piv_q)
        qsel = xp.where(qflag, piv, s4y)
        put(xp, ctx.sig["REGCA1.Ipcmd"], r, ipcmd + self.Ip_offset)
        put(xp, ctx.sig["REGCA1.Iqcmd"], r, -iqcmd)
        # derivatives
        f = ctx.f
        frz = xp.where(dip, xp.asarray(0.0, dtype=xp.float64), 1.0)
        f[..., sl[0]] = self.s0b.deriv(s0, v)
        f[..., sl[1]] = self.S1b.deriv(S1, Pe)
        f[..., sl[2]] = frz * self.PIQb.deriv(xq, uq, p["VMIN"], p["VMAX"])
        f[..., sl[3]] = frz * self.s4b.deriv(s4, pfsel / vp)
        f[..., sl[4]] = self.pfb.deriv(pfl, pref)
        f[..., sl[5]] = frz * self.s5b.deriv(s5, pfy)
        f[..., sl[6]] = frz * self.PIVb.deriv(xv, uv, -iqmax, iqmax)
        o = ctx.out
        tn = self.type_name
        o[f"{tn}.Ipcmd"], o[f"{tn}.Iqcmd"] = ipcmd, iqcmd
        o[f"{tn}.Ipmax"], o[f"{tn}.Iqmax"] = ipmax, iqmax
        o[f"{tn}.Iqinj"], o[f"{tn}.Pord"] = iqinj, pord
        o[f"{tn}.Volt_dip"] = xp.astype(dip, xp.float64)
        o[f"{tn}.Qsel"], o[f"{tn}.PIQ_y"], o[f"{tn}.PIV_y"] = qsel, piq, piv
        o[f"{tn}.fThld2"] = xp.astype(fthld2, xp.float64)
        o[f"{tn}.s4_y"] = s4y
        o[f"{tn}.Pref"] = pref

    def accept(self, t, ctx):
        """Update the discrete memory at an accepted point: dip end times, held values."""
        xp, o = self.xp, ctx.out
        tn = self.type_name
        dip = o[f"{tn}.Volt_dip"] > 0.5
        ended = self._dip_prev & ~dip
        self._t_thld = xp.where(ended, t + self.Thld_abs, self._t_thld)
        self._t_thld2 = xp.where(ended, t + self.p["Thld2"], self._t_thld2)
        self._dip_prev = dip
        run = ~dip
        self._piq_hold = xp.where(run, o[f"{tn}.PIQ_y"], self._piq_hold)
        self._piv_hold = xp.where(run, o[f"{tn}.PIV_y"], self._piv_hold)
        self._s4_hold = xp.where(run, o[f"{tn}.s4_y"], self._s4_hold)
        self._pord_hold = xp.where(run, o[f"{tn}.Pord"], self._pord_hold)
        f2 = o[f"{tn}.fThld2"] > 0.5
        self._ipmax_hold = xp.where(f2, self._ipmax_hold, o[f"{tn}.Ipmax"])
