"""A sweep's cached signals may be a run file (a study sweep with ``signals = true``)."""

import numpy as np

from weakgrid.sim.results import Results
from weakgrid.sim.runfile import read_meta, read_run, run_table
from weakgrid.sweep.cache import ResultCache


def test_a_run_file_table_is_cached_and_read_back(tmp_path):
    t = np.array([0.0, 0.1, 0.1, 0.2])
    res = Results(t, ["G1.omega", "bus1.v"], np.column_stack([1 + t, 1 - t]),
                  ["speed", "voltage"], [2 * np.pi * 50, 20.0])
    cache = ResultCache(tmp_path)
    cache.put({"key": "k1", "status": "ok", "metrics": {}},
              signals=run_table(res, meta={"scenario": "s"}))
    assert cache.get("k1") is not None               # the checksum covers the run file
    df = read_run(cache.signals_path("k1"), pre_event=True)
    assert np.array_equal(df["G1.omega"], 1 + t) and df["pre_event"].tolist() == [0, 1, 0, 0]
    assert read_meta(cache.signals_path("k1"))["scenario"] == "s"
