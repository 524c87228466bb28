"""Maps of a swept quantity over two study fields (e.g. UPQC rating × fault duration).

A map is drawn from the result table of a sweep (:func:`weakgrid.sweep.run_sweep`):
one panel per value of a facet field (e.g. the load level), the two swept fields
on the axes as evenly spaced categories (their values as tick labels), each
cell coloured by the quantity and labelled with its value, and with the claim's
verdict in that cell as a mark: ``✓`` holds, ``✗`` does not (also: the controller failed where
its baseline finished), ``=`` tie within the measured uncertainty (its ± printed), ``!`` a run
failed with nothing to compare (both runs, or the only one), ``n/c`` on a grey hatched cell
no comparison: both runs not stable (:mod:`weakgrid.study.sweep_maps`). A cell whose device
power went beyond the UPQC's rating or the line's power carries a marker in its corner
(:data:`DEVICE_MARK`). A cell without a value shows ``–`` and, instead
of a verdict, why (a ``note``: a run failed, no settling, …). The setting the paper (or the
shipped study) uses is outlined.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["plot_map", "VERDICT_MARKS", "DEVICE_MARK"]

VERDICT_MARKS = {"holds": "✓", "not": "✗", "tie": "=", "failed": "!", "no comparison": "n/c",
                 None: ""}
#: hatching of a cell whose two runs are both not stable (verdict "no comparison")
NO_COMPARISON_HATCH = "///"
#: corner marker of a cell whose UPQC power exceeded its rating ("rating") or the line's
#: power ("line"), and its legend
DEVICE_MARK = {"rating": "S>", "line": "S>L", "rating+line": "S>L"}
DEVICE_LEGEND = ("corner S>: the UPQC's peak device power above its rating (s_rating), "
                 "S>L: above the line's power")


def _fmt(v):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    a = abs(v)
    if a != 0 and (a < 1e-2 or a >= 1e4):
        return f"{v:.1e}"
    return f"{v:.3g}"


def plot_map(table, x: str, y: str, value: str, *, verdict: str | None = None,
             note: str | None = None, uncertainty: str | None = None, facet: str | None = None, mark=None, title: str = "", value_label: str = "",
             x_label: str = "", y_label: str = "", cmap: str = "RdBu_r", center=None,
             mark_label: str = "the paper's setting", path=None, device: str | None = None):
    """Draw (and optionally save) a map of ``value`` over fields ``x`` and ``y``.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per run; columns ``x``, ``y``, ``value`` (and ``verdict``, ``facet``).
        Several rows on one cell are averaged (the verdict of the first is shown).
    x, y : str
        Columns of the swept fields (e.g. ``"upqc.rating"``, ``"fault.duration"``).
    value : str
        Column of the measured quantity (e.g. the HJI/(29) cost ratio).
    verdict : str, optional
        Column holding ``"holds"``, ``"not"``, ``"tie"`` or ``"failed"`` per cell.
    uncertainty : str, optional
        Column of the relative uncertainty of a cell's comparison, printed (``±x %``) under
        a tie's mark.
    note : str, optional
        Column of short texts written in the cell under its value (why a cell has no
        value: a failed run, no settling, …).
    facet : str, optional
        Column whose values get one panel each (e.g. ``"load"``).
    mark : tuple, optional
        ``(x_value, y_value)`` of the paper's setting, outlined in every panel
        (described in the legend by ``mark_label``).
    center : float, optional
        Value at the middle of the colour scale (e.g. 1 for a ratio, 0 for a
        difference); default: no centring.
    path : str or Path, optional
        Where to save the figure (PNG or SVG, atomically).
    device : str, optional
        Column of ``"rating"``, ``"line"``, ``"rating+line"`` or ``""`` per cell: where the
        UPQC's peak power exceeded its rating or the line's power, a corner marker
        (:data:`DEVICE_MARK`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.patches import Rectangle

    from ..figure import new_figure

    facets = [None] if facet is None else list(dict.fromkeys(table[facet].tolist()))
    xs = sorted(dict.fromkeys(table[x].tolist()))
    ys = sorted(dict.fromkeys(table[y].tolist()))
    vals = table[value].astype(float).to_numpy()
    finite = vals[np.isfinite(vals)]
    vmin, vmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if vmin == vmax:
        vmin, vmax = vmin - 0.5, vmax + 0.5
    norm = None
    if center is not None and vmin < center < vmax:
        norm = TwoSlopeNorm(vcenter=center, vmin=vmin, vmax=vmax)
    import textwrap

    fig_w = 1.2 + 0.9 * len(xs) * len(facets) + 1.2
    legend = ""
    if mark is not None:
        legend += f"outlined: {mark_label}"
    if verdict is not None:
        legend += ("; " if legend else "") + ("✓ holds (a baseline's failure or instability "
                                              "named)  ✗ does not (a failure of ours, or our "
                                              "instability, where the baseline is stable "
                                              "counts: named)  = tie: the difference "
                                              "is within the measured uncertainty ± (step "
                                              "halving + the metric's definition)  ! a run "
                                              "failed, nothing to compare  n/c (grey, "
                                              "hatched) both runs unstable: no comparison  "
                                              "– no value (why, in the cell)")
    if device is not None and device in table and any(
            DEVICE_MARK.get(str(v or ""), "") for v in table[device]):
        legend += ("; " if legend else "") + DEVICE_LEGEND
    width = max(40, int(fig_w * 13))       # characters that fit at fontsize 9
    heading = "\n".join(textwrap.fill(t, width) for t in (title, legend) if t)
    # the heading's lines get their own height (else they squash a one-row map)
    n_lines = heading.count("\n") + 1 if heading else 0
    fig, axes = new_figure(1, len(facets), figsize=(fig_w, 1.4 + 0.55 * len(ys)
                                                    + 0.17 * n_lines),
                           squeeze=False, layout="constrained")
    im = None
    for ax, fv in zip(axes[0], facets):
        sub = table if fv is None else table[table[facet] == fv]
        Z = np.full((len(ys), len(xs)), np.nan)
        V = [["" for _ in xs] for _ in ys]
        N = [["" for _ in xs] for _ in ys]
        D = {}
        NC = []
        for (xv, yv), grp in sub.groupby([x, y], sort=False):
            i, j = ys.index(yv), xs.index(xv)
            Z[i, j] = float(np.nanmean(grp[value].astype(float))) if \
                np.isfinite(grp[value].astype(float)).any() else np.nan
            if verdict is not None:
                v0 = grp[verdict].iloc[0]
                if v0 == "no comparison":
                    NC.append((i, j))
                V[i][j] = VERDICT_MARKS.get(None if v0 is None or v0 != v0 else v0, "?")
                u0 = grp[uncertainty].iloc[0] if uncertainty is not None and \
                    uncertainty in grp else None
                if v0 == "tie" and isinstance(u0, float) and math.isfinite(u0):
                    V[i][j] += f" ±{u0 * 100:.2g}%"
            if note is not None and note in grp and isinstance(grp[note].iloc[0], str):
                N[i][j] = grp[note].iloc[0]
            if device is not None and device in grp:
                D[(i, j)] = DEVICE_MARK.get(str(grp[device].iloc[0] or ""), "")
        im = ax.pcolormesh(np.arange(len(xs) + 1) - 0.5, np.arange(len(ys) + 1) - 0.5,
                           np.ma.masked_invalid(Z), cmap=cmap, norm=norm,
                           vmin=None if norm else vmin, vmax=None if norm else vmax,
                           shading="flat", edgecolors="white", linewidth=0.5)
        for i in range(len(ys)):
            for j in range(len(xs)):
                txt = _fmt(Z[i, j]) + (f"\n{V[i][j]}" if V[i][j] else "")
                if N[i][j] and not np.isfinite(Z[i, j]):   # why there is no value
                    import textwrap

                    txt += "\n" + "\n".join(textwrap.wrap(N[i][j], 13,
                                                           break_on_hyphens=False)[:3])
                dark = False
                if np.isfinite(Z[i, j]):
                    r, g, b, _ = im.cmap(im.norm(Z[i, j]))
                    dark = 0.299 * r + 0.587 * g + 0.114 * b < 0.5
                ax.text(j, i, txt, ha="center", va="center",
                        fontsize=8 if txt.count("\n") < 2 else 6,
                        color="white" if dark else "black")
        for i, j in NC:
            ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, facecolor="0.85",
                                   hatch=NO_COMPARISON_HATCH, edgecolor="0.55", lw=0,
                                   zorder=1.5))
        for (i, j), dm in D.items():
            if dm:
                ax.text(j + 0.45, i + 0.42, dm, ha="right", va="top", fontsize=6,
                        color="black", bbox=dict(boxstyle="round,pad=0.1", fc="orange",
                                                 ec="none", alpha=0.9))
        if mark is not None and mark[0] in xs and mark[1] in ys:
            j, i = xs.index(mark[0]), ys.index(mark[1])
            ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.5,
                                       edgecolor="black"))
        ax.set_xticks(range(len(xs)), [_fmt(v) if isinstance(v, float) else str(v) for v in xs])
        ax.set_yticks(range(len(ys)), [_fmt(v) if isinstance(v, float) else str(v) for v in ys])
        ax.set_xlabel(x_label or x)
        ax.set_ylabel(y_label or y)
        if fv is not None:
            ax.set_title(f"{facet} = {fv}", fontsize=10)
    cb = fig.colorbar(im, ax=axes[0].tolist(), shrink=0.9)
    # the label runs along the bar: wrap it to the bar's length (else it is clipped)
    import textwrap

    bar_in = 0.9 * (fig.get_figheight() - 1.0)            # the bar's length, roughly [in]
    per_line = max(12, int(bar_in * 72 / (0.6 * 9)))      # characters of 9-pt text in it
    cb.set_label("\n".join(textwrap.wrap(value_label or value, per_line)), fontsize=9)
    if heading:
        fig.suptitle(heading, fontsize=9)
    if path is not None:
        from ..fileio import savefig_atomic

        savefig_atomic(fig, path, dpi=120)
    return fig
