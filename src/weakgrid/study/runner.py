"""Run one scenario on the detailed simulator and measure it."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..sim.controllers import DigitalController, UPQCTarget
from ..sim.events import Fault
from ..sim.integrate import simulate
from .cases import build_case
from .controllers import case_variant, make_controller
from .metrics import backswing, control_cost, itae, running_cost, settling_time, stability_verdict

__all__ = ["RunRecord", "run_scenario", "FAULT_IMPEDANCE"]

# default fault impedance (pu on the system base) where a case's data give none
FAULT_IMPEDANCE = {"rf": 0.0, "xf": 1e-3}
Q_DESIGN = 0.01 * np.eye(2)  # the paper's state weight of (18)
R_DESIGN = np.eye(2)


class _MeasureOnly:
    """A controller target that applies nothing: samples the design states for the
    running cost when no UPQC is driven (PQ baseline)."""

    size = 2

    def bind(self, system):
        self._u = np.zeros(2)

    def get(self):
        return self._u

    def apply(self, u):
        self._u = np.asarray(u, float)


@dataclass
class RunRecord:
    """What a run produced: metrics (flat dict) and the series the figures need."""

    scenario: object
    metrics: dict
    series: dict
    info: dict = field(default_factory=dict)


def _disable_pss(system):
    pss = system.components.get("IEEEST")
    if pss is not None:
        pss.p["KS"] = np.zeros_like(pss.p["KS"])


def run_scenario(sc, trained=None, dt=None) -> RunRecord:
    """Simulate scenario ``sc`` and compute its metrics.

    Parameters
    ----------
    sc : Scenario
    trained : dict, optional
        ``(case, load, upqc) -> GameController`` cache of trained HJI controllers.
    dt : float, optional
        Integration step (default: the controller's sampling period T).
    """
    case = build_case(sc.case, sc.load, sc.upqc, case_variant(sc.controller))
    key = (sc.case, sc.load, sc.upqc)
    ctl = (trained or {}).get(key)
    up_ = case.system.components.get("UPQC")
    rating = float(up_.p["Vmax"][up_.names.index(case.upqc_name)]) if up_ is not None and \
        case.upqc_name in up_.names else None
    choice = make_controller(sc.controller, sc.case, case.design, ctl, u_bound=rating)
    if not choice.pss:
        _disable_pss(case.system)
    T = case.design.T
    xs = []
    policy = choice.policy

    def K(m):
        m = np.asarray(m, float)
        u = np.zeros(2) if policy is None else np.asarray(policy(m), float).reshape(2)
        xs.append(m.copy())
        return u

    target = UPQCTarget(case.upqc_name) if case.upqc_name else _MeasureOnly()
    dc = DigitalController(K, T=T, measure=case.measure, target=target,
                           enable=[(0.0, sc.t_fault), (sc.t_clear, sc.t_end + 1.0)],
                           name=sc.controller)
    fz = {k: float(case.info.get("fault", {}).get(k, v)) for k, v in FAULT_IMPEDANCE.items()}
    fault = Fault(bus=case.fault_bus, t_on=sc.t_fault, t_off=sc.t_clear, **fz)
    t0 = time.perf_counter()
    res = simulate(case.system, sc.t_end, dt=dt or T, events=[fault], controllers=[dc],
                   on_failure="return")
    wall = time.perf_counter() - t0
    # controller samples: times and (bypass-aware) outputs actually applied
    tk = np.asarray(dc.log_t)
    uk = np.asarray(dc.log_u).reshape(-1, 2)
    xk = np.full((len(tk), 2), np.nan)
    # measurements were logged only when active; align them by the active mask
    active = np.array([dc.active(t) for t in tk])
    xk[active] = np.asarray(xs).reshape(-1, 2)[: active.sum()]
    sig = case.signals
    t = res.t
    series = {"t": t}
    for key_, name in sig.items():
        if name in res:
            series[key_] = res[name]
    metrics = {"id": sc.id, "case": sc.case, "load": sc.load, "upqc": sc.upqc,
               "controller": sc.controller, "fault": f"{sc.t_fault:g}-{sc.t_clear:g} s",
               "failed": res.failure is not None,
               "failure": str(res.failure) if res.failure is not None else "",
               "wall_s": wall}
    after = sc.t_clear
    post = t >= after
    for key_, label in (("sg_speed", "speed"), ("dc_voltage", "vdc")):
        if key_ not in series:
            continue
        y = series[key_]
        ok = np.isfinite(y) & post
        if ok.sum() > 2:
            metrics[f"{label}_peak_dev_pu"] = float(np.max(np.abs(y[ok] - y[0])))
            metrics[f"{label}_backswing_pu"] = backswing(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_settling_s"] = settling_time(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_itae"] = itae(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_verdict"] = stability_verdict(t[ok], y[ok], after) \
                if res.failure is None else "unstable"
        else:
            metrics.update({f"{label}_peak_dev_pu": float("nan"),
                            f"{label}_backswing_pu": float("nan"),
                            f"{label}_settling_s": float("nan"),
                            f"{label}_itae": float("nan"), f"{label}_verdict": "unstable"})
    xa = np.nan_to_num(xk)
    # what the UPQC applied: |Vu| scaled down to its rating, as the simulator does
    up = case.system.components.get("UPQC")
    vmax = float(up.p["Vmax"][up.names.index(case.upqc_name)]) if up is not None and \
        case.upqc_name in up.names else float("inf")
    mag = np.hypot(uk[:, 0], uk[:, 1]) if uk.size else np.zeros(0)
    ua = uk * np.minimum(1.0, vmax / np.where(mag > 0, mag, 1.0))[:, None] if uk.size else uk
    metrics["control_cost"] = control_cost(ua, R_DESIGN, T)
    metrics["control_cost_demanded"] = control_cost(uk, R_DESIGN, T)
    rc = running_cost(xa, ua, Q_DESIGN, R_DESIGN)
    metrics["running_cost_18"] = float(rc[-1]) if rc.size else 0.0
    series["tk"], series["running_cost"] = tk, rc
    series["x_design"] = xk
    if "vup" in series and "vuq" in series:
        vu = np.hypot(series["vup"], series["vuq"])
        series["vu"] = vu
        metrics["vu_peak_pu"] = float(np.nanmax(vu)) if vu.size else 0.0
        metrics["vu_rms_pu"] = float(np.sqrt(np.nanmean(vu[post] ** 2))) if post.any() else 0.0
        metrics["vu_rating_pu"] = vmax
        metrics["vu_rating_reached"] = bool(metrics["vu_peak_pu"] >= vmax * (1 - 1e-6))
    if "p_series" in series:
        pmw = series["p_series"] * case.Sb_mva
        series["p_series_mw"] = pmw
        pk = float(np.nanmax(np.abs(pmw[post]))) if post.any() else float("nan")
        metrics["p_series_peak_mw"] = pk
        metrics["p_series_peak_pct_line"] = 100 * pk / abs(case.line_power_mw) \
            if case.line_power_mw else float("nan")
    metrics["line_power_mw"] = case.line_power_mw
    info = {"design": case.design.to_dict(), "case_info": case.info, "controller": choice.info}
    return RunRecord(sc, metrics, series, info)
