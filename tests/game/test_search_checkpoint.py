"""Checkpoints of the γ search and of the DP ground truth: a resumed run gives the result of
the uninterrupted one bit for bit, from any point (after a decided trial, in the middle of a
trial's training, after the failed training of a rejected start, after any DP iteration),
through a file; a damaged or stale file is refused."""

from __future__ import annotations

import numpy as np
import pytest

from weakgrid.game.checkpoint import (CheckpointError, StaleCheckpointError,
                                      load_dp_checkpoint, load_search_checkpoint,
                                      save_checkpoint, save_dp_checkpoint,
                                      save_search_checkpoint)
from weakgrid.game.dynamic_programming import DPSettings, solve_game_dp
from weakgrid.game.gamma_search import SearchSettings, search_min_gamma
from weakgrid.models import load_preset

SETTINGS = SearchSettings(rtol=0.05, rollout_steps=1500)


def _search(p, **kw):
    return search_min_gamma(p.system, p.basis, p.cost, p.mesh, p.initial_policy, p.settings,
                            SETTINGS, problem={"name": p.name}, **kw)


@pytest.fixture(scope="module")
def search():
    """case2-paper's search and every state it reported: (preset, result, [(state, decided)])."""
    p = load_preset("case2-paper")
    states = []
    res = _search(p, checkpoint=lambda s, decided: states.append((s, decided)))
    return p, res, states


def _same(got, ref):
    assert got.gamma_star == ref.gamma_star and got.bracket == ref.bracket
    assert [(t.gamma, t.accepted, t.reason, t.start, t.outer) for t in got.history] == \
        [(t.gamma, t.accepted, t.reason, t.start, t.outer) for t in ref.history]
    np.testing.assert_array_equal(got.controller.weights, ref.controller.weights)
    assert [r.max_du for r in got.controller.history] == \
        [r.max_du for r in ref.controller.history]


def _decided(states):
    return [s for s, finished in states if finished and s.running is None]


def test_the_search_reports_every_decided_trial_failed_start_and_training_iteration(search):
    p, ref, states = search
    decided = _decided(states)
    assert [len(s.trials) for s in decided] == list(range(1, len(ref.history) + 1))
    training = [s for s, finished in states if not finished]
    assert training and all(s.running.training.outer >= 1 for s in training)
    assert {s.running.gamma for s in training} == {t.gamma for t in ref.history}
    # a failed start is saved at once, with the next start due and the reasons so far
    failed = [s for s, finished in states if finished and s.running is not None]
    rejected = [t for t in ref.history if not t.accepted]
    assert failed and all(s.running.training is None for s in failed)
    assert {s.running.gamma for s in failed} == {t.gamma for t in rejected}
    for t in rejected:  # every start of a rejected trial but the last one
        marks = [s.running for s in failed if s.running.gamma == t.gamma]
        assert [m.start for m in marks] == list(SETTINGS.starts[1:])
        assert len(marks[-1].reasons) == len(SETTINGS.starts) - 1
        assert t.reason.startswith("; ".join(marks[-1].reasons) + f"; [{SETTINGS.starts[-1]}]")


@pytest.mark.parametrize("where", ["after trial 3", "mid-training", "failed training",
                                   "after a failed start", "all decided"])
def test_a_resumed_search_gives_the_uninterrupted_result(tmp_path, search, where):
    p, ref, states = search
    decided = _decided(states)
    rejected = {t.gamma for t in ref.history if not t.accepted}
    training = [s for s, finished in states if not finished]
    if where == "after trial 3":
        state = decided[2]
    elif where == "mid-training":  # an accepted trial after an accepted and a rejected one
        cand = [s for s in training if s.running.gamma not in rejected
                and any(not t.accepted for t in s.trials) and s.running.training.outer > 3]
        state = cand[len(cand) // 2]
    elif where == "failed training":  # the last iteration of a start that does not converge
        cand = [s for s in training if s.running.gamma in rejected]
        state = cand[-1]
    elif where == "after a failed start":  # the last start of a rejected trial is due
        state = [s for s, finished in states if finished and s.running is not None][-1]
        assert state.running.training is None and state.running.reasons
    else:
        state = decided[-1]
    path = save_search_checkpoint(tmp_path / "s.npz", state, "key")
    resume = load_search_checkpoint(path, "key")
    assert isinstance(resume.best, dict) or resume.best is None
    ran = []
    got = _search(p, resume=resume, progress=ran.append)
    _same(got, ref)
    # only the trials not decided in the checkpoint were run (and reported)
    assert [t.gamma for t in ran] == [t.gamma for t in ref.history[len(state.trials):]]


def test_a_search_checkpoint_of_other_inputs_or_damaged_is_refused(tmp_path, search):
    p, ref, states = search
    state = [s for s, finished in states if not finished][5]
    path = save_search_checkpoint(tmp_path / "s.npz", state, "key")
    with pytest.raises(StaleCheckpointError):
        load_search_checkpoint(path, "other")
    (tmp_path / "bad.npz").write_bytes(path.read_bytes()[:100])
    with pytest.raises(CheckpointError):
        load_search_checkpoint(tmp_path / "bad.npz", "key")
    # a training checkpoint is not a search checkpoint (and says so)
    save_checkpoint(tmp_path / "t.npz", state.running.training, "key")
    with pytest.raises(CheckpointError, match="not a weakgrid-gamma-search-checkpoint"):
        load_search_checkpoint(tmp_path / "t.npz", "key")


def test_a_resumed_dp_gives_the_uninterrupted_result_after_any_iteration(tmp_path):
    p = load_preset("case1-paper")
    cost = p.cost
    st = DPSettings(n_points=(31, 31))
    kept = []
    ref = solve_game_dp(p.system, cost, p.mesh.lower, p.mesh.upper, st, checkpoint=kept.append)
    assert [s.iteration for s in kept] == list(range(1, len(ref.history) + 1))
    for state in kept:
        path = save_dp_checkpoint(tmp_path / "d.npz", state, "key")
        ran = []
        got = solve_game_dp(p.system, cost, p.mesh.lower, p.mesh.upper, st,
                            start=load_dp_checkpoint(path, "key"), progress=ran.append)
        np.testing.assert_array_equal(got.residual, ref.residual)
        np.testing.assert_array_equal(got.policy, ref.policy)
        assert got.converged == ref.converged
        assert [h["max_rel_dV"] for h in got.history] == [h["max_rel_dV"] for h in ref.history]
        assert [h["iteration"] for h in ran] == list(range(state.iteration + 1,
                                                           len(ref.history) + 1))
    with pytest.raises(StaleCheckpointError):
        load_dp_checkpoint(path, "other")
