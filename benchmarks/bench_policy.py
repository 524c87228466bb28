"""The cost of one sample's policy evaluation (not a test: prints medians, asserts nothing).

A digital controller's sample calls the trained HJI policy ``u*(x)``
(:meth:`weakgrid.game.controller.GameController.control`: the basis' derivatives, the design
model, the saddle point of (22)) once per member, or once for a batch's members that share
the law (:meth:`weakgrid.study.law.StudyLaw.rows`). This file times that call for one state,
6 and 45 rows (a quick sweep's batch, a map's batch; the rows through
:meth:`~weakgrid.game.controller.GameController.rows`, each row's floats those of its call
alone), unbounded and with an input bound (the rating-bounded law: one minimization per
point), and the LQR law, on the paper's basis and the case-1 design
model (the ``case1-paper`` preset's controller, trained here first, about a second): CPU time
(``time.process_time``) per call, median of 5 rounds after a warm-up. Its cost is the number
of NumPy calls, not arithmetic; compare two versions of the code by running this file with
each on ``PYTHONPATH``, back to back.

Measured 2026-12-02 (load ≈ 0.7, the code before and after the basis' powers became one
cumulative product, its factors one gather and the Hessian planes one index, alternated
twice; the outputs bit for bit the same): one state 57–61 → 46–65 µs, 45 rows 112–119 →
98–169 µs — within this machine's noise at this size. Late that evening (load ≈ 1.3, old and
new alternated twice), the bounded law's point form with its sums written out (the same
floats): one state 157/190 → 120/122 µs, 6 rows 513/526 → 295/301 µs; 45 rows (the
vectorized iteration) 1032/1085 → 1053/1087 µs, unchanged. 2026-12-03 evening, the code before
and after the policies' term-by-term arithmetic (``weakgrid.game.rowwise``: a row's floats those
of its call alone) alternated twice, the machine noisy (up to 1.6× between rounds of the same
code): unbounded one state 50/83 → 82/85 µs, 6 rows 67/115 → 102/113 µs, 45 rows 104/160 →
183/215 µs; bounded 6 rows 493/529 → 316/487 µs, 45 rows 1809/1943 → 1919/3026 µs (point by
point now, the vectorized iteration rounding otherwise); LQR 4–6 → 6–12 µs.

Run:  PYTHONPATH=src python benchmarks/bench_policy.py
"""

from __future__ import annotations

import statistics
import time

import numpy as np


def _per_call(fn, rounds=5, calls=2000):
    for _ in range(calls // 10):
        fn()
    per = []
    for _ in range(rounds):
        c0 = time.process_time()
        for _ in range(calls):
            fn()
        per.append((time.process_time() - c0) / calls)
    return statistics.median(per)


def main():
    from weakgrid.game.controller import GameController
    from weakgrid.game.input_bound import InputBound
    from weakgrid.models.policies import lqr_policy
    from weakgrid.models.problem import load_preset

    ctl = load_preset("case1-paper").train()
    bounded = GameController(ctl.system, ctl.basis, ctl.weights,
                             ctl.cost.with_bound(InputBound.for_inputs(2, 0.05)), ctl.problem)
    rng = np.random.default_rng(0)
    X = rng.normal(scale=[0.05, 0.5], size=(45, 2))
    for name, c in (("unbounded", ctl), ("bounded (|u| ≤ 0.05 pu)", bounded)):
        for rows in (None, 6, 45):
            x = X[0] if rows is None else X[:rows]
            calls = 2000 if rows is None or name == "unbounded" else 200
            # the batched call of a simulation (GameController.rows; code before it: control)
            fn = c.control if rows is None else getattr(c, "rows", c.control)
            t = _per_call(lambda: fn(x), calls=calls)
            what = "one state" if rows is None else f"{rows} rows"
            print(f"{name:24s} {what:10s}: {1e6 * t:7.1f} µs CPU per call")
    lqr = lqr_policy(ctl.system, 0.01 * np.eye(2), np.eye(2))
    for rows in (None, 6, 45):
        x = X[0] if rows is None else X[:rows]
        t = _per_call(lambda: lqr(x))
        what = "one state" if rows is None else f"{rows} rows"
        print(f"{'LQR':24s} {what:10s}: {1e6 * t:7.1f} µs CPU per call")


if __name__ == "__main__":
    main()
