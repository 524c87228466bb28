"""The UPQC as a physical device in a study: its power rating, losses and dc link
(:class:`weakgrid.sim.upqc.UPQC`), from the study's ``[upqc]`` fields, and its power metrics.

Study fields (``[upqc]``; all optional):

``s_rating``  MVA, the apparent-power rating of each converter (series and shunt); default
              ``upqc.insert.sn_mva`` when given, else none (no current limit, no % of rating).
``chi``       the series converter's loss factor χ of the paper's (15) (dc power
              ``(1 + χ)·P_series`` while it delivers power); default: the controlled GTI's
              ``chi`` in the reduced structure (its converter feeds the series power, as in
              (15)), 0 in the conventional one.
``h_dc``      s, the dc-link energy ``Cdc·Vdc0²/2`` in seconds of ``s_rating`` (of ``Sb``
              without one); default 0.01 s.
``t_dc``      s, the dc-voltage loop's time constant ``Cdc·Vdc0/kp_dc``; the integral gain
              puts the PI's zero at ``4·t_dc``; default 0.02 s.
``r_shunt``   pu on ``s_rating`` (on ``Sb`` without one), the shunt converter's loss resistance
              ``P_loss = r·I_shunt²``; default 0.

The shunt converter's current limit is ``s_rating`` at 1 pu voltage: ``Imax = s_rating/Sb``.
"""

from __future__ import annotations

import math

import numpy as np

H_DC, T_DC = 0.01, 0.02


def s_rating_mva(up: dict) -> float | None:
    """The study's converter rating [MVA]: ``upqc.s_rating``, else ``upqc.insert.sn_mva``."""
    v = up.get("s_rating", (up.get("insert") or {}).get("sn_mva"))
    return None if v is None else float(v)


def upqc_params(data: dict, structure: str, Sb: float) -> dict:
    """The simulator parameters (system base ``Sb`` [MVA]) of the study's UPQC in
    ``structure``: ``Vmax``, ``chi``, ``Cdc``, ``kp_dc``, ``ki_dc``, ``Imax``, ``Rsh``."""
    up = data["upqc"]
    s = s_rating_mva(up)
    base = (s if s is not None else Sb) / Sb          # device power base in pu of Sb
    if "chi" in up:
        chi = float(up["chi"])
    elif structure == "reduced":
        ctl = data["machine"]["name"]
        chi = next((float(g.get("chi", 0.0)) for g in data["dynamics"]["gti"]
                    if g["name"] == ctl), 0.0)
    else:
        chi = 0.0
    h, t = float(up.get("h_dc", H_DC)), float(up.get("t_dc", T_DC))
    Cdc = 2 * h * base                                  # Vdc0 = 1 pu
    kp = Cdc / t
    return {"Vmax": float(up["rating"]), "chi": chi, "Cdc": Cdc, "kp_dc": kp,
            "ki_dc": kp / (4 * t), "Imax": base if s is not None else 0.0,
            "Rsh": float(up.get("r_shunt", 0.0)) / base}


def power_metrics(series: dict, post, Sb: float, s_rating: float | None,
                  line_mva: float) -> dict:
    """Peak apparent power of the series and shunt converters after the last disturbance
    (``post``: boolean mask of the samples) [MVA], as % of ``s_rating`` and of the line's
    apparent power ``line_mva`` at the operating point, and the flags ``over_rating`` /
    ``over_line`` (the peak of either converter beyond it)."""
    out = {}
    for key, name in (("s_series", "series"), ("s_shunt", "shunt")):
        if key not in series:
            continue
        y = np.abs(np.asarray(series[key], float)[post]) * Sb
        pk = float(np.nanmax(y)) if y.size else math.nan
        out[f"s_{name}_peak_mva"] = pk
        out[f"s_{name}_peak_pct_rating"] = 100 * pk / s_rating if s_rating else math.nan
        out[f"s_{name}_peak_pct_line"] = 100 * pk / line_mva if line_mva else math.nan
    if "shunt_limited" in series:
        out["shunt_limit_reached"] = bool(np.any(np.asarray(series["shunt_limited"]) > 0.5))
    peaks = [out.get(f"s_{n}_peak_mva", math.nan) for n in ("series", "shunt")]
    pk = max((p for p in peaks if p == p), default=math.nan)
    out["device_over_rating"] = bool(s_rating and pk > s_rating * (1 + 1e-9))
    out["device_over_line"] = bool(line_mva and pk > line_mva * (1 + 1e-9))
    return out
