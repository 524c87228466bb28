"""What the DPsim engines can run, checked before anything is built or run.

:func:`check_supported` refuses (a :class:`~weakgrid.sim.errors.DataError` naming the model,
field or event) everything :func:`weakgrid.sim.emt.simulate_dpsim` would refuse on the way —
machines and controls (:mod:`.machines`), devices (:mod:`.topology`), the network's branches
and the events (:mod:`.events`) — without importing ``dpsimpy``, so that a study asking for a
DPsim engine stops at planning, before any training or run. :func:`dpsim_step` is the step a
study's run takes in DPsim.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from ..events import Fault, GeneratorTrip, LoadStep
from ..network import BR_STATUS, BR_X, SHIFT
from .dpsim_module import domain_of
from .events import BOLTED_MAX, removed_load, _unit
from .machines import check_machines
from .topology import check_devices

#: largest DPsim step [s] of a study's run (EMT needs a step well below the 50/60 Hz period)
DT_MAX = 1e-4


def dpsim_step(dt: float, dt_max: float = DT_MAX) -> float:
    """The DPsim step [s] for a run whose phasor step is ``dt`` [s]: ``dt`` divided into the
    fewest equal parts of at most ``dt_max`` (so a controller sampled every ``dt`` samples on
    a whole number of DPsim steps)."""
    return dt / math.ceil(dt / dt_max - 1e-9)


def check_supported(system, events=(), engine: str = "dpsim-emt") -> None:
    """Raise :class:`DataError` if ``system`` (set up) or ``events`` has anything the DPsim
    engine ``engine`` does not map (refused by name, never substituted)."""
    domain_of(engine)
    check_machines(system)
    check_devices(system)
    net = system.network
    for k, row in enumerate(net.branch):
        if row[BR_STATUS] > 0 and row[SHIFT] != 0:
            raise DataError(f"branch {net.branch_label(k)}", "SHIFT", float(row[SHIFT]),
                            "a phase-shifting transformer is not mapped to DPsim; use SHIFT = 0")
        if row[BR_STATUS] > 0 and row[BR_X] <= 0:
            raise DataError(f"branch {net.branch_label(k)}", "BR_X", float(row[BR_X]),
                            "the DPsim engines need an inductive branch (BR_X > 0)")
    gti = system.components.get("GTI")
    refs = set(np.asarray(gti.ref).tolist()) if gti is not None and gti.n else set()
    for j, ev in enumerate(events or ()):
        if isinstance(ev, Fault):
            ev.validate(system)
            if abs(complex(ev.rf, ev.xf)) <= BOLTED_MAX and net.index_of(ev.bus) in refs:
                raise DataError(f"Fault at bus {ev.bus}", "bus", ev.bus, "a bolted fault at a "
                                "GTI's reference bus is not mapped (weakgrid.sim.emt.events)")
        elif isinstance(ev, GeneratorTrip):
            _unit(system, ev)
        elif not isinstance(ev, LoadStep):
            raise DataError(f"event {j}", "kind", type(ev).__name__,
                            "the DPsim engines map bus faults (Fault), load steps (LoadStep) "
                            "and generator trips (GeneratorTrip) so far")
    rem = removed_load(system, events)
    if rem.any():
        from ..network import GS

        y = net.load_admittance(net.pf.V).real + net.bus[:, GS] / system.Sb
        for b in np.nonzero(rem.real > y + 1e-12)[0]:
            raise DataError(f"LoadStep at bus {net.bus_ids[b]}", "dP", -rem[b].real * system.Sb,
                            f"removes more load than the bus holds ({y[b] * system.Sb:g} MW)")
