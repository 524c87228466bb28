"""`weakgrid modes --plot` shows the electromechanical range, not the fastest pole's scale."""

import numpy as np

import weakgrid.figure
from weakgrid.cli.main import main
from weakgrid.cli.modes import EM_HZ_MAX


def test_modes_plot_zooms_on_the_electromechanical_modes(tmp_path, capsys, monkeypatch):
    made = []
    real = weakgrid.figure.new_figure

    def spy(*a, **k):
        fig, ax = real(*a, **k)
        made.append(ax)
        return fig, ax

    monkeypatch.setattr(weakgrid.figure, "new_figure", spy)
    assert main(["modes", "ieee9-sg-upqc", "--plot", str(tmp_path / "m.png")]) == 0
    ax = made[0]
    pts = np.concatenate([c.get_offsets() for c in ax.collections if len(c.get_offsets())])
    lam = ax.collections[0].get_offsets()                 # the full grid's poles
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    # the imaginary axis spans the electromechanical range (and the design model's mode)
    top = max(2 * np.pi * EM_HZ_MAX, np.abs(pts[:, 1]).max() if len(pts) else 0.0)
    assert y1 <= 1.2 * top
    assert y1 < 2 * np.pi * 4.0                            # ≈ 3 Hz, not the fastest pole's
    # the real axis is set by those modes: the fast real poles are outside it, and counted
    assert x0 > lam[:, 0].min()
    em = lam[(np.abs(lam[:, 1]) > 1e-6) & (np.abs(lam[:, 1]) < y1)
             & (-lam[:, 0] / np.hypot(*lam.T) < 0.3)]
    assert len(em) >= 4 and (em[:, 0] > x0).all()          # G3's and the inter-area modes
    assert x0 > -10.0                                      # zoomed: the modes are ~ -1 1/s
    note = [t.get_text() for t in ax.texts]
    assert any("poles outside the view" in t for t in note)
