"""Maps of a swept quantity: one panel per facet, a labelled cell per run, the setting outlined."""

import itertools

import numpy as np
import pandas as pd
from matplotlib.patches import Rectangle

from weakgrid.study.maps import plot_map


def _table():
    rows = []
    for load, r, d in itertools.product(["high", "low"], [0.1, 0.15, 0.3], [0.02, 0.05]):
        v = r / d
        rows.append({"load": load, "rating": r, "dur": d, "v": v,
                     "verdict": "holds" if v > 4 else "not"})
    df = pd.DataFrame(rows)
    df.loc[0, "v"] = np.nan
    df.loc[0, "verdict"] = "failed"
    return df


def test_map_cells_marks_and_setting(tmp_path):
    fig = plot_map(_table(), "rating", "dur", "v", verdict="verdict", facet="load",
                   mark=(0.15, 0.05), path=tmp_path / "m.png")
    panels = [ax for ax in fig.axes if ax.get_title().startswith("load")]
    assert [ax.get_title() for ax in panels] == ["load = high", "load = low"]
    texts = [t.get_text() for t in panels[0].texts]
    assert len(texts) == 6
    assert "–\n!" in texts                                   # failed run: no value, marked
    assert any(t.startswith("15\n") for t in texts)          # 0.3 / 0.02 = 15, holds
    assert f"{0.15 / 0.05:.3g}\n✗" in texts
    rects = [p for p in panels[1].patches if isinstance(p, Rectangle) and not p.get_fill()]
    assert len(rects) == 1 and rects[0].get_xy() == (0.5, 0.5)  # x index 1, y index 1
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_colour_bar_label_fits_the_figure(tmp_path):
    """A long quantity label (as the studies' maps have) is wrapped along the bar, not clipped."""
    label = "HJI-bounded / (29) applied control cost Σu'Ru·T of the series voltage, per run"
    fig = plot_map(_table(), "rating", "dur", "v", verdict="verdict", facet="load",
                   value_label=label, path=tmp_path / "m.png")
    fig.canvas.draw()
    box = fig.bbox
    lab = [ax.yaxis.label for ax in fig.axes if ax.yaxis.label.get_text().replace("\n", " ")
           == label]
    assert len(lab) == 1
    ext = lab[0].get_window_extent()
    assert box.y0 <= ext.y0 and ext.y1 <= box.y1 and ext.x1 <= box.x1


def test_cell_without_value_says_why_not_a_verdict(tmp_path):
    df = _table()
    df["note"] = ""
    df.loc[3, ["v", "verdict", "note"]] = [np.nan, None, "hji: no settling"]
    fig = plot_map(df, "rating", "dur", "v", verdict="verdict", note="note", facet="load",
                   path=tmp_path / "m.png")
    panel = [ax for ax in fig.axes if ax.get_title() == "load = high"][0]
    texts = [t.get_text() for t in panel.texts]
    assert "–\nhji: no\nsettling" in texts or "–\nhji: no settling" in texts   # why; no ✓/✗
    assert not any(t.startswith("–") and ("✗" in t or "✓" in t) for t in texts)


def test_a_tie_prints_its_uncertainty_and_the_legend_says_what_counts(tmp_path):
    df = _table()
    df["u"] = np.nan
    df.loc[1, "verdict"] = "tie"
    df.loc[1, "u"] = 0.031
    fig = plot_map(df, "rating", "dur", "v", verdict="verdict", uncertainty="u", facet="load")
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any(t.endswith("= ±3.1%") for t in texts)
    legend = fig._suptitle.get_text().replace("\n", " ")
    assert "within the measured uncertainty" in legend and "failure of ours" in legend
