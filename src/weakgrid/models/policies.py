"""Control laws of the paper: the initial nonlinear controller (29) and the LQR policy."""

from __future__ import annotations

import numpy as np

from ..game.errors import ParameterError
from ..game.lq import dlqr
from ..game.policies import LinearPolicy

__all__ = ["NonlinearInitialPolicy", "lqr_policy"]


class NonlinearInitialPolicy:
    """The paper's initial stabilizing controller (29), in its general form

        u1 = k·(−υ − ϕ̂)·cos(ϕ̂ + θ),   u2 = k·(−υ − ϕ̂)·sin(ϕ̂ + θ),
        k = gain·C/(B·Vs·τ)

    (the paper uses gain 125 and θ = 0.069 rad). On the calibrated design model,
    ``C/(B·Vs·τ) = (1+χ)/a``, i.e. ``k = gain/a`` for χ = 0.

    Parameters
    ----------
    coefficient : float
        ``k`` in pu voltage per rad (or per rad/s).
    phase : float
        θ, rad.
    gain : float, optional
        The dimensionless gain, for the record.
    """

    def __init__(self, coefficient, phase, gain=None):
        if not np.isfinite(coefficient) or coefficient <= 0:
            raise ParameterError("coefficient", coefficient, "must be positive", "(29)")
        if not np.isfinite(phase):
            raise ParameterError("phase", phase, "must be finite", "(29)")
        self.coefficient, self.phase, self.gain = float(coefficient), float(phase), gain

    @classmethod
    def on_design_model(cls, model, gain=125.0, phase=0.069, chi=0.0):
        """(29) with ``C/(B·Vs·τ) = (1+χ)/a`` taken from the design model."""
        return cls(gain * (1.0 + chi) / model.a, phase, gain)

    @classmethod
    def from_physical(cls, *, gain, C, B, Vs, tau, phase):
        return cls(gain * C / (B * Vs * tau), phase, gain)

    def __call__(self, x):  # (29)
        x = np.asarray(x, float)
        ph, up = x[..., 0], x[..., 1]
        s = self.coefficient * (-up - ph)
        return np.stack([s * np.cos(ph + self.phase), s * np.sin(ph + self.phase)], axis=-1)

    def to_dict(self):
        return {"kind": "nonlinear-29", "coefficient": self.coefficient, "phase": self.phase,
                "gain": self.gain}


def lqr_policy(system, Q, R, x0=None) -> LinearPolicy:
    """Discrete LQR of the linearization at ``x0`` (default the origin): ``u = −Kx``."""
    A, B, _ = system.linearize(x0)
    K, _, _ = dlqr(A, B, Q, R)
    pol = LinearPolicy(K, name="discrete LQR of the linearization at the origin")
    pol.Q = np.atleast_2d(np.asarray(Q, float)).tolist()
    pol.R = np.atleast_2d(np.asarray(R, float)).tolist()
    return pol
