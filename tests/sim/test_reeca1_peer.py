"""REGCA1 + REECA1 against ANDES 2.0 on a case ANDES ships (``kundur/kundur_reg.xlsx``).

The case replaces generator 4 of the Kundur system by a 700-MW converter (REGCA1) with its
electrical control (REECA1); its plant control (REPCA1) is switched off in both tools, and its
line trip is replaced by a three-phase fault at bus 8 from 1.0 to 1.1 s. The fault drives the
converter through the voltage-dip logic (Volt_dip, frozen controls, Iqinj for |Thld| = 2 s
after the dip, Ipmax held for Thld2 = 1 s), the VDL1 reactive current limit and the LVPL.

ANDES's "fixed" step (``fixt = 1``) is only an upper bound: after a step that needs more than
6 Newton iterations it shortens the next one (by 5 %, by half above 15) and regrows it by 10 %
a step; here its steps shrink to 1-4 ms (h/8 to h/2) through the fault and the recovery. The
runs below hold ANDES's step at ``tstep`` (``run_andes_ss(..., hold_step=True)``, which wraps
its step control; ANDES's points 1e-4 s around each event are kept). Measured (5 s; largest
speed difference in pu, relative angle to GENROU_1 in deg; h = 1/120 s; both tools at the
same truly fixed step):

=======================  =================  =================  ==================
step (both tools)         as shipped         QFLAG = 1 (PI)     limits (PQFLAG = 1)
=======================  =================  =================  ==================
h                         1.04e-4, 0.54      1.62e-4, 0.47      7.4e-5, 0.39
h/2                       5.4e-5, 0.28       5.3e-5, 0.28       3.1e-5, 0.17
h/4                       2.8e-5, 0.15       2.8e-5, 0.15       3.0e-5, 0.13
h/8                       1.53e-5, 0.083     1.52e-5, 0.082     3.1e-5, 0.12
ANDES h/4 vs h/8          9.9e-6             1.5e-5             1.25e-5
weakgrid h/4 vs h/8       2.3e-5             9.4e-6             9.8e-7
=======================  =================  =================  ==================

As shipped and with the voltage PI on (QFLAG = 1, Kvp = 5, Kvi = 20, Vref1 = v0 = 1), the
difference halves with the step in both tools and is below 2e-5 pu at h/8: it is the step
error of both (first order: limiter and dip flags switch at step boundaries). (Against ANDES
with its own step control, weakgrid at h/8 vs ANDES at nominal h gave 1.9e-5 pu.)

With P priority (PQFLAG = 1: VDL2 bounds the active current, the reactive current reaches
sqrt(Imax^2 - Ip^2), |I| reaches Imax) two departures of ANDES kept the tools 3e-5 pu apart
at every step (weakgrid's standard models converged to 1e-6 pu from h/4 to h/8), and 1.4e-2
pu with the voltage PI on too:

* LVPL. ANDES's ``AntiWindup`` resets a state above its upper limit only while the state's
  derivative is >= 0. When LVPL falls in the fault below REGCA1's active current state S0,
  which is decreasing towards Ipcmd, ANDES lets S0 stay above the limit (S0 = 5.4 pu with
  LVPL = 0.34 pu at the end of the fault). weakgrid's standard REGCA1 holds S0 at LVPL;
  ``conventions="andes"`` sets its flag ``LVPL_strict = 0`` (ANDES's reset). Up to the
  clearing: 1.9e-5 pu with the standard LVPL, 3.2e-6 pu with ANDES's.
* Newton start at the clearing. ANDES's ``Fault`` restores all algebraic variables but the
  bus angles to their pre-fault values at clearing (config ``restore = 1``), so the first
  Newton iterate of the step after it has v = 1.0 pu, inside [Vdip, Vup]. ANDES evaluates
  its discrete services (``Volt_dip``, the Thld2 ``ExtendedEvent``, the ``VarHold`` of Ipmax,
  the PI freeze, which switches the PI's algebraic equations off so that they keep the
  iterate's values) at every Newton iterate and keeps what they record there, so that iterate "ends" the dip: the Thld2 hold starts and captures the
  restored Ipmax (Imax = 10 pu), although at every *accepted* point the voltage stays outside
  the band (0.45 pu before, 1.12 pu after the clearing); with the voltage PI on, its frozen
  output is recomputed at that iterate (8.948 pu, its upper limit) and frozen there when the
  dip resumes at the next one, and ANDES stops at h/4 ("Time step reduced to zero"). This is
  an artifact of iterates, not a model to reproduce: the harness removes it from ANDES
  (``solve_network_at_clearing``: after ANDES's restore the network is solved
  with the states and every ``VarService`` kept as at the clearing; ANDES's own step then
  starts there, nothing else changes). (``restore = 0`` is no remedy: ANDES's Newton then
  converges to a low-voltage solution, v = 0.44 pu after clearing.)

With both (weakgrid ``conventions="andes"``, ANDES started on the solution), both tools at
the same truly fixed step:

=======================  ======================  ==========================
step (both tools)         limits (PQFLAG = 1)     QFLAG = 1 and PQFLAG = 1
=======================  ======================  ==========================
h                         9.3e-5, 0.49            9.3e-5, 0.49
h/2                       4.7e-5, 0.25            4.7e-5, 0.24
h/4                       3.1e-5, 0.15            2.9e-5, 0.15
h/8                       1.69e-5, 0.082          1.58e-5, 0.080
ANDES h/4 vs h/8          2.3e-5                  2.2e-5
weakgrid h/4 vs h/8       1.5e-5                  1.5e-5
=======================  ======================  ==========================

The difference shrinks with the step and is within 2e-5 pu at h/8, where each tool's own
step error from h/4 to h/8 is as large (ANDES's LVPL reset makes S0 jump at a step
boundary, a first-order error in both).
"""

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.peer.andes_case import (compare_named, load_case, run_andes_ss,  # noqa: E402
                                          run_weakgrid_ss, solve_network_at_clearing)
