"""`weakgrid reproduce` on a handful of short runs (for the interrupt/resume tests).

Run as a script: ``python small_reproduce.py OUTPUT [N_RUNS] [T_END]``. It replaces the
paper's studies by the case-1 study with short runs that need no training, then calls the
real CLI, so that interruption, the error boundary and resumption are the real ones.
"""

import sys

import weakgrid.study.reproduce as rp
from weakgrid.cli.main import main
from weakgrid.study.studyfile import load_study, study_from_dict


def small_study(n=4, t_end=0.4):
    st = load_study("case1-weak-grid")
    d = dict(st.data)
    scs = []
    for k in range(n):
        load = ("high", "low")[k % 2]
        ctl = ("pq", "nonlinear-29")[(k // 2) % 2]
        # the (29) runs last twice as long: batched by controller, the two batches do not
        # end together (the interrupt test stops the command between them)
        scs.append({"id": f"s{k}", "load": load, "upqc": "conventional",
                    "t_end": t_end * (1 + (k // 2) % 2),
                    "controllers": [ctl],
                    "events": [{"kind": "fault", "bus": 3, "t_on": 0.1,
                                "t_off": 0.15 + 0.01 * k, "rf": 0.0, "xf": 0.1}]})
    d.update(scenarios=scs, figures=[], claims=[])
    d.pop("sweep", None)          # no maps: the short runs only
    return study_from_dict(d, st.source, st.base_dir)


if __name__ == "__main__":
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    t_end = float(sys.argv[3]) if len(sys.argv) > 3 else 0.4
    rp.paper_studies = lambda: [small_study(n, t_end)]
    sys.exit(main(["reproduce", "--output", sys.argv[1]] + sys.argv[4:]))
