"""How far a trained controller is from the dynamic-programming ground truth.

Two measures (used by ``weakgrid verify``):

* **value error** — the approximate cost ``J`` against the DP value ``V`` at the
  DP grid nodes inside Ω: ``max|J − V| / max V`` and the median of
  ``|J − V| / V`` over nodes with ``V ≥ 1 %`` of its maximum (the relative error is
  meaningless where both vanish, at the origin);
* **closed-loop optimality gap** — from a set of starts, the accumulated cost
  ``Σ x'Qx + u'Ru − γ²w'Pw`` over a horizon of the controller's ``u*`` against the
  DP policy, (a) with no disturbance and (b) with the DP's worst-case
  disturbance ``w_dp(x)`` feeding back. By the saddle-point inequality
  ``J(u, w*) ≥ J(u*, w*)``, gap (b) is ≥ 0 up to the DP's accuracy, whose own
  consistency is reported too (``|cost(u_dp, w_dp) − V(x₀)| / V(x₀)``).
"""

from __future__ import annotations

import numpy as np

from .rollout import rollout

__all__ = ["value_error", "closed_loop_gap", "default_starts"]


def default_starts(lower, upper, fraction=0.5):
    """Corners, edge midpoints and face centres of Ω shrunk by ``fraction`` about its centre.

    Shrinking keeps the trajectories (which overshoot under the worst case) on the DP
    grid, where the DP policy is defined.
    """
    from .mesh import GridMesh

    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    c, h = 0.5 * (lo + hi), 0.5 * (hi - lo) * fraction
    return GridMesh(c - h, c + h, h).corners_and_midpoints()


def value_error(controller, dp, lower, upper) -> dict:
    """``J`` vs the DP value at the DP nodes inside ``[lower, upper]``."""
    X = dp.points
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    tol = 1e-9 * (hi - lo)
    X = X[np.all((X >= lo - tol) & (X <= hi + tol), axis=1)]
    V, J = dp.value(X), controller.value(X)
    big = V >= 0.01 * V.max()
    rel = np.abs(J - V)[big] / V[big]
    k = int(np.argmax(np.abs(J - V)))
    return {"n_nodes": int(X.shape[0]), "max_V": float(V.max()), "max_J": float(J.max()),
            "sup_error_over_max_V": float(np.abs(J - V).max() / V.max()),
            "median_relative_error": float(np.median(rel)),
            "p90_relative_error": float(np.quantile(rel, 0.9)),
            "worst_state": X[k].tolist(), "J_at_worst": float(J[k]), "V_at_worst": float(V[k]),
            "mean_signed_error_over_max_V": float((J - V).mean() / V.max())}


def _cost(system, cost, pol, dist, starts, steps):
    r = rollout(system, pol, starts, steps, Q=cost.Q, R=cost.R, disturbance=dist, P=cost.P,
                gamma=cost.gamma,
                penalty=cost.control_penalty if cost.bound is not None else None)
    return r.cost, r.diverged, r.states


def closed_loop_gap(controller, dp, starts, steps) -> dict:
    """Closed-loop costs of ``u*`` and of the DP policy, without and with the DP worst case."""
    system, cost = controller.system, controller.cost
    out = {"starts": np.asarray(starts).tolist(), "steps": int(steps),
           "J_at_starts": controller.value(starts).tolist(),
           "V_at_starts": dp.value(starts).tolist()}
    lo = np.array([a[0] for a in dp.axes])
    hi = np.array([a[-1] for a in dp.axes])
    for label, dist in (("no_disturbance", None), ("worst_case", dp.disturbance)):
        c_nn, d_nn, _ = _cost(system, cost, controller.control, dist, starts, steps)
        c_dp, d_dp, xs = _cost(system, cost, dp.control, dist, starts, steps)
        gap = (c_nn - c_dp) / np.abs(c_dp)
        xs = xs[np.all(np.isfinite(xs), axis=-1)]
        off = float(np.mean(np.any((xs < lo) | (xs > hi), axis=-1)))
        out[label] = {"cost_controller": c_nn.tolist(), "cost_dp": c_dp.tolist(),
                      "relative_gap": gap.tolist(), "mean_relative_gap": float(gap.mean()),
                      "max_relative_gap": float(gap.max()),
                      "min_relative_gap": float(gap.min()),
                      "diverged_controller": int(d_nn.sum()), "diverged_dp": int(d_dp.sum()),
                      "dp_fraction_of_steps_off_grid": off}
        if dist is not None:
            V0 = dp.value(starts)
            out["dp_consistency"] = float(np.max(np.abs(c_dp - V0) / V0))
    return out
