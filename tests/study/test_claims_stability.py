"""Stability first: every judge that compares two runs asks whether each is stable before it
compares costs, ITAE, overshoot or settling (weakgrid.study.claims.stability_gate)."""

import math

import numpy as np
import pandas as pd
import pytest

from weakgrid.study.claims import judge_claim, run_instability, stability_gate
from weakgrid.study.metrics import stability_verdict
from weakgrid.study.reproduce import paper_studies


def claim(cid, **over):
    c = next(c for st in paper_studies() for c in st.data["claims"] if c["id"] == cid)
    return dict(c, **over)


def stable(**kw):
    """A finished run whose speed and dc link settle (the runner's keys)."""
    r = {"failed": False, "failure": "", "speed_verdict": "stable", "vdc_verdict": "stable",
         "speed_settling_s": 1.0, "vdc_settling_s": 0.3, "speed_peak_dev_pu": 0.006,
         "speed_final_dev_pu": 1e-5, "vdc_peak_dev_pu": 0.16, "vdc_final_dev_pu": 1e-5}
    r.update(kw)
    return r


def runaway(**kw):
    """Finished, but the dc link ran away from its set-point (the EMT `measured` runs of
    docs/emt-findings.md): the runner's stability_verdict calls it unstable, its settling is
    undefined and it ends at its peak deviation."""
    return stable(**{"vdc_verdict": "unstable", "vdc_settling_s": math.nan,
                     "vdc_peak_dev_pu": 0.84, "vdc_final_dev_pu": 0.84, **kw})


LOST = {"failed": True, "failure": "t = 3.427 s: loss of synchronism: rotor angle spread 181 deg"}


# ---------------------------------------------------------------- what "not stable" is
def test_run_instability_names_the_cause():
    assert run_instability(stable()) == ""
    assert run_instability({}) == "" and run_instability(None) == ""   # nothing recorded
    assert run_instability(LOST) == "failed: loss of synchronism"
    assert run_instability(stable(speed_verdict="unstable")) == "not stable: SG speed unstable"
    assert run_instability(stable(vdc_verdict="undamped")) == "not stable: dc link undamped"
    assert run_instability(runaway()) == "not stable: dc link unstable"
    assert run_instability(stable(speed_verdict="unstable", vdc_verdict="undamped")) == \
        "not stable: SG speed unstable, dc link undamped"


def test_one_definition_from_the_signal_to_the_gate():
    """A dc link ramping away from its set-point (|Vc − 1| → 0.8 pu in 3 s): the verdict the
    runner records makes the run not stable; a swing still decaying at the end of a short
    record (case 1's 0.5-Hz mode, outside its 2 % band, 9 % of its peak away) does not."""
    t = np.linspace(0.0, 3.0, 3001)
    ramp = stability_verdict(t, 1 + 0.8 * t / 3, y_set=1.0)
    swing = stability_verdict(t, 1 + 0.006 * np.exp(-0.8 * t) * np.cos(np.pi * t), y_set=1.0)
    r = stable(vdc_verdict=ramp, speed_verdict=swing, speed_settling_s=math.nan)
    assert run_instability(r) == "not stable: dc link unstable"


def test_run_instability_reads_a_sweep_table_row():
    """The maps judge a sweep table's rows (status, not failed) by the same function."""
    rows = pd.DataFrame([{"status": "ok", "failure": "", "vdc_verdict": "unstable",
                          "speed_verdict": "stable"},
                         {"status": "failed", "failure": "t = 1 s: voltage collapse",
                          "vdc_verdict": math.nan, "speed_verdict": math.nan},
                         {"status": "ok", "failure": math.nan, "vdc_verdict": "stable",
                          "speed_verdict": math.nan}])
    assert [run_instability(r) for _, r in rows.iterrows()] == [
        "not stable: dc link unstable", "failed: voltage collapse", ""]


def test_gate_each_case():
    m = {"a": stable(), "b": stable(), "ua": runaway(), "ub": runaway(), "fa": LOST}
    assert stability_gate(m, "a", "b") is None                        # compare them
    v, why = stability_gate(m, "ua", "b")
    assert v == "not" and why.startswith("ua not stable: dc link unstable")
    v, why = stability_gate(m, "a", "ub")
    assert v == "reproduced" and "ub not stable" in why and "a stable: a win" in why
    assert stability_gate(m, "a", "ub", baseline_unstable="not")[0] == "not"
    v, why = stability_gate(m, "ua", "ub")
    assert v == "not" and why.startswith("both runs unstable: no comparison")
    v, why = stability_gate(m, "fa", "ub")               # a failure and a never-settling run
    assert v == "not" and "fa failed: loss of synchronism" in why and "ub not stable" in why