from converter_outputs import pq_gap  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]

CASE = "kundur/kundur_reg.xlsx"
FAULT = (8, 1.0, 1.1)
H = 1 / 120
TF = 5.0


def no_plant(ss):
    ss.REPCA1.u.v[0] = 0


def _set(**fields):
    def modify(ss):
        no_plant(ss)
        for f, v in fields.items():
            getattr(ss.REECA1, f).v[0] = v
    return modify


limits = _set(PQFLAG=1)
voltage_pi = _set(QFLAG=1, Kvp=5, Kvi=20)            # Vref1 = v0 = 1 pu in the case
voltage_pi_p = _set(QFLAG=1, Kvp=5, Kvi=20, PQFLAG=1)


def _run(tool, h, modify, hold_step=True, solve_at_clearing=False, conventions="standard"):
    ss = load_case(CASE, fault=FAULT, modify=modify)
    if tool == "andes":
        return run_andes_ss(ss, TF, h, hold_step=hold_step,
                            configure=solve_network_at_clearing if solve_at_clearing else None)
    return run_weakgrid_ss(ss, TF, h, conventions=conventions)


def _andes(a, model, var):
    """ANDES trajectory of ``model.var`` (first device), from its stored time series."""
    ss = a["ss"]
    v = getattr(ss.models[model], var)
    return (ss.dae.ts.x if v.v_code == "x" else ss.dae.ts.y)[:, v.a[0]]


def _steps(a):
    """ANDES's step sizes away from its event points (1e-4 s around each switching time)."""
    t = a["t"]
    dt = np.diff(t)
    near = np.any([np.abs(t[:-1] - ts) < 2e-4 for ts in (0.0, *FAULT[1:])], axis=0)
    near |= np.any([np.abs(t[1:] - ts) < 2e-4 for ts in FAULT[1:]], axis=0)
    return t[:-1][~near], dt[~near]


@pytest.fixture(scope="module")
def runs():
    return {"a": _run("andes", H, no_plant), "a2": _run("andes", H / 2, no_plant),
            "a8": _run("andes", H / 8, no_plant), "own": _run("andes", H, no_plant, hold_step=False),
            "w": _run("weakgrid", H, no_plant), "w2": _run("weakgrid", H / 2, no_plant),
            "w8": _run("weakgrid", H / 8, no_plant)}


