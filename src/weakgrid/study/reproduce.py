"""``weakgrid reproduce``: train, run every scenario, write figures, tables and the report."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from .. import __version__
from ..fileio import replace_atomic, write_json_atomic
from ..models import load_preset
from .cases import build_case
from .claims import judge_all
from .controllers import train_hji_for
from .figures import write_figures
from .report import write_html, write_tables
from .runner import run_scenario
from .scenarios import paper_scenarios

__all__ = ["reproduce", "Progress"]


class Progress:
    """A text progress bar on stderr (one line, redrawn)."""

    def __init__(self, total, stream=None, width=30):
        self.total, self.n, self.width = total, 0, width
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()

    def step(self, label):
        self.n += 1
        frac = self.n / max(self.total, 1)
        bar = "#" * int(frac * self.width)
        el = time.perf_counter() - self.t0
        self.stream.write(f"\r[{bar:<{self.width}}] {self.n}/{self.total} {el:5.0f} s  "
                          f"{label[:40]:<40}")
        self.stream.flush()
        if self.n == self.total:
            self.stream.write("\n")


def _save_series(rec, folder: Path):
    s = rec.series
    t = s["t"]
    cols = {k: v for k, v in s.items() if isinstance(v, np.ndarray) and v.shape == t.shape}
    df = pd.DataFrame(cols)
    replace_atomic(folder / f"{rec.scenario.id}.parquet", df.to_parquet)


def reproduce(output="reproduce-output", quick=False, log=print) -> dict:
    """Run the paper's case studies and write everything to ``output``.

    Returns a summary dict (claims, metrics, files).
    """
    out = Path(output)
    runs_dir = out / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    scenarios = paper_scenarios(quick)
    keys = sorted({(s.case, s.load, s.upqc) for s in scenarios if s.controller == "hji"})
    prog = Progress(len(keys) + len(scenarios))
    trained, designs, notes = {}, [], {}
    for case, load, upqc in keys:
        build = build_case(case, load, upqc)
        problem, ctl = train_hji_for(case, build.design)
        trained[(case, load, upqc)] = ctl
        info = build.info
        case_notes = [info[k] for k in ("difference",) if isinstance(info.get(k), str)]
        case_notes += [n for n in info.get("notes", []) if isinstance(n, str)]
        notes.setdefault(case, case_notes)
        preset = load_preset({"case1-weak-grid": "case1-paper",
                              "case2-lv-microgrid": "case2-paper"}[case]).system
        d = build.design
        designs.append((case, load, upqc, f"{d.T:.4g}", f"{d.a:.4g}", f"{d.Vr_bar:.4g}",
                        f"{d.phi_s0:.4g}",
                        f"{preset.T:.4g}, {preset.a:.4g}, {preset.Vr_bar:.4g}, "
                        f"{preset.phi_s0:.4g}",
                        f"{ctl.iterations['outer']} outer, W = "
                        f"{np.array2string(ctl.weights, precision=3, max_line_width=200)}"))
        ctl.save(out / "controllers" / f"{case}-{load}-{upqc}.controller.json")
        prog.step(f"trained {case} {load} {upqc}")
    records, metrics = {}, []
    for sc in scenarios:
        rec = run_scenario(sc, trained)
        records[sc.id] = rec
        metrics.append(rec.metrics)
        _save_series(rec, runs_dir)
        write_json_atomic(runs_dir / f"{sc.id}.json", {
            "scenario": sc.to_dict(), "metrics": rec.metrics, "info": rec.info,
            "weakgrid_version": __version__})
        prog.step(sc.id)
    figs = write_figures(records, out / "figures")
    csv, md = write_tables(metrics, out)
    claims = judge_all({m["id"]: m for m in metrics})
    wall = time.perf_counter() - t0
    params = json.dumps({"scenarios": [s.to_dict() for s in scenarios],
                         "quick": quick}, indent=1)
    report = write_html(out / "report.html", claims=claims, metrics=metrics,
                        figures=[str(p.relative_to(out)) for p in figs if p.suffix == ".png"],
                        designs=designs, notes=notes, meta={"version": __version__, "n_runs": len(metrics),
                                               "wall_s": wall, "mode": "quick" if quick else
                                               "full", "parameters": params})
    write_json_atomic(out / "claims.json", {"claims": claims, "weakgrid_version": __version__,
                                            "quick": quick, "wall_s": wall})
    log(f"wrote {report}, {csv}, {md}, {len(figs)} figure files in {wall:.0f} s")
    return {"claims": claims, "metrics": metrics, "figures": figs, "report": report,
            "csv": csv, "markdown": md, "wall_s": wall}
