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

__all__ = ["FAILED_CELLS_NOTE", "failure_kind", "failure_text"]

#: What a failed cell ("!") of a sweep map means (the report prints it beside the maps).
FAILED_CELLS_NOTE = (
    "A cell marked ! is a run that did not finish; its cause is in the sweep table's 'failure' "
    "column and in the summary. 'voltage collapse' is a real loss of the operating point of the "
    "simulated grid, not a numerical failure: the network equations have no solution beyond a "
    "fold (saddle-node), found by following the network's solution along the controller's "
    "series-voltage step (at a sample) or along the states' motion (between samples), and "
    "the failure says at which "
    "series voltage, series power, shunt-bus voltage and machine angle. 'loss of synchronism' "
    "means the machines' rotor angles swung apart from their initial operating point beyond the "
    "simulator's limit (180°). Either way the controlled "
    "grid lost its operating point in that cell; the study's notes say where and why.")


def failure_kind(text) -> str:
    """The kind of a failure cause (``""`` if none): "voltage collapse", "loss of
    synchronism", "Newton failure", "divergence", "controller error" or "failed"."""
    text = str(text or "")
    if not text:
        return ""
    for key, kind in (("voltage collapse", "voltage collapse"),
                      ("loss of synchronism", "loss of synchronism"),
                      ("newton", "Newton failure"), ("divergence", "divergence"),
                      ("controller", "controller error")):
        if key in text:
            return kind
    return "failed"


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
        phi, ups = _at(out, "GTI.phi_s", j), _at(out, "GTI.upsilon", j)
        parts.append(f"GTI '{name}' angle ϕs = {phi:.3g} rad w.r.t. bus r (rate υ = {ups:.3g} "
                     f"rad/s), power {_at(out, 'GTI.P_ac', j) * setup_sb(setup):.3g} MW"
                     + (" — past 90° and still rising: the GTI is slipping out of step"
                        if phi > math.pi / 2 and ups > 0 else ""))
    if not parts:
        return text
    return (f"voltage collapse at t = {failure.t:.6g} s: the network cannot carry the "
            f"operating point beyond a fold — at the fold: " + "; ".join(parts) + f". [{text}]")


def setup_sb(setup) -> float:
    """System base [MVA] of a setup (1 if unknown: values stay in pu)."""
    return float(getattr(setup, "Sb_mva", None) or 1.0)
