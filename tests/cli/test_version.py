"""``weakgrid --version`` prints the package version recorded in every result file."""

import pytest

import weakgrid
from weakgrid.cli.main import main


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"weakgrid {weakgrid.__version__}"
