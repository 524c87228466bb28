"""A failed run's cause in the grid's terms (the row of a sweep, the report).

The simulator says *that* the network's operating point ended at a fold (cause ``"voltage
collapse"``, :meth:`weakgrid.sim.integrate.Simulator._collapse`) and where, as the outputs of
every device at the last network solution before the fold. This module turns that into what
happened to the UPQC and the controlled machine: the series voltage applied at the fold (and
the rating and the controller's demand), the series power the shunt converter had to draw from
bus r, the shunt-bus voltage, and the controlled GTI's angle and its rate.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["failure_text"]


def _at(out, key, i):
    v = out.get(key)
    if v is None:
        return math.nan
    v = np.asarray(v).reshape(-1)
    return float(v[i]) if i < v.size else math.nan


def failure_text(failure, setup, demanded=None) -> str:
    """The failure cause of a run: the simulator's message, with the grid quantities at a fold.

    Parameters
    ----------
    failure : SimulationError or None
    setup : weakgrid.study.build.Setup
        The run's grid (names of the UPQC and of the controlled machine).
    demanded : array_like, optional
        The controller's last output ``[Vup, Vuq]`` [pu] (before the rating clips it).
    """
    if failure is None:
        return ""
    text = str(failure)
    fold = getattr(failure, "fold", None)
    if getattr(failure, "cause", "") != "voltage collapse" or not fold:
        return text
    out = fold["outputs"]
    sys = setup.system
    parts = []
    up = sys.components.get("UPQC")
    if up is not None and setup.upqc_name in up.names:
        i = up.names.index(setup.upqc_name)
        vmax = float(up.p["Vmax"][i])
        vu = _at(out, "UPQC.Vu", i)
        p = _at(out, "UPQC.P_series", i)
        vr = float(np.abs(fold["V"][up.r[i]]))
        s = f"series voltage |Vu| = {vu:.3g} pu applied (rating {vmax:g} pu"
        if demanded is not None and np.size(demanded) == 2:
            s += f", demanded {float(np.hypot(*np.asarray(demanded, float))):.3g} pu"
        s += (f"), series power P_series = {p * setup_sb(setup):.3g} MW (the shunt converter draws it "
              f"from bus r), "
              f"shunt-bus voltage |Vr| = {vr:.3g} pu")
        parts.append(s)
    gti = sys.components.get("GTI")
    name = getattr(setup, "source", None)      # the controlled machine's name
    if gti is not None and name in gti.names:
        j = gti.names.index(name)
        parts.append(f"GTI '{name}' angle ϕs = {_at(out, 'GTI.phi_s', j):.3g} rad "
                     f"(rate υ = {_at(out, 'GTI.upsilon', j):.3g} rad/s), power "
                     f"{_at(out, 'GTI.P_ac', j) * setup_sb(setup):.3g} MW")
    if not parts:
        return text
    return (f"voltage collapse at t = {failure.t:.6g} s: the network cannot carry the "
            f"operating point beyond a fold — at the fold: " + "; ".join(parts) + f". [{text}]")


def setup_sb(setup) -> float:
    """System base [MVA] of a setup (1 if unknown: values stay in pu)."""
    return float(getattr(setup, "Sb_mva", None) or 1.0)
