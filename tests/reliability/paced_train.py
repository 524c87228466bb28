"""`weakgrid train ARGS…` with a pause after each outer iteration (for the interrupt tests).

The paper's training takes ~30 ms, too short to interrupt between two iterations; a pause
of PACE seconds after each reported iteration (``WEAKGRID_TEST_PACE``, default 0.1) gives
the test time to send its signal. Everything else is the real command.
"""

import os
import sys
import time

from weakgrid.models.problem import TrainingProblem

PACE = float(os.environ.get("WEAKGRID_TEST_PACE", "0.1"))
_train = TrainingProblem.train


def _paced(self, settings=None, progress=None, **kw):
    def paced(rec):
        if progress is not None:
            progress(rec)
        time.sleep(PACE)
    return _train(self, settings, paced, **kw)


TrainingProblem.train = _paced

if __name__ == "__main__":
    from weakgrid.cli.main import main

    sys.exit(main(sys.argv[1:]))
