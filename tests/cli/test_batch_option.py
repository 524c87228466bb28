"""`--no-batch` of run, reproduce and sweep: batching is the default, the scalar path
selectable, and what the command passes on (the study functions' ``batched``)."""

import pytest

from weakgrid.cli.main import build_parser


@pytest.mark.parametrize("argv", [["run", "case1-weak-grid"], ["reproduce"],
                                  ["sweep", "case1-weak-grid"]])
def test_batching_is_the_default_and_no_batch_selects_the_scalar_path(argv):
    p = build_parser()
    assert p.parse_args(argv).batched is True
    assert p.parse_args(argv + ["--no-batch"]).batched is False


def test_sweep_passes_no_batch_on(monkeypatch, tmp_path):
    import pandas as pd

    import weakgrid.study.sweep as sweep
    import weakgrid.study.sweep_estimate as est

    seen = {}

    def fake(st, out, **kw):
        seen.update(kw)
        return pd.DataFrame({"status": ["ok"]})

    class _Est:
        def line(self):
            return "estimate"

    monkeypatch.setattr(sweep, "run_study_sweep", fake)
    monkeypatch.setattr(est, "estimate_sweep", lambda *a, **k: _Est())
    monkeypatch.setattr(est, "check_sweep", lambda *a, **k: None)
    from weakgrid.cli.main import main

    assert main(["sweep", "case1-weak-grid", "--quick", "--workers", "0", "--no-batch",
                 "-o", str(tmp_path / "o")]) == 0
    assert seen["batched"] is False
    assert main(["sweep", "case1-weak-grid", "--quick", "--workers", "0",
                 "-o", str(tmp_path / "p")]) == 0
    assert seen["batched"] is True
