"""weakgrid's exciters, governors and stabilizers in the DPsim loop (co-simulation at DPsim's step).

DPsim 1.4 has its own machine controls (``dpsimpy.signal.ExciterDC1``, ``ExciterST1Simp``,
``TurbineGovernorType1``, ``PSS1A``, ...), but none is the same model as the PSS/E blocks a
study uses (EXDC2, SEXS, TGOV1, IEEEST, ...: DPsim's DC1 exciter is IEEE DC1A without EXDC2's
limits and rate feedback form, its TurbineGovernorType1 has a servo and a reheat stage, not
TGOV1's). So weakgrid's own control components run here unchanged, stepped in Python:

* before DPsim step ``k`` (time ``t = k dt``) each control's :meth:`compute` is evaluated with
  the machine signals measured at ``t`` (after DPsim's step ``k - 1``): ``omega`` (``w_r``),
  ``Pe = Vd Id + Vq Iq - ra |I|²`` and ``Qe = Vq Id - Vd Iq`` at the bus (DPsim's ``Vdq0``,
  ``Idq0``, inside the stator resistor), ``Vt`` and
  ``Ecomp`` (the terminal bus voltage magnitude), ``XadIfd = E'q + (Ld - Ld') Id`` (the field
  current of DPsim's model, from ``Edq0_t``); the bus voltages are the recorded phasors;
* the controls' states advance by forward Euler over ``dt`` (DPsim's own shaft does the same),
  each non-windup limited state clipped to its limits;
* the outputs at ``t`` — field voltage ``vf`` and mechanical torque ``tm`` — are held over the
  step (zero-order hold): a one-step (``dt``) delay against the phasor engine, where they are
  simultaneous; the torque acts from DPsim's next step (its shaft uses the previous step's
  torque), a second ``dt``.

How the held values enter DPsim 1.4's reduced-order machines (``Base_ReducedOrderSynchronGenerator``):

* field voltage: the attribute ``Ef``. Without a DPsim exciter the machine integrates
  ``Td0' dE'q/dt`` by the trapezoid with ``Ef + Ef_prev`` where ``Ef_prev`` stays at its initial
  value ``Ef0``; so ``Ef = 2 e - Ef0`` is written, which makes the trapezoid's sum ``2 e``,
  the zero-order hold of ``e`` (``tests/sim/test_emt_machines.py`` checks the field response),
  with ``e = Ef0 + (vf - vf0)``: the exciter's change from its initial output. ``Ef0`` is
  DPsim's own initial field voltage, equal to weakgrid's ``vf0`` to 1e-8 for an unsaturated
  machine (so ``e = vf``); with saturation dropped (``drop_saturation``) DPsim's unsaturated
  machine needs less field voltage at the same operating point, and the exciter's changes are
  applied to it from its own ``Ef0`` (it starts at rest).
* mechanical torque: DPsim's shaft reads the torque only through a governor object. A
  ``dpsimpy.signal.TurbineGovernorType1`` is attached as a pass-through (``T3 = Tc``, ``T4 =
  T5``: its servo and reheat states stay zero and its output is its first state ``Xg1``;
  ``Ts = R = 1e9`` s/pu: that state does not move by itself, 1e-13 pu per step), and its
  attribute ``Xg1`` is set to ``tm`` before each step.
"""

from __future__ import annotations

import numpy as np

from ..component import Context
from .machines import FIELD_MODELS

#: weakgrid component kinds run in the Python loop
KINDS = ("pss", "exciter", "governor")

#: pass-through governor (T3, T4, T5, Tc, Ts, R, Tmin, Tmax, OmRef): output = state Xg1
_PASS = (1.0, 1.0, 1.0, 1.0, 1e9, 1e9, -1e9, 1e9, 1.0)


