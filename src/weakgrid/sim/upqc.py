"""UPQC: a series voltage source inside a network branch and (conventional structure) a shunt
converter with a dc link.

The UPQC sits in branch ``branch`` of the case (from-bus = shunt bus ``r``,
to-bus = bus 1, series impedance ``Zu = R + jX`` of that branch = the series
transformer leakage). The network keeps the branch impedance; the series converter adds::

    Vu = (Vuq + j*Vup) * exp(j*theta_r),   |Vu| <= Vmax  (scaled down on the limit)
    I  = (Vr + Vu - V1)/Zu                   branch current r -> 1
    injections: +Vu/Zu at bus 1, -Vu/Zu at bus r           (Norton equivalent of Vu)
    P_series = Re(Vu * conj(I)),  Q_series = Im(Vu * conj(I)),  S_series = |Vu|*|I|

``Vuq`` is in phase with the shunt-bus voltage, ``Vup`` in quadrature (the
paper's u = [u1, u2] = [Vup, Vuq]). The series converter's losses follow the paper's (15):
the power it draws from its dc side is ``(1 + chi)*P_series`` while it delivers power
(``P_series >= 0``); a loss is never a source, so while it absorbs power it returns
``(1 - chi)*|P_series|`` (together: ``P_dc = P_series + chi*|P_series|``).

Where the series converter's dc power ``P_dc`` comes from:

* ``structure="conventional"``: the shunt converter at bus r and the dc-link capacitor
  between the two converters (states ``Vdc``, ``xi_dc``)::

      Cdc*Vdc*dVdc/dt = P_shunt - P_loss - P_dc           (energy Cdc*Vdc^2/2, pu·s on Sb)
      P_ref   = P_dc + kp_dc*(Vdc0 - Vdc) + xi_dc           (feed-forward + dc-voltage PI)
      d(xi_dc)/dt = ki_dc*(Vdc0 - Vdc)                       (held while the current limit binds)
      I_shunt = clip(P_ref/|Vr|, -Imax, Imax)                 (active current, in phase with Vr)
      P_shunt = I_shunt*|Vr|,  P_loss = Rsh*I_shunt^2,  S_shunt = |I_shunt|*|Vr|

  The shunt converter draws ``I_shunt*Vr/|Vr|`` from bus r (no reactive current). The series
  voltage the link can carry shrinks with it: ``|Vu| <= Vmax*min(1, Vdc/Vdc0)`` (the
  converter's modulation limit), so a link drained while the current limit binds lowers
  ``|Vu|`` and with it the series power, rather than running below zero. With
  ``chi = Rsh = 0`` and the limit not reached, ``P_shunt = P_series`` at every instant and the
  dc link stays at ``Vdc0``: the lossless constant-power draw of the ideal model. The law is
  :func:`shunt_dc_law` (and the modulation limit :func:`link_vmax`), which the DPsim engines
  step between their steps too (:mod:`weakgrid.sim.emt.upqc`).
* ``structure="reduced"``: drawn from the dc link of GTI ``gti``, entering its
  balance ``C*Vc*dVc/dt = Pin - Pe - P_dc`` (the UPQC's own dc-link states stay constant).

The inputs ``Vup``, ``Vuq`` [pu] are held values set by a digital controller
(:mod:`weakgrid.sim.controllers`) or directly via :meth:`set_input`.
"""

from __future__ import annotations

import math

import numpy as np

from .component import Component, fast_index
from .errors import DataError
from .namespace import add_at, take
from .network import BR_B, BR_R, BR_X, F_BUS, SHIFT, T_BUS, TAP
from .params import Param


def rating_clip(u, Vmax):
    """``u = [Vup, Vuq]`` [pu] (or rows of them) scaled down to ``|u| <= Vmax`` as the UPQC
    applies it: ``u·min(1, Vmax/|u|)`` with ``|u| = hypot(Vup, Vuq)`` (``Vmax = inf``: u).

    This is the rating clip of the exported digital controller
    (:mod:`weakgrid.models.export_digital`, same operations).
    """
    u = np.asarray(u, float)
    mag = np.hypot(u[..., 0], u[..., 1])
    return u * np.minimum(1.0, Vmax / np.where(mag > 0, mag, 1.0))[..., None]


def series_dc_power(P, chi, xp=np):
    """The series converter's dc-side power [pu on Sb] for its ac power ``P`` (to the line):
    ``P + chi*|P|`` — the paper's ``(1 + chi)*P`` while it delivers power (15), and a loss
    (never a gain) while it absorbs power."""
    return P + chi * xp.abs(P)