def test_imports_the_renewable_chain():
    from weakgrid.sim.io.andes import from_andes

    system, _ = from_andes(load_case(CASE, modify=no_plant))
    assert system.components["REECA1"].n == 1
    assert system.components.get("REPCA1") is None or system.components["REPCA1"].n == 0
    system, _ = from_andes(load_case(CASE))
    assert system.components["REPCA1"].n == 1
    assert system.components["REPCA1"].links[0]["ree"] == "REECA1_1"


def test_andes_step_is_held(runs):
    """The harness holds ANDES's step; ANDES's own control shortens it after the clearing."""
    for k, h in (("a", H), ("a2", H / 2), ("a8", H / 8)):
        _, dt = _steps(runs[k])
        assert np.allclose(dt[:-1], h, rtol=1e-9, atol=0), k     # the last one ends at TF
    t, dt = _steps(runs["own"])
    after = (t > 1.1) & (t < 1.25)
    assert dt[after].min() < H / 2                  # ANDES's own steps in the recovery


def test_speeds_angles_and_converter_outputs_match_andes(runs):
    """Same truly fixed step in both tools: the difference halves with the step and is below
    2e-5 pu at h/8 (measured 1.04e-4, 5.4e-5, 1.53e-5 pu)."""
    assert all(r["ok"] for r in runs.values())
    d = [compare_named(runs["a" + k], runs["w" + k]) for k in ("", "2", "8")]
    (dw, _), (dw2, _), (dw8, dd8) = d
    assert dw8 < 2e-5 and dd8 < 0.5, d
    assert dw2 < 0.65 * dw and dw8 < 0.25 * dw, d       # shrinks with the step in both
    # both tools' own step error is of the size of the difference
    assert compare_named(runs["w"], runs["w2"])[0] > 0.5 * dw
    assert compare_named(runs["a"], runs["a2"])[0] > 0.3 * dw
    eP, eQ = pq_gap(runs["a8"], runs["w8"], TF)
    assert eP < 0.1 and eQ < 0.1, (eP, eQ)      # pu on 100 MVA, of a 700-MW plant
    # the dip logic and limits acted (weakgrid trajectories)
    r = runs["w8"]["res"]
    t = r.t
    dip = np.asarray(r["REECA1_1.Volt_dip"]) > 0
    assert dip[(t > 1.01) & (t < 1.09)].all() and not dip[t > 1.2].any()
    iq, iqmax = np.asarray(r["REECA1_1.Iqcmd"]), np.asarray(r["REECA1_1.Iqmax"])
    assert np.any((np.abs(iq - iqmax) < 1e-9) & (iqmax < 9.0))     # VDL1 limit reached
    assert np.all(iq <= iqmax + 1e-9)
    assert np.asarray(r["REGCA1_1.LVPL"]).min() < 0.5                # LVPL acted
    assert np.asarray(r["REECA1_1.fThld2"]).max() == 1               # Ipmax held after the dip


def test_voltage_pi_matches_andes():
    """QFLAG = 1: the voltage PI (frozen in the dip) drives the reactive current. Measured
    1.62e-4 pu at h, 1.52e-5 pu at h/8 (both tools)."""
    a, w = _run("andes", H, voltage_pi), _run("weakgrid", H, voltage_pi)
    a8, w8 = _run("andes", H / 8, voltage_pi), _run("weakgrid", H / 8, voltage_pi)
    assert a["ok"] and w["ok"] and a8["ok"] and w8["ok"]
    dw, _ = compare_named(a, w)
    dw8, dd8 = compare_named(a8, w8)
    assert dw8 < 2e-5 and dd8 < 0.5 and dw8 < 0.25 * dw, (dw, dw8, dd8)
    r = w8["res"]
    t, piv = r.t, np.asarray(r["REECA1_1.PIV_y"])
    dip = np.asarray(r["REECA1_1.Volt_dip"]) > 0
    assert dip.any() and np.ptp(piv[dip]) < 1e-12                   # frozen in the dip
    assert np.ptp(piv[t > 2.0]) > 1e-3                              # and acting after it


