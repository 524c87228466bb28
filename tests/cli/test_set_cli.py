"""`--set DOTTED.FIELD=VALUE` on the study commands: the field changes what runs, a value
is validated as the study file's would be, an unknown field is named with the valid keys."""

import argparse

import pytest

from weakgrid.cli._study import field_value
from weakgrid.cli.main import build_parser, main
from weakgrid.game.errors import ParameterError
from weakgrid.study.studyfile import load_study


def _err(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def test_every_study_command_takes_set():
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name in ("run", "simulate", "design", "modes", "sweep"):
        assert "--set" in sub.choices[name]._option_string_actions, name


@pytest.mark.parametrize("text, value", [
    ("upqc.rating=0.3", 0.3), ("scenarios.c1-high-conv.t_end=4", 4),
    ("controllers.compare=[\"lqr\"]", ["lqr"]), ("scenarios.0.load=low", "low"),
    ("study.reproduce=false", False), ("design.load = \"high\"", "high"),
])
def test_values_are_toml(text, value):
    assert field_value(text)[1] == value


@pytest.mark.parametrize("text", ["upqc.rating", "=3", "upqc..rating=1", "a.b=", "x=[1,"])
def test_malformed_set_is_refused(text):
    with pytest.raises(argparse.ArgumentTypeError):
        field_value(text)


def test_design_uses_the_value(capsys):
    code, out, _ = _err(["design", "case1-weak-grid", "--no-train"], capsys)
    assert code == 0 and "T = 0.002 s" not in out
    code, out, _ = _err(["design", "case1-weak-grid", "--no-train", "--set", "design.T=0.002"],
                        capsys)
    assert code == 0 and "=> T = 0.002 s" in out


def test_modes_of_a_changed_study_differ(tmp_path, capsys):
    """A machine parameter set by --set (an array element by its name) changes the modes."""
    import pandas as pd

    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert main(["modes", "case1-weak-grid", "-o", str(a)]) == 0
    assert main(["modes", "case1-weak-grid", "-o", str(b),
                 "--set", "dynamics.gti.WF.C=0.1"]) == 0
    ta, tb = pd.read_csv(a), pd.read_csv(b)
    assert not (len(ta) == len(tb) and (ta["real"] - tb["real"]).abs().max() < 1e-9)


def test_run_refuses_an_unknown_field_listing_the_valid_keys(capsys, tmp_path):
    code, _, err = _err(["run", "case1-weak-grid", "-o", str(tmp_path / "o"), "--set",
                         "upqc.ratng=0.3"], capsys)
    assert code == 2 and "upqc.ratng" in err and "'rating'" in err and "'structure'" in err
    code, _, err = _err(["run", "case1-weak-grid", "-o", str(tmp_path / "o"), "--set",
                         "scenarios.nope.t_end=3"], capsys)
    assert code == 2 and "nope" in err and "c1-high-conv" in err
    code, _, err = _err(["run", "case1-weak-grid", "-o", str(tmp_path / "o"), "--set",
                         "grid.kindd=1"], capsys)
    assert code == 2 and "kindd" in err and "'kind'" in err
    assert not (tmp_path / "o").exists()                  # refused before any work


def test_run_validates_the_value_set(capsys, tmp_path):
    """The value goes through the study's validation (set before it, not after)."""
    code, _, err = _err(["run", "case1-weak-grid", "-o", str(tmp_path / "o"), "--set",
                         "upqc.rating=-1"], capsys)
    assert code == 2 and "upqc.rating" in err and "> 0" in err


def test_set_reaches_optional_fields_and_array_elements_by_id():
    st = load_study("case1-weak-grid", [("simulation.dt", 0.0004),
                                        ("scenarios.c1-low-red.t_end", 7.5)])
    assert st.get("simulation.dt") == 0.0004
    assert st.get("scenarios.c1-low-red.t_end") == 7.5
    assert load_study("case1-weak-grid").get("scenarios.c1-low-red.t_end") != 7.5
    with pytest.raises(ParameterError, match="report"):
        load_study("case1-weak-grid", [("report.speed_off", 1)])
