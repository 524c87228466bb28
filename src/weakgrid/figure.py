"""Figures drawn without touching the host's matplotlib state (layer-neutral).

:func:`new_figure` makes a :class:`matplotlib.figure.Figure` on its own Agg canvas: no pyplot
figure manager, no backend switch, no ``rcParams`` change — a notebook's inline backend or a
GUI session importing weakgrid stays as it was. Such a figure is saved with
:func:`weakgrid.fileio.savefig_atomic` (which keeps SVG text as text for that one call) and
is freed like any Python object; in a notebook ``display(fig)`` shows it.
"""

from __future__ import annotations

__all__ = ["new_figure"]


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize=(7.0, 4.0), layout=None, **subplot_kw):
    """A figure on a private Agg canvas and its axes, as ``pyplot.subplots`` returns them.

    Parameters
    ----------
    nrows, ncols : int
        Grid of axes.
    figsize : (float, float)
        Size [inch].
    layout : str, optional
        Matplotlib layout engine (``"constrained"``, ``"tight"``).
    **subplot_kw
        Passed to :meth:`matplotlib.figure.Figure.subplots` (``sharex``, ``squeeze``, ...).

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : Axes or ndarray of Axes
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout=layout)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **subplot_kw)
