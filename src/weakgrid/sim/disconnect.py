"""Units disconnected during a run (:class:`~weakgrid.sim.events.GeneratorTrip`).

A *unit* is what stands on one row of the gen table: its machine or converter (or the models
sharing the row by ``gammap``/``gammaq``) together with every control linked to them by name —
an exciter's, governor's, stabilizer's or compensator's ``machine``, REECA1/REECB1's ``reg``,
REPCA1's ``ree``, the wind models' links — followed transitively. PSS/E's machine trip and
PSID's ``GeneratorTrip`` mean the same: the unit is no longer connected, so from the trip on

* it injects no current (a model that can be disconnected passes its injection through
  :meth:`~weakgrid.sim.component.Component.connected`: ``disconnectable = True``);
* its states are frozen (zero derivatives; PSID sets them to zero — nothing reads them any
  more, since the unit's controls are frozen with it);
* its power and current outputs (``injection_outputs``) record zero.

An ideal source (``InfiniteBus``, ``PVSource``), a GTI and a load cannot be disconnected this
way: a trip of their row is refused, naming them.
"""

from __future__ import annotations

import numpy as np

from .errors import DataError


def unit_instances(system, gen) -> list[tuple[object, int]]:
    """``(component, position)`` of every instance of the unit on gen-table row ``gen``
    (0-based): the models on the row, then their controls (transitively, by the names their
    links hold). Raises :class:`DataError` for a row without models or with a model that cannot
    be disconnected."""
    comps = list(system.components.values())
    on_row = [(c, i) for c in comps if c.kind in ("machine", "device")
              for i, lk in enumerate(c.links) if lk.get("gen") == gen]
    el = f"GeneratorTrip of gen row {gen}"
    if not on_row:
        raise DataError(el, "gen", gen, "no machine or converter stands on this row of the gen table; "
                        "give the row of an in-service unit with a dynamic model")
    bad = [c.element(i) for c, i in on_row if not c.disconnectable]
    if bad:
        raise DataError(el, "gen", gen, f"{', '.join(bad)} cannot be disconnected by a generator trip "
                        "(only machines and converters can: REGCA1, PVD1, ESD1)")
    names = {c.names[i] for c, i in on_row}
    out = list(on_row)
    grown = True
    while grown:   # controls of the unit, and controls of those controls
        grown = False
        for c in comps:
            for i, lk in enumerate(c.links):
                if c.names[i] in names or (c, i) in out:
                    continue
                if any(isinstance(v, str) and v in names for v in lk.values()):
                    out.append((c, i))
                    names.add(c.names[i])
                    grown = True
    return out


class Disconnected:
    """The instances disconnected so far in a run, as the system's evaluation applies them
    (:meth:`apply`, after every component's ``finish``)."""

    def __init__(self):
        self.states = np.zeros(0, dtype=int)
        self.comps = []
        self.names: list[str] = []   # names of the disconnected instances, in trip order

    def add(self, instances):
        """Disconnect ``instances`` (``(component, position)`` pairs, :func:`unit_instances`)."""
        for c, i in instances:
            if c.live is None:
                c.live = np.ones(c.n)
            c.live = c.live.copy()
            c.live[i] = 0.0
            if c.names[i] not in self.names:
                self.names.append(c.names[i])
            if c not in self.comps:
                self.comps.append(c)
            if len(c.states):
                self.states = np.union1d(self.states, c.instance_states(i)).astype(int)

    def apply(self, ctx):
        """Freeze the disconnected states and zero the disconnected outputs in ``ctx``."""
        ctx.f[..., self.states] = 0.0
        out = ctx.out
        for c in self.comps:
            for o in c.injection_outputs:
                key = f"{c.type_name}.{o}"
                if key in out:
                    out[key] = out[key] * c.live
