"""`weakgrid reproduce` on a handful of short runs (for the interrupt/resume tests).

Run as a script: ``python small_reproduce.py OUTPUT [N_RUNS] [T_END]``. It replaces the
paper's scenario list by short case-1 runs that need no training, then calls the
real CLI, so that interruption, the error boundary and resumption are the real ones.
"""

import sys

import weakgrid.study.reproduce as rp
from weakgrid.cli.main import main
from weakgrid.study.scenarios import C1, Scenario


def small_scenarios(n=4, t_end=0.4):
    out = []
    for k in range(n):
        load = ("high", "low")[k % 2]
        ctl = ("pq", "nonlinear-29")[(k // 2) % 2]
        out.append(Scenario(f"s{k}-{load}-{ctl}", C1, load, "conventional", ctl, 0.1,
                            0.15 + 0.01 * k, t_end))
    return out


if __name__ == "__main__":
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    t_end = float(sys.argv[3]) if len(sys.argv) > 3 else 0.4
    rp.paper_scenarios = lambda quick=False: small_scenarios(n, t_end)
    sys.exit(main(["reproduce", "--output", sys.argv[1]]))
