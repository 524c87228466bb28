"""A study's sweep in batches of one grid (the seam for the batched simulator): the batches of
the case-1 quick sweep, and a batched sweep's table equal to the one-by-one sweep's."""

import copy

import pandas as pd
import pytest

from weakgrid.study.batches import batch_key
from weakgrid.study.studyfile import load_study, study_from_dict
from weakgrid.study.sweep import run_study_sweep, sweep_points
from weakgrid.sweep import group

TIMES = ["wall_s", "sim_wall_s"]


def _two_ratings_two_loads(controllers):
    """Case 1's quick sweep cut to two ratings × two loads of 0.4 s, no maps."""
    d = copy.deepcopy(load_study("case1-weak-grid").data)
    d["sweep"].update(controllers=controllers,
                      quick={"axes": {"upqc.rating": [0.15, 0.6],
                                      "scenarios.c1-high-conv.load": ["high", "low"]},
                             "t_end": 0.4})
    d["sweep"].pop("maps", None)
    return study_from_dict(d)


def _alone_and_together(st, runs, monkeypatch):
    """``(runs alone, runs batched, the batch sizes the batched call made)``."""
    import weakgrid.sim.batch as batch
    from weakgrid.study.runner import run_scenarios

    alone = run_scenarios(st, runs, batched=False)
    sizes = []
    real = batch.BatchSimulator.__init__

    def counting(self, system, scenarios, **kw):
        sizes.append(len(scenarios))
        real(self, system, scenarios, **kw)

    monkeypatch.setattr(batch.BatchSimulator, "__init__", counting)
    return alone, run_scenarios(st, runs, batched=True), sizes


def _same_metrics(a, b):
    """Run records ``a`` and ``b`` have the same metrics (floats to 1e-8), wall time aside."""
    ma, mb = (dict(r.metrics) for r in (a, b))
    ma.pop("wall_s"), mb.pop("wall_s")
    assert ma.keys() == mb.keys()
    for k in ma:
        if isinstance(ma[k], float):
            assert mb[k] == pytest.approx(ma[k], rel=1e-8, abs=1e-12, nan_ok=True), k
        else:
            assert mb[k] == ma[k], k


def test_the_case1_quick_sweep_is_one_batch():
    """The ratings, the loads and the controllers share a batch: the rating is a per-member
    parameter of the batched simulator, the load a member's own admittances and the set-points
    its initialization computed from them."""
    st = load_study("case1-weak-grid")
    pts = sweep_points(st, quick=True)
    batches = group(pts, key=lambda p: batch_key(p.inputs))
    load = "scenarios.c1-high-conv.load"
    assert len(pts) == 12 and len(batches) == 1
    members = [pts[i].params for i in batches[0].rows]
    assert len(members) == 12
    assert sorted({m[load] for m in members}) == ["high", "low"]
    assert sorted({m["upqc.rating"] for m in members}) == [0.15, 0.6]
    assert sorted({m["controller"] for m in members}) == \
        sorted(["hji", "nonlinear-29", "hji-bounded"])
    name, upqc, *_ = batches[0].key
    assert (name, upqc) == ("case1-weak-grid", "conventional")


def _grids_of(pts):
    from weakgrid.study.sweep import prepare_point

    return [prepare_point(p.inputs).setup.system for p in pts]


def test_the_two_loads_grids_are_one_grid_to_the_batch_simulator_and_others_are_not():
    """The grids of the two loads (and two ratings) have one fingerprint, so the batched
    simulator keeps them in one batch; a grid that differs in a line, a bus shunt or a device
    parameter that is not batchable does not (it would be wrongly merged)."""
    from weakgrid.sim.batch import system_fingerprint
    from weakgrid.sim.network import BR_X, BS, GS

    st = _two_ratings_two_loads(["nonlinear-29"])
    pts = sweep_points(st, quick=True)
    grids = _grids_of(pts)
    assert len({system_fingerprint(g) for g in grids}) == 1
    ref = system_fingerprint(grids[0])

    for edit in (lambda n: n.branch.__setitem__((0, BR_X), n.branch[0, BR_X] * 1.1),
                 lambda n: n.bus.__setitem__((2, BS), n.bus[2, BS] + 5.0),
                 lambda n: n.bus.__setitem__((2, GS), n.bus[2, GS] + 5.0)):
        g = copy.deepcopy(grids[0])
        edit(g.network)
        assert system_fingerprint(g) != ref
    g = copy.deepcopy(grids[0])
    exc = g.components["EXDC2"]
    exc.p["KA"] = exc.p["KA"] * 2
    assert system_fingerprint(g) != ref
    assert system_fingerprint(grids[0]) == ref      # the comparison left the grid as it was


