"""The RENA cases' last gap to PSS/E, measured and closed: PSS/E's converter P and Q right after a switch.

PSS/E's RENA results (REGCA1 + REECB1 + REPCA1 at bus 103, trip of line 101-103 at 1 s) show the
converter's P and Q rising over ~15 ms after the trip, while the converter's currents are states
(lags Tg = 0.02 s) that cannot jump: at constant current P and Q jump with the bus voltage
(1.015 -> 1.02464 pu) and then follow the controls. The continuous converter (ANDES's form,
``psse_interface = 0``) is 25-28 % of PSS/E's (tiny) swing off there. PSS/E's P and Q are short of
it by the *same* fraction: 0.47 % at the event sample (half the voltage jump), 0.21 % at +5 ms,
0.11 % at +10 ms, 0.05 % at +15 ms -- exactly ``Vest/|V|``, ``Vest`` averaged with ``|V|`` once per
5-ms step (``Vest <- (Vest + |V|)/2``, from ``(Vold + Vnew)/2`` at the event), a discrete state of
PSS/E's step, not a time constant (the data have none below 20 ms, and a continuous lag would
show the whole jump, not half, at the event). PSS/E's bus voltage is that of the *unscaled*
current: the scale is on the converter's P and Q, not on what the network receives.

weakgrid's REGCA1 reproduces this as ``psse_interface = 1`` (set by the PSS/E reader; see
:mod:`weakgrid.sim.renewables.regca1`). These tests check the measurement on the continuous form
(the factor applied afterwards closes the gap), that the model closes it the same way, and that
the network's voltage stays the unscaled current's. They also pin REPCA1's P limits on the plant's
total power reference (``P_total``): in the frequency-flag case PSS/E's power dips below P0
(0.39974 pu at 1.21 s) and weakgrid's could not (its PI pinned at Pmin = 0 as an increment).
"""

from pathlib import Path

import numpy as np
import pytest

from weakgrid.sim.peer import psid
from weakgrid.sim.renewables import REGCA1

pytestmark = pytest.mark.psse

TABLE = Path(__file__).resolve().parents[1] / "data" / "psid" / "cases.toml"
STEP = 0.005      # PSS/E's time step in these results (its sample spacing)
CASES = ("psid29_rena_default_flags", "psid29_rena_freq_flag")


@pytest.fixture
def continuous(monkeypatch):
    """Make the PSS/E reader build REGCA1 with the continuous form (``psse_interface = 0``)."""
    read = REGCA1.psse_params.__func__

    def params(cls, values, ctx):
        return {**read(cls, values, ctx), "psse_interface": 0.0}
    monkeypatch.setattr(REGCA1, "psse_params", classmethod(params))


def _series(case_id, dt=None):
    case = next(c for c in psid.load_cases(TABLE) if c["id"] == case_id)
    run = psid.run_weakgrid(case, dt=dt)
    assert run["res"].ok
    res, names = run["res"], run["names"]
    m = names.machine(103, "1")
    t = np.asarray(res.t)
    out = {q: psid.dedupe(t, np.asarray(res[k]))[1]
           for q, k in (("P", f"{m}.Pe"), ("Q", f"{m}.Qe"), ("V", f"bus{names.bus(103)}.v"))}
    tw = psid.dedupe(t, t)[0]
    ref = np.loadtxt(TABLE.parent / case["csv"], delimiter=",")
    keep = np.r_[True, np.diff(ref[:, 0]) > 1e-9]    # PSS/E's repeated event stamp: pre-event kept
    ref = ref[keep]
    return case, tw, out, ref


def _psse_interface(case, tw, V, tr):
    """``Vest/|V|`` at PSS/E's samples ``tr`` (1 before the event), from a continuous run."""
    ev = case["event"]["t"]
    Vi = np.interp(tr, tw, V)
    vold, vnew = np.interp(ev - 1e-9, tw, V), V[np.searchsorted(tw, ev + 1e-9)]
    scale, vest = np.ones_like(tr), 0.5 * (vold + vnew)
    for k in np.nonzero(tr > ev + 1e-9)[0]:
        vest = 0.5 * (vest + Vi[k])
        scale[k] = vest / Vi[k]
    assert np.allclose(np.diff(tr[(tr > ev) & (tr < ev + 0.1)]), STEP, atol=1e-5)
    return scale


