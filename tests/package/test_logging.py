"""The library speaks through ``logging`` (logger ``weakgrid`` and its children), never
``print``; the CLI shows those messages on stdout, ``--quiet`` hides them, and leaves the
host's logging as it was."""

import argparse
import logging

from weakgrid.logs import console, logger
from weakgrid.study.cache import remove_stale
from weakgrid.sweep import expand, run_sweep


def _run(inputs):
    return {"v": inputs["x"] * 2.0}


def test_sweep_messages_are_log_records_not_prints(tmp_path, caplog, capsys):
    pts = expand({"x": 1.0}, {"x": [1.0, 2.0]})
    with caplog.at_level(logging.INFO, logger="weakgrid"):
        run_sweep(pts, _run, cache_dir=tmp_path / "c", workers=0, progress=False)
    msgs = [r for r in caplog.records if r.name.startswith("weakgrid.sweep")]
    assert msgs and "2 runs" in msgs[0].getMessage()
    assert capsys.readouterr().out == ""          # nothing printed by the library


def test_removed_files_are_a_warning_record(tmp_path, caplog):
    from weakgrid.manifest import Manifest

    (tmp_path / "old.json").write_text("{}")
    Manifest(tmp_path).claim([tmp_path / "old.json"], force=True)   # a file weakgrid wrote
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        assert remove_stale(tmp_path, []) == ["old"]
    assert any(r.levelno == logging.WARNING and "old" in r.getMessage() for r in caplog.records)


def test_console_shows_messages_and_restores_the_logger(capsys):
    before = (logger.level, logger.propagate, list(logger.handlers))
    with console(0):
        logging.getLogger("weakgrid.study.engine").info("a progress line")
        logging.getLogger("weakgrid.study.engine").debug("a detail")
    with console(-1):
        logging.getLogger("weakgrid.study.engine").info("hidden by --quiet")
        logging.getLogger("weakgrid.study.engine").warning("a warning")
    with console(1):
        logging.getLogger("weakgrid.study.engine").debug("a detail with -v")
    out = capsys.readouterr().out
    assert "a progress line" in out and "a detail\n" not in out
    assert "hidden by --quiet" not in out and "a warning" in out
    assert "a detail with -v" in out
    assert (logger.level, logger.propagate, list(logger.handlers)) == before


def test_every_command_takes_quiet_and_verbose():
    from weakgrid.cli.main import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, sp in sub.choices.items():
        assert {"--quiet", "--verbose", "--no-progress"} <= set(sp._option_string_actions), name