def test_a_batched_study_sweep_gives_the_scalar_table(tmp_path):
    st = _two_ratings_two_loads(["nonlinear-29"])
    scalar = run_study_sweep(st, tmp_path / "scalar", quick=True, workers=0, progress=False,
                             batched=False)
    batched = run_study_sweep(st, tmp_path / "batched", quick=True, workers=0, progress=False,
                              batched=True)
    assert len(scalar) == 4
    pd.testing.assert_frame_equal(scalar.drop(columns=TIMES), batched.drop(columns=TIMES))


def test_bounded_laws_of_two_ratings_share_a_call_and_give_the_scalar_table(tmp_path,
                                                                            monkeypatch):
    """The rating-bounded controllers trained at two ratings differ only in their weights and
    bound (one family): the batch samples their members in one call of ``rows_of``, each row
    with its own controller, and the table equals the one-by-one sweep's to the last bit."""
    from weakgrid.game.controller import GameController

    st = _two_ratings_two_loads(["hji-bounded"])
    scalar = run_study_sweep(st, tmp_path / "scalar", quick=True, workers=0, progress=False,
                             batched=False)
    calls = []
    real = GameController.rows_of

    def counting(controllers, x):
        calls.append(sorted({c.cost.bound.limit[0] for c in controllers}))
        return real(controllers, x)

    monkeypatch.setattr(GameController, "rows_of", staticmethod(counting))
    batched = run_study_sweep(st, tmp_path / "batched", quick=True, workers=0, progress=False,
                              batched=True)
    assert len(scalar) == 4
    assert calls and all(bounds == [0.15, 0.6] for bounds in calls)
    pd.testing.assert_frame_equal(scalar.drop(columns=TIMES), batched.drop(columns=TIMES))


def _failing_sweep():
    """Case 1, two controllers (the PQ baseline takes the UPQC out: another grid), points
    that run, one whose fault has no network solution (Newton) and one whose grid collapses
    under the (29) controller, two ratings."""
    d = copy.deepcopy(load_study("case1-weak-grid").data)
    d["sweep"].pop("maps", None)
    ev = "scenarios.c1-high-conv.events.0"
    d["sweep"].update(mode="points", controllers=["nonlinear-29", "pq"], quick={
        "t_end": 0.4, "axes": {"upqc.rating": [0.15, 0.6, 0.15, 0.6],
                               f"{ev}.bus": [3, 3, 4, 4], f"{ev}.xf": [0.1, 0.1, 0.005, 0.1],
                               f"{ev}.t_off": [0.25, 0.25, 0.25, 0.35]}})
    return study_from_dict(d)


def test_a_batched_sweep_with_failing_members_gives_the_scalar_tables(tmp_path, monkeypatch):
    """The table (and its Parquet file) of the batched sweep equals the scalar one's, failed
    rows and their causes included; the runs of one grid were simulated together."""
    import weakgrid.sim.batch as batch

    sizes = []
    real = batch.simulate_batch

    def counting(system, scenarios, *a, **kw):
        sizes.append(len(scenarios))
        return real(system, scenarios, *a, **kw)

    st = _failing_sweep()
    scalar = run_study_sweep(st, tmp_path / "scalar", quick=True, workers=0, progress=False,
                             batched=False)
    assert sizes == []
    monkeypatch.setattr(batch, "simulate_batch", counting)
    batched = run_study_sweep(st, tmp_path / "batched", quick=True, workers=0, progress=False)
    # one call per grid variant (the PQ baseline has no UPQC) and fault clearing time off the
    # step grid (0.25 s: 3 points; 0.35 s: 1 point, simulated alone)
    assert sorted(sizes) == [3, 3]
    assert len(scalar) == 8
    failed = scalar[scalar["status"] == "failed"]
    causes = " ".join(failed["failure"])
    assert len(failed) == 3 and "newton" in causes and "voltage collapse" in causes
    pd.testing.assert_frame_equal(scalar.drop(columns=TIMES), batched.drop(columns=TIMES),
                                  rtol=1e-8)
    files = [pd.read_parquet(p / f"{st.name}-sweep-quick.parquet")
             for p in (tmp_path / "scalar", tmp_path / "batched")]
    pd.testing.assert_frame_equal(files[0].drop(columns=TIMES), files[1].drop(columns=TIMES),
                                  rtol=1e-8)


