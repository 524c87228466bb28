"""``weakgrid --version`` prints the package version recorded in every result file."""

import weakgrid
from weakgrid.cli.main import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"weakgrid {weakgrid.__version__}"
