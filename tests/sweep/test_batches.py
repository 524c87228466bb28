"""Batches of a sweep: grouping (keys, order, every run once), results back on their rows, and
a sweep run in batches giving the table of the one-by-one sweep (failures stay their own row)."""

from __future__ import annotations

import sys

import cloudpickle
import pandas as pd
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.sweep import execute_batch, expand, group, run_sweep, scatter

cloudpickle.register_pickle_by_value(sys.modules[__name__])

BASE = {"upqc": {"rating": 0.15}, "load": "high", "fault": 0.05}


def toy_run(inputs):
    """A deterministic 'simulation': raises for a negative rating, fails at zero."""
    r = inputs["upqc"]["rating"]
    if r < 0:
        raise ValueError(f"rating {r} < 0")
    if r == 0:
        return {"status": "failed", "failure": "loss of synchronism", "peak": float("nan")}
    return {"peak": r * inputs["fault"], "label": inputs["load"]}


def toy_many(runs):
    """The batch hook of the toy: one by one, an exception is that run's result."""
    out = []
    for inp in runs:
        try:
            out.append(toy_run(inp))
        except Exception as exc:
            out.append(exc)
    return out


def by_load(inputs):
    return inputs["load"]


def short_many(runs):
    return [toy_run(runs[0])]      # a broken batch hook: one result for the whole batch


def _tab(df):
    return df.drop(columns=["wall_s", "traceback_tail"]).reset_index(drop=True)


def test_group_keys_order_and_sizes():
    items = ["a1", "b1", "a2", "c1", "b2", "a3"]
    bs = group(items, key=lambda s: s[0])
    assert [(b.key, b.rows) for b in bs] == [("a", (0, 2, 5)), ("b", (1, 4)), ("c", (3,))]
    bs = group(items, key=lambda s: s[0], max_size=2)
    assert [(b.key, b.rows) for b in bs] == [("a", (0, 2)), ("b", (1, 4)), ("c", (3,)),
                                             ("a", (5,))]
    assert sorted(i for b in bs for i in b.rows) == list(range(len(items)))
    assert max(len(b) for b in bs) == 2
    assert group([], key=str) == []


def test_group_splits_a_group_costlier_than_max_weight_into_equal_parts():
    items = [("a", 1.0)] * 5 + [("b", 4.0), ("a", 1.0), ("c", 0.5)]
    bs = group(items, key=lambda it: it[0], weight=lambda it: it[1], max_weight=2.5)
    # a: 6 runs of cost 1 -> 3 parts of 2; b: one run of 4 stays whole; c: under the limit
    assert [(b.key, b.rows) for b in bs] == [("a", (0, 1)), ("a", (2, 3)), ("a", (4, 6)),
                                             ("b", (5,)), ("c", (7,))]
    # both limits: the count's parts where they are more
    bs = group(items, key=lambda it: it[0], max_size=2, weight=lambda it: it[1],
               max_weight=100.0)
    assert [len(b) for b in bs if b.key == "a"] == [2, 2, 2]
    # sizes differ by one at most: 7 runs of cost 1 over a limit of 3 -> 3 parts of 3, 2, 2
    bs = group([1.0] * 7, key=lambda x: 0, weight=float, max_weight=3.0)
    assert [len(b) for b in bs] == [3, 2, 2]


def test_balanced_caps_a_batch_at_a_workers_share_of_the_cost():
    from weakgrid.sweep.batches import balanced

    items = [("a", 1.0)] * 6 + [("b", 2.0)] * 2      # cost 10: a worker's share of 2 is 5
    bs = balanced(items, key=lambda it: it[0], cost=lambda it: it[1], balance=2)
    assert [(b.key, len(b)) for b in bs] == [("a", 3), ("a", 3), ("b", 2)]
    assert [len(b) for b in balanced(items, key=lambda it: it[0], cost=lambda it: it[1],
                                     balance=1)] == [6, 2]
    # no cost, or costs that are not finite numbers (counted 0): by count alone
    assert len(balanced(items, key=lambda it: it[0], balance=2)) == 2
    assert len(balanced(items, key=lambda it: it[0], cost=lambda it: float("nan"),
                        balance=2)) == 2
    for bad in (0, -2, 1.5, True):
        with pytest.raises(ParameterError, match="balance"):
            balanced(items, key=lambda it: it[0], cost=lambda it: it[1], balance=bad)


