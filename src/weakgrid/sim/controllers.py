"""Digital controllers: ``u = K(measurements)`` sampled every ``T`` with zero-order hold.

A :class:`DigitalController` samples at ``t0 + k*T`` (exact breakpoints of the
integrator), computes ``u = K(m)`` from a measurement function, checks it
(finite, right size) and holds it on its target until the next sample. Outside
its enable windows (e.g. bypassed during a fault) it outputs ``bypass``.

Measurements of the paper's design states from the simulated grid
(:func:`gti_design_states`, :func:`sg_design_states`) return ``[phi_hat, upsilon]``:

* GTI: ``phi_hat`` = inverter angle w.r.t. the UPQC shunt bus minus ``phi_s0``;
  ``upsilon = tau*(Vc^2 - Vc0^2)/2`` from the dc-link energy;
* SG (classical-model analogue): ``phi_hat`` = rotor angle w.r.t. the UPQC
  shunt bus minus its initial value; ``upsilon`` = speed error ``omega - 1`` [pu]
  (times ``ws`` if given).

Each is a measurement of signals (:func:`gti_signals`, :func:`sg_signals`) composed with a
measurement mapping of :mod:`weakgrid.sim.design_states` (:func:`gti_state_map`,
:func:`sg_state_map`): the part a device runs, exported to C with the controller.

A measurement function ``measure(sim, t, z, ctx)`` may also carry ``measure.key`` (what it
measures: equal keys measure the same signals) and ``measure.rows(fns, sims, t, ctx, pos)``:
the measurements of rows ``pos`` of a batched evaluation context ``ctx`` (one per member,
``sims`` their simulators, ``fns`` their measurement functions) as an ``(n, m)`` array equal
row by row to each member's own call, or None when they cannot be taken together. The batch
simulator uses it to measure all its members at a sampling instant in one gather.
"""

from __future__ import annotations

import math

import numpy as np

from .design_states import GTIStateMap, SGStateMap
from .errors import DataError, SimulationError


class UPQCTarget:
    """Apply ``u = [Vup, Vuq]`` [pu] to UPQC ``name``."""

    size = 2

    def __init__(self, name):
        self.name = name

    def bind(self, system):
        up = system.components.get("UPQC")
        if up is None or self.name not in up.names:
            raise DataError(f"UPQCTarget '{self.name}'", "name", self.name, "no UPQC with that name")
        self.upqc = up
        self.i = up.names.index(self.name)

    def get(self):
        return np.array([self.upqc.u_p[self.i], self.upqc.u_q[self.i]])

    def apply(self, u):
        self.upqc.u_p[self.i], self.upqc.u_q[self.i] = float(u[0]), float(u[1])

    def slots(self):
        """Where each element of ``u`` is held: ``(component type, attribute, instance)``
        (the batch simulator writes the outputs of many members at once there)."""
        return (("UPQC", "u_p", self.i), ("UPQC", "u_q", self.i))


def gti_signals(gti_name):
    """Measurement function returning the measured signals ``[phi_s, Vc]`` of GTI ``gti_name``
    (:attr:`GTIStateMap.signals <weakgrid.sim.design_states.GTIStateMap.signals>`)."""

    def measure(sim, t, z, ctx):
        g = sim.sys.components["GTI"]
        i = g.names.index(gti_name)
        return np.array([ctx.out["GTI.phi_s"][i], ctx.x[g.idx("Vc")[i]]])

    def rows(fns, sims, t, ctx, pos):
        g = sims[0].sys.components["GTI"]
        i = g.names.index(gti_name)
        return np.stack([_gather(ctx.out["GTI.phi_s"], pos, i), ctx.x[pos, g.idx("Vc")[i]]], axis=1)

    measure.key, measure.rows = ("gti_signals", gti_name), rows
    return measure


def _gather(v, pos, i):
    """Column ``i`` of rows ``pos`` of a batched context array ``v`` (a 1-D ``v`` holds one
    value per instance for every row)."""
    return v[pos, i] if np.ndim(v) >= 2 else np.full(len(pos), v[i])


def gti_state_map(system, gti_name) -> GTIStateMap:
    """The :class:`~weakgrid.sim.design_states.GTIStateMap` of GTI ``gti_name`` of a set-up
    ``system`` (its operating point ``phi0`` and its ``tau``, ``Vc0``)."""
    g = system.components["GTI"]
    i = g.names.index(gti_name)
    return GTIStateMap(float(g.phi0[i]), float(g.p["tau"][i]), float(g.p["Vc0"][i]))


