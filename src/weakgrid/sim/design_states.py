"""Measurement mappings: measured signals of the grid -> the design state ``x = [ϕ̂, υ]``.

A digital UPQC controller does not see the design model's states directly: it measures
signals of its machine and computes ``x`` from them with constants of the operating point.
The two mappings of the paper (module :mod:`weakgrid.sim.controllers` measures their
signals in the simulator; :mod:`weakgrid.models.export_digital` emits them as C):

* :class:`GTIStateMap` (GTI with a dc link, (4)–(9))::

      ϕ̂ = ϕs − ϕs0                       ϕs: inverter internal-voltage angle w.r.t. the
                                          UPQC shunt-bus voltage [rad]
      υ  = τ·(Vc·Vc − Vc0·Vc0)/2          Vc: dc-link voltage [pu]

* :class:`SGStateMap` (SG, Remark 5)::

      ϕ̂ = (δ − θr) − (δ0 − θr0)          δ: rotor angle, θr: shunt-bus voltage angle, both
                                          in one reference frame [rad]
      υ  = (ω − 1)·ωs                     ω: rotor speed [pu], ωs = 2π·f [rad/s]

Each map lists its ``signals`` and ``constants`` as ``(name, unit, meaning)`` and evaluates
``x = map(y)`` with the same floating-point operations, in the same order, as the C code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import DataError

__all__ = ["GTIStateMap", "SGStateMap"]


@dataclass(frozen=True)
class GTIStateMap:
    """``[ϕs, Vc] -> [ϕ̂, υ]`` of a GTI (see the module docstring).

    Parameters
    ----------
    phi_s0 : float
        Equilibrium inverter angle w.r.t. the UPQC shunt bus [rad].
    tau : float
        Phase-control gain τ of (5) [1/(pu·s)].
    Vc0 : float
        dc-link voltage set-point [pu].
    """

    phi_s0: float
    tau: float
    Vc0: float

    machine = "gti"
    signals = (("phi_s", "rad", "inverter internal-voltage angle w.r.t. the UPQC shunt-bus "
                "voltage (the inverter's PLL angle)"),
               ("Vc", "pu", "dc-link voltage (pu of its base, Vc0 at the set-point)"))
    constants = (("phi_s0", "rad", "equilibrium inverter angle w.r.t. the shunt bus"),
                 ("tau", "1/(pu s)", "phase-control gain tau of (5)"),
                 ("Vc0", "pu", "dc-link voltage set-point"))

    def __post_init__(self):
        for k in ("phi_s0", "tau", "Vc0"):
            if not math.isfinite(getattr(self, k)):
                raise DataError("GTIStateMap", k, getattr(self, k), "give a finite number")

    def __call__(self, y) -> np.ndarray:
        phi_s, Vc = float(y[0]), float(y[1])
        return np.array([phi_s - self.phi_s0, self.tau * (Vc * Vc - self.Vc0 * self.Vc0) / 2.0])

    @staticmethod
    def map_rows(maps, Y) -> np.ndarray:
        """``maps[i](Y[i])`` for every row ``i`` of ``Y`` (``(n, 2)``) in one array operation
        (the same floating-point operations, element by element): ``(n, 2)``."""
        phi_s0, tau, Vc0 = (np.array([getattr(mp, k) for mp in maps]) for k in ("phi_s0", "tau", "Vc0"))
        Vc = Y[:, 1]
        return np.stack([Y[:, 0] - phi_s0, tau * (Vc * Vc - Vc0 * Vc0) / 2.0], axis=1)

    def values(self) -> dict:
        """The constants by name."""
        return {"phi_s0": self.phi_s0, "tau": self.tau, "Vc0": self.Vc0}


@dataclass(frozen=True)
class SGStateMap:
    """``[δ, θr, ω] -> [ϕ̂, υ]`` of a synchronous machine (see the module docstring).

    Parameters
    ----------
    angle0 : float
        ``δ0 − θr0``: the rotor angle w.r.t. the shunt-bus voltage at the operating point [rad].
    ws : float
        Synchronous speed ``2π·f`` [rad/s] (1.0 gives υ as the speed error in pu).
    """

    angle0: float
    ws: float

    machine = "sg"
    signals = (("delta", "rad", "rotor angle (in the frame of theta_r)"),
               ("theta_r", "rad", "angle of the UPQC shunt-bus voltage"),
               ("omega", "pu", "rotor speed (1 = synchronous)"))
    constants = (("angle0", "rad", "delta0 - theta_r0 at the operating point"),
                 ("ws", "rad/s", "synchronous speed 2 pi f"))

    def __post_init__(self):
        for k in ("angle0", "ws"):
            if not math.isfinite(getattr(self, k)):
                raise DataError("SGStateMap", k, getattr(self, k), "give a finite number")

    def __call__(self, y) -> np.ndarray:
        delta, theta_r, omega = float(y[0]), float(y[1]), float(y[2])
        return np.array([delta - theta_r - self.angle0, (omega - 1.0) * self.ws])

    @staticmethod
    def map_rows(maps, Y) -> np.ndarray:
        """``maps[i](Y[i])`` for every row ``i`` of ``Y`` (``(n, 3)``) in one array operation
        (the same floating-point operations, element by element): ``(n, 2)``."""
        angle0, ws = (np.array([getattr(mp, k) for mp in maps]) for k in ("angle0", "ws"))
        return np.stack([Y[:, 0] - Y[:, 1] - angle0, (Y[:, 2] - 1.0) * ws], axis=1)

    def values(self) -> dict:
        """The constants by name."""
        return {"angle0": self.angle0, "ws": self.ws}
