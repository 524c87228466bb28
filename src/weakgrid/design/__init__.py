"""From a set-up grid to the paper's design model (10), and the check of it.

* :func:`derive_design` — (10) for a GTI with dc link or an SG behind a UPQC, with every
  intermediate value and its source;
* :func:`source_twoport` — the Kron-reduced two-port from a source's internal voltage to the
  UPQC's series node (the ``B`` of (9));
* :func:`modes`, :func:`linearize`, :func:`machine_mode` — small-signal analysis of the full DAE;
* :func:`grid_thevenin` — the grid seen from the UPQC shunt bus (the ``thevenin`` design form);
* :func:`state_space` — the linearized grid with the UPQC's inputs as a python-control model;
* :func:`insert_upqc_pandapower`, :func:`insert_upqc_matpower` — put a UPQC into a branch.

Layering: ``study → design → (sim, models) → game``.
"""

from .derive import (Derivation, derive_design, design_mode, find_machine, mode_states,
                     upqc_branch_of)
from .modes import Modes, linearize, machine_mode, modes
from .state_space import input_matrix, state_space
from .thevenin import GridThevenin, grid_thevenin, two_machine_factor
from .twoport import TwoPort, machine_side_buses, source_twoport
from .upqc_insert import insert_upqc_matpower, insert_upqc_pandapower

__all__ = ["Derivation", "derive_design", "design_mode", "find_machine", "mode_states", "upqc_branch_of",
           "Modes", "linearize", "machine_mode", "modes", "TwoPort", "machine_side_buses",
           "source_twoport", "insert_upqc_matpower", "insert_upqc_pandapower", "state_space",
           "input_matrix", "GridThevenin", "grid_thevenin", "two_machine_factor"]
