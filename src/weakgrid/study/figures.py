"""The paper's figures (Figs. 7–16 for case 1, 18–25 for case 2), from run records.

Each figure is a row of :data:`FIGURES`: the panels (signal, axis label with its
unit) and the runs drawn in every panel. Missing runs (``--quick``) are left out
and named in the figure's note.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.fonttype"] = "none"  # keep text as text: labels stay searchable
import matplotlib.pyplot as plt  # noqa: E402

from ..fileio import savefig_atomic  # noqa: E402

__all__ = ["FIGURES", "write_figures"]

SPEED = ("sg_speed", "SG speed [pu]")
VDC = ("dc_voltage", "dc-link voltage [pu]")
VUP = ("vup", "series voltage Vup [pu]")
VUQ = ("vuq", "series voltage Vuq [pu]")
PMW = ("p_series_mw", "UPQC injected power [MW]")
PKW = ("p_series_kw", "UPQC injected power [kW]")
COST = ("running_cost", "running cost of (18) [–]")

HJI, N29, PQ = "HJI (optimal, (24))", "nonlinear (29)", "PQ control, no UPQC"
LQR = "LQR"


def _c1(load, ctrl, upqc="conv"):
    return f"c1-{load}-{upqc}-{ctrl}"


def _c2(load, f, ctrl):
    return f"c2-{load}-{f}-{ctrl}"


FIGURES = [
    ("fig07", "Case 1, high load: SG speed and RG dc-link voltage", [SPEED, VDC],
     [(_c1("high", "hji"), HJI), (_c1("high", "nonlinear-29"), N29), (_c1("high", "pq"), PQ)]),
    ("fig08", "Case 1, high load: UPQC series voltage", [VUP, VUQ],
     [(_c1("high", "hji"), HJI), (_c1("high", "nonlinear-29"), N29)]),
    ("fig09", "Case 1, high load: UPQC injected power", [PMW],
     [(_c1("high", "hji"), HJI), (_c1("high", "nonlinear-29"), N29)]),
    ("fig10", "Case 1, high load: running cost", [COST],
     [(_c1("high", "hji"), HJI), (_c1("high", "nonlinear-29"), N29)]),
    ("fig11", "Case 1, low load: SG speed and RG dc-link voltage", [SPEED, VDC],
     [(_c1("low", "hji"), HJI), (_c1("low", "nonlinear-29"), N29), (_c1("low", "pq"), PQ)]),
    ("fig12", "Case 1, low load: UPQC series voltage", [VUP, VUQ],
     [(_c1("low", "hji"), HJI), (_c1("low", "nonlinear-29"), N29)]),
    ("fig13", "Case 1, low load: running cost", [COST],
     [(_c1("low", "hji"), HJI), (_c1("low", "nonlinear-29"), N29)]),
    ("fig14", "Case 1, reduced UPQC, HJI: SG speed and dc-link voltage", [SPEED, VDC],
     [(_c1("high", "hji", "red"), "high load"), (_c1("low", "hji", "red"), "low load")]),
    ("fig15", "Case 1, reduced UPQC, HJI: series voltage", [VUP, VUQ],
     [(_c1("high", "hji", "red"), "high load"), (_c1("low", "hji", "red"), "low load")]),
    ("fig16", "Case 1, reduced UPQC, HJI: injected power", [PMW],
     [(_c1("high", "hji", "red"), "high load"), (_c1("low", "hji", "red"), "low load")]),
    ("fig18", "Case 2, high load, fault 0.2 s: SG speed", [SPEED],
     [(_c2("high", "f200", "hji"), HJI), (_c2("high", "f200", "lqr"), LQR)]),
    ("fig19", "Case 2, high load, fault 0.2 s: UPQC series voltage", [VUP, VUQ],
     [(_c2("high", "f200", "hji"), HJI), (_c2("high", "f200", "lqr"), LQR)]),
    ("fig20", "Case 2, high load, fault 0.2 s: UPQC injected power", [PKW],
     [(_c2("high", "f200", "hji"), HJI), (_c2("high", "f200", "lqr"), LQR)]),
    ("fig21", "Case 2, high load, fault 0.1 s: SG speed", [SPEED],
     [(_c2("high", "f100", "hji"), HJI), (_c2("high", "f100", "lqr"), LQR)]),
    ("fig22", "Case 2, high load, fault 0.1 s: UPQC series voltage", [VUP, VUQ],
     [(_c2("high", "f100", "hji"), HJI), (_c2("high", "f100", "lqr"), LQR)]),
    ("fig23", "Case 2, high load, fault 0.1 s: UPQC injected power", [PKW],
     [(_c2("high", "f100", "hji"), HJI), (_c2("high", "f100", "lqr"), LQR)]),
    ("fig24", "Case 2, low load, fault 0.1 s: SG speed", [SPEED],
     [(_c2("low", "f100", "hji"), HJI), (_c2("low", "f100", "lqr"), LQR),
      (_c2("low", "f100", "pss-only"), "PSS alone")]),
    ("fig25", "Case 2, low load, fault 0.1 s: UPQC series voltage", [VUP, VUQ],
     [(_c2("low", "f100", "hji"), HJI), (_c2("low", "f100", "lqr"), LQR)]),
]


def _series(rec, key):
    s = rec.series
    if key == "p_series_kw":
        return (s["t"], s["p_series_mw"] * 1e3) if "p_series_mw" in s else None
    if key == "running_cost":
        return (s["tk"], s["running_cost"]) if len(s.get("tk", [])) else None
    return (s["t"], s[key]) if key in s else None


def write_figures(records: dict, folder, formats=("png", "svg")) -> list[Path]:
    """Write every figure of :data:`FIGURES` for the runs in ``records`` (id → RunRecord)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for fig_id, title, panels, runs in FIGURES:
        fig, axes = plt.subplots(len(panels), 1, figsize=(7.0, 2.6 * len(panels) + 0.6),
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
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=8, loc="best")
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle(f"{fig_id.replace('fig', 'Fig. ')} — {title}", fontsize=10)
        if missing:
            fig.text(0.01, 0.005, "not run: " + ", ".join(missing), fontsize=7, color="0.4")
        fig.tight_layout(rect=(0, 0.02, 1, 1))
        for fmt in formats:
            p = folder / f"{fig_id}.{fmt}"
            savefig_atomic(fig, p, dpi=110)
            written.append(p)
        plt.close(fig)
    return written
