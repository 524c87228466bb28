"""weakgrid's sampled controllers in the DPsim loop, measured from DPsim's signals.

A :class:`~weakgrid.sim.controllers.DigitalController` runs unchanged — its law, period ``T``,
enable windows, bypass output, target (:class:`~weakgrid.sim.controllers.UPQCTarget`) and log —
with a measurement function of the same signature ``measure(sim, t, z, ctx)`` where ``ctx`` is
the dict of DPsim's latest recorded signals (:mod:`weakgrid.sim.emt.run` names) and ``sim.sys``
the system. :func:`sg_signals` is the DPsim twin of :func:`weakgrid.sim.controllers.sg_signals`
(the same measured signals ``[delta, theta_r, omega]``), so the same design-state map
(:func:`weakgrid.sim.controllers.mapped` with
:func:`weakgrid.sim.controllers.sg_state_map`) and the same trained law apply. The UPQC's series
source follows the held output from the next DPsim step (zero-order hold).
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError


class _Loop:
    """What ``DigitalController.sample`` and ``mapped`` read: the system and the latest signals."""

    def __init__(self, system):
        self.sys = system
        self.z = None        # no phasor solution: measurements read ``_ctx``
        self._ctx = {}


def sg_signals(machine_name, upqc_bus):
    """DPsim measurement ``[delta, theta_r, omega]`` of machine ``machine_name`` and the UPQC
    shunt bus ``upqc_bus`` (external number): rotor angle [rad], bus-voltage angle [rad], speed
    [pu] — the signals of :func:`weakgrid.sim.controllers.sg_signals`."""
    keys = (f"{machine_name}.delta", f"bus{upqc_bus}.a", f"{machine_name}.omega")
    return _reader(keys, "sg_signals", f"machine '{machine_name}', bus {upqc_bus}")


def gti_signals(gti_name):
    """DPsim measurement ``[phi_s, Vc]`` of GTI ``gti_name`` (its phase angle w.r.t. its
    reference bus [rad] and dc-link voltage [pu], :mod:`weakgrid.sim.emt.gti`) — the signals of
    :func:`weakgrid.sim.controllers.gti_signals`."""
    keys = (f"{gti_name}.phi_s", f"{gti_name}.Vc")
    return _reader(keys, "gti_signals", f"GTI '{gti_name}'")


def _reader(keys, where, what):
    """A measurement reading the signals ``keys`` of the last DPsim step (``ctx``), refusing a
    missing one by name."""

    def measure(sim, t, z, ctx):
        missing = [k for k in keys if k not in ctx]
        if missing:
            raise DataError(where, "signal", missing[0], f"no such DPsim signal ({what}); "
                            f"recorded: {sorted(ctx)[:8]} ...")
        return np.array([ctx[k] for k in keys])

    return measure


def bind(controllers, system, dt):
    """``[(every, controller)]``: each controller bound to ``system``, sampled every ``every``
    DPsim steps (its period ``T`` a whole number of steps ``dt``, first sample at ``t0 = 0``)."""
    out = []
    for dc in controllers or ():
        where = f"controller '{getattr(dc, 'name', dc)}'"
        if not all(hasattr(dc, a) for a in ("sample", "bind", "T", "t0")):
            raise DataError(where, "controllers", type(dc).__name__,
                            "give weakgrid.sim.controllers.DigitalController objects")
        every = int(round(dc.T / dt))
        if every < 1 or abs(every * dt - dc.T) > 1e-9 * max(1.0, dc.T):
            raise DataError(where, "T", dc.T, f"the sampling period must be a whole number of "
                            f"DPsim steps dt = {dt:g} s")
        if dc.t0 != 0.0:
            raise DataError(where, "t0", dc.t0, "the DPsim loop samples from t = 0; use t0 = 0")
        dc.bind(system)
        out.append((every, dc))
    return out


def sample_all(bound, loop, k, t, signals):
    """Sample every controller due at step ``k`` (time ``t``) with the latest ``signals``."""
    loop._ctx = signals
    for every, dc in bound:
        if k % every == 0:
            dc.sample(loop, t, None)
