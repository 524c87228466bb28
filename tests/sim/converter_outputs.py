"""Shared by the REECA1/REPCA1 peer tests: the converter's P and Q in both tools."""

import numpy as np

from weakgrid.sim.peer.andes_runs import interp_to


def pq_gap(a, w, tf, switching=(1.0, 1.1), margin=0.03):
    """Largest |P| and |Q| differences [pu] of REGCA1_1 between ANDES (``a``) and weakgrid
    (``w``) over ``[0, tf]`` s, away (``margin`` s) from the switching instants."""
    ss, r = a["ss"], w["res"]
    tg = np.linspace(0.0, tf, 2001)
    keep = np.all([np.abs(tg - ts) > margin for ts in switching], axis=0)
    out = []
    for v, k in ((ss.REGCA1.Pe, "REGCA1_1.Pe"), (ss.REGCA1.Qe, "REGCA1_1.Qe")):
        ya = interp_to(tg, a["t"], ss.dae.ts.y[:, [v.a[0]]])[:, 0]
        yw = interp_to(tg, r.t, np.asarray(r[k])[:, None])[:, 0]
        out.append(float(np.max(np.abs(ya - yw)[keep])))
    return out
