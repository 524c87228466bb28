"""What the DPsim engines can run, checked before anything is built or run.

:func:`check_supported` refuses (a :class:`~weakgrid.sim.errors.DataError` naming the model,
field or event) everything :func:`weakgrid.sim.emt.simulate_dpsim` would refuse on the way —
machines and controls (:mod:`weakgrid.sim.emt.machines`), devices
(:mod:`weakgrid.sim.emt.topology`), the network's branches and the events
(:mod:`weakgrid.sim.emt.events`: a line trip that islands a bus, for instance) — without importing ``dpsimpy``, so that a study asking for a
DPsim engine stops at planning, before any training or run. :func:`dpsim_step` is the step a
study's run takes in DPsim.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import DataError
from ..events import Fault, GeneratorTrip, LineTrip, LoadStep
from .dpsim_module import domain_of
from .events import BOLTED_MAX, UNMAPPED, line_switching, removed_load, _unit
from .gti import check_gti
from .machines import check_machines
from .topology import check_devices, check_network

#: largest DPsim step [s] of a study's run (EMT needs a step well below the 50/60 Hz period)
DT_MAX = 1e-4


def dpsim_step(dt: float, dt_max: float = DT_MAX) -> float:
    """The DPsim step [s] for a run whose phasor step is ``dt`` [s]: ``dt`` divided into the
    fewest equal parts of at most ``dt_max`` (so a controller sampled every ``dt`` samples on
    a whole number of DPsim steps)."""
    return dt / math.ceil(dt / dt_max - 1e-9)


def check_supported(system, events=(), engine: str = "dpsim-emt",
                    drop_saturation: bool = False, gti_power: str = "measured") -> None:
    """Raise :class:`DataError` if ``system`` (set up) or ``events`` has anything the DPsim
    engine ``engine`` does not map (refused by name, never substituted); ``drop_saturation``
    and ``gti_power`` as in :func:`weakgrid.sim.emt.simulate_dpsim`."""
    domain_of(engine)
    check_machines(system, drop_saturation)
    check_gti(system, gti_power)
    check_devices(system)
    net = system.network
    switched = line_switching(system, events)
    check_network(system, removed_load(system, events), {k: v[0] for k, v in switched.items()})
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
        elif not isinstance(ev, (LoadStep, LineTrip)):
            raise DataError(f"event {j}", "kind", type(ev).__name__, UNMAPPED)