def test_balanced_counts_the_workers_other_tasks_in_their_shares():
    """Beside other tasks of cost 10 (the scenario runs beside the maps), the workers' shares
    are (10 + 10) / 2 = 10: group 'a' (cost 6) stays one batch, which alone it is cut in two."""
    from weakgrid.sweep.batches import balanced

    items = [("a", 1.0)] * 6 + [("b", 2.0)] * 2
    kw = dict(key=lambda it: it[0], cost=lambda it: it[1], balance=2)
    assert [len(b) for b in balanced(items, **kw)] == [3, 3, 2]
    assert [len(b) for b in balanced(items, other_cost=10.0, **kw)] == [6, 2]
    assert [len(b) for b in balanced(items, other_cost=1.0, **kw)] == [3, 3, 2]   # 5.5: cut
    for bad in (-1.0, float("nan"), float("inf"), True, "1"):
        with pytest.raises(ParameterError, match="other_cost"):
            balanced(items, other_cost=bad, **kw)


@pytest.mark.parametrize("mw", [0, -1.0, float("inf"), float("nan"), True])
def test_group_refuses_a_bad_max_weight(mw):
    with pytest.raises(ParameterError, match="max_weight"):
        group([1, 2], key=str, weight=float, max_weight=mw)
    with pytest.raises(ParameterError, match="max_weight"):
        group([1, 2], key=str, max_weight=1.0)      # a limit without a weight


@pytest.mark.parametrize("size", [0, -1, 1.5, True])
def test_group_refuses_a_bad_size(size):
    with pytest.raises(ParameterError, match="max_size"):
        group([1, 2], key=str, max_size=size)


def test_scatter_puts_each_result_on_its_row():
    items = [3, 10, 4, 11, 5]
    bs = group(items, key=lambda x: x >= 10)
    res = [[x * 2 for x in (items[i] for i in b.rows)] for b in bs]
    assert scatter(bs, res, len(items)) == [x * 2 for x in items]
    with pytest.raises(ParameterError, match="one result per run"):
        scatter(bs, [res[0][:1], res[1]], len(items))
    with pytest.raises(ParameterError, match="one list of results per batch"):
        scatter(bs, res[:1], len(items))
    with pytest.raises(ParameterError, match="in no batch"):
        scatter(bs, res, len(items) + 1)


def test_a_batched_sweep_gives_the_one_by_one_table(tmp_path):
    pts = expand(BASE, {"upqc.rating": [-0.1, 0.0, 0.1, 0.3], "load": ["high", "low"]})
    one = run_sweep(pts, toy_run, cache_dir=tmp_path / "one", workers=0, progress=False)
    seen = []

    def spy(runs):
        seen.append([(r["load"], r["upqc"]["rating"]) for r in runs])
        return toy_many(runs)

    many = run_sweep(pts, toy_run, cache_dir=tmp_path / "many", workers=0, progress=False,
                     batch=(by_load, spy))
    pd.testing.assert_frame_equal(_tab(one), _tab(many))
    assert list(many["status"]) == ["failed", "failed"] * 2 + ["ok", "ok"] * 2
    assert "ValueError: rating -0.1 < 0" in many["failure"][0]
    assert [len(b) for b in seen] == [4, 4]            # two loads, a batch each, in order
    assert seen[0] == [("high", -0.1), ("high", 0.0), ("high", 0.1), ("high", 0.3)]
    # the cache is shared: the one-by-one sweep over the batched one's cache runs nothing
    again = run_sweep(pts, toy_run, cache_dir=tmp_path / "many", workers=0, progress=False)
    pd.testing.assert_frame_equal(_tab(again), _tab(many))


def test_a_broken_batch_fails_each_of_its_runs_with_the_cause():
    recs = execute_batch(short_many, [dict(BASE), dict(BASE)], ["k1", "k2"])
    assert [r["record"]["key"] for r in recs] == ["k1", "k2"]
    assert all(r["record"]["status"] == "failed" for r in recs)
    assert "returned 1 results for a batch of 2" in recs[0]["record"]["failure"]


def test_batches_on_a_cluster_give_the_serial_table(tmp_path):
    from weakgrid.sweep import open_client

    pts = expand(BASE, {"upqc.rating": [-0.1, 0.1, 0.2], "load": ["high", "low", "mid"]})
    serial = run_sweep(pts, toy_run, cache_dir=tmp_path / "s", workers=0, progress=False)
    with open_client(None, 1) as client:
        par = run_sweep(pts, toy_run, cache_dir=tmp_path / "p", client=client, progress=False,
                        batch=(by_load, toy_many), batch_size=2,
                        cost=lambda inp: inp["upqc"]["rating"])
    pd.testing.assert_frame_equal(_tab(par), _tab(serial))
