"""Metrics table (CSV, Markdown) and the HTML report with a verdict per claim."""

from __future__ import annotations

import html
import math
from pathlib import Path

import pandas as pd

from ..fileio import write_text_atomic
from .failure import FAILED_CELLS_NOTE
from .ties import compare, run_uncertainty

__all__ = ["metrics_frame", "write_tables", "write_html", "sweep_html", "TOPICS", "BETTER",
           "who_did_best", "md_cell"]

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
    ("s_series_peak_pct_rating", "S_series peak [% s_rating]"),
    ("s_series_peak_pct_line", "S_series peak [% line]"),
    ("s_shunt_peak_pct_rating", "S_shunt peak [% s_rating]"),
    ("shunt_limit_reached", "shunt current limit reached"),
    ("device_over_rating", "device power > s_rating"),
    ("device_over_line", "device power > line"),
    ("design_load", "controllers designed at (load)"),
    ("clip_fraction", "post-fault samples clipped by the rating [–]"),
    ("u_demanded_peak_pu", "demanded |u| peak [pu]"), ("u_applied_peak_pu", "applied |u| peak [pu]"),
    ("omega_reach", "reach of Ω (> 1: outside) [–]"), ("extrapolation", "extrapolation"),
    ("vdc_final_dev_pu", "Vdc at the end − Vc0 [pu]"), ("failed", "failed"),
    ("wall_s", "wall time [s]"),
]


# the metrics table split by topic (every table starts with the run's id); columns empty in
# every run are dropped
TOPICS = {
    "Runs": ("load", "upqc", "controller", "design_load", "fault", "failed", "wall_s"),
    "Stability": ("speed_peak_dev_pu", "speed_backswing_pu", "speed_settling_s", "speed_itae",
                  "speed_verdict", "vdc_peak_dev_pu", "vdc_backswing_pu", "vdc_settling_s",
                  "vdc_itae", "vdc_final_dev_pu"),
    "Control effort": ("control_cost", "control_cost_demanded", "running_cost_18",
                       "u_demanded_peak_pu", "u_applied_peak_pu", "clip_fraction"),
    "Device": ("vu_peak_pu", "vu_rms_pu", "vu_rating_reached", "p_series_peak_mw",
               "p_series_peak_pct_line", "s_series_peak_pct_rating", "s_series_peak_pct_line",
               "s_shunt_peak_pct_rating", "shunt_limit_reached", "device_over_rating",
               "device_over_line", "omega_reach", "extrapolation"),
}

# which way is better, per metric, declared once ("lower" or "higher"): the "who did best"
# table compares the controllers of a scenario on these
BETTER = {
    "speed_peak_dev_pu": "lower", "speed_backswing_pu": "lower", "speed_settling_s": "lower",
    "speed_itae": "lower", "vdc_peak_dev_pu": "lower", "vdc_backswing_pu": "lower",
    "vdc_settling_s": "lower", "vdc_itae": "lower", "control_cost": "lower",
    "running_cost_18": "lower", "vu_peak_pu": "lower",
}
# effort metrics: a controller that does not drive the UPQC (exactly 0) does not take part
EFFORT = ("control_cost", "vu_peak_pu")

# the sweep table's metrics (of those a run measures), when any run has them
SWEEP_METRICS = ("speed_peak_dev_pu", "speed_settling_s", "speed_verdict", "vdc_peak_dev_pu",
                 "vdc_settling_s", "control_cost", "vu_peak_pu", "u_demanded_peak_pu",
                 "clip_fraction", "omega_reach", "s_series_peak_pct_rating",
                 "device_over_rating", "device_over_line")


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
            f"{f', {n_fail} failed' if n_fail else ''}</summary><div class='scroll'><table><tr>"
            f"{head}</tr>{rows}</table></div></details>")


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


def _empty(v) -> bool:
    return v is None or (isinstance(v, float) and math.isnan(v)) or v == ""


def kept_columns(df: pd.DataFrame, keys) -> list[str]:
    """``keys`` of ``df`` with a value in at least one row (all-empty columns dropped)."""
    return [k for k in keys if k in df and not df[k].map(_empty).all()]


def md_cell(v) -> str:
    """A value as a Markdown table cell: ``|`` escaped, line breaks as spaces."""
    return " ".join(_fmt(v).splitlines()).replace("\\", "\\\\").replace("|", "\\|")


def write_tables(metrics: list[dict], folder, title: str = "study") -> tuple[Path, Path]:
    """``metrics.csv`` (every metric, machine-readable) and ``metrics.md`` (the report's
    columns with a value in some run, titled by ``title``: the study or run)."""
    folder = Path(folder)
    df = metrics_frame(metrics)
    csv = folder / "metrics.csv"
    write_text_atomic(csv, df.to_csv(index=False))
    labels = dict(COLUMNS)
    keys = kept_columns(df, [k for k, _ in COLUMNS])
    head = "| " + " | ".join(md_cell(labels[k]) for k in keys) + " |"
    sep = "|" + "---|" * len(keys)
    rows = ["| " + " | ".join(md_cell(r[k]) for k in keys) + " |" for r in
            df.to_dict("records")]
    md = folder / "metrics.md"
    write_text_atomic(md, "\n".join([f"# {' '.join(title.splitlines())} — metrics", "", head,
                                     sep, *rows, ""]))
    return csv, md


