"""Baselines defined on the controlled machine, not the grid: every run of a study starts at
equilibrium, whatever the controller, on a multi-machine grid too.

The invariant: before the first event nothing happens, so every recorded variable of the run
(every state, bus voltage and output of the full grid) stays at its initial value. The
``none`` baseline takes only the controlled machine's stabilizer out, before the grid is
initialized (zeroing the gain of every IEEEST after the initialization made ANDES's ieee39
drift: a Pe-input IEEEST's washout holds the initial power, and its output jumped at t = 0+).
"""

import copy

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.study import runner as runner_mod
from weakgrid.study.build import baseline_machine, build_setup
from weakgrid.study.controllers import controller_variant
from weakgrid.study.runner import Run, run_scenario
from weakgrid.study.studyfile import load_study, study_from_dict

# largest change of any recorded variable before the first event [pu, rad]: the integrator's
# Newton tolerance is ~1e-7 at these steps; the drift this catches was 4e-4 pu (speed) and
# 1.3e-2 pu (shunt bus voltage)
DRIFT_TOL = 1e-6
T_ON = 0.3   # s, the fault of the ieee39 study


def ieee39_study(compare):
    """ANDES's ieee39 (ten GENROU with IEEEX1 and Pe-input IEEEST), a UPQC inserted into
    generator 3's step-up (Line_37, bus 10 -> 32): the shunt bus r is bus 10."""
    return study_from_dict({
        "study": {"name": "ieee39-g3"},
        "grid": {"kind": "andes", "file": "andes:ieee39/ieee39_full.xlsx"},
        "machine": {"name": "GENROU_3"},
        "upqc": {"insert": {"branch": "Line_37", "side": "from", "x": 0.01}, "rating": 0.1},
        "design": {"T": 1e-3, "settings": "case2-paper"},
        "controllers": {"compare": list(compare)},
        "scenarios": [{"id": "f", "t_end": T_ON + 0.05, "events": [
            {"kind": "fault", "bus": "10", "t_on": T_ON, "duration": 0.02, "xf": 0.05}]}],
    })


def first_event(run):
    return min(e.get("t_on", e.get("t")) for e in run.events)


def pre_event_drift(study, sc, controller, monkeypatch):
    """``(run record, {variable: max |x(t) - x(0)|})`` over the run's recorded variables
    before its first event (the run's own simulation, captured)."""
    seen = {}
    real = runner_mod.simulate

    def capture(*a, **kw):
        seen["res"] = res = real(*a, **kw)
        return res

    monkeypatch.setattr(runner_mod, "simulate", capture)
    run = Run.of(study, sc, controller)
    rec = run_scenario(study, run)
    res = seen["res"]
    pre = res.t < first_event(run) - 1e-9
    assert pre.sum() > 10
    d = np.abs(res.data[pre] - res.data[0])
    return rec, dict(zip(res.names, np.nanmax(d, axis=0)))


def worst(drift):
    k = max(drift, key=drift.get)
    return k, drift[k]


@pytest.mark.andes
@pytest.mark.parametrize("controller", ["none", "pss-only", "lqr", "nonlinear-29"])
def test_ieee39_no_drift_before_the_fault(controller, monkeypatch):
    """Fails on the grid-wide KS = 0 of the old `none` (its worst: 1.3e-2 pu at bus 10)."""
    pytest.importorskip("andes")
    st = ieee39_study([controller])
    rec, drift = pre_event_drift(st, st.scenarios()[0], controller, monkeypatch)
    assert not rec.metrics["failed"]
    name, d = worst(drift)
    assert d < DRIFT_TOL, (controller, name, d)


@pytest.mark.andes
@pytest.mark.slow
def test_ieee39_no_drift_hji(monkeypatch):
    pytest.importorskip("andes")
    st = ieee39_study(["hji"])
    _, drift = pre_event_drift(st, st.scenarios()[0], "hji", monkeypatch)
    assert worst(drift)[1] < DRIFT_TOL, worst(drift)


@pytest.mark.andes
def test_ieee39_none_takes_out_only_the_controlled_machines_stabilizer():
    pytest.importorskip("andes")
    st = ieee39_study(["pss-only", "none"])
    assert controller_variant(st, "none") == "no-pss"
    full = build_setup(st, variant=controller_variant(st, "pss-only")).system
    bare = build_setup(st, variant=controller_variant(st, "none")).system
    ctl = "GENROU_3"
    assert baseline_machine(st, bare) == ctl
    assert len(full.controls_of(ctl, "pss")) == 1 and bare.controls_of(ctl, "pss") == []
    others = [m for m in full.machine_names if m != ctl]
    assert all(len(bare.controls_of(m, "pss")) == 1 == len(full.controls_of(m, "pss"))
               for m in others)
    # the same operating point: only a stabilizer (zero output at equilibrium) left
    assert bare.network.pf.V == pytest.approx(full.network.pf.V, abs=1e-12)
    assert bare.nx == full.nx - len(full.components["IEEEST"].states)


