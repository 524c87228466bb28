"""Figures of a study's runs, as data: each ``[[figures]]`` entry of a study file gives the
panels (series keys of :data:`PANELS`, each with its axis label and unit) and the runs drawn
in every panel (``[run id, legend label]``). The paper's Figs. 7–16 and 18–25 are such entries
in the shipped paper studies. Missing runs (``--quick``) are left out and named in the
figure's note.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

from ..figure import new_figure
from ..fileio import savefig_atomic
from .protocol import controller_name, describe_event, speed_machine

__all__ = ["PANELS", "MACHINE_PANELS", "figure_specs", "panel_label", "write_figures"]

# panel key -> axis label (with unit); keys are run series (see weakgrid.study.build signals)
PANELS = {
    "sg_speed": "SG speed [pu]",
    "dc_voltage": "dc-link voltage [pu]",
    "vup": "series voltage Vup [pu]",
    "vuq": "series voltage Vuq [pu]",
    "vu": "series voltage |Vu| [pu]",
    "p_series_mw": "UPQC injected power [MW]",
    "p_series_kw": "UPQC injected power [kW]",
    "running_cost": "(18): Σx'Qx+u'Ru [–]",
    "running_cost_w": "(18) with −γ²w'Pw [–]",
    "value_J": "J(x(t)) of (30) [–]",
    "shunt_bus_v": "shunt-bus voltage [pu]",
    "phi_hat": "GTI phase error [rad]",
    "sg_pe": "SG electrical power [pu]",
}
# panels of one machine: their label names it (``{m}``: the machine, spec key ``machine``)
MACHINE_PANELS = {"sg_speed": "speed of {m} [pu]", "sg_pe": "electrical power of {m} [pu]"}


def panel_label(key: str, machine: str | None = None) -> str:
    """The axis label of panel ``key``, naming ``machine`` where the panel is one machine's."""
    if machine and key in MACHINE_PANELS:
        return MACHINE_PANELS[key].format(m=machine)
    return PANELS.get(key, key)


def figure_specs(study, quick=False) -> list[dict]:
    """The study's ``[[figures]]`` (id, title, panels, runs = [[run id, label]]), or one figure
    per scenario (every controller; speed, dc link, series voltage, power) if it gives none."""
    figs = study.data.get("figures") or []
    machine = speed_machine(study)
    if figs:
        return [dict(f, machine=machine) for f in figs]
    out = []
    kind_gti = any(g["name"] == study.data["machine"]["name"] for g in
                   study.data["dynamics"]["gti"])
    for sc in study.scenarios(quick):
        speed = [] if study.data["report"].get("speed_of") == "" else ["sg_speed"]
        panels = speed + (["dc_voltage"] if kind_gti else []) + ["vu", "p_series_mw"]
        event = "; ".join(describe_event(e) for e in sc["events"]) or "no event"
        out.append({"id": f"{study.name}-{sc['id']}", "machine": machine,
                    "title": f"{study.name}, {sc['id']}: {event}",
                    "panels": panels,
                    "runs": [[f"{sc['id']}-{c}", controller_name(study, c)]
                             for c in sc["controllers"]]})
    return out


def _series(rec, key):
    s = rec.series
    if key == "p_series_kw":
        return (s["t"], s["p_series_mw"] * 1e3) if "p_series_mw" in s else None
    if key in ("running_cost", "running_cost_w", "value_J"):   # per controller sample
        k = rec.samples
        return (k["tk"], k[key]) if len(k.get("tk", [])) and key in k else None
    return (s["t"], s[key]) if key in s else None


VOLTAGE_PANELS = {"vu": 1, "vup": 2, "vuq": 2}   # series-voltage panels: draw the rating (±)


def _annotate(ax, key, recs):
    """Shade the fault windows of the drawn runs; draw the UPQC rating on series voltages."""
    seen = set()
    for rec in recs:
        for ev in rec.scenario.events:
            if ev.get("kind") == "fault" and (ev["t_on"], ev["t_off"]) not in seen:
                seen.add((ev["t_on"], ev["t_off"]))
                ax.axvspan(ev["t_on"], ev["t_off"], color="0.85", zorder=0,
                           label="fault" if len(seen) == 1 else None)
    if key in VOLTAGE_PANELS:
        ratings = {rec.metrics.get("vu_rating_pu") for rec in recs}
        for r in sorted(v for v in ratings if v is not None and v == v and v < 1e6):
            ax.axhline(r, color="k", ls="--", lw=0.8, label=f"UPQC rating {r:g} pu")
            if VOLTAGE_PANELS[key] == 2:
                ax.axhline(-r, color="k", ls="--", lw=0.8)


def write_figures(records: dict, folder, specs, formats=("png", "svg")) -> list[Path]:
    """Write every figure of ``specs`` (:func:`figure_specs`) for ``records`` (id → RunRecord)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for spec in specs:
        fig_id, title = spec["id"], spec["title"]
        panels = [(k, panel_label(k, spec.get("machine"))) for k in spec["panels"]]
        runs = [tuple(r) for r in spec["runs"]]
        fig, axes = new_figure(len(panels), 1, figsize=(7.0, 2.6 * len(panels) + 0.6),
                               sharex=True, squeeze=False)
        missing = []
        for ax, (key, ylabel) in zip(axes[:, 0], panels):
            for rid, label in runs:
                rec = records.get(rid)
                if rec is None:
                    if rid not in missing:
                        missing.append(rid)
                    continue
                ts = _series(rec, key)
                if ts is None:
                    continue
                t, y = ts
                failed = rec.metrics.get("failed")
                ax.plot(t, y, lw=1.1, label=label + (" (simulation failed)" if failed else ""))
            _annotate(ax, key, [records[r] for r, _ in runs if r in records])
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=8, loc="best")
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle("\n".join(textwrap.wrap(f"{spec.get('label', fig_id)} — {title}", 90)),
                     fontsize=10)
        if missing:
            fig.text(0.01, 0.005, "not run: " + ", ".join(missing), fontsize=7, color="0.4")
        fig.tight_layout(rect=(0, 0.02, 1, 1))
        for fmt in formats:
            p = folder / f"{fig_id}.{fmt}"
            savefig_atomic(fig, p, dpi=110)
            written.append(p)
    return written
