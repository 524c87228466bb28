"""Maps of a study's sweep: per claim, the measured quantity and its verdict per cell.

Each ``[[sweep.maps]]`` entry of a study names a claim and how to measure it on the sweep's
table (a row per run; :mod:`weakgrid.study.sweep`)::

    claim, title, label        the claim's id, the map's title and colour-bar label
    id                         the map's own id when a claim has several maps [claim]
    kind = "ratio"             metric of controller a / of b; holds if ≤ holds_below, a tie
                               if a is within the runs' uncertainty of holds_below·b
                               (stability first, below: only two stable runs are compared)
    kind = "value"             metric of controller a; holds if within holds_within = [lo, hi]
                               (no rule: the map only shows the quantity)
    kind = "wins"              a smaller than b on every one of ``metrics`` (stability first)
    kind = "stable"            a's speed verdict "stable" while b's is not (or b failed)
    x, y, facet                table columns (default: the sweep's first three axes)

Ties: a comparison (ratio, wins) whose difference is smaller than the runs' measured
uncertainty is a tie, not a win — the one rule of :mod:`weakgrid.study.ties`, as in the claim
table. A run's uncertainty is its step-halving part plus its metric's sensitivity to its own
definition (``<metric>_def_unc``, recorded with every run: the settling band 1.5 %/3 %, …).
The step-halving part is measured by running the ``[sweep.dt_check]`` points again at half the
integration step: ``|m(T) − m(T/2)|`` relative to ``|m(T)|``, per load level and fault severity
(the row of the map), applied to every cell of that row (a row without a check takes the
largest measured at its load level).

Stability first (ratio, wins; as the claim table, with its one definition of a stable run,
:func:`weakgrid.study.stability.run_instability`: finished, SG speed and dc link neither
unstable — growing or running away from the set-point — nor undamped): only two stable runs
are compared. Where controller a is not stable and the baseline b is, the cell is a loss,
``not``, with the note "a failed: cause" or "a not stable: dc link unstable"; where only b is
not stable, ``holds`` without a value ("b failed: cause", …); where both are not stable, the
cell is ``no comparison`` (its own mark and hatching; the numbers of two diverged runs say
nothing about the claim), except where both failed (or a ``value`` map's run failed): marked
failed, its detail naming the cause (voltage collapse, loss of synchronism, …;
:mod:`weakgrid.study.failure`). A not stable run's metric gives its cell no value. Any other
cell without a value gets no verdict but a ``note`` saying why: the metric is undefined for a
run that finished (e.g. the speed did not settle inside the run: no settling time).
"""

from __future__ import annotations

import math

import pandas as pd

from ..game.errors import ParameterError
from .failure import failure_kind
from .maps import plot_map
from .stability import run_failed, run_instability
from .ties import compare, run_uncertainty

__all__ = ["map_cells", "draw_maps", "map_summaries", "MAP_KINDS"]

MAP_KINDS = ("ratio", "value", "wins", "stable")