def test_a_studys_runs_simulated_together_equal_their_runs_alone():
    """`weakgrid run`/`reproduce`'s path (run_scenarios): the records of runs of one study
    simulated in batches are those of the runs alone (metrics, series, controller samples);
    the three controllers make three grids (UPQC, PQ baseline, no PSS)."""
    import numpy as np

    from weakgrid.study.runner import Run, run_scenarios

    st = load_study("case1-weak-grid")
    sc = dict(next(s for s in st.scenarios() if s["id"] == "c1-high-conv"), t_end=0.4)
    runs = [Run.of(st, sc, c) for c in ("nonlinear-29", "pq", "none")]
    runs.append(Run.of(st, dict(sc, events=[dict(sc["events"][0], t_off=0.3)]),
                       "nonlinear-29"))
    alone = run_scenarios(st, runs, batched=False)
    together = run_scenarios(st, runs, batched=True)
    for a, b in zip(alone, together):
        _same_metrics(a, b)
        for d_a, d_b in ((a.series, b.series), (a.samples, b.samples)):
            assert d_a.keys() == d_b.keys()
            for k in d_a:
                np.testing.assert_allclose(d_b[k], d_a[k], rtol=1e-8, atol=1e-10)
    assert together[0].metrics["speed_peak_dev_pu"] != together[3].metrics["speed_peak_dev_pu"]


def test_runs_at_both_loads_simulated_in_one_batch_equal_their_runs_alone(monkeypatch):
    """A batch mixing the high- and the low-load grid (each member its own load admittances,
    initial point and set-points) gives each run's trajectories to 1e-10 and its metrics."""
    import numpy as np

    from weakgrid.study.runner import Run

    st = load_study("case1-weak-grid")
    sc = dict(next(s for s in st.scenarios() if s["id"] == "c1-high-conv"), t_end=0.4)
    runs = [Run.of(st, dict(sc, load=load), c)
            for load in ("high", "low") for c in ("nonlinear-29", "hji")]
    assert [r.load for r in runs] == ["high", "high", "low", "low"]
    alone, together, sizes = _alone_and_together(st, runs, monkeypatch)
    assert sizes == [4]                      # one batch holds both loads
    for a, b in zip(alone, together):
        _same_metrics(a, b)
        assert a.series.keys() == b.series.keys()
        for k in a.series:
            np.testing.assert_allclose(b.series[k], a.series[k], rtol=0, atol=1e-10, err_msg=k)
    # the loads act: another operating point
    assert abs(together[0].series["sg_pe"][0] - together[2].series["sg_pe"][0]) > 1e-3


def test_machines_without_controls_keep_their_own_initial_signals_in_a_mixed_load_batch(
        monkeypatch):
    """Case 1 with a classical SG and no exciter or governor: its field voltage and torque
    are the initial signals of its own operating point (``System._sig_stack``), held per
    member; both loads in one batch equal their runs alone (the runs differ by far more if a
    member took another's: checked by not binding them)."""
    import numpy as np
    from paper_setups import classical_case1

    import weakgrid.sim.batch as batch
    from weakgrid.study.runner import Run, run_scenarios

    d, src = classical_case1()
    st = study_from_dict(d, source=src)
    sc = dict(next(s for s in st.scenarios() if s["id"] == "c1-high-conv"), t_end=0.4)
    runs = [Run.of(st, dict(sc, load=load), "nonlinear-29") for load in ("high", "low")]
    alone, together, sizes = _alone_and_together(st, runs, monkeypatch)
    assert sizes == [2]
    for a, b in zip(alone, together):
        assert a.series.keys() == b.series.keys()
        for k in a.series:
            np.testing.assert_allclose(b.series[k], a.series[k], rtol=0, atol=1e-10, err_msg=k)
    monkeypatch.setattr(batch, "member_signals", lambda systems: None)
    wrong = run_scenarios(st, runs, batched=True)
    assert any(len(w.series["sg_speed"]) != len(a.series["sg_speed"])
               or np.abs(w.series["sg_speed"] - a.series["sg_speed"]).max() > 1e-6
               for w, a in zip(wrong, alone))


