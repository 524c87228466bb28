"""The UPQC (conventional structure) in DPsim: a series voltage source and its shunt converter
with the dc link between them.

weakgrid's UPQC (:mod:`weakgrid.sim.upqc`) inserts ``Vu = (Vuq + j Vup) e^{j theta_r}`` in its
branch, at the shunt bus ``r``; its series converter pays ``P_dc = P_series + chi |P_series|``
(:func:`~weakgrid.sim.upqc.series_dc_power`) from a dc link. In DPsim:

* the branch becomes ``bus r — VoltageSource(Vu) — node — R — L — bus 1``; the source's set
  point is rewritten between steps (zero-order hold over one step ``dt``) from the held inputs
  ``Vup``, ``Vuq`` after the rating clip (:func:`weakgrid.sim.upqc.rating_clip`) at the
  conventional UPQC's modulation limit ``Vmax min(1, Vdc/Vdc0)`` with the current ``Vdc``
  (:func:`weakgrid.sim.upqc.link_vmax`), and the angle ``theta_r`` of bus ``r`` measured at the
  previous step;
* the conventional structure's shunt converter is a ``CurrentSource`` at bus ``r`` drawing
  ``I_shunt`` in phase with the measured ``Vr``, and its dc link (states ``Vdc``, ``xi_dc``) is
  co-simulated with the phasor engine's own law (:func:`weakgrid.sim.upqc.shunt_dc_law`: the
  feed-forward + dc-voltage PI ``P_ref``, the current limit ``Imax``, the loss ``Rsh I²``,
  ``Cdc Vdc dVdc/dt = P_shunt − P_loss − P_dc``), stepped like the GTI's
  (:mod:`weakgrid.sim.emt.gti`): at ``t_k`` the law is evaluated at the states ``x_k`` and the
  measurements, the shunt current is set for ``[t_k, t_k + dt]`` and the states advance by
  forward Euler, ``x_{k+1} = x_k + dt f_k``.

The series power the dc link pays is the *measured* one (the convention of the GTI's default
``gti_power = "measured"``, whatever a run's ``gti_power``): ``P_series = Re(Vu conj(I))`` with
``I`` the branch current measured in DPsim's series inductor at ``t_k`` and ``Vu`` the set
point the source holds from ``t_k`` — the power the DPsim source delivers at the start of the
step the dc link is advanced over, network current transients included (the phasor engine's
``I = (Vr + Vu − V1)/Zu`` leaves them out). Without a current limit and losses (``Imax = 0``,
``chi = Rsh = 0``) ``P_shunt = P_series`` at every step and ``Vdc`` stays at ``Vdc0``: the
ideal constant-power shunt this bridge had before. When the series power spikes beyond
``Imax |Vr|`` (a fault's clearing), the link drains and the modulation limit lowers ``|Vu|``.

The phasor engine applies all of this algebraically at every instant; here the set points lag
by one step (1e-4 s by default). The reduced structure has no shunt converter: its series power
``P_dc`` (the same measured ``P_series``) is drawn from the dc link of its GTI
(:mod:`weakgrid.sim.emt.gti`, :meth:`UPQCBridge.gti_draw`); its own ``Vdc`` stays ``Vdc0``.
Recorded per UPQC: :data:`SIGNALS` with the phasor engine's names (``<upqc>.Vdc``,
``.xi_dc``, ``.P_dc``, ``.P_shunt``, ``.I_shunt``, ``.P_loss``, ``.limited``, ...).
"""

from __future__ import annotations

import math

import numpy as np

from ..network import BR_R, BR_X
from ..upqc import UPQC, link_vmax, rating_clip, series_dc_power, shunt_dc_law

#: recorded UPQC signals (the phasor engine's names ``<upqc>.<name>``), in
#: :meth:`UPQCBridge.update`'s order: the series converter's, then the dc link's states and the
#: shunt converter's
SIGNALS = ("Vup", "Vuq", "Vu", "P_series", "Vdc", "xi_dc", "P_dc", "P_shunt", "S_shunt",
           "I_shunt", "P_loss", "limited")