def _vdl2(ree, s0):
    """REECA1's VDL2 table (ANDES device ``ree``) at filtered voltage ``s0``."""
    vp = [getattr(ree, f"Vp{j}").v[0] for j in range(1, 5)]
    ipv = [getattr(ree, f"Ip{j}").v[0] for j in range(1, 5)]
    return float(np.interp(s0, vp, ipv))


def _ipmax_after_clearing(a):
    """ANDES's Ipmax at its first point after the clearing, and VDL2 of its filtered voltage."""
    k = np.searchsorted(a["t"], FAULT[2] + 5e-5)
    return _andes(a, "REECA1", "Ipmax")[k], _vdl2(a["ss"].REECA1, _andes(a, "REECA1", "s0_y")[k])


def _fault_part(a, w):
    return compare_named(a, w, np.linspace(0.0, FAULT[2], 2001))[0]


@pytest.fixture(scope="module")
def lim():
    """The limits case (P priority). ANDES with its first Newton iterate after the clearing
    on the network's solution (``solve_network_at_clearing``) and, at h, as ANDES does it
    (``"a_raw"``); weakgrid with ANDES's conventions (REGCA1 ``LVPL_strict = 0``) and, at h,
    with the standard LVPL (``"w_std"``)."""
    return {"a": _run("andes", H, limits, solve_at_clearing=True),
            "a8": _run("andes", H / 8, limits, solve_at_clearing=True),
            "a_raw": _run("andes", H, limits),
            "w": _run("weakgrid", H, limits, conventions="andes"),
            "w8": _run("weakgrid", H / 8, limits, conventions="andes"),
            "w_std": _run("weakgrid", H, limits)}


def test_limits_case_matches_andes(lim):
    """P priority (PQFLAG = 1), with ANDES's LVPL reset (``conventions="andes"``) and ANDES
    started on the network's solution after the clearing: 9.3e-5, 4.7e-5, 3.1e-5, 1.69e-5 pu
    at h, h/2, h/4, h/8 (0.49, 0.25, 0.15, 0.082 deg); each tool moves by as much from h/4 to
    h/8 (ANDES 2.3e-5, weakgrid 1.5e-5 pu): the step error of both."""
    assert all(r["ok"] for r in lim.values())
    dw, _ = compare_named(lim["a"], lim["w"])
    dw8, dd8 = compare_named(lim["a8"], lim["w8"])
    print(f"limits: {dw:.3g} pu at h, {dw8:.3g} pu / {dd8:.3g} deg at h/8; ANDES h vs h/8 "
          f"{compare_named(lim['a'], lim['a8'])[0]:.3g}, weakgrid {compare_named(lim['w'], lim['w8'])[0]:.3g}")
    assert dw8 < 2e-5 and dd8 < 0.5, (dw, dw8, dd8)
    assert dw8 < 0.3 * dw, (dw, dw8)                              # shrinks with the step
    assert compare_named(lim["a"], lim["a8"])[0] > 2 * dw8        # ANDES's own step error
    assert compare_named(lim["w"], lim["w8"])[0] > 2 * dw8        # weakgrid's
    eP, eQ = pq_gap(lim["a8"], lim["w8"], TF)
    assert eP < 0.1 and eQ < 0.1, (eP, eQ)
    # the case drives the limits (weakgrid trajectories)
    r = lim["w8"]["res"]
    ip, iq = np.asarray(r["REECA1_1.Ipcmd"]), np.asarray(r["REECA1_1.Iqcmd"])
    assert np.max(np.hypot(ip, iq)) == pytest.approx(10.0, abs=1e-6)   # |I| reaches Imax = 10 pu
    iqmax, ipmax = np.asarray(r["REECA1_1.Iqmax"]), np.asarray(r["REECA1_1.Ipmax"])
    assert np.any(np.abs(iq - iqmax) < 1e-9) and np.all(iq <= iqmax + 1e-9)   # sqrt(Imax^2 - Ip^2)
    assert np.any((np.abs(ip - ipmax) < 1e-9) & (ipmax < 9.0))         # VDL2 bound Ip in the dip
    dip = np.asarray(r["REECA1_1.Volt_dip"]) > 0
    assert dip[(r.t > 1.01) & (r.t < 1.09)].all() and not dip[r.t > 1.5].any()
    lvpl = np.asarray(r["REGCA1_1.LVPL"])
    assert lvpl.min() < 0.5                                            # LVPL acted
    # and so does ANDES's LVPL reset: S0 above LVPL in the fault, in both tools
    s0 = np.asarray(r["REGCA1_1.S0"])
    fault = (r.t > 1.05) & (r.t < 1.1)
    assert np.max((s0 - lvpl)[fault]) > 1.0
    ta = lim["a8"]["t"]
    fa = (ta > 1.05) & (ta < 1.1)
    assert np.max((_andes(lim["a8"], "REGCA1", "S0_y") - _andes(lim["a8"], "REGCA1", "LVPL_y"))[fa]) > 1.0
    # after the clearing both tools take Ipmax from VDL2 (the dip goes on)
    ipmax_a, vdl2 = _ipmax_after_clearing(lim["a8"])
    assert ipmax_a == pytest.approx(vdl2, abs=1e-6) and vdl2 < 5.0