def test_a_member_rerun_alone_keeps_the_samples_of_its_own_run():
    """A batch member whose step had to be halved is re-run alone: its controller's log starts
    again, while the policy's own log of design states still holds the batched attempt's
    samples before the rerun's. The record takes the rerun's (the last ones), as alone."""
    import numpy as np

    from weakgrid.study.runner import Run, finish_run, prepare_run, simulate_prepared

    st = load_study("case1-weak-grid")
    sc = dict(next(s for s in st.scenarios() if s["id"] == "c1-high-conv"), t_end=0.35)
    run = Run.of(st, sc, "nonlinear-29")
    prep = prepare_run(st, run)
    res, wall = simulate_prepared([prep], batched=False)[0]
    ref = finish_run(prep, res, wall)
    n = len(prep.xs)
    assert n > 10
    prep.xs[:0] = [x + 1.0 for x in prep.xs[: n // 2]]      # an abandoned batched attempt
    prep.ys[:0] = [y + 1.0 for y in prep.ys[: n // 2]]
    again = finish_run(prep, res, wall)
    for k in ("x_design[0]", "x_design[1]", "y_measured[0]", "running_cost"):
        np.testing.assert_array_equal(again.samples[k], ref.samples[k])
    assert again.metrics["running_cost_18"] == ref.metrics["running_cost_18"]


def test_a_batch_whose_simulator_raises_runs_its_members_one_by_one(monkeypatch):
    """Not a member's failure (those are in its Results): the batch's runs are simulated one
    by one instead, each with its own row as in the scalar path."""
    import weakgrid.sim.batch as batch
    from weakgrid.study.batches import simulate_many
    from weakgrid.study.sweep import run_point

    pts = [p.inputs for p in sweep_points(_failing_sweep(), quick=True)
           if p.params["controller"] == "nonlinear-29"][:2]
    want = [run_point(i) for i in pts]

    def broken(*a, **k):
        raise RuntimeError("no batch today")

    monkeypatch.setattr(batch, "simulate_batch", broken)
    got = simulate_many(pts)
    for w, g in zip(want, got):
        w, g = dict(w), dict(g)
        w.pop("sim_wall_s"), g.pop("sim_wall_s")
        assert g.keys() == w.keys()
        for k, v in w.items():
            if isinstance(v, float):
                assert g[k] == pytest.approx(v, rel=1e-12, abs=0, nan_ok=True), k
            else:
                assert g[k] == v, k


def test_runs_of_one_controller_share_one_policy_call_per_sample(tmp_path, monkeypatch):
    """In the batch (both loads, both ratings) the four runs of the HJI controller (one
    trained controller: designed at high load for both loads) and of (29) (a policy object per
    run, the same parameters) have equal law keys (the policy's content, not the controller's
    name), so the batch samples each four with one policy call; the table equals the scalar
    sweep's."""
    from weakgrid.study.law import StudyLaw

    st = _two_ratings_two_loads(["hji", "nonlinear-29"])
    scalar = run_study_sweep(st, tmp_path / "scalar", quick=True, workers=0, progress=False,
                             batched=False)
    sizes = []
    real = StudyLaw.rows

    def counting(laws, Y):
        sizes.append(len(laws))
        assert len({law.key for law in laws}) == 1
        return real(laws, Y)

    monkeypatch.setattr(StudyLaw, "rows", staticmethod(counting))
    batched = run_study_sweep(st, tmp_path / "batched", quick=True, workers=0, progress=False,
                              batched=True)
    assert len(scalar) == 8 and (scalar["status"] != "failed").all()
    assert sizes and set(sizes) == {4}
    pd.testing.assert_frame_equal(scalar.drop(columns=TIMES), batched.drop(columns=TIMES),
                                  rtol=1e-8)


def test_the_policy_key_is_the_content_of_the_policy():
    """Equal laws (a copy of a trained controller without its history; (29) built twice) have
    equal keys; another weight, gain or kind of policy, another key; an idle UPQC is "idle"."""
    import numpy as np

    from weakgrid.models import NonlinearInitialPolicy
    from weakgrid.study.law import policy_key
    from weakgrid.study.sweep import prepare_point

    st = load_study("case1-weak-grid")
    pt = next(p.inputs for p in sweep_points(st, quick=True) if p.params["controller"] == "hji")
    ctl = prepare_point(pt).ctl
    twin = copy.copy(ctl)
    twin.history, twin.train_seconds = [], 0.0
    other = copy.copy(ctl)
    other.weights = ctl.weights * (1 + 1e-15 * np.arange(ctl.weights.size))
    assert policy_key(ctl.control) == policy_key(twin.control) != policy_key(other.control)
    assert policy_key(ctl.control) != policy_key(ctl.disturbance)
    a, b, c = (NonlinearInitialPolicy(0.14, 0.069, g) for g in (125.0, 125.0, 120.0))
    assert policy_key(a) == policy_key(b) != policy_key(c)
    assert policy_key(None) == "idle"
    assert policy_key(lambda x: x) != policy_key(lambda x: x)     # closures: by identity


def test_a_studys_scenario_runs_of_both_loads_share_a_batch():
    """`weakgrid run`/`reproduce` batch a study's runs by UPQC structure and grid variant,
    both load levels together (each member holds its own loads, as in a sweep's batches):
    case 1's 20 runs in 4 batches, none of one run (8 batches, 4 of one run, when the load
    level split them)."""
    from weakgrid.study.controllers import controller_variant
    from weakgrid.study.engine import _run_batches
    from weakgrid.study.runner import Run

    st = load_study("case1-weak-grid")
    runs = [Run.of(st, sc, c) for sc, c in st.runs(False)]
    assert len(runs) == 20
    batches = _run_batches([(st, r, {}, None) for r in runs], 0)
    assert sorted(len(b) for b in batches) == [2, 2, 4, 12]
    for b in batches:
        assert {runs[i].load for i in b} == {"high", "low"}
        assert len({(runs[i].upqc, controller_variant(st, runs[i].controller)) for i in b}) == 1
    # the costliest first (all runs of 6 s at one step: the largest first)
    assert [len(b) for b in batches] == sorted((len(b) for b in batches), reverse=True)
    # on 2 workers no batch holds more than half the runs' steps: the 12 runs split in two
    two = _run_batches([(st, r, {}, None) for r in runs], 2)
    assert sorted(len(b) for b in two) == [2, 2, 4, 6, 6]
    assert sorted(i for b in two for i in b) == list(range(20))


def test_a_sweep_point_without_run_files_records_only_what_its_metrics_read(tmp_path,
                                                                           monkeypatch):
    """A sweep that keeps no run file records only the signals its metrics read (the grid's
    aliased signals): the table is the same as with every signal recorded, the recorded
    columns are those signals alone."""
    import dataclasses

    import weakgrid.study.sweep as sweep
    from weakgrid.study.runner import simulate_prepared

    st = _two_ratings_two_loads(["nonlinear-29"])
    pts = sweep_points(st, quick=True)
    prep = sweep.prepare_point(pts[0].inputs)
    assert prep.record == list(dict.fromkeys(prep.setup.signals.values()))
    res, _ = simulate_prepared([prep], batched=False)[0]
    assert sorted(res.names) == sorted(prep.record)
    full = dataclasses.replace(sweep.prepare_point(pts[0].inputs), record=None)
    res_full, _ = simulate_prepared([full], batched=False)[0]
    assert len(res_full.names) > 5 * len(res.names)
    for n in res.names:
        assert (res[n] == res_full[n]).all(), n
    lean = run_study_sweep(st, tmp_path / "lean", quick=True, workers=0, progress=False)
    real = sweep.prepare_point
    monkeypatch.setattr(sweep, "prepare_point",
                        lambda inputs: dataclasses.replace(real(inputs), record=None))
    every = run_study_sweep(st, tmp_path / "every", quick=True, workers=0, progress=False)
    pd.testing.assert_frame_equal(lean.drop(columns=TIMES), every.drop(columns=TIMES))


def test_a_run_file_sweep_point_records_every_signal():
    """With ``signals = true`` (the run files kept) a sweep point records every signal."""
    import weakgrid.study.sweep as sweep

    st = _two_ratings_two_loads(["nonlinear-29"])
    pt = sweep_points(st, quick=True)[0]
    assert sweep.prepare_point(dict(pt.inputs, signals=True)).record is None


@pytest.mark.slow
def test_case1_runs_sharing_a_trained_law_equal_their_runs_alone_bit_for_bit():
    """Case 1's 6-s HJI runs at both loads (one controller, designed at high load: one policy
    call per sample for both) give the trajectories of their runs alone to the last bit. A
    closed loop amplifies any difference: when the trained policy rounded its two-row call
    otherwise than a one-row call, one ulp at 0.3 s became 1.8e-8 rad in the SG's angle."""
    import numpy as np

    from weakgrid.study.runner import Run, run_scenarios

    st = load_study("case1-weak-grid")
    runs = [Run.of(st, sc, c) for sc, c in st.runs(False)
            if c == "hji" and sc["id"] in ("c1-high-conv", "c1-low-conv")]
    assert len(runs) == 2 and runs[0].t_end >= 6.0
    alone = run_scenarios(st, runs, batched=False)
    together = run_scenarios(st, runs, batched=True)
    for a, b in zip(alone, together):
        assert a.results.names == b.results.names
        assert np.array_equal(a.results.t, b.results.t)
        assert np.array_equal(a.results.data, b.results.data)
