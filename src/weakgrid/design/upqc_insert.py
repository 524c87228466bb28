"""Insert a UPQC series branch into a branch of a network, on a chosen side.

The UPQC's series transformer is an impedance ``Zu`` between the chosen end bus of the branch
(which becomes the UPQC shunt bus r) and a new bus ``b1`` that takes that end's place on the
branch. The simulator's UPQC adds its series voltage at the r end of ``Zu`` (from-bus = r).

Works on a pandapower net (:func:`insert_upqc_pandapower`) and a MATPOWER case dict
(:func:`insert_upqc_matpower`); PSS/E and ANDES data reach the simulator as MATPOWER-form dicts
(:mod:`weakgrid.sim.io`), so they go through the MATPOWER version.
"""

from __future__ import annotations

import numpy as np

from ..game.errors import ParameterError

__all__ = ["insert_upqc_pandapower", "insert_upqc_matpower", "SIDES"]

SIDES = ("from", "to")


def _side(side):
    if side not in SIDES:
        raise ParameterError("upqc.side", side, f"choose one of {SIDES} (the branch end that "
                             "becomes the UPQC shunt bus)")


def insert_upqc_pandapower(net, element: str, index: int, side: str, r_pu: float, x_pu: float,
                           sn_mva: float, name: str = "UPQC series"):
    """Insert a UPQC series impedance into pandapower ``element`` (``line``/``trafo``/``impedance``).

    Parameters
    ----------
    net : pandapowerNet (modified in place)
    element : {"line", "trafo", "impedance"}
    index : int
        Index of the element in its table.
    side : {"from", "to"}
        Which end becomes the UPQC shunt bus r (for a trafo: "from" = hv side, "to" = lv side).
    r_pu, x_pu : float
        Series-transformer impedance, pu on ``sn_mva``.

    Returns
    -------
    dict
        ``{"shunt_bus": r, "series_bus": b1, "impedance": idx}`` (pandapower indices).
    """
    import pandapower as pp

    _side(side)
    cols = {"line": ("from_bus", "to_bus"), "trafo": ("hv_bus", "lv_bus"),
            "impedance": ("from_bus", "to_bus")}
    if element not in cols:
        raise ParameterError("upqc.element", element, f"choose one of {sorted(cols)}")
    tab = getattr(net, element)
    if index not in tab.index:
        raise ParameterError("upqc.index", index, f"no {element} with that index; "
                             f"choose one of {list(tab.index)[:20]}")
    col = cols[element][0 if side == "from" else 1]
    r = int(tab.at[index, col])
    b1 = pp.create_bus(net, float(net.bus.at[r, "vn_kv"]), name=f"{name} (series side)")
    tab.at[index, col] = b1
    imp = pp.create_impedance(net, r, b1, rft_pu=r_pu, xft_pu=x_pu, sn_mva=sn_mva, name=name)
    return {"shunt_bus": r, "series_bus": int(b1), "impedance": int(imp)}


def insert_upqc_matpower(case: dict, branch: int, side: str, r: float, x: float):
    """Insert a UPQC series branch (pu on the case base) at one end of branch row ``branch``.

    Returns ``(new_case, upqc_row, shunt_bus_id, series_bus_id)``; ``upqc_row`` is the 0-based
    branch row of the UPQC (from = shunt bus r, to = the new bus).
    """
    _side(side)
    bus = np.array(case["bus"], float)
    br = np.array(case["branch"], float)
    if not (0 <= branch < len(br)):
        raise ParameterError("upqc.branch", branch, f"give a branch row 0..{len(br) - 1}")
    col = 0 if side == "from" else 1
    r_id = int(br[branch, col])
    new_id = int(bus[:, 0].max()) + 1
    row = bus[bus[:, 0] == r_id][0].copy()
    row[0], row[1], row[2:6] = new_id, 1, 0.0            # PQ bus, no load, no shunt
    bus = np.vstack([bus, row])
    br[branch, col] = new_id
    up = np.zeros(br.shape[1])
    up[:5] = [r_id, new_id, r, x, 0.0]
    up[10] = 1
    if br.shape[1] > 12:
        up[11], up[12] = -360, 360
    br = np.vstack([br, up])
    out = dict(case, bus=bus, branch=br)
    return out, len(br) - 1, r_id, new_id