def test_limits_case_lvpl_reset_convention(lim):
    """REGCA1's LVPL: the standard limit (S0 never above LVPL) against ANDES's reset only
    while dS0/dt >= 0. Up to the clearing the standard model differs from ANDES by 2.0e-5 pu
    at h, ANDES's convention by 3.2e-6 pu."""
    std, anc = _fault_part(lim["a"], lim["w_std"]), _fault_part(lim["a"], lim["w"])
    print(f"LVPL: to the clearing standard {std:.3g} pu, ANDES's convention {anc:.3g} pu; total "
          f"{compare_named(lim['a'], lim['w_std'])[0]:.3g} / {compare_named(lim['a'], lim['w'])[0]:.3g} pu")
    assert anc < 5e-6 and std > 3 * anc, (std, anc)
    r = lim["w_std"]["res"]
    assert np.all(np.asarray(r["REGCA1_1.S0"]) <= np.asarray(r["REGCA1_1.LVPL"]) + 1e-6)
    s = lim["w"]["system"]
    assert s.components["REGCA1"].p["LVPL_strict"][0] == 0
    assert lim["w_std"]["system"].components["REGCA1"].p["LVPL_strict"][0] == 1
    assert any("REGCA1 (1): ANDES 2.0 conventions, LVPL_strict = 0" in n for n in s.import_notes)


def test_limits_case_andes_newton_start_at_clearing(lim):
    """ANDES's first Newton iterate after the clearing starts from the restored pre-fault
    values (v = 1.0 pu, inside [Vdip, Vup]); its dip flags, evaluated there, end the dip and
    start the Thld2 hold of Ipmax at Imax, although at every accepted point the voltage stays
    outside the band. Started on the network's solution, ANDES takes Ipmax from VDL2 as
    weakgrid does; the artifact alone moves ANDES's result by 1.2e-4 pu at h (to weakgrid:
    1.69e-4 pu as ANDES does it, 9.3e-5 pu started on the solution)."""
    a, a_raw = lim["a"], lim["a_raw"]
    ree = a_raw["ss"].REECA1
    ta, v = a_raw["t"], _andes(a_raw, "REECA1", "v")
    around = (ta > 1.0 + 1e-3) & (ta < 1.1 + 2e-3)
    assert np.all((v[around] < ree.Vdip.v[0]) | (v[around] > ree.Vup.v[0]))   # the dip goes on
    ipmax_raw, vdl2_raw = _ipmax_after_clearing(a_raw)
    assert ipmax_raw == pytest.approx(ree.Imax.v[0]) and vdl2_raw < 5.0         # held at Imax
    ipmax, vdl2 = _ipmax_after_clearing(a)
    assert ipmax == pytest.approx(vdl2, abs=1e-6)                               # VDL2
    r = lim["w"]["res"]
    kw = np.searchsorted(r.t, FAULT[2] + 1e-3)                                # weakgrid: VDL2
    ipmax_w, vdl2_w = np.asarray(r["REECA1_1.Ipmax"])[kw], _vdl2(ree, np.asarray(r["REECA1_1.s0"])[kw])
    assert ipmax_w == pytest.approx(vdl2_w, abs=1e-6) and ipmax_w < 9.0
    # the same run up to the clearing: the start after it alone moves ANDES by more than the
    # whole remaining difference to weakgrid
    assert _fault_part(a, a_raw) < 1e-9
    d_art = compare_named(a_raw, a)[0]
    d_raw = compare_named(a_raw, lim["w"])[0]
    d_fix = compare_named(a, lim["w"])[0]
    print(f"Newton start: ANDES restored vs solved {d_art:.3g} pu; to weakgrid {d_raw:.3g} / {d_fix:.3g} pu")
    assert d_art > 5e-5 and d_raw > d_fix, (d_art, d_raw, d_fix)


