"""Side by side: the same study run by several engines (`weakgrid run STUDY --engine ...`).

    PYTHONPATH=src python scripts/compare_engines.py OUT_DIR NAME \\
        --run phasor=RUN_A --run DP=RUN_B --run EMT=RUN_C [--speed SG.omega] [--vu U.Vu] \\
        [--dc WF.Vc] [--peak UPQC.Vdc] [--scenario ID ...] [--from 2.8] [--to 5]

Each ``RUN_*`` is a run folder written by ``weakgrid run`` (its ``metrics.csv``, ``claims.json``
and ``runs/<id>.parquet``); the first is the reference. Writes, atomically:

- ``OUT_DIR/NAME-metrics.md`` and ``.csv``: per run id and engine the speed peak deviation
  (``speed_peak_dev_pu``), the dc-link peak deviation (``vdc_peak_dev_pu``), the speed and
  dc-link settling times, the largest ``|Vu|`` (``vu_peak_pu``), the demanded peak, the peak
  series power, the running cost of (18) (``running_cost_18``), the run's wall time, each
  with its difference from the reference in per cent (``--metrics`` picks columns), and per
  ``--peak SIGNAL`` the signal's largest deviation from its initial value over the run
  (``SIGNAL peak dev``, read from ``runs/<id>.parquet``: e.g. a conventional UPQC's dc link
  ``UPQC.Vdc``, which ``metrics.csv`` does not carry);
- ``OUT_DIR/NAME-claims.md``: the verdict of every claim in each engine (the ``claims.json``
  each run writes);
- ``OUT_DIR/NAME-<scenario>.png``: per scenario, one row per controller, the speed, dc-link
  voltage (if ``--dc``), each ``--peak`` signal and ``|Vu|`` of every engine overlaid.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from weakgrid.fileio import savefig_atomic, write_text_atomic  # noqa: E402
from weakgrid.sim.runfile import read_run  # noqa: E402

#: (metrics.csv column, table heading)
METRICS = (("speed_peak_dev_pu", "speed peak [pu]"),
           ("speed_backswing_pu", "back swing [pu]"),
           ("speed_settling_s", "speed settling [s]"),
           ("vdc_peak_dev_pu", "dc-link peak [pu]"),
           ("vdc_settling_s", "dc-link settling [s]"),
           ("vu_peak_pu", "series voltage peak [pu]"),
           ("u_demanded_peak_pu", "demanded u peak [pu]"),
           ("p_series_peak_mw", "series power peak [MW]"),
           ("running_cost_18", "running cost (18)"),
           ("wall_s", "wall [s]"))
COLORS = ("k", "tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple")
STYLES = ("-", "--", ":", "-.", (0, (5, 1)), (0, (1, 2)))


def load(runs: list[tuple[str, Path]]) -> dict:
    """``{engine: metrics DataFrame indexed by run id}``; a folder without metrics.csv refused."""
    out = {}
    for label, folder in runs:
        f = folder / "metrics.csv"
        if f.is_file():
            out[label] = pd.read_csv(f).set_index("id")
            continue
        # a run still under way: the finished runs' metrics, each in its runs/<id>.json
        rows = [json.loads(j.read_text(encoding="utf-8"))["metrics"]
                for j in sorted((folder / "runs").glob("*.json"))] if (folder / "runs").is_dir() \
            else []
        if not rows:
            raise SystemExit(f"--run {label}={folder}: no metrics.csv and no finished run there "
                             "(a `weakgrid run` output folder is expected)")
        print(f"{label}: no metrics.csv yet, {len(rows)} finished runs read from "
              f"{folder / 'runs'}", file=sys.stderr)
        out[label] = pd.DataFrame(rows).set_index("id")
    return out


def peak_column(signal: str) -> str:
    """The table column of ``--peak signal``."""
    return f"{signal} peak dev"


def add_peaks(m: dict, folders, signals) -> None:
    """Per engine and run id, ``max |y − y(0)|`` of each of ``signals`` over the run (its
    ``runs/<id>.parquet``; NaN where the run or the signal is missing), as column
    :func:`peak_column` of ``m[label]``."""
    for lab, folder in folders:
        df = m[lab]
        for sig in signals:
            vals = []
            for rid in df.index:
                p = folder / "runs" / f"{rid}.parquet"
                v = math.nan
                if p.is_file():
                    r = read_run(p)
                    if sig in r.columns:
                        y = r[sig].to_numpy(dtype=float)
                        ok = y[pd.notna(y)]
                        v = float(abs(ok - ok[0]).max()) if ok.size else math.nan
                vals.append(v)
            df[peak_column(sig)] = vals


def _num(x) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def _fmt(v: float) -> str:
    return "–" if not math.isfinite(v) else f"{v:.4g}"


def _pct(v: float, ref: float) -> str:
    if not (math.isfinite(v) and math.isfinite(ref)) or abs(ref) < 1e-12:
        return ""                          # no reference, or one at round-off (a 1e-16 swing)
    if abs(v / ref) >= 10:                 # orders of magnitude: a factor reads better
        return f" (×{v / ref:.3g})"
    return f" ({100 * (v / ref - 1):+.0f} %)"


def metrics_table(m: dict, only=None, peaks=()) -> tuple[str, pd.DataFrame]:
    """Markdown table (rows run id × engine; each non-reference value with its difference from the
    reference engine in per cent) and the long table behind it; ``only``: these metrics;
    ``peaks``: the ``--peak`` signals (columns :func:`peak_column`, after the metrics)."""
    labels = list(m)
    ref = labels[0]
    cols = [(c, h) for c, h in METRICS if any(c in df.columns for df in m.values())
            and (not only or c in only)]
    cols += [(peak_column(s), f"{s} peak dev [pu]") for s in peaks]
    ids = [i for i in m[ref].index if any(i in df.index for lab, df in m.items() if lab != ref)]
    rows, lines = [], []
    lines.append("| run | engine | " + " | ".join(h for _, h in cols) + " |")
    lines.append("|---|---|" + "---|" * len(cols))
    for rid in ids:
        for lab in labels:
            df = m[lab]
            if rid not in df.index:
                continue
            cells = []
            for c, _ in cols:
                v = _num(df.at[rid, c]) if c in df.columns else math.nan
                r = _num(m[ref].at[rid, c]) if c in m[ref].columns else math.nan
                failed = "failed" in df.columns and str(df.at[rid, "failed"]) == "True"
                cells.append(_fmt(v) + ("" if lab == ref or c == "wall_s" else _pct(v, r))
                             + (" ✗" if failed and c == cols[0][0] else ""))
                rows.append({"id": rid, "engine": lab, "metric": c, "value": v,
                             "reference": r, "rel_diff": (v / r - 1) if r not in (0,) and
                             math.isfinite(v) and math.isfinite(r) else math.nan})
            lines.append(f"| {rid} | {lab} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n", pd.DataFrame(rows)


def claims_table(folders: list[tuple[str, Path]]) -> str:
    """Markdown: claim id × engine verdict (and the measured text of the last engine)."""
    verdicts, paper, measured = {}, {}, {}
    for lab, folder in folders:
        f = folder / "claims.json"
        if not f.is_file():
            continue
        for c in json.loads(f.read_text(encoding="utf-8"))["claims"]:
            verdicts.setdefault(c["id"], {})[lab] = c["verdict"]
            paper[c["id"]] = c["paper"]
            measured.setdefault(c["id"], {})[lab] = c.get("measured", "")
    labs = [lab for lab, _ in folders]
    lines = ["| claim | paper | " + " | ".join(labs) + " |", "|---|---|" + "---|" * len(labs)]
    for cid, v in verdicts.items():
        lines.append(f"| {cid} | {paper[cid]} | " + " | ".join(v.get(lab, "–") for lab in labs)
                     + " |")
    return "\n".join(lines) + "\n"


def _scenario_of(rid: str, controllers) -> tuple[str, str]:
    for c in sorted(controllers, key=len, reverse=True):
        if rid.endswith("-" + c):
            return rid[: -len(c) - 1], c
    return rid, ""


def figures(out: Path, name: str, folders, m: dict, panels, scenarios, t_from, t_to) -> list:
    """One PNG per scenario: rows = controllers, columns = panels, engines overlaid."""
    ref = folders[0][0]
    df = m[ref]
    ctrl = dict(zip(df.index, df["controller"])) if "controller" in df.columns else {}
    by_scn: dict = {}
    for rid in df.index:
        scn, c = _scenario_of(rid, [ctrl.get(rid, "")])
        by_scn.setdefault(scn, []).append((c, rid))
    written = []
    for scn, items in by_scn.items():
        if scenarios and scn not in scenarios:
            continue
        fig, axes = plt.subplots(len(items), len(panels), figsize=(4.2 * len(panels),
                                 2.4 * len(items)), squeeze=False, sharex=True)
        for i, (c, rid) in enumerate(items):
            drawn = set()
            for k, (lab, folder) in enumerate(folders):
                p = folder / "runs" / f"{rid}.parquet"
                if not p.is_file():
                    continue
                r = read_run(p)
                t = r["t"].to_numpy()
                keep = (t >= t_from) & (t <= t_to if t_to else True)
                for j, (s, _) in enumerate(panels):
                    if s in r.columns:
                        axes[i][j].plot(t[keep], r[s].to_numpy()[keep],
                                        linestyle=STYLES[k % len(STYLES)],
                                        color=COLORS[k % len(COLORS)], lw=1.0, label=lab)
                        drawn.add(j)
            for j, (_, title) in enumerate(panels):
                axes[i][j].set_title(f"{c}: {title}", fontsize=9)
                axes[i][j].grid(alpha=0.3)
                axes[i][j].tick_params(labelsize=8)
                if j not in drawn:           # the run has no such signal (e.g. no UPQC)
                    axes[i][j].set_yticks([])
                    axes[i][j].text(0.5, 0.5, "not in this run", ha="center", va="center",
                                    transform=axes[i][j].transAxes, fontsize=8, color="0.4")
            axes[i][0].legend(fontsize=7, loc="best")
        for j in range(len(panels)):
            axes[-1][j].set_xlabel("t [s]", fontsize=8)
        fig.suptitle(f"{name}: {scn}", fontsize=10)
        fig.tight_layout()
        path = out / f"{name}-{scn}.png"
        savefig_atomic(fig, path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("name")
    ap.add_argument("--run", action="append", required=True, metavar="LABEL=FOLDER",
                    help="an engine's run folder; the first is the reference")
    ap.add_argument("--speed", default="SG.omega", help="speed signal [pu]")
    ap.add_argument("--vu", default="U.Vu", help="series-voltage magnitude signal [pu]")
    ap.add_argument("--dc", default=None, help="dc-link voltage signal [pu] (a GTI's `<gti>.Vc`)")
    ap.add_argument("--peak", action="append", default=[], metavar="SIGNAL",
                    help="a table column: the signal's largest deviation from its initial value "
                         "over the run [pu] (e.g. UPQC.Vdc); repeatable")
    ap.add_argument("--scenario", action="append", default=[], help="only these scenarios' figures")
    ap.add_argument("--metrics", default="", help="comma-separated metrics.csv columns of the "
                    "table (default: all of " + ", ".join(c for c, _ in METRICS) + ")")
    ap.add_argument("--from", dest="t_from", type=float, default=0.0, help="figure start [s]")
    ap.add_argument("--to", dest="t_to", type=float, default=None, help="figure end [s]")
    a = ap.parse_args(argv)
    folders = []
    for spec in a.run:
        if "=" not in spec:
            raise SystemExit(f"--run {spec!r}: expected LABEL=FOLDER, e.g. --run EMT=out-emt")
        lab, folder = spec.split("=", 1)
        folders.append((lab, Path(folder)))
    m = load(folders)
    a.out.mkdir(parents=True, exist_ok=True)
    only = [c.strip() for c in a.metrics.split(",") if c.strip()]
    unknown = sorted(set(only) - {c for c, _ in METRICS})
    if unknown:
        raise SystemExit(f"--metrics: unknown {unknown}; known: {[c for c, _ in METRICS]}")
    add_peaks(m, folders, a.peak)
    md, long = metrics_table(m, only, a.peak)
    write_text_atomic(a.out / f"{a.name}-metrics.md", md)
    write_text_atomic(a.out / f"{a.name}-metrics.csv", long.to_csv(index=False))
    write_text_atomic(a.out / f"{a.name}-claims.md", claims_table(folders))
    panels = [(a.speed, f"{a.speed} [pu]")] + ([(a.dc, f"{a.dc} [pu]")] if a.dc else []) + \
        [(s, f"{s} [pu]") for s in a.peak] + [(a.vu, f"{a.vu} [pu]")]
    figs = figures(a.out, a.name, folders, m, panels, a.scenario, a.t_from, a.t_to)
    print(md)
    print(claims_table(folders))
    print("wrote", ", ".join(str(p) for p in figs), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