def sg_signals(machine_name, upqc_bus):
    """Measurement function returning ``[delta, theta_r, omega]`` of machine ``machine_name``
    and the UPQC shunt bus ``upqc_bus`` (external number)."""

    def measure(sim, t, z, ctx):
        s = sim.sys
        m = s.machine_number(machine_name)
        b = s.network.index_of(upqc_bus)
        return np.array([ctx.sig["delta"][m], float(np.angle(ctx.V[b])), ctx.sig["omega"][m]])

    def rows(fns, sims, t, ctx, pos):
        s = sims[0].sys
        m = s.machine_number(machine_name)
        b = s.network.index_of(upqc_bus)
        return np.stack([_gather(ctx.sig["delta"], pos, m), np.angle(ctx.V[pos, b]),
                         _gather(ctx.sig["omega"], pos, m)], axis=1)

    measure.key, measure.rows = ("sg_signals", machine_name, upqc_bus), rows
    return measure


def sg_state_map(system, machine_name, upqc_bus, ws=1.0) -> SGStateMap:
    """The :class:`~weakgrid.sim.design_states.SGStateMap` of a machine of a set-up ``system``
    w.r.t. the UPQC shunt bus ``upqc_bus`` (``ws``: υ per pu of speed error, 1 = pu)."""
    m = system.machine_number(machine_name)
    b = system.network.index_of(upqc_bus)
    th0 = float(np.angle(system.network.pf.V[b]))
    return SGStateMap(float(system.sig_defaults["delta0"][m]) - th0, float(ws))


def mapped(signals, state_map):
    """Measurement function ``state_map(signals(...))``; ``state_map(system)`` builds the map
    when the first sample is taken if it is a callable of the system, else it is the map."""
    cache = {}

    def map_of(system):
        mp = cache.get(id(system))
        if mp is None:
            mp = cache[id(system)] = state_map(system) if not hasattr(state_map, "signals") \
                else state_map
        return mp

    def measure(sim, t, z, ctx):
        return map_of(sim.sys)(signals(sim, t, z, ctx))

    measure.map_of = map_of
    if hasattr(signals, "rows"):
        def rows(fns, sims, t, ctx, pos):
            maps = [f.map_of(sim.sys) for f, sim in zip(fns, sims)]
            kind = type(maps[0])
            if not hasattr(kind, "map_rows") or any(type(mp) is not kind for mp in maps):
                return None      # measured one by one
            return kind.map_rows(maps, signals.rows([signals], sims, t, ctx, pos))

        measure.key, measure.rows = ("mapped",) + signals.key, rows
    return measure


def gti_design_states(gti_name):
    """Measurement function returning ``[phi_hat, upsilon]`` of GTI ``gti_name`` (see module docstring)."""
    return mapped(gti_signals(gti_name), lambda s: gti_state_map(s, gti_name))


def sg_design_states(machine_name, upqc_bus, ws=1.0):
    """Measurement ``[delta - theta_r - (delta0 - theta_r0), (omega - 1)*ws]`` of a machine vs.
    the UPQC shunt bus (``ws = 1``: speed error in pu)."""
    return mapped(sg_signals(machine_name, upqc_bus),
                  lambda s: sg_state_map(s, machine_name, upqc_bus, ws))