@pytest.mark.andes
def test_ieee39_none_differs_from_pss_only_after_the_fault(monkeypatch):
    """The baseline is real: after the fault G3's stabilizer acts in `pss-only` and is
    silent in `none`, while the other units' stabilizers act in both."""
    pytest.importorskip("andes")
    st = ieee39_study(["pss-only", "none"])
    st = st.with_values(**{"scenarios": [dict(st.data["scenarios"][0], t_end=1.0, events=[
        {"kind": "fault", "bus": "10", "t_on": T_ON, "duration": 0.1, "xf": 0.05}])]})
    sc = st.scenarios()[0]
    seen = {}
    real = runner_mod.simulate
    for c in ("pss-only", "none"):
        monkeypatch.setattr(runner_mod, "simulate",
                            lambda *a, c=c, **kw: seen.setdefault(c, real(*a, **kw)))
        run_scenario(st, Run.of(st, sc, c))
    vs = {c: {m: np.abs(r[f"{m}.vs"]).max() for m in (f"GENROU_{k}" for k in range(1, 11))}
          for c, r in seen.items()}
    assert vs["none"]["GENROU_3"] == 0.0 < 1e-3 < vs["pss-only"]["GENROU_3"]
    assert all(v > 1e-4 for m, v in vs["none"].items() if m != "GENROU_3"), vs
    w = {c: r["GENROU_3.omega"] for c, r in seen.items()}
    t = seen["none"].t
    diff = np.abs(w["none"] - w["pss-only"])
    assert diff[t < T_ON].max() < DRIFT_TOL < diff.max()


def shortened(name, scenario):
    """Scenario ``scenario`` of a shipped study, ending shortly after its last event."""
    st = load_study(name)
    d = copy.deepcopy(st.data)
    sc = next(s for s in d["scenarios"] if s["id"] == scenario)
    sc["t_end"] = max(e.get("t_off", e.get("t")) for e in sc["events"]) + 0.01
    sc.pop("quick", None)
    d["scenarios"] = [sc]
    d.pop("sweep", None)     # its axes and claims name the full study's runs
    d.pop("claims", None)
    d.pop("figures", None)   # they draw runs of the full study's other scenarios
    return study_from_dict(d, source=st.source, base_dir=st.base_dir)


@pytest.mark.slow
@pytest.mark.parametrize("name, scenario", [
    ("ieee9-sg-upqc", "fault-r"),            # an SG study: its own IEEEST out for `none`
    ("case1-weak-grid", "c1-high-conv"),     # every kind: hji, (29), lqr, pq, pss-only, none, ...
    ("cigre-mv-wind-gti", "fault-bus8"),     # a GTI study on a pandapower grid
])
def test_shipped_study_no_drift_before_the_first_event(name, scenario, monkeypatch):
    """Every controller of a shipped study's scenario starts at equilibrium."""
    st = shortened(name, scenario)
    for sc, c in st.runs():
        _, drift = pre_event_drift(st, sc, c, monkeypatch)
        assert worst(drift)[1] < DRIFT_TOL, (sc["id"], c, worst(drift))


def test_case1_none_takes_out_the_sgs_stabilizer():
    """A GTI-controlled study: the baseline machine is the SG the study follows."""
    st = load_study("case1-weak-grid")
    s = build_setup(st, variant="no-pss").system
    assert baseline_machine(st, s) == "SG"
    assert s.controls_of("SG", "pss") == [] and "IEEEST" not in s.components
    assert build_setup(st).system.controls_of("SG", "pss") == [("IEEEST", "SG.pss")]


def test_remove_controls_refuses_an_unknown_machine():
    s = build_setup(load_study("case1-weak-grid")).system
    with pytest.raises(DataError, match="no such machine"):
        s.remove_controls("G9")


@pytest.mark.andes
def test_grid_data_warning_once_per_process_with_a_count(monkeypatch, caplog):
    """ieee39's nine GENROU with xl >= xd2: one line for the model, however many times a study
    builds the grid (once per run); the repeats go to DEBUG."""
    import logging
    import warnings

    from weakgrid.study import build as build_mod

    pytest.importorskip("andes")
    monkeypatch.setattr(build_mod, "_SAID", set())
    st = ieee39_study(["pss-only", "none"])
    with caplog.at_level(logging.DEBUG, logger="weakgrid.study.build"), \
            warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for variant in ("upqc", "no-pss", "upqc"):
            build_setup(st, variant=variant)
    said = [r for r in caplog.records if "leakage reactance" in r.getMessage()]
    assert [r.levelno for r in said] == [logging.WARNING, logging.DEBUG, logging.DEBUG]
    assert "GENROU (9 of 10)" in said[0].getMessage()
    assert not [w for w in caught if "leakage" in str(w.message)]   # said through the log only


def test_gti_study_without_an_sg_says_none_equals_pss_only(monkeypatch, caplog):
    """CIGRE MV: a GTI behind the UPQC, the external grid an infinite bus (speed_of = "")."""
    import logging

    from weakgrid.study import build as build_mod

    monkeypatch.setattr(build_mod, "_SAID", set())
    st = load_study("cigre-mv-wind-gti")
    with caplog.at_level(logging.INFO, logger="weakgrid.study.build"):
        s = build_setup(st, variant="no-pss").system
    assert baseline_machine(st, s) is None
    assert any("'none' equals 'pss-only'" in r.getMessage() and r.levelno == logging.WARNING
               for r in caplog.records)
    assert s.nx == build_setup(st).system.nx
