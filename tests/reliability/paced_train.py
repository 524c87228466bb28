"""`weakgrid COMMAND ARGS…` with pauses in its long loops (for the interrupt tests).

The presets train in ~30 ms, too fast to interrupt between two steps; pauses give the test
time to send its signal. Everything else is the real command. The pauses (seconds):

* ``WEAKGRID_TEST_PACE`` (default 0.1) — after each outer iteration of a training of a
  problem (`train`, `design`, the training of `verify`);
* ``WEAKGRID_TEST_PACE_TRIAL`` (default 0) — after each training of a γ trial (`gamma`),
  before the trial is decided;
* ``WEAKGRID_TEST_PACE_DP`` (default 0) — after each iteration of the dynamic programming
  (`verify`).
"""

import os
import sys
import time

from weakgrid.game import dynamic_programming, gamma_search
from weakgrid.models.problem import TrainingProblem

PACE = float(os.environ.get("WEAKGRID_TEST_PACE", "0.1"))
PACE_TRIAL = float(os.environ.get("WEAKGRID_TEST_PACE_TRIAL", "0"))
PACE_DP = float(os.environ.get("WEAKGRID_TEST_PACE_DP", "0"))
_train = TrainingProblem.train
_solve_hji = gamma_search.solve_hji
_solve_game_dp = dynamic_programming.solve_game_dp


def _paced(progress, pace):
    def paced(rec):
        if progress is not None:
            progress(rec)
        time.sleep(pace)
    return paced


def _paced_train(self, settings=None, progress=None, **kw):
    return _train(self, settings, _paced(progress, PACE), **kw)


def _paced_solve_hji(*args, **kw):
    try:
        return _solve_hji(*args, **kw)
    finally:
        time.sleep(PACE_TRIAL)


def _paced_dp(*args, progress=None, **kw):
    return _solve_game_dp(*args, progress=_paced(progress, PACE_DP), **kw)


TrainingProblem.train = _paced_train
gamma_search.solve_hji = _paced_solve_hji
dynamic_programming.solve_game_dp = _paced_dp   # `verify` imports it when it runs

if __name__ == "__main__":
    from weakgrid.cli.main import main

    sys.exit(main(sys.argv[1:]))
