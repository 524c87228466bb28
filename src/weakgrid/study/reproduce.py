"""``weakgrid reproduce``: train, run every scenario, write figures, tables and the report."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..fileio import write_json_atomic
from ..models import load_controller, load_preset
from .cache import inputs_key, load_run, remove_stale, save_run
from .cases import build_case
from .claims import judge_all
from .controllers import train_hji_for
from .figures import write_figures
from .report import write_html, write_tables
from .runner import RunRecord, run_scenario
from .scenarios import paper_scenarios

__all__ = ["reproduce", "Progress"]


class Progress:
    """A progress bar on stderr (tqdm)."""

    def __init__(self, total, stream=None):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=total, file=stream or sys.stderr, unit="step",
                        dynamic_ncols=True, disable=None)

    def step(self, label):
        self.bar.set_postfix_str(label[:40], refresh=False)
        self.bar.update(1)
        if self.bar.n >= self.bar.total:
            self.bar.close()


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
    # a used folder: runs this plan does not make are stale; finished runs with the same
    # inputs are kept and not redone (an interrupted reproduce continues where it stopped)
    remove_stale(runs_dir, [s.id for s in scenarios], log)
    remove_stale(out / "controllers", [f"{c}-{ld}-{u}" for c, ld, u in keys], log,
                 suffix=".controller.json")
    prog = Progress(len(keys) + len(scenarios))
    trained, designs, notes, ctl_keys, n_kept = {}, [], {}, {}, 0
    for case, load, upqc in keys:
        build = build_case(case, load, upqc)
        d = build.design
        ckey = inputs_key(case=case, design=[d.T, d.a, d.Vr_bar, d.phi_s0],
                          machine=getattr(d, "machine", None), upqc=getattr(d, "upqc", None))
        cpath = out / "controllers" / f"{case}-{load}-{upqc}.controller.json"
        ctl = None
        if cpath.is_file():
            try:
                ctl = load_controller(cpath)
            except (ValueError, OSError):
                ctl = None
            if ctl is not None and ctl.problem.get("inputs_key") != ckey:
                ctl = None
        if ctl is None:
            problem, ctl = train_hji_for(case, build.design)
            ctl.problem["inputs_key"] = ckey
            ctl.save(cpath)
        else:
            n_kept += 1
        ctl_keys[(case, load, upqc)] = ckey
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
        prog.step(f"trained {case} {load} {upqc}")
    records, metrics = {}, []
    for sc in scenarios:
        rkey = inputs_key(scenario=sc.to_dict(),
                          controller=ctl_keys.get((sc.case, sc.load, sc.upqc)))
        rec = load_run(runs_dir, sc, rkey, RunRecord)
        if rec is None:
            rec = run_scenario(sc, trained)
            save_run(rec, runs_dir, rkey)
        else:
            n_kept += 1
        records[sc.id] = rec
        metrics.append(rec.metrics)
        prog.step(sc.id)
    if n_kept:
        log(f"kept {n_kept} finished result(s) of an earlier run with the same inputs")
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
