"""The PI outputs ANDES 2.0 holds in a voltage dip of REECA1/REECB1, replayed in weakgrid.

In a voltage dip (``v < Vdip`` or ``v > Vup``) the electrical controls freeze their reactive
power and voltage PI controllers (``PIQ``, ``PIV``). weakgrid holds each output at its value at
the last accepted point before the dip. ANDES evaluates the dip flag at every Newton iterate and
freezes the output (its algebraic variable ``PIQ_y``, ``PIV_y``) at its value in the iterate at
which the flag switched. After a network event that value is neither the pre-dip output nor the
in-dip one:

* at a fault, the first (polar) Newton iterate still carries the pre-fault flag and lands about
  half-way down in voltage, so the output is held at the proportional response to that iterate;
* at the clearing, ANDES's ``Fault`` restores every algebraic variable to its pre-fault value
  (``Fault.config.restore = 1``), so the first iterate is again outside the dip and the output is
  held once more at a new iterate value, with the integrator states still frozen.

The held values depend on ANDES's Newton path (coordinates, starting point), not on the model, so
no model flag reproduces them. :func:`andes_dip_holds` reads them from an ANDES run and
:func:`impose_dip_holds` makes a weakgrid system hold the same values, which isolates this
difference from the rest of the model (``tests/sim/test_reecb1_peer.py``). ANDES (GPL) is
imported, never copied.
"""

from __future__ import annotations

import numpy as np

MODELS = ("REECA1", "REECB1")


def andes_dip_holds(ss, models=MODELS):
    """Held PI outputs of every REECA1/REECB1 of a simulated ANDES system.

    Returns ``{(model, weakgrid name): [(t, PIQ_y, PIV_y), ...]}``: one entry per dip point at
    which ANDES's held pair first takes a new value (the start of a dip, and every event inside
    one), in time order. ``ss`` must have run its time domain (``ss.dae.ts``).
    """
    ts = ss.dae.ts
    t = np.asarray(ts.t)
    out = {}
    for mname in models:
        m = ss.models.get(mname)
        if m is None:
            continue
        for k in range(m.n):
            if m.u.v[k] <= 0:
                continue
            v = np.asarray(ts.y[:, m.v.a[k]])
            piq = np.asarray(ts.y[:, m.PIQ_y.a[k]])
            piv = np.asarray(ts.y[:, m.PIV_y.a[k]])
            dip = (v < m.Vdip.v[k]) | (v > m.Vup.v[k])
            segs = []
            for i in np.nonzero(dip)[0]:
                if i == 0 or not dip[i - 1] or piq[i] != piq[i - 1] or piv[i] != piv[i - 1]:
                    segs.append((float(t[i]), float(piq[i]), float(piv[i])))
            out[(mname, f"{mname}_{m.idx.v[k]}")] = segs
    return out


def impose_dip_holds(system, holds, lead=2e-4):
    """Make the REECA1/REECB1 of a set-up weakgrid ``system`` hold ANDES's values in a dip.

    ``holds`` as returned by :func:`andes_dip_holds`. From each entry's time on (less ``lead``
    [s], since ANDES's first point after an event lies 1e-4 s after it) the device's held PI
    outputs are those of the latest entry (outside a dip they are not read). The dips are
    assumed to be the same in both tools (true when the trajectories agree). Only this system
    object is changed.
    """
    by_model = {}
    for (mname, name), segs in holds.items():
        by_model.setdefault(mname, []).append((name, segs))
    for mname, devs in by_model.items():
        comp = system.components.get(mname)
        if comp is None:
            continue
        rows = [(comp.names.index(name), segs) for name, segs in devs if name in comp.names]
        compute = comp.compute

        def compute_held(ctx, comp=comp, rows=rows, compute=compute):
            t = float(np.max(ctx.t))
            for i, segs in rows:
                cur = [s for s in segs if t >= s[0] - lead]
                if cur:
                    comp._piq_hold[i], comp._piv_hold[i] = cur[-1][1], cur[-1][2]
            return compute(ctx)

        comp.compute = compute_held
    return system