def who_did_best(metrics: list[dict], uncertainty: dict | None = None,
                 names: dict | None = None) -> list[dict]:
    """Per scenario and metric of :data:`BETTER`, the controller that did best.

    ``uncertainty``: metric → relative numerical uncertainty (``|m(T) − m(T/2)| / |m(T)|``,
    the sweeps' half-step check), when measured; with each run's ``<metric>_def_unc`` it makes
    the tie rule of :mod:`weakgrid.study.ties`: a controller within it of the best is a tie.
    ``names``: controller → full name. Returns rows ``scenario``, ``metric``, ``best``
    (names, ``" = "`` between tied ones), ``value``, ``tie`` (bool), ``uncertainty`` (NaN when
    not measured), ``others`` (the rest, with their values). Failed runs are left out, and
    on the effort metrics (:data:`EFFORT`) the controllers that do not drive the UPQC.
    """
    names = names or {}
    uncertainty = uncertainty or {}
    by_sc: dict[str, list[dict]] = {}
    for m in metrics:
        if m.get("failed"):
            continue
        ctl = str(m.get("controller", ""))
        rid = str(m.get("id", ""))
        sc = rid[: -len(ctl) - 1] if ctl and rid.endswith("-" + ctl) else rid
        by_sc.setdefault(sc, []).append(m)
    out = []
    for sc, ms in by_sc.items():
        for key, way in BETTER.items():
            runs = [m for m in ms
                    if isinstance(m.get(key), (int, float)) and not _empty(m.get(key))
                    and not isinstance(m.get(key), bool)
                    and not (key in EFFORT and m[key] == 0)]
            vals = [(m["controller"], float(m[key])) for m in runs]
            if len(vals) < 2:
                continue
            order = sorted(range(len(vals)), key=lambda i: vals[i][1], reverse=(way == "higher"))
            vals = [vals[i] for i in order]
            runs = [runs[i] for i in order]
            best = vals[0][1]
            u = float(uncertainty.get(key, float("nan")))
            # the one tie rule (weakgrid.study.ties): step halving + the metric's definition
            ub = run_uncertainty(runs[0], key, u)
            tied = [c for (c, v), r in zip(vals, runs)
                    if compare(v, best, run_uncertainty(r, key, u), ub)[0] == "tie"]
            out.append({"scenario": sc, "metric": key, "better": way,
                        "best": " = ".join(names.get(c, c) for c in tied), "value": best,
                        "tie": len(tied) > 1, "uncertainty": u,
                        "others": ", ".join(f"{names.get(c, c)} {_fmt(v)}" for c, v in vals
                                            if c not in tied)})
    return out


def _unc(u) -> str:
    return "not measured" if u != u else f"{u:.2%}"


def _best_html(rows) -> str:
    e = html.escape
    labels = dict(COLUMNS)
    if not rows:
        return ""
    body = "".join(
        f"<tr><td>{e(r['scenario'])}</td><td>{e(labels.get(r['metric'], r['metric']))} "
        f"({r['better']} is better)</td><td>{e(r['best'])}{' (tie)' if r['tie'] else ''}</td>"
        f"<td>{e(_fmt(r['value']))}</td><td>"
        f"{_unc(r['uncertainty'])}"
        f"</td><td>{e(r['others'])}</td></tr>" for r in rows)
    return ("<h2>Who did best</h2><p>Per scenario and metric, the controller with the best "
            "value (failed runs left out; on control cost and |Vu| peak, the controllers that do "
            "not drive the UPQC left out). Controllers within the measured uncertainty of "
            "the best are a tie, named together — the tie rule of the claim table and the "
            "maps: step halving (relative, from the half-step check of the study's sweep; the "
            "column below) plus each run's sensitivity of the metric to its own definition "
            "(settling band 1.5–3 %, …).</p><div class='scroll'>"
            "<table><tr><th>scenario</th><th>metric</th><th>best</th><th>value</th>"
            f"<th>numerical uncertainty</th><th>the others</th></tr>{body}</table></div>")