class MachineControls:
    """The system's exciters, governors and stabilizers stepped beside DPsim.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up; its machines built in DPsim (``gens``).
    kit : weakgrid.sim.emt.dpsim_module.Kit
    gens : list of (name, generator)
        :func:`weakgrid.sim.emt.machines.build_machines`'s output.
    dt : float
        DPsim's step [s].

    Attributes
    ----------
    vf, tm : dict
        The held field voltage [pu] and mechanical torque [pu on Sb] per controlled machine name.
    """

    def __init__(self, system, kit, gens, dt):
        self.sys, self.kit, self.dt = system, kit, float(dt)
        self.comps = [c for c in system.comps if c.kind in KINDS and c.n > 0]
        self.x = np.array(system.z0[:system.nx], dtype=float)
        own = np.zeros(system.nx, bool)
        for c in self.comps:
            for i in range(c.n):
                own[c.instance_states(i)] = True
        self.own = np.nonzero(own)[0]
        lim = own[system.lim_idx] if len(system.lim_idx) else np.zeros(0, bool)
        self._lim = lim
        by_kind = {k: set() for k in KINDS}
        for c in self.comps:
            for lk in c.links:
                by_kind[c.kind].add(lk["machine"])
        mtype = {nm: c.type_name for c in system.components.values() if c.kind == "machine"
                 for nm in c.names}
        self.gens = [(nm, g, system.machine_number(nm)) for nm, g in gens]
        self.field = [(nm, g, m) for nm, g, m in self.gens
                      if nm in by_kind["exciter"] and mtype[nm] in FIELD_MODELS]
        self.turbine = [(nm, g, m) for nm, g, m in self.gens if nm in by_kind["governor"]]
        self._bus = {nm: int(c.bus[i]) for c in system.components.values() if c.kind == "machine"
                     for i, nm in enumerate(c.names)}
        self._ra = {nm: float(c.p["ra"][i]) for c in system.components.values()
                    if c.kind == "machine" for i, nm in enumerate(c.names)}
        self._dL = {}
        for c in system.components.values():
            if c.kind == "machine":
                for i, nm in enumerate(c.names):
                    self._dL[nm] = float(c.p["xd"][i] - c.p["xd1"][i]) if "xd" in c.p else 0.0
        self._gov = {}
        self._edq = "Edq0_t" if kit.three_phase else "Edq_t"     # DPsim's names (EMT, DP)
        self.Ef0 = {}
        self.vf = {nm: float(system.sig_defaults["vf0"][m]) for nm, _, m in self.field}
        self.vf0 = dict(self.vf)
        self.tm = {nm: float(system.sig_defaults["tm0"][m]) for nm, _, m in self.turbine}

    @property
    def active(self) -> bool:
        return bool(self.comps)

    def attach(self):
        """Before ``sim.start()``: a pass-through DPsim governor on each governed machine."""
        sig = self.kit.d.signal
        for nm, g, _ in self.turbine:
            gov = sig.TurbineGovernorType1(f"{nm}.tm", self.kit.d.LogLevel.off)
            gov.set_parameters(*_PASS)
            g.add_governor(gov)
            self._gov[nm] = gov

    def start(self):
        """After ``sim.start()``: DPsim's initial field voltage ``Ef0`` of each excited machine."""
        self.Ef0 = {nm: float(g.attr("Ef").get()) for nm, g, _ in self.field}

    def step(self, t, rec):
        """Evaluate the controls at ``t`` with the signals ``rec`` measured there, write the held
        ``vf``/``tm`` into DPsim for the coming step, and advance the control states by ``dt``."""
        s = self.sys
        V = np.array([rec.phasor(b) for b in range(s.nb)], dtype=complex)
        ctx = Context(s, t, self.x, V)
        sig = ctx.sig
        for nm, g, m in self.gens:
            v = np.asarray(g.attr("Vdq0").get(), float).ravel()
            i = np.asarray(g.attr("Idq0").get(), float).ravel()
            e = np.asarray(g.attr(self._edq).get(), float).ravel() if nm in self.vf else None
            Vt = V[self._bus[nm]]
            sig["omega"][m] = g.attr("w_r").get()
            sig["delta"][m] = g.attr("delta").get()
            sig["Pe"][m] = v[0] * i[0] + v[1] * i[1] - self._ra[nm] * (i[0] ** 2 + i[1] ** 2)
            sig["Qe"][m] = v[1] * i[0] - v[0] * i[1]
            sig["Vt"][m] = sig["Ecomp"][m] = abs(Vt)
            sig["theta"][m] = np.angle(Vt)
            if e is not None:
                sig["XadIfd"][m] = e[1] + self._dL[nm] * i[0]
        for c in self.comps:
            c.compute(ctx)
        for c in self.comps:
            if hasattr(c, "accept"):
                c.accept(t, ctx)
        for nm, g, m in self.field:
            self.vf[nm] = vf = float(sig["vf"][m])
            e = self.Ef0[nm] + (vf - self.vf0[nm])
            g.attr("Ef").set(2.0 * e - self.Ef0[nm])
        for nm, g, m in self.turbine:
            self.tm[nm] = tm = float(sig["tm"][m])
            self._gov[nm].attr("Xg1").set(tm)
        x = self.x
        x[self.own] += self.dt * ctx.f[self.own]
        if self._lim.any():
            s.update_limits(ctx)
            li = s.lim_idx[self._lim]
            x[li] = np.clip(x[li], s.lim_lo[self._lim], s.lim_hi[self._lim])


__all__ = ["KINDS", "MachineControls"]
