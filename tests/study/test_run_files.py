"""Study runs keep every signal by name (run files), the cache reads back what it needs.

A run of the shipped ``ieee9-sg-upqc`` (fault at the shunt bus, 1.0-1.1 s; cut to 1.3 s)."""

import dataclasses

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import weakgrid
from weakgrid.game.errors import ParameterError
from weakgrid.sim.errors import DataError
from weakgrid.sim.runfile import read_meta, read_run, read_samples
from weakgrid.study.build import build_setup
from weakgrid.study.cache import load_run, save_run
from weakgrid.study.figures import _series
from weakgrid.study.runner import Run, RunRecord, run_scenario
from weakgrid.study.studyfile import load_study, read_study_dict, set_path, study_from_dict

STUDY = "ieee9-sg-upqc"


def _run(st, controller="lqr", t_end=1.3):
    sc = next(s for s in st.scenarios(False) if s["id"] == "fault-r")
    return dataclasses.replace(Run.of(st, sc, controller), t_end=t_end)


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    st = load_study(STUDY)
    run = _run(st)
    rec = run_scenario(st, run)
    folder = tmp_path_factory.mktemp("runs")
    save_run(rec, folder, "key")
    return st, run, rec, folder


def test_every_machine_and_bus_by_name_with_units_in_metadata(saved):
    st, run, rec, folder = saved
    path = folder / f"{run.id}.parquet"
    schema = pq.read_schema(path)
    names = set(schema.names)
    machines = [g["name"] for g in st.data["dynamics"]["generator"]]
    assert len(machines) == 3
    for m in machines:
        assert {f"{m}.omega", f"{m}.delta"} <= names
        assert schema.field(f"{m}.omega").metadata[b"kind"] == b"speed"
        assert schema.field(f"{m}.delta").metadata[b"unit"] == b"rad"
    net = build_setup(st, run.load, run.upqc).system.network
    for bid in net.bus_ids:
        f = schema.field(f"bus{bid}.v").metadata
        assert f[b"unit"] == b"pu" and f[b"si_unit"] == b"kV" and f[b"base"].startswith(b"bus base")
    assert set(rec.results.names) <= names        # every recorded signal, not 10 aliases
    assert schema.field("UPQC.P_series").metadata[b"base"] == b"Sb = 100 MVA"
    meta = read_meta(path)
    assert (meta["study"], meta["scenario"], meta["controller"]) == (STUDY, "fault-r", "lqr")
    assert meta["weakgrid_version"] == weakgrid.__version__
    assert meta["dt"] == pytest.approx(1e-3) and meta["events"][0]["kind"] == "fault"
    assert meta["aliases"]["sg_speed"] == "G3.omega"          # the figure keys: a mapping


def test_speed_read_back_equals_the_simulators(saved):
    st, run, rec, folder = saved
    path = folder / f"{run.id}.parquet"
    full = weakgrid.read_run(path, ["G3.omega"], pre_event=True)
    assert np.array_equal(full["G3.omega"].to_numpy(), rec.results["G3.omega"])
    assert np.array_equal(full["t"].to_numpy(), rec.results.t)
    df = weakgrid.read_run(path, "G*.omega")
    assert list(df.columns) == ["t", "G1.omega", "G2.omega", "G3.omega"]
    assert np.all(np.diff(df["t"].to_numpy()) > 0)           # one row per instant
    assert len(df) == len(np.unique(rec.results.t))
    # the fault's breakpoints: a pre-event row, then the post-event row at the same t
    pre = full["pre_event"].to_numpy()
    for t_ev in (1.0, 1.1):
        i = np.flatnonzero(np.isclose(rec.results.t, t_ev))
        assert len(i) == 2 and pre[i[0]] and not pre[i[1]]
    si = read_run(path, ["G3.omega"], si=True)
    assert si.attrs["units"]["G3.omega"] == "rad/s"
    assert np.allclose(si["G3.omega"], 2 * np.pi * 60 * df["G3.omega"])
    # the controller's samples alongside
    s = read_samples(path)
    assert np.array_equal(s["t"].to_numpy(), rec.samples["tk"])
    assert np.array_equal(s["u_applied[0]"].to_numpy(), rec.samples["u_applied[0]"])


def test_series_and_samples_each_make_a_data_frame(saved):
    """Regression: ``RunRecord.series`` mixed per-instant and per-sample (2-D) arrays, so
    ``pd.DataFrame(rec.series)`` raised; the run file kept ~10 aliased columns."""
    _, run, rec, folder = saved
    a = pd.DataFrame(rec.series)
    b = pd.DataFrame(rec.samples)
    assert len(a) == len(rec.results.t) and len(b) == len(rec.samples["tk"]) > 0
    assert rec.sample("x_design").shape == (len(b), 2)
    assert len(pq.read_schema(folder / f"{run.id}.parquet").names) > 100


def test_the_cached_run_reads_back_what_figures_and_metrics_use(saved):
    st, run, rec, folder = saved
    got = load_run(folder, run, "key", RunRecord)
    assert got is not None and got.results is None
    assert set(got.series) == set(rec.series) and set(got.samples) == set(rec.samples)
    for k in rec.series:
        assert np.array_equal(got.series[k], rec.series[k], equal_nan=True), k
    for k in rec.samples:
        assert np.array_equal(got.samples[k], rec.samples[k], equal_nan=True), k
    assert got.aliases == rec.aliases
    for key in ("sg_speed", "vu", "p_series_mw", "running_cost"):
        (t1, y1), (t2, y2) = _series(rec, key), _series(got, key)
        assert np.array_equal(t1, t2) and np.array_equal(y1, y2)
    m1 = {k: v for k, v in rec.metrics.items() if k != "wall_s"}
    m2 = {k: v for k, v in got.metrics.items() if k != "wall_s"}
    assert m1.keys() == m2.keys()
    for k in m1:
        assert m1[k] == m2[k] or (m1[k] != m1[k] and m2[k] != m2[k]), k


def test_selective_recording():
    st = load_study(STUDY)
    st.data.setdefault("simulation", {})["record"] = ["*.omega"]
    run = _run(st, controller="pss-only", t_end=1.15)
    rec = run_scenario(st, run)
    # the machines' speeds and the signals the figures and metrics need, nothing else
    needed = build_setup(st, run.load, run.upqc).signals.values()
    assert set(rec.results.names) == {"G1.omega", "G2.omega", "G3.omega", *needed}
    assert "G1.delta" not in rec.results
    assert rec.metrics["speed_peak_dev_pu"] > 0
    st.data["simulation"]["record"] = ["G3.omegaa"]
    with pytest.raises(DataError, match=r"G3\.omega"):
        run_scenario(st, run)


@pytest.mark.parametrize("value", ["*.omega", [], [1]])
def test_record_must_be_a_list_of_names(value):
    d = read_study_dict(STUDY)[0]
    set_path(d, "simulation", {"record": value})
    with pytest.raises(ParameterError, match="simulation.record"):
        study_from_dict(d, "test")


def test_simulate_writes_a_run_file_that_plot_reads(tmp_path, capsys):
    from weakgrid.cli.main import main

    out = tmp_path / "run.parquet"
    assert main(["simulate", STUDY, "--scenario", "fault-r", "--controller", "pss-only",
                 "--t-end", "1.15", "-o", str(out)]) == 0
    df = weakgrid.read_run(out, ["G*.omega", "G*.delta"])
    assert df.shape[1] == 7 and df.attrs["meta"]["controller"] == "pss-only"
    assert main(["plot", str(out), "G*.omega", "bus*.v"]) == 0
    assert out.with_suffix(".png").is_file()
