"""One dotted-path mechanism (weakgrid.dotted) for study files, sweep axes and --set."""

import pytest

from weakgrid.dotted import get_path, set_path
from weakgrid.game.errors import ParameterError

D = {"upqc": {"rating": 0.2}, "scenarios": [{"id": "a", "t_end": 5.0, "events": [{"xf": 1}]},
                                             {"id": "b", "t_end": 6.0}],
     "gens": [{"name": "G1", "H": 3.0}]}


def test_elements_by_id_name_or_index():
    assert get_path(D, "scenarios.b.t_end") == 6.0
    assert get_path(D, "scenarios.1.t_end") == 6.0
    assert get_path(D, "scenarios.-1.t_end") == 6.0
    assert get_path(D, "gens.G1.H") == 3.0
    assert get_path(D, "scenarios.a.events.0.xf") == 1


@pytest.mark.parametrize("path, words", [
    ("upqc.ratng", ["no field 'ratng' in upqc", "['rating']"]),
    ("scenarios.c.t_end", ["no element 'c'", "indices 0..1", "['a', 'b']"]),
    ("upqc.rating.x", ["upqc.rating is a value"]),
    ("nope", ["'nope'", "['gens', 'scenarios', 'upqc']"]),
    ("upqc..rating", ["dotted field path"]),
])
def test_a_miss_names_what_exists(path, words):
    with pytest.raises(ParameterError) as e:
        get_path(D, path, field="--set")
    assert str(e.value).startswith("--set = ")
    for w in words:
        assert w in str(e.value)


def test_set_strict_or_creating():
    import copy

    d = copy.deepcopy(D)
    set_path(d, "scenarios.b.t_end", 9.0)
    assert d["scenarios"][1]["t_end"] == 9.0
    with pytest.raises(ParameterError, match="no field 'dt'"):
        set_path(d, "simulation.dt", 0.1) if "simulation" in d else set_path(d, "upqc.dt", 0.1)
    set_path(d, "simulation.dt", 0.1, create=True)          # a missing optional table
    assert d["simulation"] == {"dt": 0.1}
    with pytest.raises(ParameterError, match="no element 'z'"):
        set_path(d, "scenarios.z", {}, create=True)          # list elements are never created
    set_path(d, "scenarios.a", {"id": "a2"})
    assert d["scenarios"][0] == {"id": "a2"}
