"""Closed-loop rollouts of a control-affine system under state feedback (batched)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import NonFiniteError, ParameterError

__all__ = ["Rollout", "rollout"]


@dataclass
class Rollout:
    """Trajectories of a batch of closed-loop runs.

    Attributes
    ----------
    states : ndarray (N+1, B, n)
    controls : ndarray (N, B, m)
    disturbances : ndarray (N, B, q)
    cost : ndarray (B,)
        Accumulated ``Σ x'Qx + u'Ru`` (and ``− γ² w'Pw`` if ``include_disturbance``).
    diverged : ndarray of bool (B,)
        Runs whose state left ``bound`` (their cost is accumulated until then and
        their later states are NaN).
    """

    states: np.ndarray
    controls: np.ndarray
    disturbances: np.ndarray
    cost: np.ndarray
    diverged: np.ndarray

    def final_norm(self) -> np.ndarray:
        return np.linalg.norm(self.states[-1], axis=-1)


def rollout(system, policy, x0, n_steps: int, *, Q=None, R=None, disturbance=None,
            P=None, gamma=None, bound: float = 1e6, penalty=None) -> Rollout:
    """Simulate ``x+ = f + g·π(x) + h·w(x)`` from a batch of initial states.

    Parameters
    ----------
    system : ControlAffineSystem
    policy : callable, (B, n) -> (B, m)
    x0 : array_like (B, n) or (n,)
    n_steps : int
    Q, R : weights of the accumulated cost (default identity)
    disturbance : callable, (B, n) -> (B, q), optional
        State feedback of the disturbance (e.g. the worst case ``w*``); default 0.
    P, gamma : used to subtract ``γ²w'Pw`` from the cost when a disturbance is given.
    bound : float
        A run whose state norm exceeds this is stopped and marked diverged.
    penalty : callable, (B, m) -> (B,), optional
        The control's charge instead of ``u'Ru`` (e.g. ``GameCost.control_penalty``
        of a cost with an input bound).
    """
    x = np.atleast_2d(np.asarray(x0, float)).copy()
    if n_steps < 1:
        raise ParameterError("n_steps", n_steps, "must be ≥ 1")
    n, m, q = system.n_states, system.n_controls, system.n_disturbances
    Q = np.eye(n) if Q is None else np.atleast_2d(Q)
    R = np.eye(m) if R is None else np.atleast_2d(R)
    B = x.shape[0]
    xs = np.full((n_steps + 1, B, n), np.nan)
    us = np.full((n_steps, B, m), np.nan)
    ws = np.zeros((n_steps, B, q))
    cost = np.zeros(B)
    alive = np.ones(B, bool)
    xs[0] = x
    for k in range(n_steps):
        xa = x[alive]
        if xa.shape[0] == 0:
            break
        u = np.asarray(policy(xa), float).reshape(-1, m)
        if not np.all(np.isfinite(u)):
            raise NonFiniteError(f"the policy returned NaN/inf at step {k}")
        w = np.zeros((xa.shape[0], q)) if disturbance is None else \
            np.asarray(disturbance(xa), float).reshape(-1, q)
        c = np.einsum("bi,ij,bj->b", xa, Q, xa) + (
            np.einsum("bi,ij,bj->b", u, R, u) if penalty is None else penalty(u))
        if disturbance is not None and gamma is not None:
            Pm = np.eye(q) if P is None else np.atleast_2d(P)
            c = c - gamma**2 * np.einsum("bi,ij,bj->b", w, Pm, w)
        cost[alive] += c
        xn = system.step(xa, u, w)
        us[k, alive], ws[k, alive] = u, w
        bad = ~np.all(np.isfinite(xn), axis=1) | (np.linalg.norm(xn, axis=1) > bound)
        idx = np.flatnonzero(alive)
        x[idx] = np.where(bad[:, None], np.nan, xn)
        alive[idx[bad]] = False
        xs[k + 1] = np.where(alive[:, None], x, np.nan)
    return Rollout(xs, us, ws, cost, ~alive)
