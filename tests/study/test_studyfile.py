"""Study files: validation (errors name the field), dotted paths, defaults, shipped studies."""

import copy

import pytest

from weakgrid.cli.main import main
from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import (get_path, load_study, read_study_dict, set_path,
                                      shipped_studies, study_from_dict)


def paper1():
    return read_study_dict("case1-weak-grid")[0]


def test_every_shipped_study_validates():
    names = shipped_studies()
    assert {"case1-weak-grid", "case2-lv-microgrid", "ieee9-sg-upqc",
            "cigre-mv-wind-gti"} <= set(names)
    for n in names:
        st = load_study(n)
        assert st.runs() and st.scenarios(quick=True)


@pytest.mark.parametrize("path, value, field", [
    ("upqc.rating", -0.1, "upqc.rating"),
    ("machine.name", "G9", "machine.name"),
    ("upqc.structure", "partial", "upqc.structure"),
    ("design.T", "fast", "design.T"),
    ("design.settings", "nope", "design.settings"),
    ("controllers.compare", ["hji", "magic"], "controllers.compare"),
    ("scenarios.c1-high-conv.t_end", 0.1, "scenarios.c1-high-conv.events.0.t_off"),
    ("scenarios.c1-high-conv.load", "medium", "scenarios.c1-high-conv.load"),
    ("scenarios.c1-high-conv.events.0.kind", "earthquake", "scenarios.c1-high-conv.events.0.kind"),
    ("scenarios.c1-high-conv.events.0.xf", 0.0, None),
    ("grid.kind", "csv", "grid.kind"),
    ("claims.0.judge", "vibes", "claims.0.judge"),
    ("upqc.colour", "red", "upqc.colour"),
])
def test_a_malformed_study_is_refused_with_the_field_named(path, value, field):
    d = paper1()
    if path.endswith(".xf"):     # a bolted fault with no impedance: rf = xf = 0
        set_path(d, path, 0.0)
        field = path
    else:
        set_path(d, path, value)
    with pytest.raises(ParameterError) as e:
        study_from_dict(d, "test")
    assert field in str(e.value)


def test_missing_tables_are_named():
    for key in ("grid", "machine", "upqc", "design", "scenarios"):
        d = paper1()
        del d[key]
        with pytest.raises(ParameterError, match=key):
            study_from_dict(d)


def test_dotted_paths_and_defaults():
    st = load_study("case2-lv-microgrid")
    assert st.get("upqc.rating") == 0.1
    assert st.get("scenarios.c2-high-f200.events.0.xf") == 0.01
    assert st.get("scenarios.1.id") == "c2-high-f100"
    # defaults a user expects: bypass = the fault windows, controllers = the compared ones
    assert st.scenarios()[0]["bypass"] == [[3.0, 3.2]]
    assert st.get("scenarios.c2-high-f200.controllers") == ["hji", "lqr", "pss-only", "hji-bounded"]
    with pytest.raises(ParameterError, match="upqc.ratin"):
        st.get("upqc.ratin")
    # a fault may be given by its duration
    st2 = st.with_values(**{"scenarios.c2-high-f200.events.0.duration": 0.15})
    assert st2.get("scenarios.c2-high-f200.events.0.t_off") == pytest.approx(3.15)
    assert st2.scenarios()[0]["bypass"] == [[3.0, pytest.approx(3.15)]]   # follows the fault
    assert st.get("scenarios.c2-high-f200.events.0.t_off") == 3.2     # the original unchanged


def test_a_study_as_a_dict_modified_and_built():
    d = copy.deepcopy(load_study("case1-weak-grid").data)
    assert get_path(d, "upqc.rating") == 0.15
    set_path(d, "upqc.rating", 0.3)
    s = build_setup(study_from_dict(d), "high")
    assert s.system.components["UPQC"].p["Vmax"][0] == 0.3


def test_cli_refuses_a_malformed_file_naming_the_field(tmp_path, capsys):
    import tomllib  # noqa: F401  (the file is TOML)

    text = (tmp_path / "ok.toml")
    from importlib import resources

    src = resources.files("weakgrid") / "data" / "studies" / "case1-weak-grid.toml"
    body = src.read_text().replace('rating = 0.15', 'rating = "high"')
    text.write_text(body)
    assert main(["design", str(text), "--no-train"]) == 2
    err = capsys.readouterr().err
    assert "upqc.rating" in err and "high" in err


def test_simulation_settings_of_a_study_reach_the_simulator(monkeypatch):
    """[simulation] tol is the tolerance of the study's runs; the half-step reference of the
    sweeps' uncertainty check keeps the simulator's (tighter) default."""
    import weakgrid.study.runner as runner
    from weakgrid.study.runner import Run, run_scenario, sim_settings

    d = paper1()
    T = d["design"]["T"]
    st = study_from_dict(copy.deepcopy(d))
    assert sim_settings(st) == (T, d["simulation"]["tol"])
    assert sim_settings(st, 0.5) == (T / 2, None)
    d2 = copy.deepcopy(d)
    d2["simulation"] = {"dt": T / 4, "tol": 3e-9}
    assert sim_settings(study_from_dict(d2)) == (T / 4, 3e-9)
    del d2["simulation"]
    assert sim_settings(study_from_dict(d2)) == (T, None)
    for bad in ({"tol": -1.0}, {"tol": 1.0}, {"dt": 0.0}, {"step": 1e-3}):
        d3 = copy.deepcopy(d)
        d3["simulation"] = bad
        with pytest.raises(ParameterError, match=f"simulation.{next(iter(bad))}"):
            study_from_dict(d3)
    seen = {}
    real = runner.simulate

    def spy(*a, **kw):
        seen.update(dt=kw["dt"], tol=kw["tol"])
        return real(*a, **kw)

    monkeypatch.setattr(runner, "simulate", spy)
    sc = dict(st.scenarios()[0], t_end=0.05, events=[])
    run_scenario(st, Run.of(st, sc, "nonlinear-29"))
    assert seen == {"dt": T, "tol": d["simulation"]["tol"]}
