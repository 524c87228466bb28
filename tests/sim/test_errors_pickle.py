"""Errors travel by pickle (a Dask worker's failed run carries its SimulationError to the
client): every error class of weakgrid round-trips with its fields.

Regression: ``reproduce`` on a Dask cluster stopped with "SimulationError.__init__() missing 1
required positional argument: 'cause'" when a run lost synchronism (its record now carries the
simulator's Results, whose ``failure`` is the error).
"""

import pickle

import numpy as np

from weakgrid.game.errors import ParameterError, ShapeError
from weakgrid.sim.errors import DataError, PowerFlowError, SimulationError


def _round_trip(err):
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is type(err) and str(back) == str(err)
    return back


def test_simulation_error_keeps_time_cause_detail_and_extra_attributes():
    err = SimulationError(3.427, "loss of synchronism", "G3 swung 180 deg")
    err.fold = np.arange(3.0)
    back = _round_trip(err)
    assert (back.t, back.cause, back.detail) == (3.427, "loss of synchronism", "G3 swung 180 deg")
    assert np.array_equal(back.fold, err.fold)


def test_input_errors_keep_their_fields():
    back = _round_trip(DataError("GENROU 'G1'", "Td10", -1.0, "give a positive time constant"))
    assert (back.element, back.field, back.value) == ("GENROU 'G1'", "Td10", -1.0)
    back = _round_trip(ParameterError("upqc.rating", 1e9, "at most 1 pu"))
    assert back.field == "upqc.rating" and back.value == 1e9
    _round_trip(ShapeError("K", (3, 2), "(2, 2)"))
    _round_trip(PowerFlowError("did not converge"))


def test_a_results_object_with_its_failure_pickles():
    from weakgrid.sim.results import Results

    r = Results([0.0, 1.0], ["G1.omega"], np.ones((2, 1)), ["speed"], [1.0],
                failure=SimulationError(1.0, "newton"))
    back = pickle.loads(pickle.dumps(r))
    assert back.failure.cause == "newton" and back.failure.t == 1.0
