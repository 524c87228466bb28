"""Links of the WECC type-3 wind-turbine chain (drive train, aerodynamics, pitch, torque).

The chain follows ANDES's links, each model naming the one before it::

    REGCA1 <-reg- REECA1 <-ree- WTDTA1 <-rego- WTARA1 <-rea- WTPTA1 <-rep- WTTQA1

Each turbine model resolves its link at initialization (when every component is set up) and
keeps the index of its REECA1, the row of its converter REGCA1 and the converter's rating
``Sn``. Signals to the electrical control (``wg``, ``Pref``) and from the aerodynamics to the
drive train (``Pm``) are arrays in ``ctx.sig`` indexed by the receiving model's instance.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ..namespace import NUMPY, put


def resolve(comp, system, field, target):
    """Indices in component ``target`` of the instances named by link ``field`` of ``comp``.

    Returns ``(target_component, indices)``; refuses a missing name and two instances of
    ``comp`` linked to one ``target`` instance (one turbine model of each kind per chain).
    """
    tc = system.components.get(target)
    out = np.zeros(comp.n, int)
    for i, lk in enumerate(comp.links):
        if tc is None or lk.get(field) not in tc.names:
            raise DataError(comp.element(i), field, lk.get(field), f"give the name of a {target} of the system")
        out[i] = tc.names.index(lk[field])
    if len(set(out.tolist())) != comp.n:
        raise DataError(comp.element(0), field, [lk.get(field) for lk in comp.links],
                        f"one {comp.type_name} per {target}")
    return tc, out


def andes_link(m, k, dev_name, field, target, why=""):
    """Link ``{field: weakgrid name}`` of ANDES turbine device ``k`` of model ``m`` to the ``target``
    device its ``field`` names; ``None`` (skipped) when that device exists but was skipped
    (out of service); refuses a name that is not a ``target``."""
    idx = getattr(m, field).v[k]
    name = dev_name.get((target, idx))
    if name is None:
        ss = m.system
        if target in ss.models and idx in list(ss.models[target].idx.v):
            return None
        raise DataError(f"ANDES {m.class_name} {m.idx.v[k]}", field, idx, f"no {target} with this idx{why}")
    return {field: name}


def chain_of(comp):
    """``(REECA1 component, REECA1 indices)`` of the instances of a turbine model (after init)."""
    return comp.ree_comp, comp.ree


def publish(ctx, key, n, idx, values, default, xp=NUMPY):
    """Write ``values`` at positions ``idx`` of the signal ``key`` (``n`` entries, ``default``
    elsewhere unless the signal already exists); ``xp``: the arrays' namespace."""
    x = ctx.x
    shape = tuple(x.shape[:-1]) + (n,)
    arr = ctx.sig.get(key)
    if arr is None or tuple(getattr(arr, "shape", ())) != shape:
        arr = xp.asarray(xp.broadcast_to(xp.asarray(default, dtype=xp.float64), shape), copy=True)
        ctx.sig[key] = arr
    put(xp, arr, idx, values)
    return arr


def chain_pattern(system, ree_comp, ree_idx, extra_states):
    """Jacobian coupling group of one turbine: its electrical control, converter, plant control
    (if any), bus variables and the turbine models' states (``extra_states``)."""
    rc = ree_comp.regc
    r = ree_comp.reg[ree_idx]
    v = list(extra_states) + ree_comp.instance_states(ree_idx) + rc.instance_states(r) + system.bus_vars(rc.bus[r])
    pc = system.components.get("REPCA1")
    if pc is not None:
        for i in range(pc.n):
            if pc.ree_comps[i] is ree_comp and pc.ree[i] == ree_idx:
                v += pc.instance_states(i) + system.bus_vars(pc.b1[i]) + system.bus_vars(pc.b2[i])
    for name in ("WTDTA1", "WTPTA1", "WTTQA1"):
        c = system.components.get(name)
        if c is not None and getattr(c, "ree", None) is not None:
            for i in np.nonzero(c.ree == ree_idx)[0]:
                v += c.instance_states(int(i))
    v = sorted(set(v))
    return (v, v)


def held(dx, x, lower, upper, xp=NUMPY):
    """``dx`` with 0 where the state ``x`` sits at a non-windup limit and is pushed outward.

    The integrator holds such a state (:mod:`weakgrid.sim.integrate`); writing the held
    derivative also makes a state that *starts* at its limit with an outward push (ANDES's
    pitch controller, whose speed reference is below the initial speed) an equilibrium.
    ``xp``: the arrays' namespace.
    """
    return xp.where(((x <= lower) & (dx < 0)) | ((x >= upper) & (dx > 0)), 0.0, dx)
