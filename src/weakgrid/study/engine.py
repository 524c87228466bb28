"""The study engine: design, train, run every scenario × controller, measure, write a report.

:func:`run_studies` is what ``weakgrid run STUDY`` and ``weakgrid reproduce`` (the shipped
studies marked ``reproduce = true``) execute. Per study it derives the design model (10) at every
operating point a scenario needs (load level × UPQC structure), compares the design model's
mode with the full grid's (:mod:`weakgrid.design.modes`), trains the HJI controller once per
operating point, runs every (scenario, controller), and writes:

* ``runs/<run id>.parquet`` (every signal) and ``runs/<run id>.json`` (scenario, metrics, design),
* ``controllers/<study>-<load>-<upqc>.controller.json``,
* ``figures/*.png|svg``, ``metrics.csv``, ``metrics.md``, ``claims.json``, ``report.html``.

Every file is written atomically (:mod:`weakgrid.fileio`).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..design import design_mode, machine_mode, mode_states, modes
from ..fileio import write_json_atomic
from ..models import load_preset
from .build import build_setup
from .cache import inputs_key, load_run, remove_stale, save_run
from .claims import judge_all
from .controllers import controller_kind, train_hji
from .figures import figure_specs, write_figures
from .report import write_html, write_tables
from .runner import Run, RunRecord, run_scenario

__all__ = ["run_studies", "mode_check", "MODE_TOLERANCE"]

MODE_TOLERANCE = 0.05   # design-model mode vs the full grid's mode: relative frequency mismatch


def _progress(total, enabled=True):
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, unit="step", dynamic_ncols=True,
                bar_format="{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}] {postfix}")


def mode_check(setup) -> dict:
    """The design model's mode beside the full grid's mode in which the machine participates
    most; ``ok`` when their frequencies agree within :data:`MODE_TOLERANCE`."""
    der = setup.derivation
    lam_d = design_mode(der.model)
    m = modes(setup.system)
    k, part = machine_mode(m, mode_states(der))
    out = {"design_lambda": lam_d, "design_f_hz": abs(lam_d.imag) / (2 * np.pi),
           "states": mode_states(der)}
    if k is None:
        out.update(grid_lambda=None, grid_f_hz=float("nan"), grid_zeta=float("nan"),
                   participation=0.0, mismatch=float("inf"), ok=False, dominant="")
        return out
    lam = m.eigenvalues[k]
    f = float(m.frequency_hz[k])
    mis = abs(out["design_f_hz"] - f) / f
    out.update(grid_lambda=complex(lam), grid_f_hz=f, grid_zeta=float(m.damping_ratio[k]),
               participation=part, mismatch=mis, ok=bool(mis <= MODE_TOLERANCE),
               dominant=", ".join(f"{n} {p:.2f}" for n, p in m.dominant_states(k)))
    return out


def _load_trained(path: Path, key: str):
    """The controller trained earlier into ``path`` if it was trained on the same inputs."""
    from ..models import load_controller

    if not path.is_file():
        return None
    try:
        ctl = load_controller(path)
    except (ValueError, OSError):
        return None
    return ctl if ctl.problem.get("inputs_key") == key else None


def _design_notes(study, setup, check):
    d = setup.design
    pre = load_preset(study.data["design"]["settings"]).system
    rel = {k: (getattr(d, k) - getattr(pre, k)) / getattr(pre, k)
           for k in ("a", "Vr_bar", "phi_s0")}
    notes = [f"{study.name}, {setup.load} load, {setup.upqc} UPQC: the training uses Q, R, P, γ, "
             f"Ω, mesh, basis and initial policy of the {study.data['design']['settings']} "
             "preset" + (f"; derived a {rel['a']:+.2%}, V̄r {rel['Vr_bar']:+.2%}, ϕs0 "
                         f"{rel['phi_s0']:+.2%} from its design model"
                         if study.data["study"]["reproduce"] else "")]
    if not check["ok"]:
        notes.append(f"MISMATCH: the design model's mode ({check['design_f_hz']:.3g} Hz) differs "
                     f"from the full grid's mode of the controlled machine "
                     f"({check['grid_f_hz']:.3g} Hz) by {check['mismatch']:.1%} "
                     f"(> {MODE_TOLERANCE:.0%}): the design model (10) does not describe this "
                     "grid's dynamics well at this operating point")
    return notes


def run_studies(studies, output, quick=False, log=print, title=None, progress=True) -> dict:
    """Run every (scenario, controller) of ``studies`` and write everything to ``output``.

    Returns a summary dict (claims, metrics, figures, report, designs).
    """
    out = Path(output)
    runs_dir = out / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    plan = []   # (study, [Run], training keys)
    for st in studies:
        runs = [Run.of(st, sc, c) for sc, c in st.runs(quick)]
        keys = sorted({(r.load, r.upqc) for r in runs if controller_kind(st, r.controller) == "hji"})
        plan.append((st, runs, keys))
    total = sum(len(r) + len(k) for _, r, k in plan)
    # a used folder: runs this plan does not make are stale; finished runs with the same
    # inputs are kept and not redone (an interrupted run continues where it stopped)
    remove_stale(runs_dir, [r.id for _, runs, _ in plan for r in runs], log)
    remove_stale(out / "controllers", [f"{st.name}-{ld}-{u}" for st, _, keys in plan
                                       for ld, u in keys], log, suffix=".controller.json")
    n_kept = 0
    bar = _progress(total, progress)
    designs, notes, metrics, records, claims_spec, fig_specs = [], {}, [], {}, [], []
    for st, runs, keys in plan:
        trained = {}
        case_notes = list(st.data["study"]["notes"]) + list(st.data["report"]["notes"])
        pre = load_preset(st.data["design"]["settings"]).system
        for load, upqc in keys:
            bar.set_postfix_str(f"design + train {st.name} {load} {upqc}")
            setup = build_setup(st, load, upqc)
            check = mode_check(setup)
            ckey = inputs_key(study=st.data, load=load, upqc=upqc)
            cpath = out / "controllers" / f"{st.name}-{load}-{upqc}.controller.json"
            ctl = _load_trained(cpath, ckey)
            if ctl is None:
                problem, ctl = train_hji(st, setup.design)
                ctl.problem["inputs_key"] = ckey
                ctl.save(cpath)
            else:
                n_kept += 1
            trained[(load, upqc)] = ctl
            case_notes += _design_notes(st, setup, check)
            d = setup.design
            designs.append({
                "case": st.name, "load": load, "upqc": upqc, "T": f"{d.T:.4g}",
                "a": f"{d.a:.4g}", "Vr_bar": f"{d.Vr_bar:.4g}", "phi_s0": f"{d.phi_s0:.4g}",
                "preset": f"{pre.T:.4g}, {pre.a:.4g}, {pre.Vr_bar:.4g}, {pre.phi_s0:.4g}",
                "modes": f"{check['design_f_hz']:.3g} Hz vs {check['grid_f_hz']:.3g} Hz "
                         f"(ζ = {check['grid_zeta']:.3g}; {check['mismatch']:+.1%})"
                         + ("" if check["ok"] else " MISMATCH"),
                "training": f"{ctl.iterations['outer']} outer, W = "
                            f"{np.array2string(ctl.weights, precision=3, max_line_width=200)}",
                "derivation": setup.derivation.to_dict(), "mode_check": {
                    k: (str(v) if isinstance(v, complex) else v) for k, v in check.items()}})
            bar.update(1)
        notes[st.name] = case_notes
        for run in runs:
            bar.set_postfix_str(run.id)
            hji = trained.get((run.load, run.upqc))
            rkey = inputs_key(study=st.data, run=run.to_dict(),
                              controller=hji.problem.get("inputs_key") if hji else None)
            rec = load_run(runs_dir, run, rkey, RunRecord)
            if rec is None:
                rec = run_scenario(st, run, trained)
                save_run(rec, runs_dir, rkey)
            else:
                n_kept += 1
            records[run.id] = rec
            metrics.append(rec.metrics)
            bar.update(1)
        claims_spec += st.data["claims"]
        fig_specs += figure_specs(st, quick)
    bar.close()
    if n_kept:
        log(f"kept {n_kept} finished result(s) of an earlier run with the same inputs")
    figs = write_figures(records, out / "figures", fig_specs)
    csv, md = write_tables(metrics, out)
    claims = judge_all(claims_spec, {m["id"]: m for m in metrics})
    wall = time.perf_counter() - t0
    params = json.dumps({"studies": [{"source": st.source, "study": st.data} for st in studies],
                         "quick": quick}, indent=1, default=str)
    report = write_html(out / "report.html", claims=claims, metrics=metrics,
                        figures=[str(p.relative_to(out)) for p in figs if p.suffix == ".png"],
                        designs=designs, notes=notes,
                        meta={"version": __version__, "n_runs": len(metrics), "wall_s": wall,
                              "mode": "quick" if quick else "full", "parameters": params,
                              "title": title or ", ".join(st.name for st in studies)})
    write_json_atomic(out / "claims.json", {"claims": claims, "weakgrid_version": __version__,
                                            "quick": quick, "wall_s": wall})
    write_json_atomic(out / "designs.json", {"designs": designs, "weakgrid_version": __version__})
    log(f"wrote {report}, {csv}, {md}, {len(figs)} figure files in {wall:.0f} s")
    return {"claims": claims, "metrics": metrics, "figures": figs, "report": report,
            "csv": csv, "markdown": md, "wall_s": wall, "designs": designs}
