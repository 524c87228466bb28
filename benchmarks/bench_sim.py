"""Benchmark of weakgrid.sim (not a test: prints medians, asserts nothing).

1. kundur_full (ANDES stock case) with a 3-phase fault at bus 8, 1.0-1.05 s, trip disabled, 10 s:
   weakgrid and ANDES in the same run, each at the largest step whose speeds stay within
   2e-4 pu of its own converged solution (reference: step 1/480 s); median wall time of 9 runs
   (3 runs moved the ratio by 20-30 % between identical runs: single runs take 31-59 ms).
2. Throughput of 100 fault scenarios on a GTI + UPQC + SG grid (5 s each).
3. A DigitalController run: the GTI + UPQC + SG grid (reduced UPQC), a controller sampled every
   T = 1 ms (zero-order hold, a consistent algebraic re-solve after each sample) driving the UPQC
   with a smooth feedback of the GTI design states, fault 0.2-0.25 s, 5 s at dt = 1 ms; median of 3.

4. The cost of recording every signal (``record="all"``, what study runs keep in their run
   files) against selective recording (``record="machines"``: speeds and angles only), measured
   in the same run, interleaved: the controlled run of 3. and the fault scenarios of 2. (20 of
   them); medians of ``n`` repeats and their ratio (goal: all / selective ≤ 1.10).

5. Batched simulation (:mod:`weakgrid.sim.batch`): the 100 fault scenarios of 2. with their
   clearing times on the 5-ms step grid (so that every member takes the steps of its run alone;
   batched and one-by-one results are equal, ``tests/sim/test_batch.py``), run by
   ``simulate_batch`` at batch sizes 1, 10, 50, 100 in one process, interleaved (the two UPQC
   structures are two grids: a batch holds members of one grid, so 100 means two batches of 50),
   and by 2 processes (a pool started before timing), one grid's 50 scenarios in one batch each;
   medians of ``repeats``; batch size 1 on the first ``n_alone`` scenarios only (its rate is per
   scenario). Scenarios/s, their ratio to batch size 1, and the cost per batched step broken
   down (residual, Jacobian, LU, Newton update, recording, events/samples).
   ``batched_controlled``: the controlled run of 3. with a batched policy, alone and 10 and 50 of
   them (fault impedances 0.05-0.14 pu) in one batch, interleaved, medians; wall time per run and
   the same breakdown. ``batched-quick``: batch 1 / 50 / 100 and controlled 1 / 10 (a loaded machine).

Run:  PYTHONPATH=src python benchmarks/bench_sim.py [kundur] [scenarios] [controlled] [recording] [batched]
      [batched_controlled] | batched-quick
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "sim"))

from weakgrid.sim.peer.andes_runs import compare, run_andes, run_weakgrid  # noqa: E402

CASE = "kundur/kundur_full.xlsx"
FAULT = dict(fault=(8, 1.0, 1.05), disable_toggles=True)
STEPS = [1 / 5, 1 / 10, 1 / 15, 1 / 20, 1 / 30, 1 / 60, 1 / 120]


def largest_ok_step(run, ref, **kw):
    for h in STEPS:
        try:
            r = run(CASE, 10.0, h, **FAULT, **kw)
        except Exception:
            continue
        if r["ok"] and r["t"][-1] > 9.999 and compare(r, ref)[0] < 2e-4:
            return h, r
    return None, None


def median_wall(run, h, n=9, **kw):
    return statistics.median(run(CASE, 10.0, h, **FAULT, **kw)["wall"] for _ in range(n))


def kundur():
    print("== kundur_full, fault at bus 8 (1.0-1.05 s), 10 s ==")
    out = {}
    for name, run, kw in (("weakgrid", run_weakgrid, dict(tol=1e-5)), ("ANDES", run_andes, dict(tol=1e-4))):
        ref = run(CASE, 10.0, 1 / 480, **FAULT, **kw)
        h, r = largest_ok_step(run, ref, **kw)
        wall = median_wall(run, h, **kw)
        err = compare(r, ref)[0]
        out[name] = wall
        print(f"{name:9s} step 1/{1 / h:.0f} s  speed error vs own 1/480-s solution {err:.2e} pu  "
              f"median wall {wall * 1e3:.1f} ms")
    print(f"speed-up weakgrid vs ANDES: {out['ANDES'] / out['weakgrid']:.2f}x")


def scenarios(n=100):
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import Simulator

    rng = np.random.default_rng(0)
    t0 = time.perf_counter()
    ok = 0
    for k in range(n):
        s = build_gti_upqc_sg("reduced" if k % 2 else "conventional")
        bus = int(rng.integers(1, 4))
        ton = 0.2
        toff = ton + float(rng.uniform(0.03, 0.15))
        xf = float(rng.uniform(0.02, 0.2))
        r = Simulator(s, dt=5e-3, tol=1e-6).run(5.0, events=[Fault(bus, ton, toff, xf=xf)], on_failure="return")
        ok += r.ok
    wall = time.perf_counter() - t0
    print(f"== {n} fault scenarios, GTI + UPQC + SG grid, 5 s each, dt 5 ms ==")
    print(f"total {wall:.2f} s, {n / wall:.1f} runs/s, {ok}/{n} completed")


def controlled(n=3, tf=5.0):
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import simulate

    def K(m):   # smooth state feedback on [phi_hat, upsilon], within the series rating
        return [float(np.clip(-0.5 * m[0] - 2.0 * m[1], -0.15, 0.15)), float(np.clip(-0.2 * m[1], -0.1, 0.1))]

    walls = []
    for _ in range(n):
        s = build_gti_upqc_sg("reduced")
        ctrl = DigitalController(K, 1e-3, gti_design_states("PV"), UPQCTarget("U"), enable=[(0.25, tf)])
        t0 = time.perf_counter()
        r = simulate(s, tf, dt=1e-3, events=[Fault(3, 0.2, 0.25, xf=0.05)], controllers=[ctrl], on_failure="return")
        walls.append(time.perf_counter() - t0)
    print(f"== DigitalController T = 1 ms (ZOH) on the GTI + UPQC + SG grid, {tf:g} s, dt 1 ms ==")
    print(f"median wall {statistics.median(walls):.2f} s, {len(ctrl.log_t)} samples, ok={r.ok}, stats {r.stats}")


def recording(n=5, tf=5.0, n_scen=20):
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import Simulator, simulate

    def K(m):
        return [float(np.clip(-0.5 * m[0] - 2.0 * m[1], -0.15, 0.15)), float(np.clip(-0.2 * m[1], -0.1, 0.1))]

    def controlled_run(record):
        s = build_gti_upqc_sg("reduced")
        ctrl = DigitalController(K, 1e-3, gti_design_states("PV"), UPQCTarget("U"), enable=[(0.25, tf)])
        t0 = time.perf_counter()
        r = simulate(s, tf, dt=1e-3, events=[Fault(3, 0.2, 0.25, xf=0.05)], controllers=[ctrl],
                     on_failure="return", record=record)
        return time.perf_counter() - t0, r

    def scenario_runs(record):
        rng = np.random.default_rng(0)
        wall, cols = 0.0, 0
        for k in range(n_scen):
            s = build_gti_upqc_sg("reduced" if k % 2 else "conventional")
            bus, toff, xf = int(rng.integers(1, 4)), 0.2 + float(rng.uniform(0.03, 0.15)), float(rng.uniform(0.02, 0.2))
            t0 = time.perf_counter()
            r = Simulator(s, dt=5e-3, tol=1e-6, record=record).run(
                5.0, events=[Fault(bus, 0.2, toff, xf=xf)], on_failure="return")
            wall += time.perf_counter() - t0
            cols = r.data.shape[1]
        return wall, cols

    modes = {"all": None, "selective": "machines"}   # None = every signal on these grids
    walls = {("controlled", m): [] for m in modes} | {("scenarios", m): [] for m in modes}
    shape = {}
    for _ in range(n):          # interleaved: drift hits both alike
        for m, rec in modes.items():
            w, r = controlled_run(rec)
            walls[("controlled", m)].append(w)
            shape[("controlled", m)] = r.data.shape
            w, c = scenario_runs(rec)
            walls[("scenarios", m)].append(w)
            shape[("scenarios", m)] = c
    print(f"== recording every signal vs selective (speeds and angles), medians of {n} ==")
    for case in ("controlled", "scenarios"):
        a, b = (statistics.median(walls[(case, m)]) for m in modes)
        print(f"{case:10s} all {a:.3f} s ({shape[(case, 'all')]} recorded)  selective {b:.3f} s "
              f"({shape[(case, 'selective')]})  all/selective {a / b:.3f}")


def _fault_scenarios(n, dt=5e-3):
    """The scenarios of :func:`scenarios`, clearing times rounded onto the step grid."""
    from weakgrid.sim.events import Fault

    rng = np.random.default_rng(0)
    out = []
    for k in range(n):
        bus = int(rng.integers(1, 4))
        toff = 0.2 + round(float(rng.uniform(0.03, 0.15)) / dt) * dt
        xf = float(rng.uniform(0.02, 0.2))
        out.append(("reduced" if k % 2 else "conventional", {"events": [Fault(bus, 0.2, toff, xf=xf)]}))
    return out


def _breakdown(timing, steps, wall=None):
    """Time per batched step of each timed part [ms]; with the run's ``wall`` time, the rest
    (``other``: the per-member bookkeeping of the batch loop, jump re-solves' solves, checks)."""
    parts = dict(timing)
    if wall is not None:
        parts["other"] = wall - sum(timing.values())
    return "  ".join(f"{k} {v / max(steps, 1) * 1e3:.3f}" for k, v in parts.items()) + " [ms/step]"


def _batch_part(args):
    """Worker of :func:`batched`'s 2-process case: one grid's scenarios in batches of ``b``."""
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.batch import simulate_batch

    grid, n, b, tf = args
    sc = [s for g, s in _fault_scenarios(n) if g == grid]
    t0, c0 = time.perf_counter(), time.process_time()
    simulate_batch(build_gti_upqc_sg(grid), sc, tf, dt=5e-3, tol=1e-6, batch_size=b)
    return time.perf_counter() - t0, time.process_time() - c0


def batched(n=100, sizes=(1, 10, 50, 100), repeats=3, n_alone=10, tf=5.0, procs=True):
    import multiprocessing as mp

    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.batch import simulate_batch

    grids = {st: build_gti_upqc_sg(st) for st in ("conventional", "reduced")}
    print(f"== batched: {n} fault scenarios (clearing on the 5-ms grid), GTI + UPQC + SG, {tf:g} s, dt 5 ms ==")
    walls = {b: [] for b in sizes}
    cpus = {b: [] for b in sizes}     # CPU time of the process(es): what the load does not inflate
    st_all = {}
    pool = None
    if procs:      # 2 processes, one grid (50 scenarios, one batch) each; started before timing
        pool = mp.get_context("spawn").Pool(2)
        pool.map(_batch_part, [(g, 2, 50, 0.3) for g in grids])     # warm: imports, a first short run
        walls["2 proc"], cpus["2 proc"] = [], []
    for _ in range(repeats):      # interleaved: load drift hits every batch size alike
        for b in sizes:
            m = n_alone if b == 1 else n
            scen = _fault_scenarios(m)
            st_b = st_all[b] = {"batches": 0, "steps": 0, "halved": 0, "rerun": 0, "timing": {}}
            t0, c0 = time.perf_counter(), time.process_time()
            for grid in grids:
                st = {}
                sc = [s for g, s in scen if g == grid]
                simulate_batch(grids[grid], sc, tf, dt=5e-3, tol=1e-6, batch_size=b, stats=st)
                for k in ("batches", "steps", "halved", "rerun"):
                    st_b[k] += st[k]
                for k, v in st["timing"].items():
                    st_b["timing"][k] = st_b["timing"].get(k, 0.0) + v
            walls[b].append(time.perf_counter() - t0)
            cpus[b].append(time.process_time() - c0)
        if pool is not None:
            t0 = time.perf_counter()
            parts = pool.map(_batch_part, [(g, n, 50, tf) for g in grids])
            walls["2 proc"].append(time.perf_counter() - t0)
            cpus["2 proc"].append(max(c for _, c in parts))   # the busier process
    if pool is not None:
        pool.close()
    rates = {}
    for b in walls:
        m = n_alone if b == 1 else n
        w, c = statistics.median(walls[b]), statistics.median(cpus[b])
        rates[b] = m / w
        if b == "2 proc":
            print(f"2 processes x batch 50: {m} scenarios median {w:.2f} s -> {m / w:.2f} scenarios/s "
                  f"(CPU of the busier process {c:.2f} s -> {m / c:.2f} scenarios per CPU-second of it)")
            continue
        st = st_all[b]
        print(f"batch {b:3d}: {m} scenarios median {w:.2f} s -> {m / w:.2f} scenarios/s, CPU {c:.2f} s -> "
              f"{m / c:.2f} scenarios per CPU-second ({st['batches']} batches, {st['steps']} batched steps, {st['halved']} halved steps, "
              f"{st['rerun']} re-run alone)  per batched step (last repeat): {_breakdown(st['timing'], st['steps'])}")
    for b in list(walls)[1:]:
        print(f"ratio {b} vs batch 1: {rates[b] / rates[1]:.1f}x")


def batched_controlled(tf=5.0, sizes=(1, 10, 50), repeats=3):
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.batch import BatchSimulator
    from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
    from weakgrid.sim.events import Fault

    def K(m):   # the policy of controlled(), on arrays: one call for the whole batch
        m = np.asarray(m, dtype=float)
        return np.stack([np.clip(-0.5 * m[..., 0] - 2.0 * m[..., 1], -0.15, 0.15),
                         np.clip(-0.2 * m[..., 1], -0.1, 0.1)], axis=-1)

    s = build_gti_upqc_sg("reduced")
    print(f"== batched DigitalController T = 1 ms, {tf:g} s, dt 1 ms (medians of {repeats}, interleaved) ==")
    walls = {B: [] for B in sizes}
    cpus = {B: [] for B in sizes}
    last = {}
    for _ in range(repeats):
        for B in sizes:    # fault impedances 0.05 + 0.01 k pu (every 10th repeats: a batch of 50)
            sc = [{"events": [Fault(3, 0.2, 0.25, xf=0.05 + 0.01 * (k % 10))],
                   "controllers": [DigitalController(K, 1e-3, gti_design_states("PV"), UPQCTarget("U"),
                                                     enable=[(0.25, tf)], batched=True)]} for k in range(B)]
            bs = BatchSimulator(s, sc, dt=1e-3)
            t0, c0 = time.perf_counter(), time.process_time()
            res, rerun = bs.run(tf)
            walls[B].append(time.perf_counter() - t0)
            cpus[B].append(time.process_time() - c0)
            last[B] = (bs, res, rerun, walls[B][-1])
    per = {}
    for B in sizes:
        bs, res, rerun, w_last = last[B]
        w, c = statistics.median(walls[B]), statistics.median(cpus[B])
        per[B] = w / B
        ok = sum(r is not None and r.ok for r in res)
        print(f"{B:3d} run(s) in one batch: median {w:.2f} s, {w / B:.3f} s per run (CPU {c / B:.3f} s), {ok}/{B} completed, "
              f"{len(rerun)} re-run alone; {bs.steps} steps, {_breakdown(bs.timing, bs.steps, w_last)}")
    print(f"    member 0 stats {last[sizes[0]][1][0].stats}")
    for B in sizes[1:]:
        print(f"ratio per run, batch {B} vs 1: {per[1] / per[B]:.1f}x")


if __name__ == "__main__":
    if sys.argv[1:2] == ["batched-quick"]:     # interleaved 1 / 50 / 100 only (a loaded machine)
        batched(sizes=(1, 50, 100), n_alone=5, repeats=2)
        batched_controlled(sizes=(1, 10), repeats=1)
        sys.exit()
    which = sys.argv[1:] or ["kundur", "scenarios", "controlled", "recording", "batched", "batched_controlled"]
    for w in which:
        globals()[w]()
