"""Small test networks in MATPOWER form."""

import numpy as np


def two_machine_case(x_line=0.3, p=0.8):
    """Two buses, one line, a PV generator at bus 1 and the slack generator at bus 2 (MATPOWER form)."""
    bus = np.array([
        [1, 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
        [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
    ], dtype=float)
    gen = np.array([
        [1, p * 100, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
        [2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
    ], dtype=float)
    branch = np.array([[1, 2, 0.0, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], dtype=float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}
