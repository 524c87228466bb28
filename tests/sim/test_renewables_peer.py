"""REGCA1 and PVD1 against ANDES 2.0 on the same data, driven into their limits.

Case: ANDES's ``kundur_full`` (its line trip off) plus
* a 150-MW converter plant (static PV + REGCA1, 300 MVA) at load bus 7, whose
  low-voltage active-current management (LVG, ``Lvpnt1 = 0.9``) and high-voltage
  reactive-current management (HVG with ``Volim = 1.005``, ``Khv = 10``, floor ``Iolim``) act;
* a 100-MW distributed PV (static PV + two PVD1 sharing it, 75 MVA each, with the
  frequency measured by a BusFreq) at load bus 9, whose Q-V droop (``v0 = 0.95``) and
  current limit (``ialim``, Q priority) act;
with a three-phase fault at bus 8 from 1.0 to 1.1 s. Both tools read the same ANDES
data (devices added with ``ss.add``) and run at the same fixed step.

At 1/120 s the speeds differ by 4.5e-5 pu and the relative angles by 0.18 deg; at 1/240 s
by 3.4e-5 pu and 0.13 deg. The difference shrinks more slowly than the trapezoidal rule's
h^2: the same holds for ``kundur_full`` alone (3.3e-5 -> 2.1e-5 pu with a 50-ms fault), and the
converter limits switch zones during the run (ANDES evaluates its limiter flags between Newton
iterations; weakgrid's clips are exact functions of the iterate), which likely adds a first-order
part. The issue's 2e-5 pu is therefore not reached on this case at these steps.
"""

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.peer.andes_case import (compare_named, load_case, run_andes_ss,  # noqa: E402
                                          run_weakgrid_ss)
from weakgrid.sim.peer.andes_runs import interp_to  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]

CASE = "kundur/kundur_full.xlsx"
FAULT = (8, 1.0, 1.1)
H = 1 / 120
RE = dict(Sn=300, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.9, Volim=1.005, Khv=10.0, Iolim=0.45)
PVD = dict(Sn=75, gammap=0.5, gammaq=0.5, v0=0.95, pqflag=0, ialim=1.1, vt0=0.2, vt1=0.3,
           ddn=0.0, ft2=60.6, ft3=60.8)


def add_plants(ss):
    ss.add("PV", {"idx": "PVre", "bus": 7, "Sn": 300, "Vn": 230, "p0": 1.5, "q0": 0.3, "v0": 1.0,
                  "qmax": 99, "qmin": -99})
    ss.add("REGCA1", {"idx": "RE1", "bus": 7, "gen": "PVre", **RE})
    ss.add("PV", {"idx": "PVd", "bus": 9, "Sn": 150, "Vn": 230, "p0": 1.0, "q0": 0.0, "v0": 0.975,
                  "qmax": 99, "qmin": -99})
    ss.add("BusFreq", {"idx": "BF9", "bus": 9, "Tf": 0.02, "Tw": 0.05})
    for k in (1, 2):
        ss.add("PVD1", {"idx": f"D{k}", "bus": 9, "gen": "PVd", "busf": "BF9", **PVD})


def _pair(h):
    w = run_weakgrid_ss(load_case(CASE, fault=FAULT, modify=add_plants), 10.0, h)
    a = run_andes_ss(load_case(CASE, fault=FAULT, modify=add_plants), 10.0, h)
    return a, w


@pytest.fixture(scope="module")
def runs():
    return {"h": _pair(H), "h2": _pair(H / 2)}


def _series(a, w):
    ss, r = a["ss"], w["res"]
    tg = np.linspace(0.0, 10.0, 4001)
    keep = (np.abs(tg - 1.0) > 0.03) & (np.abs(tg - 1.1) > 0.03)   # away from the switching instants

    def ay(v):
        return interp_to(tg, a["t"], ss.dae.ts.y[:, [v.a[0]]])[:, 0]

    def ax(v):
        return interp_to(tg, a["t"], ss.dae.ts.x[:, [v.a[0]]])[:, 0]

    def wy(k):
        return interp_to(tg, r.t, np.asarray(r[k])[:, None])[:, 0]

    return keep, ay, ax, wy, ss


def test_speeds_and_angles_match_andes(runs):
    a, w = runs["h"]
    assert a["ok"] and w["ok"]
    dw, dd = compare_named(a, w)
    assert dw < 1e-4 and dd < 0.5, (dw, dd)
    # the difference shrinks when both tools halve the step (4.5e-5 -> 3.4e-5 pu: slower than
    # the trapezoid's h^2, see the module docstring)
    dw2, dd2 = compare_named(*runs["h2"])
    assert dw2 < 0.9 * dw and dd2 < 0.9 * dd, (dw, dw2, dd, dd2)


def test_regca1_limits_engaged_and_outputs_agree(runs):
    keep, ay, ax, wy, ss = _series(*runs["h"])
    Pa, Pw = ay(ss.REGCA1.Pe), wy("REGCA1_RE1.Pe")
    Qa, Qw = ay(ss.REGCA1.Qe), wy("REGCA1_RE1.Qe")
    eP, eQ = np.max(np.abs(Pa - Pw)[keep]), np.max(np.abs(Qa - Qw)[keep])
    assert eP < 1e-2 and eQ < 1e-2, (eP, eQ)
    # step error: halving the step in both tools shrinks the difference
    k2, ay2, _, wy2, ss2 = _series(*runs["h2"])
    assert np.max(np.abs(ay2(ss2.REGCA1.Pe) - wy2("REGCA1_RE1.Pe"))[k2]) < 0.8 * eP
    # low-voltage active current management cut the current (LVG < 1) in both tools
    assert wy("REGCA1_RE1.LVG").min() < 0.6
    assert np.min(Pa[keep]) < 0.6 * Pa[0]
    # the reactive current reached its floor Iolim (system base: Iolim * Sn / Sb)
    iolim = RE["Iolim"] * RE["Sn"] / 100.0
    iq = wy("REGCA1_RE1.Iqout")
    assert np.any(np.abs(iq - iolim) < 1e-9) and np.all(iq >= iolim - 1e-9)


def test_pvd1_limits_engaged_and_outputs_agree(runs):
    errs = {}
    for key in ("h", "h2"):
        keep, ay, ax, wy, ss = _series(*runs[key])
        errs[key] = [np.abs(ax(ss.PVD1.Ipout_y) - wy("PVD1_D1.Ipout"))[keep],
                     np.abs(ax(ss.PVD1.Iqout_y) - wy("PVD1_D1.Iqout"))[keep]]
    ep, eq = errs["h"]
    assert ep.max() < 1e-2 and eq.mean() < 2e-3, (ep.max(), eq.mean())
    # the largest Iq difference (right after clearing, where the Q-V droop switches zones)
    # is step error: it shrinks with the step
    assert errs["h2"][1].max() < 0.8 * eq.max()
    keep, ay, ax, wy, ss = _series(*runs["h"])
    iq0 = wy("PVD1_D1.Iqout")[0]
    assert wy("PVD1_D1.Iqout").max() > iq0 + 0.3            # Q-V droop injected reactive current
    lim = PVD["ialim"] * PVD["Sn"] / 100.0
    ip, iq = wy("PVD1_D1.Ipcmd"), wy("PVD1_D1.Iqcmd")
    cut = wy("PVD1_D1.Ipul") - ip
    assert cut.max() > 0.05                                  # the current limit cut Ip (Q priority)
    assert np.all(ip ** 2 + iq ** 2 <= lim ** 2 + 1e-9)
