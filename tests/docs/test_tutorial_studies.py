"""The study files the tutorials use are valid and build (before the slower docs build runs them).

Beside the validation by :func:`weakgrid.study.studyfile.load_study`, each grid is built at its
design operating point (power flow, machine initialization, derivation of (10)), and the
controlled machine's rotor states must dominate the full grid's mode that the mode check picks.
"""

from pathlib import Path

import pytest

from weakgrid.study.build import build_setup
from weakgrid.study.engine import mode_check
from weakgrid.study.studyfile import load_study

DATA = Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "data"
FILES = sorted(DATA.glob("*.toml"))


def test_there_are_tutorial_studies():
    assert FILES, f"no study files in {DATA}"


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_tutorial_study_builds_and_derives(path):
    study = load_study(path)
    assert study.runs(), "a tutorial study has runs to show"
    setup = build_setup(study)
    assert setup.design.a > 0 and setup.design.Vr_bar > 0
    chk = mode_check(setup)
    assert chk["grid_lambda"] is not None
    assert chk["participation"] > 0.5        # the machine's δ, ω dominate the chosen mode