def link_vmax(Vmax, Vdc, Vdc0, xp=np):
    """The series voltage [pu] the dc link at ``Vdc`` [pu] can carry (the converter's
    modulation limit): ``Vmax*min(1, max(Vdc, 0)/Vdc0)`` (conventional structure)."""
    return xp.where(Vdc < Vdc0, Vmax * xp.maximum(Vdc, 0.0) / Vdc0, Vmax)


def shunt_dc_law(Pdc, Vdc, xi_dc, vr_abs, vr_safe, p, xp=np):
    """The conventional UPQC's shunt converter and dc link (the module docstring's equations),
    the one law every engine evaluates.

    Parameters
    ----------
    Pdc : array_like
        The series converter's dc power [pu on Sb] (:func:`series_dc_power`).
    Vdc, xi_dc : array_like
        The dc-link states: voltage [pu of ``Vdc0``'s base] and the dc-voltage loop's integral
        [pu on Sb].
    vr_abs, vr_safe : array_like
        The shunt-bus voltage magnitude ``|Vr|`` [pu], and the same kept off zero (the divisor).
    p : mapping
        ``Vdc0``, ``kp_dc``, ``ki_dc``, ``Imax`` (0: no limit), ``Rsh``, ``Cdc``
        (:attr:`UPQC.params`).
    xp : module
        The arrays' namespace (:mod:`weakgrid.sim.namespace`).

    Returns
    -------
    tuple of arrays
        ``(I_shunt, limited, P_shunt, P_loss, dVdc/dt, dxi_dc/dt)``: the active current [pu on
        Sb] drawn from bus r in phase with ``Vr``, whether the current limit binds (bool), the
        powers [pu on Sb] and the two derivatives [1/s].
    """
    err = p["Vdc0"] - Vdc
    Id = (Pdc + p["kp_dc"] * err + xi_dc) / vr_safe
    imax = xp.where(p["Imax"] > 0, p["Imax"], math.inf)   # 0: no limit
    over = xp.abs(Id) > imax
    limited = xp.any(over)
    if limited:
        Id = xp.clip(Id, -imax, imax)
    Psh = Id * vr_abs
    Ploss = p["Rsh"] * Id ** 2
    Vdcs = Vdc if xp.all(Vdc > 1e-6) else xp.maximum(Vdc, 1e-6)   # Vdc: an array or a float (EMT)
    dVdc = (Psh - Ploss - Pdc) / (p["Cdc"] * Vdcs)
    dxi = p["ki_dc"] * err
    if limited:
        dxi = xp.where(over, 0.0, dxi)
    return Id, over, Psh, Ploss, dVdc, dxi


