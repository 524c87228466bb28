"""DPsim engines: the same grid in electromagnetic transients (EMT) and dynamic phasors (DP).

`DPsim <https://github.com/sogno-platform/dpsim>`_ (PyPI ``dpsim``, module ``dpsimpy``,
MPL-2.0; the optional extra ``weakgrid[emt]``) simulates a network of R, L, C, switches, sources
and machines in two domains used here:

* ``"dpsim-emt"`` — three-phase instantaneous quantities (``dpsimpy.emt.ph3``): every inductor
  and capacitor of the network is a differential equation, so the network's own transients
  (dc offsets, 50/60 Hz ringing) are simulated;
* ``"dpsim-dp"`` — single-phase dynamic phasors (``dpsimpy.dp.ph1``): the same circuit with
  each quantity a time-varying phasor around the nominal frequency (network dynamics kept,
  the carrier removed).

A set-up weakgrid :class:`~weakgrid.sim.system.System` is translated element by element
(:mod:`weakgrid.sim.emt.topology`, :mod:`weakgrid.sim.emt.machines`,
:mod:`weakgrid.sim.emt.events`, :mod:`weakgrid.sim.emt.upqc`; a machine's capacitive node
damped: :mod:`weakgrid.sim.emt.damping`) from its own data and power
flow — the phasor engine and the DPsim engines start from the same operating point — and run
step by step (:mod:`weakgrid.sim.emt.run`; the machines' exciters, governors and stabilizers
are weakgrid's, stepped beside DPsim: :mod:`weakgrid.sim.emt.machine_controls`) into
weakgrid's :class:`~weakgrid.sim.results.Results`. Models DPsim lacks
are refused with a :class:`~weakgrid.sim.errors.DataError` naming them; nothing is substituted.

``dpsimpy`` is imported only when a DPsim run is built (:func:`.dpsim_module.dpsimpy`).
"""

from .controllers import gti_signals, sg_signals
from .dpsim_module import ENGINES
from .run import DOMAINS, simulate_dpsim
from .support import DT_MAX, check_supported, dpsim_step

__all__ = ["DOMAINS", "DT_MAX", "ENGINES", "check_supported", "dpsim_step", "gti_signals", "sg_signals",
           "simulate_dpsim"]