class DigitalController:
    """Sampled controller with zero-order hold and enable windows.

    Parameters
    ----------
    K : callable
        ``u = K(m)``; ``m`` is the measurement vector, ``u`` an array of ``target.size``.
    T : float
        Sampling period [s].
    measure : callable
        ``m = measure(sim, t, z, ctx)``.
    target : object
        Where ``u`` goes (e.g. :class:`UPQCTarget`).
    enable : list of (t_start, t_end) or callable or None
        When the controller is active; otherwise it outputs ``bypass`` (default: always).
    bypass : array_like
        Output while disabled (default zeros).
    name : str
        Used in error messages.
    t0 : float
        First sampling instant [s].
    batched : bool
        ``K`` also takes a ``(B, n)`` array of ``B`` measurement vectors and returns the
        ``(B, target.size)`` outputs (a trained network evaluated row-wise, a linear feedback on
        arrays): the batch simulator (:mod:`weakgrid.sim.batch`) then calls it once for all the
        members it samples at an instant that share this ``K``, measures them in one gather
        when ``measure`` can read rows of a batched context (it has ``key`` and ``rows``, as the
        measurements of :func:`gti_signals`, :func:`sg_signals` and :func:`mapped` do) and holds
        their outputs at once when the target names its slots (:meth:`UPQCTarget.slots`).
        ``K`` may be one of several objects that compute the same law: it then has
        ``batch_key()`` (equal keys: the same outputs for the same measurement, e.g. the
        content of a trained controller; default ``id(K)``) and may have
        ``rows(Ks, M)`` (the outputs of the members' own ``Ks`` — equal keys, ``K`` among
        them — at the rows of ``M``, row ``i`` for ``Ks[i]``, e.g. each logging its own
        samples; default ``K(M)``).
    """

    def __init__(self, K, T, measure, target, enable=None, bypass=None, name="controller", t0=0.0,
                 batched=False):
        if not (T > 0 and math.isfinite(T)):
            raise DataError(f"DigitalController '{name}'", "T", T, "sampling period must be a positive number of seconds")
        self.K, self.T, self.measure, self.target = K, float(T), measure, target
        self.enable, self.name, self.t0 = enable, name, float(t0)
        self.batched = bool(batched)
        self.bypass = None if bypass is None else np.asarray(bypass, float)
        self.k = 0
        self.log_t, self.log_u = [], []

    def bind(self, system):
        self.target.bind(system)
        if self.bypass is None:
            self.bypass = np.zeros(self.target.size)
        self.k = 0

    def active(self, t):
        if self.enable is None:
            return True
        if callable(self.enable):
            return bool(self.enable(t))
        return any(a <= t < b for a, b in self.enable)

    def _tk(self, k):
        return self.t0 + k * self.T

    def next_time(self, t):
        while self._tk(self.k) < t - 1e-12:
            self.k += 1
        tk = self._tk(self.k)
        return tk if tk > t + 1e-12 else self._tk(self.k + 1)

    def due(self, t):
        while self._tk(self.k) < t - 1e-12:
            self.k += 1
        return abs(self._tk(self.k) - t) <= 1e-9

    def sample(self, sim, t, z):
        """Compute and hold a new output; returns True if it changed."""
        m = self.measurement(sim, t, z)
        if m is None:
            return self.hold(t, self.bypass)
        try:
            u = self.K(m)
        except Exception as exc:
            raise SimulationError(t, "controller", f"'{self.name}' raised {exc!r}") from exc
        return self.hold(t, u, m)

    def measurement(self, sim, t, z=None):
        """The measurement vector at a sample ``t`` of ``sim`` (its solution ``z``, default
        ``sim.z``), or None while disabled."""
        if not self.active(t):
            return None
        return self.measure(sim, t, sim.z if z is None else z, sim._ctx)

    def batch_key(self):
        """What the members sampled together must share for one call of ``K`` (None: sampled
        alone, :meth:`sample`): ``K`` itself (declared ``batched``) and what is measured (the
        ``key`` of a measurement function that can read rows of a batched context, see
        :func:`gti_signals`; None if it cannot)."""
        if not self.batched:
            return None
        own = getattr(self.K, "batch_key", None)
        return (own() if callable(own) else id(self.K)), getattr(self.measure, "key", None)

    def call_rows(self, controllers, M):
        """The outputs of the policies of ``controllers`` (equal :meth:`batch_key`, this one
        among them) at the rows of ``M`` (row ``i`` for ``controllers[i]``): one call of
        ``K.rows`` (or ``K``) for all of them."""
        rows = getattr(self.K, "rows", None)
        if rows is not None:
            return rows([c.K for c in controllers], M)
        return self.K(M)

    def check(self, t, u, m):
        """The policy's output ``u`` for measurement ``m`` as a flat float array, checked
        (finite, ``target.size`` values); raises :class:`SimulationError` otherwise."""
        try:
            u = np.asarray(u, dtype=float).reshape(-1)
        except Exception as exc:
            raise SimulationError(t, "controller", f"'{self.name}' raised {exc!r}") from exc
        if u.shape != (self.target.size,) or not np.all(np.isfinite(u)):
            raise SimulationError(t, "controller",
                                  f"'{self.name}' returned {u.tolist()} for measurements {np.asarray(m).tolist()}; "
                                  f"expected {self.target.size} finite values")
        return u

    def logged(self, t, u):
        """Book the output ``u`` held from sample ``t`` on (the sample count and the log)."""
        self.k += 1
        self.log_t.append(t)
        self.log_u.append(u.copy())

    def hold(self, t, u, m=None):
        """Check the policy's output ``u`` for measurement ``m`` (None: the bypass) and hold it
        from sample ``t`` on; returns True if the held output changed. (:meth:`sample` in two
        halves, so that a batch of members can evaluate ``K`` once for all of them.)"""
        if m is not None:
            u = self.check(t, u, m)
        self.logged(t, u)
        old = self.target.get()
        if np.array_equal(old, u):
            return False
        self.target.apply(u)
        return True