class UPQC(Component):
    """Vectorized UPQCs (series converter, and the shunt converter with its dc link in the
    conventional structure); add instances with :meth:`add_upqc`."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    #: the series-voltage commands [pu] a controller holds: per member in a batch
    batch_inputs = ("u_p", "u_q")
    #: the device's rating, current limit and dc link may differ per member of a batch (a
    #: sweep over the rating)
    batch_params = ("Vmax", "Imax", "Cdc", "kp_dc", "ki_dc", "Rsh")

    #: the last evaluation's values (not the grid's data)
    scratch = ("_f",)

    kind = "device"
    order = 3
    params = (
        Param("Vmax", 0.2, "pu", "series voltage rating |Vu|max", "pos"),
        Param("chi", 0.0, "pu", "series-converter loss factor chi of (15): P_dc = (1+chi)*P_series "
              "while delivering power", "nonneg"),
        Param("Cdc", 0.01, "pu·s (Sb)", "dc-link capacitance (energy Cdc*Vdc^2/2 in pu·s; "
              "conventional structure)", "pos"),
        Param("Vdc0", 1.0, "pu", "dc-link voltage set-point", "pos"),
        Param("kp_dc", 1.0, "pu/pu", "dc-voltage loop proportional gain (shunt P_ref per pu of "
              "Vdc0 - Vdc)", "nonneg"),
        Param("ki_dc", 10.0, "pu/(pu·s)", "dc-voltage loop integral gain", "nonneg"),
        Param("Imax", 0.0, "pu (Sb)", "shunt-converter current limit (active current "
              "magnitude; 0: no limit)", "nonneg"),
        Param("Rsh", 0.0, "pu (Sb)", "shunt-converter loss resistance: P_loss = Rsh*I_shunt^2",
              "nonneg"),
    )
    states = ("Vdc", "xi_dc")
    outputs = ("Vup", "Vuq", "Vu", "I", "P_series", "Q_series", "S_series", "P_dc", "P_shunt",
               "S_shunt", "I_shunt", "P_loss", "P_line", "limited")
    units = {"P_series": "power", "Q_series": "power", "S_series": "apparent", "P_dc": "power",
             "P_shunt": "power", "S_shunt": "apparent", "P_loss": "power", "P_line": "power",
             "I": "current", "I_shunt": "current", "Vdc": "pu", "xi_dc": "power"}

    def add_upqc(self, name, branch, structure="conventional", gti=None, **params):
        """Add a UPQC in 0-based branch row ``branch`` (from-bus = shunt bus r).

        Parameters
        ----------
        structure : {"conventional", "reduced"}
        gti : str, optional
            Name of the GTI whose dc link feeds the series converter (reduced structure).
        **params
            Values of :attr:`params` (system base).
        """
        el = f"UPQC '{name}'"
        if structure not in ("conventional", "reduced"):
            raise DataError(el, "structure", structure, "use 'conventional' or 'reduced'")
        if structure == "reduced" and gti is None:
            raise DataError(el, "gti", None, "the reduced structure needs the name of the GTI feeding it")
        self.add(name, {"branch": branch, "structure": structure, "gti": gti}, params)
        return name

    def setup(self, system):
        super().setup(system)
        net = system.network
        n = self.n
        self.branch = np.zeros(n, int)
        self.r = np.zeros(n, int)
        self.b1 = np.zeros(n, int)
        self.yu = np.zeros(n, complex)
        self.reduced = np.zeros(n, bool)
        self.gti_i = np.zeros(n, int)
        for i, lk in enumerate(self.links):
            k = lk["branch"]
            if not (isinstance(k, (int, np.integer)) and 0 <= k < net.nl):
                raise DataError(self.element(i), "branch", k, f"give a branch row 0..{net.nl - 1}")
            row = net.branch[k]
            if row[BR_B] != 0 or row[TAP] not in (0, 1) or row[SHIFT] != 0:
                raise DataError(self.element(i), "branch", k,
                                "the UPQC branch must be a plain series impedance (B = 0, TAP = 0/1, SHIFT = 0)")
            self.branch[i] = k
            self.r[i] = net.index_of(int(row[F_BUS]))
            self.b1[i] = net.index_of(int(row[T_BUS]))
            self.yu[i] = 1.0 / complex(row[BR_R], row[BR_X])
            if lk["structure"] == "reduced":
                gti = system.components.get("GTI")
                if gti is None or lk["gti"] not in gti.names:
                    raise DataError(self.element(i), "gti", lk["gti"], "no GTI with that name in the system")
                self.reduced[i] = True
                self.gti_i[i] = gti.names.index(lk["gti"])
        self.u_p = np.zeros(n)
        self.u_q = np.zeros(n)
        self._conv = ~self.reduced
        self._any_conv = bool(self._conv.any())
        self._any_red = bool(self.reduced.any())
        self._uniq = len(set(self.r.tolist()) | set(self.b1.tolist())) == 2 * n
        self._all_conv = bool(self._conv.all())
        self._any_chi = bool((self.p["chi"] > 0).any())
        self._uniq_g = len(set(self.gti_i[self.reduced].tolist())) == int(self.reduced.sum())
        # the buses as slices where they can be (basic indexing: no gather per evaluation)
        self._ri, self._b1i = (fast_index(self.r), fast_index(self.b1)) if self._uniq else (self.r, self.b1)
        self._r_conv = fast_index(self.r[self._conv]) if self._uniq else self.r[self._conv]
        self._conv_i = np.nonzero(self._conv)[0]     # the conventional instances, the reduced
        self._red_i = np.nonzero(self.reduced)[0]    # ones and the GTIs feeding them
        self._gti_red = self.gti_i[self.reduced]

    def set_input(self, name, Vup, Vuq):
        """Hold series-voltage commands ``Vup`` (quadrature) and ``Vuq`` (in phase) [pu] for UPQC ``name``."""
        i = self.names.index(name)
        self.u_p[i] = Vup
        self.u_q[i] = Vuq

    def init(self, system, x, sig):
        x[self.sl(0)] = self.p["Vdc0"]
        x[self.sl(1)] = 0.0

    def pattern(self, system):
        groups = []
        gti = system.components.get("GTI")
        for i in range(self.n):
            own = self.instance_states(i)
            cols = system.bus_vars(self.r[i]) + system.bus_vars(self.b1[i]) + own
            rows = list(cols)
            if self.reduced[i]:
                rows.append(gti.idx("Vc")[self.gti_i[i]])
            groups.append((rows, cols))
        return groups

    def compute(self, ctx):
        xp, p = self.xp, self.p
        on = take(xp, ctx.system.branch_status, self.branch)
        Vr = take(xp, ctx.V, self._ri)
        V1 = take(xp, ctx.V, self._b1i)
        vr_abs = xp.abs(Vr)
        if xp.all(vr_abs > 1e-6):      # fast path (same values as the guarded expressions)
            ur = Vr / vr_abs
            vr_safe = vr_abs
        else:
            ur = xp.where(vr_abs > 1e-9, Vr / xp.where(vr_abs > 1e-9, vr_abs, 1.0), 1.0 + 0j)
            vr_safe = xp.maximum(vr_abs, 1e-6)
        Vu = (self.u_q + 1j * self.u_p) * ur
        mag = xp.abs(Vu)
        Vmax = p["Vmax"]
        conv = self._conv
        if self._any_conv:   # the series voltage the dc link can carry: Vmax at Vdc >= Vdc0
            Vdc = ctx.x[..., self.sl(0)]
            if xp.any(Vdc < p["Vdc0"]):
                lv = link_vmax(Vmax, Vdc, p["Vdc0"], xp)
                Vmax = lv if self._all_conv else xp.where(conv, lv, Vmax)
        if xp.any(mag > Vmax):
            Vu = Vu * xp.where(mag > Vmax, Vmax / xp.where(mag > 0, mag, 1.0), 1.0)
            mag = xp.abs(Vu)
        if not xp.all(on):
            Vu = xp.where(on, Vu, 0.0 + 0j)
            mag = xp.abs(Vu)
        Isrc = self.yu * Vu
        add_at(xp, ctx.I, self._b1i, Isrc, self._uniq)
        add_at(xp, ctx.I, self._ri, -Isrc, self._uniq)
        I = self.yu * (Vr + Vu - V1) * xp.astype(on, xp.complex128)   # NumPy's bool * complex
        S = Vu * xp.conj(I)
        P = xp.real(S)
        Pdc = series_dc_power(P, p["chi"], xp) if self._any_chi else P
        o = ctx.out
        if self._any_conv:
            Id, over, Psh, Ploss, dVdc, dxi = shunt_dc_law(Pdc, Vdc, ctx.x[..., self.sl(1)],
                                                          vr_abs, vr_safe, p, xp)
            if self._all_conv:
                add_at(xp, ctx.I, self._r_conv, -(Id * ur), self._uniq)
            else:
                Id, Psh, Ploss, dVdc, dxi = (xp.where(conv, a, 0.0)
                                             for a in (Id, Psh, Ploss, dVdc, dxi))
                over = over & conv
                add_at(xp, ctx.I, self._r_conv, take(xp, -(Id * ur), self._conv_i), self._uniq)
            self._f = (dVdc, dxi)
            o["UPQC.P_shunt"], o["UPQC.S_shunt"] = Psh, xp.abs(Psh)
            o["UPQC.I_shunt"], o["UPQC.P_loss"] = Id, Ploss
            o["UPQC.limited"] = xp.astype(over, xp.float64)
        else:
            zero = xp.zeros_like(P)
            self._f = (zero, zero)
            o["UPQC.P_shunt"] = o["UPQC.S_shunt"] = o["UPQC.I_shunt"] = zero
            o["UPQC.P_loss"] = o["UPQC.limited"] = zero
        if self._any_red:
            add_at(xp, ctx.sig["gti_p_series"], self._gti_red, take(xp, Pdc, self._red_i),
                   self._uniq_g)
        rot = Vu * xp.conj(ur)
        Iabs = xp.abs(I)
        o["UPQC.Vuq"], o["UPQC.Vup"], o["UPQC.Vu"] = xp.real(rot), xp.imag(rot), mag
        o["UPQC.I"], o["UPQC.P_series"], o["UPQC.Q_series"] = Iabs, P, xp.imag(S)
        o["UPQC.S_series"], o["UPQC.P_dc"] = mag * Iabs, Pdc
        o["UPQC.P_line"] = xp.real((Vr + Vu) * xp.conj(I))

    def finish(self, ctx):
        dVdc, dxi = self._f
        ctx.f[..., self.sl(0)] = dVdc
        ctx.f[..., self.sl(1)] = dxi