def _num(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.nan
    return v


def _axes_of(spec, axes):
    ax = list(axes)
    x = spec.get("x", ax[0] if ax else None)
    y = spec.get("y", ax[1] if len(ax) > 1 else None)
    facet = spec.get("facet", ax[2] if len(ax) > 2 else None)
    return x, y, facet


def _rel_uncertainty(half, full, match, row_keys, metric, ctl):
    """Relative ``|m(T) − m(T/2)| / |m(T)|`` of ``metric`` for controller ``ctl``, the largest
    per map row (``row_keys``); ``match`` are the columns that identify a run's point."""
    out = {}
    if half.empty or metric not in full:
        return out
    on = [c for c in match if c in full and c in half]
    merged = full[full["controller"] == ctl].merge(half[half["controller"] == ctl], on=on,
                                                   suffixes=("", "_half"))
    for _, r in merged.iterrows():
        a, b = _num(r.get(metric)), _num(r.get(f"{metric}_half"))
        if math.isfinite(a) and math.isfinite(b) and a != 0:
            key = tuple(r[k] for k in row_keys if k is not None)
            out[key] = max(out.get(key, 0.0), abs(a - b) / abs(a))
    return out


def metric_uncertainty(table: pd.DataFrame, axes) -> dict:
    """metric → the largest relative ``|m(T) − m(T/2)| / |m(T)|`` over the half-step runs of
    ``table`` (a sweep's table; every controller and point with both runs); metrics without a
    half-step run are absent."""
    if "dt_factor" not in table or "controller" not in table:
        return {}
    full, half = table[table["dt_factor"] == 1.0], table[table["dt_factor"] != 1.0]
    if half.empty:
        return {}
    from .report import BETTER

    match = list(axes) + ["scenario", "controller"]
    out = {}
    for m in BETTER:
        for c in full["controller"].unique():
            by = _rel_uncertainty(half, full, match, [], m, c)
            if by:
                out[m] = max(out.get(m, 0.0), max(by.values()))
    return out


def _why_missing(metric, who) -> str:
    """Why ``metric`` has no value for the finished run(s) of ``who`` (short, for a cell)."""
    who = " & ".join(who)
    if metric.endswith("settling_s"):
        return f"{who}: no settling"
    return f"{who}: no {metric}"


#: The verdict of a cell where both runs are not stable (:func:`_stability_gate`).
NO_COMPARISON = "no comparison"


def _stability_gate(a, ra, b, rb, fa, fb):
    """Stability first, as the claim table (:func:`weakgrid.study.claims.stability_gate`; one
    definition of stable, :func:`weakgrid.study.stability.run_instability`): ``(verdict,
    value, note, detail)`` of a ratio/wins cell decided by its runs' stability, or None when
    both ran stable (compare their numbers).

    Both failed (or a failed without a baseline): ``failed``. Otherwise a (the claim's run)
    not stable — failed where b finished, or finished but unstable/undamped — is a loss,
    ``not`` ("a failed: voltage collapse", "a not stable: dc link unstable"); only b not
    stable: ``holds`` without a value ("b failed: …"); both not stable: ``no comparison``
    (the numbers of two diverged runs say nothing about the claim). A not stable run's
    metric gives the cell no value.
    """
    if fa and (rb is None or fb):
        return "failed", math.nan, f"{a} & {b} failed" if rb is not None else f"{a} failed", ""
    wa = run_instability(ra)
    wb = run_instability(rb) if rb is not None else ""
    full = {c: f"{c} failed: {r.get('failure', '')}" if run_failed(r) else f"{c} {w}"
            for c, w, r in ((a, wa, ra), (b, wb, rb)) if w}
    if wa and wb:
        return (NO_COMPARISON, math.nan, "both unstable: no comparison",
                "; ".join(full.values())[:160])
    if wa:
        return "not", math.nan, f"{a} {wa}", full[a][:120]
    if wb:
        return "holds", math.nan, f"{b} {wb}", full[b][:120]
    return None


def _unc(by_row, rk):
    """The row's measured uncertainty, else the largest measured in its facet (load level)."""
    if rk in by_row:
        return by_row[rk]
    same = [v for k, v in by_row.items() if k[1:] == rk[1:]]
    return max(same) if same else None


def map_cells(table: pd.DataFrame, spec: dict, axes) -> pd.DataFrame:
    """One row per map cell: the swept fields, ``value``, ``verdict`` (holds/not/tie/failed or
    None), ``uncertainty`` (relative, or NaN when not measured), a short ``detail`` and a
    ``note`` (why a cell has no value: which run failed, or which metric is undefined)."""
    kind = spec.get("kind")
    if kind not in MAP_KINDS:
        raise ParameterError(f"sweep.maps[{spec.get('claim')}].kind", kind,
                             f"choose one of {list(MAP_KINDS)}")
    x, y, facet = _axes_of(spec, axes)
    keys = [k for k in (x, y, facet) if k is not None]
    dtf = table["dt_factor"] if "dt_factor" in table else pd.Series(1.0, index=table.index)
    full, half = table[dtf == 1.0], table[dtf != 1.0]
    match = list(axes) + ["scenario", "controller"]
    row_keys = [y, facet]
    a, b = spec.get("a"), spec.get("b")
    metrics = spec.get("metrics") or [spec.get("metric")]
    unc = {(m, c): _rel_uncertainty(half, full, match, row_keys, m, c) for m in metrics
           for c in (a, b) if c}
    rows = []
    for cell, grp in full.groupby(keys, sort=False):
        cell = cell if isinstance(cell, tuple) else (cell,)
        rec = dict(zip(keys, cell))
        rk = tuple(rec[k] for k in row_keys if k is not None)
        ra = grp[grp["controller"] == a]
        rb = grp[grp["controller"] == b] if b else None
        if ra.empty:
            continue
        ra = ra.iloc[0]
        rb = rb.iloc[0] if rb is not None and not rb.empty else None
        fa = ra["status"] != "ok"
        fb = rb is not None and rb["status"] != "ok"
        val, verdict, u, detail, note, gate = math.nan, None, math.nan, "", "", None
        failed = [c for c, f in ((a, fa), (b, fb)) if f]
        if failed:
            note = " & ".join(failed) + " failed"
        if kind == "value":
            val = _num(ra.get(spec["metric"]))
            if fa:
                verdict = "failed"
            elif not math.isfinite(val):
                note = _why_missing(spec["metric"], [a])     # no value: no verdict
            elif "holds_within" in spec:
                lo, hi = spec["holds_within"]
                verdict = "holds" if lo <= val <= hi else "not"
        elif kind == "ratio":
            m = spec["metric"]
            va, vb = _num(ra.get(m)), _num(rb.get(m)) if rb is not None else math.nan
            val = va / vb if vb else math.nan
            ua = run_uncertainty(ra, m, _unc(unc[(m, a)], rk))
            ub = run_uncertainty(rb, m, _unc(unc[(m, b)], rk)) if rb is not None else 0.0
            gate = _stability_gate(a, ra, b, rb, fa, fb)
            if gate:
                verdict, val, note, detail = gate
            elif not math.isfinite(val):      # a metric undefined for a finished run
                note = _why_missing(m, [c for c, v in ((a, va), (b, vb))
                                        if not math.isfinite(v)] or [f"{a}/{b}"])
            else:
                # judged against the claim's threshold θ, not against a ratio of 1: a
                # against θ·b, each with its own uncertainty (tol in a's units; u in the
                # ratio's)
                theta = float(spec.get("holds_below", 1.0))
                who, tol = compare(va, theta * vb, ua, ub)
                u = tol / abs(vb) if tol > 0 else math.nan
                verdict = {"tie": "tie", "a": "holds", "b": "not"}[who]
        elif kind == "wins":
            m0 = metrics[0]
            va0 = _num(ra.get(m0))
            vb0 = _num(rb.get(m0)) if rb is not None else math.nan
            val = va0 / vb0 if vb0 and not fb else math.nan
            gate = _stability_gate(a, ra, b, rb, fa, fb)
            if gate:
                verdict, val, note, detail = gate
            else:
                res, us = [], []
                for m in metrics:
                    va, vb = _num(ra.get(m)), _num(rb.get(m))
                    who, tol = compare(va, vb,
                                       run_uncertainty(ra, m, _unc(unc[(m, a)], rk)),
                                       run_uncertainty(rb, m, _unc(unc[(m, b)], rk)))
                    if who == "n/a":
                        res.append("not")
                    else:
                        res.append({"tie": "tie", "a": "holds", "b": "not"}[who])
                        if vb and tol > 0:
                            us.append(tol / abs(vb))
                    detail += f"{m}: {va:.3g} vs {vb:.3g}; "
                verdict = "not" if "not" in res else ("tie" if "tie" in res else "holds")
                if us:
                    u = max(us)
        elif kind == "stable":
            val = _num(ra.get(spec.get("metric", "speed_settling_s")))
            sa = "unstable" if fa else ra.get("speed_verdict")
            sb = "unstable" if fb else (rb.get("speed_verdict") if rb is not None else None)
            detail = f"{a}: {sa}, {b}: {sb}"
            verdict = "holds" if sa == "stable" and sb in ("unstable", "undamped") else "not"
            if not fa and not math.isfinite(val):   # the verdict is on stability, not on val
                note = _why_missing(spec.get("metric", "speed_settling_s"), [a])
        if kind == "wins" and not gate and not math.isfinite(val):
            verdict = None      # no value: no verdict, the reason instead
            note = _why_missing(metrics[0], [c for c, v in ((a, va0), (b, vb0))
                                             if not math.isfinite(v)] or [f"{a}/{b}"])
        if verdict == "failed":     # a failed run's metrics stop at the failure: no value
            val = math.nan
            detail = "; ".join(f"{c} {failure_kind(r.get('failure'))}" for c, r, f in
                               ((a, ra, fa), (b, rb, fb)) if f)
        rec.update(value=val, verdict=verdict, uncertainty=u, detail=detail, note=note)
        rows.append(rec)
    return pd.DataFrame(rows)


def device_power_flags(cells: pd.DataFrame, table: pd.DataFrame, spec: dict,
                       axes) -> pd.DataFrame:
    """``cells`` (from :func:`map_cells`) with a column ``device_over``: ``"rating"`` where a
    run of the cell (controller ``a`` or ``b``, full step) drew a peak converter power above
    the UPQC's ``s_rating`` (metric ``device_over_rating``), ``"line"`` where above the line's
    apparent power (``device_over_line``), ``"rating+line"`` for both, ``""`` otherwise (also
    when the sweep's runs carry no such metric: a UPQC without ``s_rating``, an old table)."""
    if cells.empty:
        return cells.assign(device_over=pd.Series(dtype=str))
    x, y, facet = _axes_of(spec, axes)
    keys = [k for k in (x, y, facet) if k is not None]
    dtf = table["dt_factor"] if "dt_factor" in table else pd.Series(1.0, index=table.index)
    who = [c for c in (spec.get("a"), spec.get("b")) if c]
    runs = table[(dtf == 1.0) & table["controller"].isin(who)]
    flags = {}
    for cell, grp in runs.groupby(keys, sort=False):
        cell = cell if isinstance(cell, tuple) else (cell,)
        over = [w for w, col in (("rating", "device_over_rating"), ("line", "device_over_line"))
                if col in grp and grp[col].fillna(False).astype(bool).any()]
        flags[cell] = "+".join(over)
    out = cells.copy()
    out["device_over"] = [flags.get(tuple(r[k] for k in keys), "") for _, r in out.iterrows()]
    return out


def _short(path):
    names = {"upqc.rating": "UPQC rating [pu]", "controller": "controller"}
    if path in names:
        return names[path]
    tail = path.split(".")[-1]
    return {"t_off": "fault cleared at t_off [s]", "xf": "fault reactance xf [pu]",
            "load": "load level", "duration": "fault duration [s]"}.get(tail, path)


def colour_centre(spec: dict):
    """Where a map's diverging colour scale turns: where its verdict turns — a ratio map at
    its claim's ``holds_below``, a wins map at 1; ``None`` (a sequential scale) otherwise."""
    return {"ratio": float(spec.get("holds_below", 1.0)), "wins": 1.0}.get(spec["kind"])


def draw_maps(study, table, folder, quick=False) -> list[dict]:
    """Draw every ``[[sweep.maps]]`` of ``study`` from its sweep ``table`` into ``folder``
    (PNG); returns per map: spec, cells (DataFrame), path, mark."""
    from pathlib import Path

    from .studyfile import get_path
    from .sweep import _axes

    sw = study.data["sweep"]
    axes = list(_axes(sw, quick))
    out = []
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for spec in sw.get("maps", []):
        cells = device_power_flags(map_cells(table, spec, axes), table, spec, axes)
        x, y, facet = _axes_of(spec, axes)
        mark = (get_path(study.data, x), get_path(study.data, y)) if x and y else None
        path = folder / f"map-{study.name}-{spec.get('id', spec['claim'])}.png"
        if cells.empty:
            out.append({"spec": spec, "cells": cells, "path": None, "mark": mark,
                        "axes": (x, y, facet)})
            continue
        center = colour_centre(spec)
        fshort = facet.split(".")[-1] if facet else None
        shown = cells.rename(columns={facet: fshort}) if facet else cells
        fig = plot_map(shown, x, y, "value", verdict="verdict", note="note", facet=fshort,
                       uncertainty="uncertainty",
                       mark=mark, device="device_over",
                       title=f"{spec['claim']}: {spec.get('title', '')}",
                       value_label=spec.get("label", spec.get("metric", "")),
                       x_label=_short(x), y_label=_short(y),
                       cmap="RdBu_r" if center else "viridis", center=center,
                       mark_label="the shipped (paper's) setting", path=path)
        del fig
        out.append({"spec": spec, "cells": cells, "path": path, "mark": mark,
                    "axes": (x, y, facet)})
    return out


def _fmtv(v):
    return "–" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.3g}"


