"""The shipped studies as pytest parameters: a study on an ANDES grid marked ``andes`` (it
needs the optional ANDES parser to build its grid)."""

import pytest

from weakgrid.study.studyfile import load_study, shipped_studies


def needs_andes(name) -> bool:
    return load_study(name).data["grid"]["kind"] == "andes"


def shipped_params():
    return [pytest.param(n, marks=[pytest.mark.andes] if needs_andes(n) else [], id=n)
            for n in shipped_studies()]


def skip_without_andes(name):
    if needs_andes(name):
        pytest.importorskip("andes")
