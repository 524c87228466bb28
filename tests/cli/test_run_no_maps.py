"""`weakgrid run --no-maps`: the study's [sweep] left out (the scenarios' runs only); the
sweep is the default, and what the command passes on is the study engine's ``maps``."""

from weakgrid.cli.main import build_parser


def test_maps_are_the_default_and_no_maps_leaves_them_out():
    p = build_parser()
    assert p.parse_args(["run", "case1-weak-grid"]).maps is True
    assert p.parse_args(["run", "case1-weak-grid", "--no-maps"]).maps is False


def test_run_passes_no_maps_on(monkeypatch, tmp_path):
    import weakgrid.study.engine as engine
    from weakgrid.cli.main import main

    seen = []

    def fake(studies, out, **kw):
        seen.append(kw)
        return {"designs": [], "metrics": [], "claims": []}

    monkeypatch.setattr(engine, "run_studies", fake)
    assert main(["run", "case1-weak-grid", "--quick", "--workers", "0", "--no-maps",
                 "-o", str(tmp_path / "o")]) == 0
    assert main(["run", "case1-weak-grid", "--quick", "--workers", "0",
                 "-o", str(tmp_path / "p")]) == 0
    assert [kw["maps"] for kw in seen] == [False, True]
