"""Run a weakgrid System in DPsim (EMT or DP) step by step and record weakgrid's Results.

Recorded signals (names as the phasor engine's where they exist):

* ``<machine>.omega`` [pu speed], ``<machine>.delta`` [rad, synchronous frame of the power flow],
  ``<machine>.te`` [pu on Sb, DPsim's air-gap torque ``Te``];
* ``bus<id>.v`` [pu], ``bus<id>.a`` [rad]: the bus voltage phasor — in DP the node's dynamic
  phasor; in EMT the space vector ``(2/3)(va + a vb + a² vc)`` taken to the synchronous frame
  (``e^{-j w t}``), equal to the phasor in balanced operation (a dc offset shows as a ripple
  at the nominal frequency);
* ``<machine>.vf`` [pu], ``<machine>.tm`` [pu on Sb]: the field voltage and mechanical torque
  weakgrid's exciter and governor hold over each step (machines with an exciter / a governor;
  :mod:`weakgrid.sim.emt.machine_controls`);
* ``<upqc>.<signal>`` for the signals of :data:`weakgrid.sim.emt.upqc.SIGNALS` (the series
  voltage and power, the dc link ``Vdc``, ``xi_dc`` and the shunt converter's ``P_shunt``,
  ``I_shunt``, ``P_loss``, ``limited``, ...), kinds and units as the phasor engine's;
* EMT only, in addition: ``bus<id>.va``, ``.vb``, ``.vc`` [pu of the peak phase-to-ground base
  ``sqrt(2/3) kV``; SI: kV instantaneous], the three-phase instantaneous voltages.

Time: DPsim steps at a fixed ``dt``; sample ``k`` is the state at ``t = k dt`` (``k = 0``: the
initial point after ``sim.start()``).
"""

from __future__ import annotations

import logging
import math
import tempfile
import time

import numpy as np

from ..errors import DataError, SimulationError
from ..results import Results
from .controllers import _Loop, bind, sample_all
from .dpsim_module import DOMAINS, Kit, domain_of
from .events import (build_events, line_switching, removed_load, trip_terminals,
                     tripped_machines)
from .gti import GTIBridge
from .machine_controls import MachineControls
from .machines import build_machines, check_machines
from .native_output import NativeOutput
from .topology import build_network, bus_base, check_devices
from .upqc import UPQCBridge

log = logging.getLogger(__name__)

__all__ = ["DOMAINS", "simulate_dpsim"]


