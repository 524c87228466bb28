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