def _metrics_html(metrics) -> str:
    """The metrics in one table per topic (:data:`TOPICS`), all-empty columns dropped."""
    e = html.escape
    labels = dict(COLUMNS)
    df = metrics_frame(metrics)
    parts = ["<h2>Metrics</h2>"]
    for topic, keys in TOPICS.items():
        cols = kept_columns(df, keys)
        if not cols:
            continue
        cols = ["id"] + cols
        parts.append(f"<h3>{e(topic)}</h3><div class='scroll'><table><tr>" +
                     "".join(f"<th>{e(labels[k])}</th>" for k in cols) + "</tr>" +
                     "".join("<tr>" + "".join(f"<td>{e(_fmt(r[k]))}</td>" for k in cols)
                             + "</tr>" for r in df.to_dict("records")) + "</table></div>")
    return "".join(parts)


_CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em}
.scroll{overflow-x:auto;max-width:100%}table{border-collapse:collapse;font-size:0.85em;
margin:1em 0}td,th{border:1px solid #ccc;padding:3px 6px;vertical-align:top;min-width:4em;
max-width:40em;overflow-wrap:break-word}td:first-child{white-space:nowrap}pre{white-space:pre-wrap;overflow-wrap:anywhere;
max-height:30em;overflow:auto}th{background:#f4f4f4}.reproduced{background:#d8f5d8}
.partly{background:#fff3c4}.tie{background:#dde8f8}.not{background:#f8d0d0}.notrun{background:#eee}
img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}"""


def data_uri(path) -> str:
    """A file as a ``data:`` URI (figures embedded in the report: one self-contained file)."""
    import base64

    p = Path(path)
    mime = {".png": "image/png", ".svg": "image/svg+xml"}.get(p.suffix, "application/octet-stream")
    return f"data:{mime};base64," + base64.b64encode(p.read_bytes()).decode("ascii")


def write_html(path, *, claims, metrics, figures, designs, meta, notes=None, maps=None,
               protocol=None, sweeps=None, best=None) -> Path:
    """One self-contained HTML page (figures embedded as data URIs): claims with verdicts,
    the protocol (``protocol``: paragraphs from the studies' own data), who did best
    (``best``: rows of :func:`who_did_best`), maps of where the claims hold, the sweeps' runs
    (``sweeps``: see :func:`sweep_html`), design models, figures, metrics by topic."""
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
        parts.append("<h2>Claims</h2><div class='scroll'><table><tr><th>claim</th>"
                     "<th>case</th><th>paper</th><th>measured (shipped setting)</th>"
                     "<th>rule</th><th>verdict at the shipped setting</th>"
                     + ("<th>map: value at the shipped setting (HIGH-load design)</th>"
                        "<th>map: where it holds</th>" if with_maps else "") + "</tr>")
    for c in claims:
        cls = c["verdict"].replace(" ", "")
        parts.append(f"<tr><td>{e(c['id'])}</td><td>{e(c['case'])}</td><td>{e(c['paper'])}"
                     f"</td><td>{e(c['measured'] or '—')}</td><td>{e(c['rule'])}</td>"
                     f"<td class='{cls}'>{e(c['verdict'])}"
                     + (f"<br><small>{e(c['why'])}</small>" if c.get("why") else "")
                     + "</td>" +
                     (f"<td>{e(c.get('map_setting') or '—')}</td>"
                      f"<td>{e(c.get('map_region') or 'not mapped')}</td>" if with_maps else "")
                     + "</tr>")
    if claims:
        parts.append("</table></div>")
    if protocol:
        parts.append("<h2>Protocol</h2>" + "".join(f"<p>{e(p)}</p>" for p in protocol))
    parts.append(_best_html(best or []))
    if maps:
        parts.append("<h2>Where the claims hold: maps</h2><div class='scroll'><table><tr>"
                     "<th>study</th><th>map"
                     "</th><th>value at the shipped setting (verdict)</th><th>where it holds"
                     "</th></tr>")
        for m in maps:
            parts.append(f"<tr><td>{e(m['study'])}</td><td>{e(m['claim'])}: {e(m['title'])}"
                         f"</td><td>{e(m['at_setting'])}</td><td>{e(m['region'])} "
                         f"({m['n_holds']} of {m['n_cells']} cells)</td></tr>")
        parts.append("</table></div>")
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
    parts.append("<h2>Design models derived from the grids</h2>")
    if designs:
        parts.append("<div class='scroll'><table><tr>" +
                     "".join(f"<th>{e(lbl)}</th>" for _, lbl in cols) + "</tr>")
        for d in designs:
            parts.append("<tr>" + "".join(f"<td>{e(str(d.get(k, '')))}</td>" for k, _ in cols)
                         + "</tr>")
        parts.append("</table></div>")
    else:       # recorded with the HJI training: a run without hji trains nothing
        parts.append("<p>None recorded: no controller of this run was trained (the design "
                     "model, its mode check and the HJI training are recorded when a run "
                     "compares hji; <code>weakgrid design STUDY</code> prints them).</p>")
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
    parts.append(_metrics_html(metrics))
    parts.append("<h2>Parameters</h2><pre>" + e(meta.get("parameters", "")) + "</pre>")
    path = Path(path)
    write_text_atomic(path, "\n".join(parts))
    return path