#: the shunt converter's dc-link parameters (weakgrid.sim.upqc.shunt_dc_law's ``p``)
_DC = ("Vdc0", "kp_dc", "ki_dc", "Imax", "Rsh", "Cdc")


class UPQCBridge:
    """The DPsim side of every UPQC of a system: sources to update between steps."""

    def __init__(self, system, kit, cir):
        self.kit, self.items = kit, []
        comp = system.components.get("UPQC")
        if comp is None or comp.n == 0:
            return
        net = system.network
        w = 2 * math.pi * net.f_hz
        off, ph = kit.d.LogLevel.off, kit.ph
        self.w = w
        for i, nm in enumerate(comp.names):
            k, r, b1 = int(comp.branch[i]), int(comp.r[i]), int(comp.b1[i])
            row = net.branch[k]
            vb = float(net.base_kv[r]) * 1e3
            zb = float(net.base_kv[r]) ** 2 / system.Sb
            Vr = cir.Vpf[r]
            mid = kit.node(f"{nm}.u", Vr)        # the source's far side (Vu = 0 at the start)
            cir.extra_nodes.append(mid)
            src = ph.VoltageSource(f"{nm}.Vu", off)
            self._set_v(src, 0j, init=True, f=net.f_hz)
            src.connect([cir.nodes[r], mid])
            cir.components.append(src)
            a = mid
            if row[BR_R] > 0:
                Is = (Vr - cir.Vpf[b1]) / (complex(row[BR_R], row[BR_X]) * zb)
                a = kit.node(f"{nm}.R", Vr - Is * row[BR_R] * zb)
                cir.extra_nodes.append(a)
                res = ph.Resistor(f"{nm}.Ru", off)
                res.set_parameters(kit.param(row[BR_R] * zb))
                res.connect([mid, a])
                cir.components.append(res)
            ind = ph.Inductor(f"{nm}.Lu", off)
            ind.set_parameters(kit.param(row[BR_X] * zb / w))
            ind.connect([a, cir.nodes[b1]])
            cir.components.append(ind)
            red = bool(comp.reduced[i])
            sh = None
            if not red:
                sh = ph.CurrentSource(f"{nm}.shunt", off)
                self._set_i(sh, 0j, init=True, f=net.f_hz)
                # injection into bus r: DPsim 1.4's DP current source drives I_ref from its
                # terminal 1 into terminal 2, its EMT one the other way (both checked by the
                # SMIB test against the phasor engine: the wrong way round the run diverges)
                sh.connect([cir.nodes[r], kit.gnd] if kit.three_phase else [kit.gnd, cir.nodes[r]])
                cir.components.append(sh)
            # the branch current is read from the series inductor (DPsim 1.4 does not update a
            # VoltageSource's i_intf in these runs: it stays 0)
            self.items.append(dict(name=nm, i=i, branch=k, r=r, src=src, sh=sh, ind=ind, mid=mid, vb=vb,
                                   ib=system.Sb * 1e6 / vb, Vmax=float(comp.p["Vmax"][i]),
                                   gti=int(comp.gti_i[i]) if red else None,
                                   chi=float(comp.p["chi"][i]),
                                   dc={q: float(comp.p[q][i]) for q in _DC},
                                   Vdc=float(comp.p["Vdc0"][i]), xi=0.0))
        self.comp = comp
        self._draw = {}
        cir.upqc_branches = {it["branch"] for it in self.items}

    # phasor → DPsim set point (EMT: three rotating phasors, same scale as the node voltages)
    def _set_v(self, src, V, init=False, f=None):
        self.kit.set_source(src, "V_ref", V, init, f)

    def _set_i(self, src, current, init=False, f=None):
        """``current`` [A, line-to-line RMS scale, ``S = V conj(I)``]. DPsim 1.4's EMT current
        source takes the line current's RMS phasor (peak ``sqrt(2) |I_ref|``, measured), a third
        of the scale's square: ``I_ref = current / sqrt(3)``; its DP one takes the scale as is."""
        self.kit.set_source(src, "I_ref", current / math.sqrt(3) if self.kit.three_phase
                            else current, init, f)

    def update(self, t, phasor_of, current_of, dt):
        """At a measurement instant ``t_k`` [s]: rewrite every UPQC's set points from its held
        inputs and the measured phasors, and advance the conventional UPQCs' dc links to
        ``t_k + dt`` (forward Euler over ``dt`` [s]).

        ``phasor_of(b)``: bus ``b``'s voltage [pu phasor]; ``current_of(element)``: the current
        [A phasor, line-to-line RMS scale] from terminal 1 to terminal 2 inside a DPsim element
        (here the branch's series inductor: from bus r towards bus 1). Returns per UPQC the
        values of :data:`SIGNALS` [pu]: the set points held over ``[t_k, t_k + dt]``, the
        powers at ``t_k`` and the dc-link states at ``t_k + dt``.
        """
        out = []
        self._draw = {}
        for it in self.items:
            i, dc = it["i"], it["dc"]
            conv = it["sh"] is not None
            vmax = float(link_vmax(it["Vmax"], it["Vdc"], dc["Vdc0"])) if conv else it["Vmax"]
            u = rating_clip(np.array([self.comp.u_p[i], self.comp.u_q[i]]), vmax)
            Vr = phasor_of(it["r"])
            vr_abs = abs(Vr)
            ur = Vr / vr_abs if vr_abs > 1e-9 else 1.0
            Vu = complex(u[1], u[0]) * ur                       # pu
            self._set_v(it["src"], Vu * it["vb"])
            I = current_of(it["ind"]) / it["ib"]                # pu on Sb, bus r -> bus 1
            P = float((Vu * np.conj(I)).real)
            Pdc = float(series_dc_power(P, it["chi"]))
            if conv:
                Id, over, Psh, Ploss, dVdc, dxi = (float(a) for a in shunt_dc_law(
                    Pdc, it["Vdc"], it["xi"], vr_abs, max(vr_abs, 1e-6), dc))
                self._set_i(it["sh"], -Id * ur * it["ib"])      # drawn from bus r, in phase with Vr
                it["Vdc"] += dt * dVdc
                it["xi"] += dt * dxi
            else:   # reduced: drawn from the GTI's dc link
                Id = over = Psh = Ploss = 0.0
                self._draw[it["gti"]] = self._draw.get(it["gti"], 0.0) + Pdc
            out.append((u[0], u[1], abs(Vu), P, it["Vdc"], it["xi"], Pdc, Psh, abs(Psh), Id,
                        Ploss, float(over)))
        return out

    def initial(self):
        """The :meth:`update` rows before the first step: nothing applied, the dc links at
        ``Vdc0``."""
        return [(0.0,) * 4 + (it["Vdc"], it["xi"]) + (0.0,) * 6 for it in self.items]

    def names(self):
        """``[(signal, kind)]`` recorded per UPQC, in :meth:`update`'s order (kinds as the
        phasor engine's, :attr:`weakgrid.sim.upqc.UPQC.units`)."""
        return [(f"{it['name']}.{s}", UPQC.units.get(s, "pu")) for it in self.items
                for s in SIGNALS]

    def gti_draw(self, n_gti: int) -> np.ndarray:
        """Per GTI (its position in the GTI component), the dc power [pu on Sb] the reduced
        UPQCs draw, as set by the last :meth:`update` (held over the step since)."""
        out = np.zeros(n_gti)
        for g, P in getattr(self, "_draw", {}).items():
            out[g] += P
        return out
