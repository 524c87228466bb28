"""The report reads for any study (issue 27): its protocol from the study's own data, who did
best with ties inside the numerical uncertainty, tables without empty columns, valid
``metrics.md``, figures naming the machine and the event."""

from __future__ import annotations

import copy
import re

from weakgrid.study.report import who_did_best, write_tables
from weakgrid.study.studyfile import load_study, study_from_dict

PAPER_TEXT = ("C2-voltage", "Fig. 10", "Figs. 10 and 13", "case-1 study file", "c1-low",
              "c2-low", "PQ baseline")


def _cells(line: str) -> list[str]:
    """A Markdown table row's cells (``|`` escaped as ``\\|`` stays inside a cell)."""
    assert line.startswith("|") and line.endswith("|"), line
    return re.split(r"(?<!\\)\|", line[1:-1])


def test_metrics_md_is_a_table_when_a_value_holds_a_pipe(tmp_path):
    runs = [{"id": "f-a", "controller": "a", "fault": "bus 6 | 1-1.1 s",
             "speed_peak_dev_pu": 0.01},
            {"id": "f-b", "controller": "b", "fault": "x|y", "speed_peak_dev_pu": 0.02}]
    _, md = write_tables(runs, tmp_path, title="my study")
    lines = md.read_text(encoding="utf-8").splitlines()
    assert lines[0] == "# my study — metrics"
    table = [ln for ln in lines if ln.startswith("|")]
    n = len(_cells(table[0]))
    assert all(len(_cells(ln)) == n for ln in table)          # every row: the header's count
    assert "bus 6 \\| 1-1.1 s" in table[2]


def test_all_empty_columns_are_dropped(tmp_path):
    runs = [{"id": "f-a", "controller": "a", "speed_peak_dev_pu": 0.01,
             "vdc_peak_dev_pu": float("nan")},
            {"id": "f-b", "controller": "b", "speed_peak_dev_pu": 0.02}]
    csv, md = write_tables(runs, tmp_path)
    text = md.read_text(encoding="utf-8")
    assert "speed peak dev. [pu]" in text
    assert "Vdc" not in text                       # no run has a dc link: no Vdc column
    assert "vdc_peak_dev_pu" in csv.read_text(encoding="utf-8").splitlines()[0]   # csv: all


def test_who_did_best_names_a_tie_inside_the_uncertainty():
    runs = [{"id": "f-hji", "controller": "hji", "speed_itae": 1.000},
            {"id": "f-lqr", "controller": "lqr", "speed_itae": 1.004},
            {"id": "f-none", "controller": "none", "speed_itae": 1.5}]
    names = {"hji": "HJI", "lqr": "LQR", "none": "none"}
    tied = who_did_best(runs, {"speed_itae": 0.01}, names)
    assert [(r["scenario"], r["metric"]) for r in tied] == [("f", "speed_itae")]
    assert tied[0]["tie"] and tied[0]["best"] == "HJI = LQR" and "none 1.5" in tied[0]["others"]
    # a difference larger than the uncertainty is a win
    won = who_did_best(runs, {"speed_itae": 0.001}, names)[0]
    assert not won["tie"] and won["best"] == "HJI"
    # higher is never better for an error: the order follows BETTER
    runs[0]["speed_itae"] = 2.0
    assert who_did_best(runs, {}, names)[0]["best"] == "LQR"


def tiny_ieee9():
    """The IEEE 9-bus example cut to one 0.5-s scenario (a 50-ms fault at 0.1 s), PSS only."""
    st = load_study("ieee9-sg-upqc")
    d = copy.deepcopy(st.data)
    sc = d["scenarios"][0]
    sc.update(controllers=["pss-only", "none"], t_end=0.5, quick={"t_end": 0.5},
              events=[dict(sc["events"][0], t_on=0.1, t_off=0.15)], bypass=[[0.1, 0.15]])
    d["scenarios"] = [sc]
    return study_from_dict(d, source=st.source, base_dir=st.base_dir)


def test_report_of_a_non_paper_study(tmp_path, monkeypatch):
    from weakgrid.study import engine, figures

    made = []
    real = figures.new_figure

    def spy(*a, **k):
        fig, axes = real(*a, **k)
        made.append(fig)
        return fig, axes

    monkeypatch.setattr(figures, "new_figure", spy)
    engine.run_studies([tiny_ieee9()], tmp_path, quick=True, progress=False, workers=0)
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    proto = page[page.index("<h2>Protocol</h2>"):page.index("<h2>Design models")]
    for text in PAPER_TEXT:
        assert text not in proto, text
    assert "three-phase fault at bus 6 at t = 0.1 s for 50 ms" in proto
    assert "PSS only (UPQC idle)" in proto and "network case9" in proto
    assert "<h2>Who did best</h2>" in page
    metrics = page[page.index("<h2>Metrics</h2>"):]
    assert "Vdc" not in metrics                           # an SG study: no dc link
    # tables scroll sideways rather than breaking cells one character per line
    assert ".scroll{overflow-x:auto" in page and "<div class='scroll'><table>" in page
    assert not re.search(r"td,th\{[^}]*overflow-wrap:anywhere", page)
    labels = [ax.get_ylabel() for fig in made for ax in fig.axes]
    assert "speed of G3 [pu]" in labels and "SG speed [pu]" not in labels
    title = made[0]._suptitle.get_text()
    assert "bus 6" in title and "0.1 s" in title
    legends = [t.get_text() for ax in made[0].axes if ax.get_legend()
               for t in ax.get_legend().get_texts()]
    assert "PSS only (UPQC idle)" in legends


def test_a_load_step_is_described_in_the_units_of_the_study_file():
    # a study file's dP, dQ are MW and Mvar (weakgrid.sim.events.LoadStep), not pu
    from weakgrid.study.protocol import describe_event

    text = describe_event({"kind": "load_step", "bus": 3, "t": 1.0, "dP": 20.0, "dQ": 5.0})
    assert "ΔP = 20 MW" in text and "ΔQ = 5 Mvar" in text