def simulate_dpsim(system, t_end: float, *, engine: str = "dpsim-emt", dt: float = 1e-4,
                   events=(), controllers=(), decimate: int = 1, name: str = "weakgrid",
                   gti_power: str = "measured", drop_saturation: bool = False) -> Results:
    """Simulate a set-up ``system`` in DPsim from ``t = 0`` to ``t_end`` [s].

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up (power flow solved); its models must have a DPsim mapping
        (:mod:`weakgrid.sim.emt.machines`, :mod:`weakgrid.sim.emt.topology`).
    t_end : float
        Final time [s].
    engine : {"dpsim-emt", "dpsim-dp"}
        DPsim domain.
    dt : float
        Fixed time step [s] (EMT needs a step well below the nominal period: 1e-4 s at 50/60 Hz).
    events : list
        weakgrid events (:mod:`weakgrid.sim.emt.events` says which are mapped).
    gti_power : {"measured", "model"}
        The ac power a GTI's dc link pays (:mod:`weakgrid.sim.emt.gti`): the power its DPsim
        source delivered (``"measured"``, energy-consistent), or weakgrid's GTI model's own
        ``Re(Es conj(-jB(Es - V)))`` at the measured voltage (``"model"``, the dc link blind to
        the coupling's current transients). A GTI in ``pq`` mode needs ``"model"``
        (refused with ``"measured"``: unstable with the network's inductors, docs/engines.md).
    decimate : int
        Record every ``decimate``-th step.
    name : str
        DPsim simulation name (its log directory, logging off).
    controllers : list of weakgrid.sim.controllers.DigitalController
        Sampled controllers in the loop (:mod:`weakgrid.sim.emt.controllers`): each sampled at
        ``t = 0, T, 2T, ...`` with its measurement reading DPsim's latest signals; a UPQC's
        series source and shunt converter follow the held output from the next step
        (zero-order hold).
    drop_saturation : bool
        Run GENROU/GENSAL machines with saturation (``S10 != 0``) unsaturated instead of
        refusing them (DPsim's machines have no saturation; :mod:`weakgrid.sim.emt.machines`).

    Returns
    -------
    Results
        With ``stats = {"steps", "wall_s", "engine", "dt"}``; ``failure`` a
        :class:`~weakgrid.sim.errors.SimulationError` (``"divergence"``) when a bus voltage
        became non-finite (the run stops there).
    """
    domain = domain_of(engine)
    if not system.is_setup:
        raise DataError("simulate_dpsim", "system", "not set up", "call System.setup() first")
    for fld, v in (("t_end", t_end), ("dt", dt)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise DataError("simulate_dpsim", fld, v, "must be a positive number of seconds")
    if dt > t_end:
        raise DataError("simulate_dpsim", "dt", dt, f"must not exceed t_end = {t_end} s")
    if not (isinstance(decimate, int) and decimate >= 1):
        raise DataError("simulate_dpsim", "decimate", decimate, "must be an integer >= 1")
    check_machines(system, drop_saturation)
    check_devices(system)
    net = system.network
    for c in system.components.values():
        if c.kind == "machine":
            bad = [v for v in c.p["fn"] if v != net.f_hz]
            if bad:
                raise DataError(c.names[0], "fn", float(bad[0]),
                                f"the DPsim network runs at one frequency, the grid's {net.f_hz:g} Hz")
    kit = Kit(domain)
    with tempfile.TemporaryDirectory(prefix="weakgrid-dpsim-") as logdir:
        # DPsim writes its own log files (MnaSolverFactory.log, scheduler.log) to a log
        # directory (default ./logs): kept out of the user's working directory
        kit.d.Logger.set_log_dir(logdir)
        return _run(system, kit, engine, domain, t_end, dt, events, decimate, name, controllers,
                    gti_power)


def _run(system, kit, engine, domain, t_end, dt, events, decimate, name, controllers,
         gti_power="measured"):
    net = system.network
    switched = {k: v[0] for k, v in line_switching(system, events).items()}
    cir = build_network(system, kit, removed_load(system, events), switched)
    bridge = UPQCBridge(system, kit, cir)
    gti = GTIBridge(system, kit, cir, power=gti_power)
    gens = build_machines(system, kit, trip_terminals(system, kit, cir, events), cir.Vpf, cir)
    cir.components.extend(g for _, g in gens)
    mc = MachineControls(system, kit, gens, dt)
    mc.attach()
    sw_events = build_events(system, kit, cir, events, dt)
    d = kit.d
    topo = d.SystemTopology(net.f_hz, cir.nodes + cir.extra_nodes, cir.components)
    sim = d.Simulation(name, d.LogLevel.off)
    sim.set_system(topo)
    sim.set_domain(kit.sim_domain)
    sim.set_time_step(float(dt))
    sim.set_final_time(float(t_end))
    sim.do_init_from_nodes_and_terminals(True)
    sim.do_system_matrix_recomputation(True)      # the switches change the system matrix
    for ev in sw_events:
        sim.add_event(ev)
    bound = bind(controllers, system, dt)
    loop = _Loop(system)
    rec = _Recorder(system, kit, gens, cir, bridge, gti, mc, tripped_machines(system, events))
    n_steps = int(round(t_end / dt))
    t0 = time.perf_counter()
    failure = None
    with NativeOutput() as out:       # DPsim's C++ console lines → logging (DEBUG)
        out.call(sim.start)
        mc.start()
        rec.measure(0.0)
        rec.gti = gti.update(dt, rec._ph, rec.current, bridge.gti_draw(len(gti.items)))
        rec.add(0.0)
        k = 0
        for k in range(1, n_steps + 1):
            t = (k - 1) * dt
            if bound and any((k - 1) % every == 0 for every, _ in bound):
                sample_all(bound, loop, k - 1, t, rec.latest())
            rec.upqc = bridge.update(t, rec.phasor, rec.current, dt)
            if mc.active:
                mc.step(t, rec)
            out.call(sim.next)
            rec.measure(k * dt)
            if not np.isfinite(rec._ph).all():
                rec.add(k * dt)
                failure = SimulationError(k * dt, "divergence",
                                          "a DPsim bus voltage is not finite")
                break
            rec.gti = gti.update(dt, rec._ph, rec.current, bridge.gti_draw(len(gti.items)))
            if k % decimate == 0 or k == n_steps:
                rec.add(k * dt)
        out.call(sim.stop)
    wall = time.perf_counter() - t0
    log.debug("DPsim %s: %d steps of %g s in %.2f s", domain, n_steps, dt, wall)
    return rec.finish({"steps": k if n_steps else 0, "wall_s": wall, "engine": engine,
                       "dt": float(dt)}, failure)


class _Recorder:
    """Reads DPsim attributes after each step into weakgrid signal columns."""

    def __init__(self, system, kit, gens, cir, bridge, gti, mc, tripped=None):
        net = system.network
        self.kit, self.gens, self.nodes, self.bridge, self.mc = kit, gens, cir.nodes, bridge, mc
        self.w = 2 * math.pi * net.f_hz
        Vb, _ = bus_base(system)
        self.Vb = Vb
        names, kinds, fac = [], [], []
        for nm, _ in gens:
            names += [f"{nm}.omega", f"{nm}.delta", f"{nm}.te"]
            kinds += ["speed", "angle", "power"]
            fac += [self.w, 180 / math.pi, system.Sb]
        for b, bid in enumerate(net.bus_ids):
            names += [f"bus{bid}.v", f"bus{bid}.a"]
            kinds += ["voltage", "angle"]
            fac += [net.base_kv[b], 180 / math.pi]
        for n, kind in bridge.names():
            names.append(n)
            kinds.append(kind)
            fac.append(system.Sb if kind in ("power", "apparent") else
                       system.Sb / (math.sqrt(3) * system.element_kv(n)) if kind == "current"
                       else 1.0)
        self.gti_names = [n for n, _ in gti.names()]
        for n, kind in gti.names():
            names.append(n)
            kinds.append(kind)
            fac.append(system.Sb if kind == "power" else 180 / math.pi if kind == "angle" else 1.0)
        self.gti = {n: 0.0 for n in self.gti_names}
        for nm in mc.vf:
            names.append(f"{nm}.vf")
            kinds.append("pu")
            fac.append(1.0)
        for nm in mc.tm:
            names.append(f"{nm}.tm")
            kinds.append("power")
            fac.append(system.Sb)
        if kit.three_phase:
            for b, bid in enumerate(net.bus_ids):
                names += [f"bus{bid}.va", f"bus{bid}.vb", f"bus{bid}.vc"]
                kinds += ["voltage"] * 3
                fac += [net.base_kv[b] * math.sqrt(2 / 3)] * 3
        self.names, self.kinds, self.fac = names, kinds, fac
        self.t, self.rows = [], []
        self._a = np.exp(2j * np.pi / 3)
        self.upqc = bridge.initial()
        self._ph, self._abc, self._t = None, None, 0.0
        self.tripped, self._frozen = dict(tripped or {}), {}

    def _space_vector(self, x, t):
        """Line-to-line RMS-scale phasor of three instantaneous phase values (EMT)."""
        x = np.asarray(x, float).ravel()
        sv = (2 / 3) * (x[0] + self._a * x[1] + self._a ** 2 * x[2]) * np.exp(-1j * self.w * t)
        return sv / math.sqrt(2 / 3)

    def measure(self, t):
        """Read every node's voltage at time ``t`` (phasors in pu; EMT: phase values too)."""
        ph, abc = [], []
        for b, n in enumerate(self.nodes):
            v = np.asarray(n.attr("v").get()).ravel()
            if self.kit.three_phase:
                abc.append(v.real / (self.Vb[b] * math.sqrt(2 / 3)))
                ph.append(self._space_vector(v.real, t) / self.Vb[b])
            else:
                ph.append(complex(v[0]) / self.Vb[b])
        self._ph, self._abc, self._t = ph, abc, t

    def phasor(self, b):
        """Bus ``b``'s voltage phasor [pu] at the last measurement."""
        return self._ph[b]

    def current(self, src):
        """Current [A, line-to-line RMS-scale phasor] from terminal 1 to 2 inside ``src``."""
        i = -np.asarray(src.attr("i_intf").get()).ravel()
        return self._space_vector(i.real, self._t) if self.kit.three_phase else complex(i[0])

    def _row(self):
        row = []
        for nm, g in self.gens:
            vals = [g.attr("w_r").get(), g.attr("delta").get(), g.attr("Te").get()]
            if nm in self.tripped and self._t >= self.tripped[nm] - 1e-12:
                # tripped: states frozen at the trip, power zero (weakgrid.sim.disconnect)
                vals = self._frozen.setdefault(nm, vals[:2] + [0.0])
            row += vals
        for ph in self._ph:
            row += [abs(ph), float(np.angle(ph))]
        for vals in self.upqc:
            row += list(vals)
        row += [self.gti[n] for n in self.gti_names]
        row += list(self.mc.vf.values()) + list(self.mc.tm.values())
        for abc in self._abc:
            row += list(abc)
        return row

    def latest(self) -> dict:
        """The signals at the last measurement, by name."""
        return dict(zip(self.names, self._row()))

    def add(self, t):
        self.t.append(t)
        self.rows.append(self._row())

    def finish(self, stats, failure=None):
        return Results(np.array(self.t), self.names, np.array(self.rows, dtype=float), self.kinds,
                       self.fac, failure=failure, stats=stats)