# ---------------------------------------------------------------- each comparing judge
def _cost(h, b):
    return {"c1-high-conv-hji": dict(h, running_cost_18=h.get("running_cost_18", 0.7)),
            "c1-high-conv-nonlinear-29": dict(b, running_cost_18=b.get("running_cost_18", 1.0))}


def test_cost_less_both_stable_compares_costs():
    r = judge_claim(claim("C1-cost"), _cost(stable(vdc_settling_s=0.30),
                                            stable(vdc_settling_s=0.31)))
    assert r["verdict"] == "reproduced" and "less" in r["measured"]


def test_cost_less_claims_run_unstable_is_not_even_with_a_lower_cost():
    r = judge_claim(claim("C1-cost"), _cost(runaway(running_cost_18=0.1), stable()))
    assert r["verdict"] == "not"
    assert "c1-high-conv-hji not stable: dc link unstable" in r["why"]
    assert "running cost" not in r["measured"]               # no cost comparison printed


def test_cost_less_only_the_baseline_unstable_is_a_win_saying_so():
    r = judge_claim(claim("C1-cost"), _cost(stable(running_cost_18=5.0), runaway()))
    assert r["verdict"] == "reproduced"
    assert "c1-high-conv-nonlinear-29 not stable" in r["why"] and "a win" in r["why"]


def test_cost_less_both_diverged_is_not_regression():
    """docs/emt-findings.md, case 1, EMT `measured`: both runs lose the dc link ("settling
    n/a vs n/a"); (29)'s diverged further at high load (running cost 2.256e6 against HJI's
    7742), HJI's at low load (1.031e5 against 1133). main judged that "partly"; two
    diverged runs are no comparison: ``not``."""
    m = {"c1-high-conv-hji": runaway(running_cost_18=7742.0),
         "c1-high-conv-nonlinear-29": runaway(running_cost_18=2.256e6, vdc_peak_dev_pu=2.97,
                                              vdc_final_dev_pu=2.97),
         "c1-low-conv-hji": runaway(running_cost_18=1.031e5, vdc_peak_dev_pu=1.8,
                                    vdc_final_dev_pu=1.8),
         "c1-low-conv-nonlinear-29": runaway(running_cost_18=1133.0, vdc_peak_dev_pu=0.33,
                                             vdc_final_dev_pu=0.33)}
    for cid in ("C1-cost", "C1-cost-applied"):
        for r in m.values():
            r.setdefault("control_cost", r["running_cost_18"])
        r = judge_claim(claim(cid), m)
        assert r["verdict"] == "not", (cid, r)
        assert r["why"].count("both runs unstable: no comparison") == 2


def test_itae_close_needs_both_runs_stable():
    c = claim("C1-reduced", pairs=[["high load", "c1-high-conv-hji", "c1-high-red-hji"]])
    itae = {"speed_itae": 1.0, "vdc_itae": 1.0}
    m = {"c1-high-conv-hji": stable(**itae), "c1-high-red-hji": stable(**itae)}
    assert judge_claim(c, m)["verdict"] == "reproduced"
    m["c1-high-red-hji"] = stable(speed_verdict="undamped", **itae)  # same ITAE, undamped
    r = judge_claim(c, m)
    assert r["verdict"] == "not" and "c1-high-red-hji not stable: SG speed undamped" in r["why"]
    m["c1-high-conv-hji"] = runaway(**itae)
    assert "both runs unstable" in judge_claim(c, m)["why"]


def test_beats_baselines_each_way():
    c = claim("C1-baselines", groups=[["high load", "c1-high-conv-hji", "pq",
                                       "c1-high-conv-pq"]])
    h = {"speed_itae": 1.0, "vdc_itae": 1.0}
    b = {"speed_itae": 2.0, "vdc_itae": 2.0}
    m = {"c1-high-conv-hji": stable(**h), "c1-high-conv-pq": stable(**b)}
    assert judge_claim(c, m)["verdict"] == "reproduced"
    m["c1-high-conv-hji"] = runaway(**h)                   # lower ITAE, but ran away
    assert judge_claim(c, m)["verdict"] == "not"
    m = {"c1-high-conv-hji": stable(**b), "c1-high-conv-pq": runaway(**h)}
    r = judge_claim(c, m)
    assert r["verdict"] == "reproduced" and "c1-high-conv-pq not stable" in r["why"]
    m["c1-high-conv-hji"] = runaway(**h)
    assert judge_claim(c, m)["verdict"] == "not"


@pytest.mark.parametrize("ours, theirs, verdict, words", [
    (stable(speed_verdict="unstable"), stable(), "not", "hji not stable: SG speed unstable"),
    (stable(), stable(speed_verdict="undamped"), "reproduced", "lqr not stable"),
    (LOST, stable(speed_verdict="unstable"), "not", "both runs unstable: no comparison"),
])
def test_less_overshoot_settling_each_way(ours, theirs, verdict, words):
    c = claim("C2-lqr")
    c = dict(c, pairs=[c["pairs"][0]])
    ours = dict(ours, speed_backswing_pu=0.001)           # ours always "better" on numbers
    theirs = dict(theirs, speed_backswing_pu=0.02, speed_settling_s=2.0)
    r = judge_claim(c, {"c2-high-f200-hji": ours, "c2-high-f200-lqr": theirs})
    assert r["verdict"] == verdict and words in r["why"]


