"""The study-level Newton tolerance ``[simulation] tol`` against the step (not a test: prints
numbers, asserts nothing).

For sweep points of the paper's studies (HJI, the shipped rating and fault, both loads), three
runs each: the study's step T with the simulator's default tolerance for it
(:func:`weakgrid.sim.integrate.default_tol`), T with the study's ``[simulation] tol``, and T/2
with the default tolerance (the sweeps' numerical-uncertainty reference). Per metric: the
relative change the tolerance makes, ``|m(T, tol) − m(T, default)| / |m|``, beside the change
halving the step makes, ``|m(T, default) − m(T/2)| / |m|`` — the study's tolerance keeps "the
step, not the tolerance, sets the error" when the first is well below the second — and the CPU
time of each run (process time: the machine may be shared).

Run:  PYTHONPATH=src python benchmarks/bench_tolerance.py [case1-weak-grid case2-lv-microgrid]
"""

from __future__ import annotations

import math
import os
import sys
import time

from weakgrid.sim.integrate import default_tol
from weakgrid.study.runner import sim_settings
from weakgrid.study.studyfile import load_study
from weakgrid.study.sweep import run_point, sweep_points

METRICS = ("control_cost", "control_cost_demanded", "speed_backswing_pu", "speed_settling_s",
           "speed_itae", "vdc_backswing_pu", "vdc_settling_s", "vdc_itae",
           "p_series_peak_pct_line", "u_demanded_peak_pu", "omega_reach")


def _rel(a, b):
    a, b = float(a), float(b)
    if not (math.isfinite(a) and math.isfinite(b)) or a == 0:
        return math.nan
    return abs(a - b) / abs(a)


def check(name):
    st = load_study(name)
    sw = st.data["sweep"]
    chk = sw["dt_check"]
    dt, tol = sim_settings(st)
    print(f"\n{name}: step {dt:g} s, default tolerance {default_tol(dt):.2g}, study "
          f"tolerance {tol}")
    pts = [p for p in sweep_points(st) if p.params["controller"] == "hji"
           and p.params["dt_factor"] == 1.0
           and all(p.params[k] in v for k, v in chk.items())]
    worst = {}
    for p in pts:
        runs = {}
        for label, inputs in (
                ("default", dict(p.inputs, study=dict(p.inputs["study"], simulation={}))),
                ("study", p.inputs),
                ("half", dict(p.inputs, dt_factor=0.5))):
            run_point(inputs) if not runs else None    # first call: training (not timed)
            c0 = time.process_time()
            runs[label] = run_point(inputs)
            runs[label]["cpu_s"] = time.process_time() - c0
        where = ", ".join(f"{k.split('.')[-1]} = {v}" for k, v in p.params.items()
                          if k not in ("scenario", "controller", "dt_factor"))
        cpu = runs["default"]["cpu_s"], runs["study"]["cpu_s"], runs["half"]["cpu_s"]
        print(f"  {where}: CPU {cpu[0]:.2f} s (default tol), {cpu[1]:.2f} s (study tol, "
              f"{cpu[1] / cpu[0] - 1:+.0%}), {cpu[2]:.2f} s (T/2)")
        for m in METRICS:
            a = runs["default"].get(m, math.nan)
            d_tol = _rel(a, runs["study"].get(m, math.nan))
            d_step = _rel(a, runs["half"].get(m, math.nan))
            if math.isfinite(d_tol) and math.isfinite(d_step):
                print(f"    {m:<24} tolerance {d_tol:8.1e}   half step {d_step:8.1e}   "
                      f"ratio {d_tol / d_step if d_step else math.inf:6.3f}")
                w = worst.setdefault(m, [0.0, math.inf])
                w[0] = max(w[0], d_tol)
                w[1] = min(w[1], d_step)
    print(f"  {name}: largest tolerance effect / smallest half-step effect per metric:")
    for m, (dtol, dstep) in worst.items():
        print(f"    {m:<24} {dtol:8.1e} / {dstep:8.1e}")


if __name__ == "__main__":
    print(f"load average before: {os.getloadavg()}")
    for name in sys.argv[1:] or ["case1-weak-grid", "case2-lv-microgrid"]:
        check(name)
    print(f"load average after: {os.getloadavg()}")
