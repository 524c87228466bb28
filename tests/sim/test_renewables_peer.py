"""REGCA1 against ANDES 2.0 on the same data, driven into its limits.

Case: ANDES's ``kundur_full`` (its line trip off) plus a 600-MW converter plant
(static PV + REGCA1, 300 MVA) at load bus 7, with a three-phase fault at bus 8
from 1.0 to 1.1 s. The converter's low-voltage active-current management (LVG,
``Lvpnt1 = 0.9``) and high-voltage reactive-current management (HVG with
``Volim = 0.99``, ``Khv = 5``, floor ``Iolim``) both act during the run.
The two tools read the same ANDES data (devices added with ``ss.add``).

At the fixed step 1/120 s the speeds differ by ~9e-5 pu, as much as on the same
case without the plant: ANDES's own step error, which halves with the step.
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
RE = dict(Sn=300, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.9, Volim=0.99, Khv=5.0, Iolim=0.16)


def add_plant(ss):
    ss.add("PV", {"idx": "PVre", "bus": 7, "Sn": 300, "Vn": 230, "p0": 2.0, "q0": 0.3, "v0": 0.98,
                  "qmax": 99, "qmin": -99})
    ss.add("REGCA1", {"idx": "RE1", "bus": 7, "gen": "PVre", **RE})


def _pair(h, modify):
    w = run_weakgrid_ss(load_case(CASE, fault=FAULT, modify=modify), 10.0, h)
    a = run_andes_ss(load_case(CASE, fault=FAULT, modify=modify), 10.0, h)
    return a, w


@pytest.fixture(scope="module")
def runs():
    return {"plant": _pair(H, add_plant), "plant_h2": _pair(H / 2, add_plant), "base": _pair(H, None)}


def test_regca1_matches_andes(runs):
    a, w = runs["plant"]
    assert a["ok"] and w["ok"]
    dw, dd = compare_named(a, w)
    assert dw < 2e-4 and dd < 1.0, (dw, dd)
    # the plant adds (almost) nothing to the difference of the case without it ...
    dw0, _ = compare_named(*runs["base"])
    assert abs(dw - dw0) < 2e-5, (dw, dw0)
    # ... and the difference is step error: it shrinks with the step
    dw2, dd2 = compare_named(*runs["plant_h2"])
    assert dw2 < 0.7 * dw, (dw, dw2)


def _series(a, w):
    ss, r = a["ss"], w["res"]
    tg = np.linspace(0.0, 10.0, 4001)
    keep = (np.abs(tg - 1.0) > 0.03) & (np.abs(tg - 1.1) > 0.03)   # away from the switching instants

    def ay(v):
        return interp_to(tg, a["t"], ss.dae.ts.y[:, [v.a[0]]])[:, 0]

    def wy(k):
        return interp_to(tg, r.t, np.asarray(r[k])[:, None])[:, 0]

    return tg, keep, ay, wy, ss


def test_regca1_limits_engaged_and_outputs_agree(runs):
    a, w = runs["plant"]
    tg, keep, ay, wy, ss = _series(a, w)
    Pa, Pw = ay(ss.REGCA1.Pe), wy("REGCA1_RE1.Pe")
    Qa, Qw = ay(ss.REGCA1.Qe), wy("REGCA1_RE1.Qe")
    assert np.max(np.abs(Pa - Pw)[keep]) < 5e-3
    assert np.max(np.abs(Qa - Qw)[keep]) < 5e-3
    # low-voltage active current management cut the current (LVG < 1) in both tools
    assert wy("REGCA1_RE1.LVG").min() < 0.5
    assert np.min(Pa) < 0.5 * Pa[0]
    # the reactive current reached its floor Iolim (system base: Iolim * Sn / Sb)
    iolim = RE["Iolim"] * RE["Sn"] / 100.0
    iq = wy("REGCA1_RE1.Iqout")
    assert np.any(np.abs(iq - iolim) < 1e-9) and np.all(iq >= iolim - 1e-9)
