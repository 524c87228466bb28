"""Metrics table (CSV, Markdown) and the HTML report with a verdict per claim."""

from __future__ import annotations

import html
import math
from pathlib import Path

import pandas as pd

from ..fileio import write_text_atomic
from .failure import FAILED_CELLS_NOTE

__all__ = ["metrics_frame", "write_tables", "write_html", "sweep_html"]

COLUMNS = [
    ("id", "run"), ("load", "load"), ("upqc", "UPQC"), ("controller", "controller"),
    ("fault", "fault"), ("speed_peak_dev_pu", "speed peak dev. [pu]"),
    ("speed_backswing_pu", "speed backswing [pu]"),
    ("speed_settling_s", "speed settling (2 %) [s]"), ("speed_itae", "speed ITAE [pu·s²]"),
    ("speed_verdict", "speed verdict"), ("vdc_peak_dev_pu", "Vdc peak dev. [pu]"),
    ("vdc_backswing_pu", "Vdc backswing [pu]"), ("vdc_settling_s", "Vdc settling (2 %) [s]"), ("vdc_itae", "Vdc ITAE [pu·s²]"),
    ("control_cost", "control cost Σu'Ru·T [pu²·s]"),
    ("control_cost_demanded", "demanded Σu'Ru·T [pu²·s]"),
    ("running_cost_18", "running cost (18) [–]"), ("vu_peak_pu", "|Vu| peak [pu]"),
    ("vu_rms_pu", "|Vu| rms [pu]"), ("vu_rating_reached", "rating reached"),
    ("p_series_peak_mw", "P_series peak [MW]"),
    ("p_series_peak_pct_line", "P_series peak [% line]"),
    ("design_load", "controllers designed at (load)"),
    ("clip_fraction", "post-fault samples clipped by the rating [–]"),
    ("u_demanded_peak_pu", "demanded |u| peak [pu]"), ("u_applied_peak_pu", "applied |u| peak [pu]"),
    ("omega_reach", "reach of Ω (> 1: outside) [–]"), ("extrapolation", "extrapolation"),
    ("vdc_final_dev_pu", "Vdc at the end − Vc0 [pu]"), ("failed", "failed"),
    ("wall_s", "wall time [s]"),
]


# the sweep table's metrics (of those a run measures), when any run has them
SWEEP_METRICS = ("speed_peak_dev_pu", "speed_settling_s", "speed_verdict", "vdc_peak_dev_pu",
                 "vdc_settling_s", "control_cost", "vu_peak_pu", "u_demanded_peak_pu",
                 "clip_fraction", "omega_reach")


def sweep_html(entry: dict) -> str:
    """The report's section of a study's sweep: what it ran and one row per run (the swept
    fields, controller, status, the main metrics; the half-step runs of the numerical check
    left out), open when the study draws no map of it.

    ``entry``: ``study``, ``text`` (what the sweep runs), ``file`` (its Parquet table, every
    metric), ``frame`` (the sweep's table), ``axes`` (the swept paths), ``open``.
    """
    e = html.escape
    df = entry["frame"]
    if "dt_factor" in df:
        df = df[df["dt_factor"] == 1.0]
    labels = dict(COLUMNS)
    cols = [a for a in entry["axes"] if a in df]
    if "scenario" in df and df["scenario"].nunique() > 1:
        cols.append("scenario")
    cols += [c for c in ("controller", "status") if c in df]
    if "failure" in df and df["failure"].fillna("").astype(str).str.len().gt(0).any():
        cols.append("failure")
    cols += [m for m in SWEEP_METRICS if m in df and df[m].notna().any()]
    head = "".join(f"<th>{e(labels.get(c, c))}</th>" for c in cols)
    rows = "".join("<tr>" + "".join(f"<td>{e(_fmt(r[c]) if r[c] is not None else '')}</td>"
                                    for c in cols) + "</tr>" for r in df.to_dict("records"))
    n_fail = int((df["status"] != "ok").sum()) if "status" in df else 0
    return (f"<h2>Sweep of {e(entry['study'])}</h2><p>{e(entry['text'])}. Every metric of "
            f"every run: <code>{e(entry['file'])}</code>.</p><details"
            f"{' open' if entry.get('open') else ''}><summary>{len(df)} runs"
            f"{f', {n_fail} failed' if n_fail else ''}</summary><table><tr>{head}</tr>{rows}"
            "</table></details>")