def map_summaries(maps) -> list[dict]:
    """Per map: the verdict at the shipped setting (per facet value) and the region where the
    claim holds, in words with numbers."""
    out = []
    for m in maps:
        spec, cells, mark = m["spec"], m["cells"], m["mark"]
        x, y, facet = m["axes"]
        if cells.empty:
            out.append({"claim": spec["claim"], "id": spec.get("id", spec["claim"]),
                        "title": spec.get("title", ""), "at_setting": "no runs", "region": "", "n_holds": 0, "n_cells": 0})
            continue
        at, region = [], []
        facets = list(dict.fromkeys(cells[facet])) if facet else [None]
        for fv in facets:
            sub = cells if fv is None else cells[cells[facet] == fv]
            pre = "" if fv is None else f"{fv}: "
            hit = sub[(sub[x] == mark[0]) & (sub[y] == mark[1])] if mark else sub.iloc[:0]
            if not hit.empty:
                r = hit.iloc[0]
                at.append(f"{pre}{_fmtv(r['value'])} ({r['verdict'] or 'no rule'})")
            if sub["verdict"].isna().all():
                continue
            parts = []
            for yv, row in sub.groupby(y, sort=True):
                hr = row[row["verdict"] == "holds"]
                ok = hr[x].tolist()
                why = (hr["note"].fillna("").tolist() if "note" in hr else [""] * len(hr))
                ties = row[row["verdict"] == "tie"][x].tolist()
                fails = row[row["verdict"] == "failed"][x].tolist()
                txt = f"{_short(y).split(' [')[0]} {yv:g}: " if isinstance(yv, float) else \
                    f"{yv}: "
                txt += ("holds at " + ", ".join(f"{v:g}" + (f" ({w})" if w else "")
                                                for v, w in zip(ok, why))) if ok else "holds nowhere"
                if ties:
                    tr = row[row["verdict"] == "tie"]
                    txt += "; tie at " + ", ".join(
                        f"{v:g}" + (f" (±{u * 100:.2g} %)" if isinstance(u, float) and math.isfinite(u)
                                    else "") for v, u in zip(ties, tr["uncertainty"]))
                lost = row[(row["verdict"] == "not") & row["note"].fillna("").str.contains(
                    " failed:| not stable:")] if "note" in row else row.iloc[:0]
                if not lost.empty:
                    txt += "; not at " + ", ".join(f"{v:g} ({n})" for v, n in
                                                   zip(lost[x], lost["note"]))
                nc = row[row["verdict"] == NO_COMPARISON]
                if not nc.empty:
                    txt += "; no comparison (both runs unstable) at " + ", ".join(
                        f"{v:g}" + (f" ({d})" if d else "") for v, d in
                        zip(nc[x], nc["detail"] if "detail" in nc else [""] * len(nc)))
                if fails:
                    fr = row[row["verdict"] == "failed"]
                    txt += "; a run failed at " + ", ".join(
                        f"{v:g}" + (f" ({d})" if d else "") for v, d in
                        zip(fr[x], fr["detail"] if "detail" in fr else [""] * len(fr)))
                if "note" in row:
                    none = row[row["verdict"].isna() & (row["note"].fillna("") != "")]
                    for n, grp in none.groupby("note", sort=False):
                        txt += "; no value at " + ", ".join(
                            f"{v:g}" if isinstance(v, float) else str(v) for v in grp[x]) \
                            + f" ({n})"
                parts.append(txt)
            region.append(pre + "; ".join(parts))
        nh = int((cells["verdict"] == "holds").sum())
        out.append({"claim": spec["claim"], "id": spec.get("id", spec["claim"]),
                    "title": spec.get("title", ""),
                    "at_setting": "; ".join(at) or "the setting is not on the map",
                    "region": " | ".join(region) if region else "(quantity only, no rule)",
                    "n_holds": nh, "n_cells": int(cells["verdict"].notna().sum()),
                    "x": _short(x)})
    return out