def _shares(tw, s, ref, scale=1.0):
    tr = ref[:, 0]
    out = {}
    for q, yr in (("P", ref[:, 1]), ("Q", ref[:, 2])):
        y = np.interp(tr, tw, s[q]) * scale
        out[q] = np.abs(y - yr).max() / (yr.max() - yr.min())
    return out


@pytest.mark.parametrize("case_id", CASES)
def test_continuous_converter_gap_is_psse_interface(case_id, continuous):
    """The measurement: the continuous form is 20+ % of the swing off; PSS/E's factor applied to
    its P and Q brings it within 5 % (P 3.4 %, Q 1.7 % with default flags)."""
    case, tw, s, ref = _series(case_id)
    tr = ref[:, 0]
    as_is = _shares(tw, s, ref)
    applied = _shares(tw, s, ref, _psse_interface(case, tw, s["V"], tr))
    assert as_is["P"] > 0.2 and as_is["Q"] > 0.2, as_is
    assert applied["P"] < 0.05 and applied["Q"] < 0.05, applied


@pytest.mark.parametrize("case_id", CASES)
def test_psse_interface_closes_the_gap(case_id):
    """``from_psse`` builds REGCA1 with PSS/E's interface: P and Q within 5 % of PSS/E's swing at
    weakgrid's step (1/240 s) and at PSS/E's (5 ms), the model matching the factor applied to the
    continuous run, and the bus voltage the unscaled current's (as PSS/E's)."""
    for dt in (None, STEP):
        case, tw, s, ref = _series(case_id, dt)
        sh = _shares(tw, s, ref)
        assert sh["P"] < 0.05 and sh["Q"] < 0.05, (dt, sh)
    # the sample after the trip: PSS/E's V within 5e-6 pu of weakgrid's (scaling the injected
    # current instead would put it 2.5e-5 pu lower)
    tr = ref[:, 0]
    k = int(np.searchsorted(tr, case["event"]["t"] + STEP - 1e-9))
    assert abs(np.interp(tr[k], tw, s["V"]) - ref[k, 3]) < 5e-6


def test_model_reproduces_the_measured_factor(monkeypatch):
    """At PSS/E's step, the model's P and Q after the trip equal the continuous run's times the
    factor measured on PSS/E's samples, to 2 % of PSS/E's swing (the rest: the controls see the
    estimated power)."""
    case, tw, s1, ref = _series(CASES[0], STEP)
    read = REGCA1.psse_params.__func__
    monkeypatch.setattr(REGCA1, "psse_params",
                        classmethod(lambda cls, v, ctx: {**read(cls, v, ctx), "psse_interface": 0.0}))
    _, tw0, s0, _ = _series(CASES[0], STEP)
    tr = ref[:, 0]
    sc = _psse_interface(case, tw0, s0["V"], tr)
    win = (tr > 1.0) & (tr < 1.1)
    for q, col in (("P", 1), ("Q", 2)):
        swing = ref[:, col].max() - ref[:, col].min()
        d = np.interp(tr, tw, s1[q]) - np.interp(tr, tw0, s0[q]) * sc
        assert np.abs(d[win]).max() < 0.02 * swing, (q, np.abs(d[win]).max() / swing)


def test_rena_freq_flag_power_dips_below_p0_as_psse():
    """REPCA1 with Fflag = 1, Pmin = 0: the plant's total power reference is bounded, not the
    increment; after the trip's power excursion the P loop (Kpg = 1, Tp = 0.25 s) lowers the
    power below P0 as in PSS/E (0.39974 pu at 1.21 s)."""
    case, tw, s, ref = _series("psid29_rena_freq_flag")
    tr, Pr = ref[:, 0], ref[:, 1]
    win = (tr > 1.1) & (tr < 1.6)
    P = np.interp(tr, tw, s["P"])
    assert Pr[win].min() < 0.3998                   # PSS/E's dip
    assert P[win].min() < 0.3998                    # weakgrid's (before: >= 0.39999)
    assert np.abs(P[win] - Pr[win]).max() < 0.05 * (Pr.max() - Pr.min())
