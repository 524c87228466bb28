"""The paper's case 2 (SG + UPQC, LV microgrid) in the phasor engine and in DPsim (DP, EMT).

    PYTHONPATH=src python scripts/emt_case2.py OUT_DIR [--t-end 6] [--dt 1e-4]

The study ``case2-lv-microgrid`` at high load, built as the phasor run builds it
(:func:`weakgrid.study.build.build_setup`), with the controllers ``pss-only`` (no UPQC control),
``lqr`` and ``hji`` (:func:`weakgrid.study.controllers.make_controller`), each in three engines.
Two changes from the study, both applied to every engine alike (DPsim lacks the models): the
SG's GENROU is unsaturated (``S10 = 0``), and the fault at the UPQC shunt bus (3.0-3.1 s,
scenario ``c2-high-f100``) is bolted (``xf = 1e-4`` pu instead of 0.01 pu on the 1 MVA base:
DPsim's fault switch is resistive). Writes ``OUT_DIR/emt_case2.json`` (metrics per controller
and engine) and ``OUT_DIR/emt_case2.png`` (SG speed and ``|Vu|``), atomically.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from weakgrid.fileio import savefig_atomic, write_json_atomic
from weakgrid.sim.controllers import DigitalController, UPQCTarget
from weakgrid.sim.emt import simulate_dpsim
from weakgrid.sim.emt.controllers import sg_signals
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.study.build import build_setup
from weakgrid.study.controllers import controller_variant, make_controller
from weakgrid.study.metrics import settling_time
from weakgrid.study.runner import enable_windows
from weakgrid.study.studyfile import load_study

CONTROLLERS = ("pss-only", "lqr", "hji")
ENGINES = ("phasor", "dpsim-dp", "dpsim-emt")
T_ON, T_OFF = 3.0, 3.1
SIGNALS = ("SG.omega", "SG.delta", "SG.vf", "U.Vu")


def run_all(t_end: float, dt: float) -> dict:
    """``{(controller, engine): (t, {signal: values}, failure)}``."""
    st = load_study("case2-lv-microgrid")
    st.data["dynamics"]["generator"][0]["machine"]["S10"] = 0.0
    out = {}
    for ctrl in CONTROLLERS:
        for eng in ENGINES:
            setup = build_setup(st, "high", None, controller_variant(st, ctrl))
            policy, smap = make_controller(st, ctrl, setup.design, None).policy, setup.state_map
            r_id = int(setup.signals["shunt_bus_v"][3:-2])       # "bus<id>.v"
            bus = setup.system.network.index_of(r_id)
            ev = [Fault(bus=r_id, t_on=T_ON, t_off=T_OFF, xf=1e-4)]

            def K(y, policy=policy, smap=smap):
                m = smap(np.asarray(y, float))
                return np.zeros(2) if policy is None else np.asarray(policy(m), float).reshape(2)

            meas = setup.measure_signals if eng == "phasor" else sg_signals("SG", r_id)
            dc = DigitalController(K, T=setup.design.T, measure=meas,
                                   target=UPQCTarget(setup.upqc_name),
                                   enable=enable_windows([], t_end), name=ctrl)
            if eng == "phasor":
                r = simulate(setup.system, t_end, dt=dt, events=ev, controllers=[dc],
                             on_failure="return")
            else:
                r = simulate_dpsim(setup.system, t_end, engine=eng, dt=dt, events=ev,
                                   controllers=[dc], drop_saturation=True)
            out[(ctrl, eng)] = (r.t, {n: r[n] for n in SIGNALS}, r.failure)
            print(ctrl, eng, "bus", bus, "failure", r.failure, file=sys.stderr, flush=True)
    return out


def metrics(runs: dict) -> dict:
    """Speed peak deviation after clearing [pu], speed settling (2 % band) [s after clearing],
    largest ``|Vu|`` [pu] per controller and engine."""
    m = {}
    for (ctrl, eng), (t, y, fail) in runs.items():
        w, post = y["SG.omega"], t >= T_OFF
        m.setdefault(ctrl, {})[eng] = {
            "speed_peak_dev_pu": float(np.max(np.abs(w[post] - 1.0))),
            "speed_settling_s": settling_time(t[post], w[post], T_OFF, y_final=1.0),
            "vu_peak_pu": float(np.nanmax(y["U.Vu"])),
            "angle_peak_rad": float(np.max(y["SG.delta"])),
            "failed": fail is not None}
    return m


def figure(runs: dict, path: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, len(CONTROLLERS), figsize=(12, 6), sharex=True, sharey="row")
    style = {"phasor": dict(color="k", lw=1.2), "dpsim-dp": dict(color="tab:orange", lw=1.0),
             "dpsim-emt": dict(color="tab:blue", lw=0.8, ls="--")}
    for j, ctrl in enumerate(CONTROLLERS):
        for eng in ENGINES:
            t, y, _ = runs[(ctrl, eng)]
            ax[0, j].plot(t, y["SG.omega"], label=eng, **style[eng])
            ax[1, j].plot(t, y["U.Vu"], label=eng, **style[eng])
        ax[0, j].set_title(ctrl)
        ax[1, j].set_xlabel("t [s]")
        ax[0, j].set_xlim(2.8, t[-1])
    ax[0, 0].set_ylabel("SG speed [pu]")
    ax[1, 0].set_ylabel("|Vu| [pu]")
    ax[0, 0].legend()
    fig.suptitle("Case 2 (unsaturated SG, bolted fault 3.0-3.1 s at the UPQC shunt bus)")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--t-end", type=float, default=6.0)
    ap.add_argument("--dt", type=float, default=1e-4)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = run_all(a.t_end, a.dt)
    write_json_atomic(out / "emt_case2.json", metrics(runs))
    figure(runs, out / "emt_case2.png")


if __name__ == "__main__":
    main()