def test_stability_contrast_uses_the_same_definition():
    """An LQR run whose speed ran away from its set-point is not stable for C2-low-load
    either (one definition: run_instability)."""
    c = claim("C2-low-load")
    m = {"c2-low-f100-hji": stable(),
         "c2-low-f100-lqr": stable(speed_verdict="unstable", speed_settling_s=math.nan,
                                  speed_final_dev_pu=0.006),
         "c2-low-f100-pss-only": stable(speed_verdict="undamped")}
    r = judge_claim(c, m)
    assert r["verdict"] == "reproduced" and "lqr: not stable: SG speed unstable" in \
        r["measured"]
    m["c2-low-f100-lqr"] = stable()
    assert judge_claim(c, m)["verdict"] == "partly"


def test_two_swings_still_decaying_are_judged_on_overshoot_alone():
    """Both stable, neither inside its settling band at the run's end (back near the
    set-point): no settling comparison (main gave it to the baseline), the overshoot decides."""
    c = claim("C2-lqr")
    c = dict(c, pairs=[c["pairs"][0]])
    decaying = dict(speed_settling_s=math.nan, speed_peak_dev_pu=0.006, speed_final_dev_pu=3e-4)
    m = {"c2-high-f200-hji": stable(speed_backswing_pu=0.001, **decaying),
         "c2-high-f200-lqr": stable(speed_backswing_pu=0.002, **decaying)}
    assert judge_claim(c, m)["verdict"] == "reproduced"
    m["c2-high-f200-lqr"]["speed_settling_s"] = 1.0         # the baseline settles: it wins that
    assert judge_claim(c, m)["verdict"] == "partly"


def test_a_record_too_short_to_judge_is_not_evidence():
    assert run_instability(stable(speed_verdict="too short", vdc_verdict="too short")) == ""


# ---------------------------------------------------------------- "not back"
def test_a_swing_that_shrinks_while_its_mean_drifts_away_is_not_back():
    """The EMT run of case 1 at low load with HJI (docs/emt-findings.md): the SG speed swings
    2.3 % and ends 1.3 % below its set-point, never inside its band. The verdict's two windows
    see a shrinking swing ("stable"); the run is still not back, so it cannot win a pair."""
    t = np.linspace(0.0, 3.0, 3001)
    y = 1.0 - 0.0115 * (1 - np.cos(2 * np.pi * 0.55 * t)) * np.exp(-0.15 * t) \
        - 0.0045 * t + 0.004 * np.sin(2 * np.pi * 4 * t) * np.exp(-0.4 * t)
    after = 0.25
    ok = t >= after
    verdict = stability_verdict(t[ok], y[ok], after, y_set=1.0)
    assert verdict == "stable"              # what the two windows see
    r = stable(speed_verdict=verdict, speed_settling_s=math.nan,
               speed_peak_dev_pu=float(np.max(np.abs(y[ok] - 1.0))),
               speed_final_dev_pu=float(y[-1] - 1.0))
    assert abs(r["speed_final_dev_pu"]) > 0.5 * r["speed_peak_dev_pu"]
    why = run_instability(r)
    assert why.startswith("not stable: SG speed"), why
    # and so HJI cannot beat an unstable PSS-only run on it: both not stable, no comparison
    c = claim("C1-baselines")
    m = {k: stable() for k in ("c1-high-conv-hji", "c1-high-conv-pss-only", "c1-low-conv-hji",
                                "c1-low-conv-pss-only", "c1-high-conv-pq", "c1-low-conv-pq",
                                "c1-high-red-hji", "c1-low-red-hji")}
    m["c1-low-conv-hji"] = r
    m["c1-low-conv-pss-only"] = stable(speed_verdict="undamped")
    out = judge_claim(c, m)
    assert "both runs unstable" in out["measured"], out["measured"]


def test_not_back_needs_all_three_keys_and_a_judgeable_record():
    far = dict(speed_settling_s=math.nan, speed_peak_dev_pu=0.02, speed_final_dev_pu=-0.013)
    assert "not back" in run_instability(stable(**far))
    assert run_instability(stable(**dict(far, speed_final_dev_pu=-0.009))) == ""   # < half
    assert run_instability(stable(**dict(far, speed_settling_s=1.2))) == ""        # settles
    assert run_instability(stable(**dict(far, speed_verdict="too short"))) == ""   # 1-s run
    row = pd.Series(stable(**far))                                                 # a table row
    assert "not back" in run_instability(row)