def test_voltage_pi_p_priority_matches_andes():
    """QFLAG = 1 with P priority. As ANDES does it, its first Newton iterate after the clearing
    (restored v = 1.0 pu) unfreezes the voltage PI, whose output jumps there (to its upper
    limit) and is frozen at that value when the dip resumes at the next iterate: 1.4e-2 pu
    apart, and ANDES stops at h/4 ("Time step reduced to zero"). Started on the network's
    solution, ANDES keeps the pre-dip PI output across the clearing as weakgrid does, runs at
    every step, and the tools differ by 9.3e-5, 4.7e-5, 2.9e-5, 1.58e-5 pu at h, h/2, h/4, h/8
    (with ANDES's LVPL convention)."""
    a_raw, a = _run("andes", H, voltage_pi_p), _run("andes", H, voltage_pi_p, solve_at_clearing=True)
    a8 = _run("andes", H / 8, voltage_pi_p, solve_at_clearing=True)
    w = _run("weakgrid", H, voltage_pi_p, conventions="andes")
    w8 = _run("weakgrid", H / 8, voltage_pi_p, conventions="andes")
    assert a_raw["ok"] and a["ok"] and a8["ok"] and w["ok"] and w8["ok"]
    dw, _ = compare_named(a, w)
    dw8, dd8 = compare_named(a8, w8)
    d_raw = compare_named(a_raw, w)[0]
    print(f"voltage PI + P priority: ANDES as it is {d_raw:.3g} pu at h; started on the solution "
          f"{dw:.3g} pu at h, {dw8:.3g} pu / {dd8:.3g} deg at h/8")
    assert d_raw > 5e-3
    assert dw8 < 2e-5 and dd8 < 0.5 and dw8 < 0.3 * dw, (dw, dw8, dd8)
    # ANDES as it is: the dip goes on at every accepted point across the clearing, yet its
    # frozen PI output jumps; started on the solution it keeps its pre-dip value, as weakgrid
    ree = a_raw["ss"].REECA1
    ta, v = a_raw["t"], _andes(a_raw, "REECA1", "v")
    around = (ta > 1.0 + 1e-3) & (ta < 1.1 + 2 * H)
    assert np.all((v[around] < ree.Vdip.v[0]) | (v[around] > ree.Vup.v[0]))

    def piv_across(x):
        t, piv = x["t"], _andes(x, "REECA1", "PIV_y")
        return piv[np.searchsorted(t, 1.0) - 1], piv[np.searchsorted(t, 1.1 + 5e-5)]

    pre, after_raw = piv_across(a_raw)
    assert abs(after_raw - pre) > 1.0, (pre, after_raw)
    pre, after = piv_across(a)
    assert after == pytest.approx(pre, abs=1e-9)
    r = w["res"]
    pw = np.asarray(r["REECA1_1.PIV_y"])
    assert pw[np.searchsorted(r.t, 1.1 + 2 * H)] == pytest.approx(pre, abs=1e-6)
    # the voltage PI acts after the dip, and the current limits are reached
    r8 = w8["res"]
    assert np.ptp(np.asarray(r8["REECA1_1.PIV_y"])[r8.t > 2.0]) > 1e-3
    ip, iq = np.asarray(r8["REECA1_1.Ipcmd"]), np.asarray(r8["REECA1_1.Iqcmd"])
    assert np.max(np.hypot(ip, iq)) == pytest.approx(10.0, abs=1e-6)
    # ANDES as it is stops at h/4
    assert not _run("andes", H / 4, voltage_pi_p)["ok"]
