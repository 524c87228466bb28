"""A failed run's cause in the sweep row, the map cells and the summaries (weakgrid.study.failure)."""

from types import SimpleNamespace

import numpy as np
import pandas as pd

from weakgrid.sim.errors import SimulationError
from weakgrid.study.failure import failure_kind, failure_text
from weakgrid.study.sweep_maps import map_cells, map_summaries

COLLAPSE = ("voltage collapse at t = 0.300519 s: the network cannot carry the operating point "
            "beyond a fold — at the fold: series voltage |Vu| = 0.264 pu applied")


def test_failure_kinds():
    assert failure_kind(COLLAPSE) == "voltage collapse"
    assert failure_kind("simulation stopped at t = 3.3 s: loss of synchronism (rotor angle "
                        "spread 180.1 deg)") == "loss of synchronism"
    assert failure_kind("simulation stopped at t = 1 s: newton (no convergence)") == \
        "Newton failure"
    assert failure_kind("") == "" and failure_kind(None) == ""


def _setup():
    upqc = SimpleNamespace(names=["UPQC"], p={"Vmax": np.array([0.6])}, r=np.array([1]))
    gti = SimpleNamespace(names=["WF"])
    return SimpleNamespace(system=SimpleNamespace(components={"UPQC": upqc, "GTI": gti}),
                           upqc_name="UPQC", source="WF", Sb_mva=100.0)


def test_failure_text_states_the_fold_in_the_grids_terms():
    err = SimulationError(0.3005, "voltage collapse", "no network solution: …")
    err.fold = {"s": 0.19, "V": np.array([1.0, 0.377 * np.exp(0.3j)]),
                "outputs": {"UPQC.Vu": np.array([0.264]), "UPQC.P_series": np.array([-0.194]),
                            "GTI.phi_s": np.array([1.9]), "GTI.upsilon": np.array([14.1]),
                            "GTI.P_ac": np.array([0.565])}}
    text = failure_text(err, _setup(), demanded=[-0.63, 1.21])
    assert text.startswith("voltage collapse at t = 0.3005 s")
    assert "|Vu| = 0.264 pu applied (rating 0.6 pu, demanded 1.36 pu)" in text
    assert "P_series = -19.4 MW" in text and "|Vr| = 0.377 pu" in text
    assert "ϕs = 1.9 rad" in text and "slipping out of step" in text   # past 90°, rising
    # other failures keep the simulator's message
    los = SimulationError(3.3, "loss of synchronism", "rotor angle spread 180.1 deg")
    assert failure_text(los, _setup()) == str(los)
    assert failure_text(None, _setup()) == ""


def test_failed_cells_name_their_cause():
    rows = []
    for r, ca, cb in ((0.1, "ok", "ok"), (0.6, "failed", "ok"), (1.0, "failed", "failed")):
        rows.append({"scenario": "s", "upqc.rating": r, "t_off": 0.3, "load": "high",
                     "controller": "a", "dt_factor": 1.0, "status": ca, "cost": 0.5,
                     "failure": COLLAPSE if ca == "failed" else ""})
        rows.append({"scenario": "s", "upqc.rating": r, "t_off": 0.3, "load": "high",
                     "controller": "b", "dt_factor": 1.0, "status": cb, "cost": 1.0,
                     "failure": COLLAPSE if cb == "failed" else ""})
    spec = {"claim": "X", "kind": "ratio", "metric": "cost", "a": "a", "b": "b",
            "holds_below": 0.8}
    axes = ["upqc.rating", "t_off", "load"]
    cells = map_cells(pd.DataFrame(rows), spec, axes)
    c = cells.set_index("upqc.rating")
    # a lost, b finished: a loss ("not"), its cause named
    assert c.loc[0.6, "verdict"] == "not" and c.loc[0.6, "note"] == "a failed: voltage collapse"
    assert c.loc[0.6, "detail"].startswith("a failed: voltage collapse at t")
    # both lost: nothing to compare
    assert c.loc[1.0, "verdict"] == "failed"
    assert c.loc[1.0, "detail"] == "a voltage collapse; b voltage collapse"
    s = map_summaries([{"spec": spec, "cells": cells, "mark": (0.1, 0.3),
                        "axes": ("upqc.rating", "t_off", "load")}])[0]
    assert "not at 0.6 (a failed: voltage collapse)" in s["region"]
    assert "a run failed at 1 (a voltage collapse; b voltage collapse)" in s["region"]
