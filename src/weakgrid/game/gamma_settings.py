"""Settings of the minimum-γ search (:mod:`weakgrid.game.gamma_search`), standard library only: the CLI
reads their defaults without loading the solvers."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import ParameterError

__all__ = ["SearchSettings"]


@dataclass(frozen=True)
class SearchSettings:
    """Parameters of the γ bisection.

    Parameters
    ----------
    rtol : float
        Stop when ``(γ_hi − γ_lo) ≤ rtol·γ_hi``.
    max_trials : int
        Cap on the number of γ values tried.
    rollout_steps : int
        Length of the worst-case closed-loop rollouts (steps of the system).
    escape_factor : float
        Rollouts must stay inside Ω enlarged by this factor about its centre.
    return_fraction : float
        The final state must lie within this fraction of Ω's half-widths.
    starts : tuple of str
        Starts of the policy iteration tried for each γ, in order (see the module).
    """

    rtol: float = 1e-3
    max_trials: int = 60
    rollout_steps: int = 4000
    escape_factor: float = 10.0
    return_fraction: float = 0.05
    starts: tuple = ("continuation", "game-riccati", "initial")

    def __post_init__(self):
        if not (math.isfinite(self.rtol) and 0 < self.rtol < 1):
            raise ParameterError("rtol", self.rtol, "use a relative tolerance in (0, 1), "
                                 "e.g. 1e-3")
        if int(self.max_trials) != self.max_trials or self.max_trials < 2:
            raise ParameterError("max_trials", self.max_trials, "use an integer ≥ 2")
        if int(self.rollout_steps) != self.rollout_steps or self.rollout_steps < 1:
            raise ParameterError("rollout_steps", self.rollout_steps, "use an integer ≥ 1")
        if not (math.isfinite(self.escape_factor) and self.escape_factor >= 1):
            raise ParameterError("escape_factor", self.escape_factor, "use a number ≥ 1")
        if not (math.isfinite(self.return_fraction) and 0 < self.return_fraction <= 1):
            raise ParameterError("return_fraction", self.return_fraction,
                                 "use a fraction in (0, 1]")
        bad = [s for s in self.starts if s not in ("continuation", "game-riccati", "initial")]
        if bad or not self.starts:
            raise ParameterError("starts", list(self.starts),
                                 "use a non-empty subset of 'continuation', 'game-riccati', "
                                 "'initial'")

    def to_dict(self):
        return {"rtol": self.rtol, "max_trials": self.max_trials,
                "rollout_steps": self.rollout_steps, "escape_factor": self.escape_factor,
                "return_fraction": self.return_fraction, "starts": list(self.starts)}
