"""Plots of run files (``weakgrid plot``): chosen signals against time, one panel per quantity
(its kind and unit: speeds and voltages in pu are not drawn on one axis)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["plot_run"]


def plot_run(path, signals, output=None, *, si: bool = False, dpi: int = 110) -> Path:
    """Plot ``signals`` of the run file ``path`` against time and write the figure.

    Parameters
    ----------
    path : str or Path
        A run file (:func:`weakgrid.sim.runfile.write_run`).
    signals : list of str
        Signal names or ``fnmatch`` patterns (``"G*.omega"``); an unknown name raises
        :class:`~weakgrid.sim.errors.DataError` listing the closest names.
    output : str or Path, optional
        Figure file (``.png``, ``.svg``, ``.pdf``); default ``<run>.png`` beside the run.
    si : bool
        SI units (MW, kV, rad/s, deg, kA) instead of per unit.

    Returns
    -------
    Path
        The written figure (written atomically on a private Agg canvas: no window, no
        change to matplotlib's global state).
    """
    from ..fileio import savefig_atomic
    from ..figure import new_figure
    from .runfile import read_run

    path = Path(path)
    output = path.with_suffix(".png") if output is None else Path(output)
    # both rows of a breakpoint: a jump is drawn as the vertical step it is
    df = read_run(path, list(signals), si=si, pre_event=True)
    units, kinds = df.attrs["units"], df.attrs.get("kinds", {})
    cols = [c for c in df.columns if c not in ("t", "pre_event")]
    groups: dict[tuple[str, str], list[str]] = {}
    for c in cols:     # one panel per quantity: its kind (speed, voltage, ...) and unit
        groups.setdefault((kinds.get(c, ""), units.get(c, "")), []).append(c)
    n = len(groups)
    fig, axes = new_figure(n, 1, figsize=(9.0, 2.4 * n + 0.8), sharex=True, squeeze=False)
    t = df["t"].to_numpy()
    for ax, ((kind, unit), names) in zip(axes[:, 0], groups.items()):
        for c in names:
            ax.plot(t, df[c].to_numpy(), lw=1.1, label=c)
        ax.set_ylabel(f"{kind} [{unit}]" if kind and kind != "pu" else unit)
        ax.grid(True, alpha=0.3)
        # beside the axes: a legend inside would hide the curves
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0,
                  ncol=1 + len(names) // 12)
    axes[-1, 0].set_xlabel("time [s]")
    meta = df.attrs.get("meta", {})
    title = " · ".join(str(meta[k]) for k in ("study", "scenario", "controller") if meta.get(k))
    fig.suptitle(title or path.name, fontsize=10)
    if meta.get("failure"):
        fig.text(0.01, 0.005, f"simulation failed: {meta['failure']}"[:160], fontsize=7,
                 color="firebrick")
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    return savefig_atomic(fig, output, dpi=dpi)