def metrics_frame(metrics: list[dict]) -> pd.DataFrame:
    """A table of run metrics, one row per run, the report's columns first (missing ones NaN)."""
    df = pd.DataFrame(metrics)
    for key, _ in COLUMNS:
        if key not in df:
            df[key] = float("nan")
    return df[[k for k, _ in COLUMNS] + [c for c in df.columns if c not in dict(COLUMNS)]]


def _fmt(v):
    if isinstance(v, float):
        return "–" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def write_tables(metrics: list[dict], folder) -> tuple[Path, Path]:
    """``metrics.csv`` (every metric, machine-readable) and ``metrics.md``."""
    folder = Path(folder)
    df = metrics_frame(metrics)
    csv = folder / "metrics.csv"
    write_text_atomic(csv, df.to_csv(index=False))
    head = "| " + " | ".join(lbl for _, lbl in COLUMNS) + " |"
    sep = "|" + "---|" * len(COLUMNS)
    rows = ["| " + " | ".join(_fmt(r[k]) for k, _ in COLUMNS) + " |" for r in
            df.to_dict("records")]
    md = folder / "metrics.md"
    write_text_atomic(md, "\n".join(["# weakgrid reproduce — metrics", "", head, sep, *rows, ""]))
    return csv, md


_CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em}
table{border-collapse:collapse;font-size:0.85em;margin:1em 0;display:block;overflow-x:auto;
max-width:100%}td,th{border:1px solid #ccc;padding:3px 6px;vertical-align:top;
overflow-wrap:anywhere;max-width:40em}pre{white-space:pre-wrap;overflow-wrap:anywhere;
max-height:30em;overflow:auto}th{background:#f4f4f4}.reproduced{background:#d8f5d8}
.partly{background:#fff3c4}.not{background:#f8d0d0}.notrun{background:#eee}
img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}"""


def data_uri(path) -> str:
    """A file as a ``data:`` URI (figures embedded in the report: one self-contained file)."""
    import base64

    p = Path(path)
    mime = {".png": "image/png", ".svg": "image/svg+xml"}.get(p.suffix, "application/octet-stream")
    return f"data:{mime};base64," + base64.b64encode(p.read_bytes()).decode("ascii")


def write_html(path, *, claims, metrics, figures, designs, meta, notes=None, maps=None,
               protocol=None, sweeps=None) -> Path:
    """One self-contained HTML page (figures embedded as data URIs): claims with verdicts,
    maps of where they hold, the sweeps' runs (``sweeps``: see :func:`sweep_html`), the
    protocol, design models, figures, metrics."""
    e = html.escape
    title = meta.get("title", "study")
    parts = [f"<!doctype html><meta charset='utf-8'><title>weakgrid — {e(title)}</title>"
             f"<style>{_CSS}</style><h1>weakgrid — {e(title)}</h1>",
             f"<p>weakgrid {e(meta.get('version', ''))}, {e(meta.get('mode', ''))} run, "
             f"{meta.get('n_runs', 0)} simulations in {meta.get('wall_s', 0):.0f} s. "
             "Every number below was measured in this run; the rules that turn them into "
             "verdicts are stated beside them.</p>",
             ]
    with_maps = any(c.get("map_region") for c in claims)
    if claims:
        parts.append("<h2>Claims</h2><table><tr><th>claim</th><th>case</th><th>paper"
                     "</th><th>measured (shipped setting)</th><th>rule</th><th>verdict at the "
                     "shipped setting</th>" + ("<th>map: value at the shipped setting (HIGH-"
                                               "load design)</th><th>map: where it holds</th>"
                                               if with_maps else "") + "</tr>")
    for c in claims:
        cls = c["verdict"].replace(" ", "")
        parts.append(f"<tr><td>{e(c['id'])}</td><td>{e(c['case'])}</td><td>{e(c['paper'])}"
                     f"</td><td>{e(c['measured'] or '—')}</td><td>{e(c['rule'])}</td>"
                     f"<td class='{cls}'>{e(c['verdict'])}</td>" +
                     (f"<td>{e(c.get('map_setting') or '—')}</td>"
                      f"<td>{e(c.get('map_region') or 'not mapped')}</td>" if with_maps else "")
                     + "</tr>")
    if claims:
        parts.append("</table>")
    if protocol:
        parts.append("<h2>Protocol</h2><ul>" + "".join(f"<li>{e(p)}</li>" for p in protocol)
                     + "</ul>")
    if maps:
        parts.append("<h2>Where the claims hold: maps</h2><table><tr><th>study</th><th>map"
                     "</th><th>value at the shipped setting (verdict)</th><th>where it holds"
                     "</th></tr>")
        for m in maps:
            parts.append(f"<tr><td>{e(m['study'])}</td><td>{e(m['claim'])}: {e(m['title'])}"
                         f"</td><td>{e(m['at_setting'])}</td><td>{e(m['region'])} "
                         f"({m['n_holds']} of {m['n_cells']} cells)</td></tr>")
        parts.append("</table>")
        parts.append(f"<p>{e(FAILED_CELLS_NOTE)}</p>")
        for m in maps:
            if m.get("path"):
                parts.append(f"<figure><img src='{data_uri(m['path'])}' alt='"
                             f"{e(m['claim'])} map'><figcaption>{e(m['claim'])}: "
                             f"{e(m['title'])}</figcaption></figure>")
    parts += [sweep_html(sw) for sw in sweeps or []]
    cols = [("case", "study"), ("load", "load"), ("upqc", "UPQC"), ("T", "T [s]"), ("a", "a"),
            ("Vr_bar", "V̄r [pu]"), ("phi_s0", "ϕs0 [rad]"),
            ("preset", "settings preset (T, a, V̄r, ϕs0)"),
            ("modes", "design-model mode vs full grid's mode"), ("training", "HJI training")]
    parts.append("<h2>Design models derived from the grids</h2><table><tr>" +
                 "".join(f"<th>{e(lbl)}</th>" for _, lbl in cols) + "</tr>")
    for d in designs:
        parts.append("<tr>" + "".join(f"<td>{e(str(d.get(k, '')))}</td>" for k, _ in cols)
                     + "</tr>")
    parts.append("</table>")
    for d in designs:
        der = d.get("derivation")
        if not der:
            continue
        parts.append(f"<details><summary>derivation: {e(d['case'])}, {e(d['load'])} load, "
                     f"{e(d['upqc'])} UPQC</summary><table><tr><th>value</th><th></th>"
                     "<th>unit</th><th>source</th></tr>" +
                     "".join(f"<tr><td>{e(v['name'])}</td><td>{e(_fmt(v['value']))}</td>"
                             f"<td>{e(v['unit'])}</td><td>{e(v['source'])}</td></tr>"
                             for v in der["values"]) + "</table></details>")
    for case, items in (notes or {}).items():
        if items:
            parts.append(f"<h3>Notes from the data of {e(case)}</h3><ul>" +
                         "".join(f"<li>{e(n)}</li>" for n in items) + "</ul>")
    parts.append("<h2>Figures</h2>")
    for f in figures:
        parts.append(f"<figure><img src='{data_uri(f)}' alt='{e(Path(f).stem)}'></figure>")
    parts.append("<h2>Metrics</h2><table><tr>" + "".join(f"<th>{e(lbl)}</th>"
                                                         for _, lbl in COLUMNS) + "</tr>")
    for r in metrics_frame(metrics).to_dict("records"):
        parts.append("<tr>" + "".join(f"<td>{e(_fmt(r[k]))}</td>" for k, _ in COLUMNS) +
                     "</tr>")
    parts.append("</table><h2>Parameters</h2><pre>" + e(meta.get("parameters", "")) + "</pre>")
    path = Path(path)
    write_text_atomic(path, "\n".join(parts))
    return path
