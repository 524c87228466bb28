"""The controllers the paper compares, built for a case's design model.

================  ========================================================``nonlinear-29``  the paper's initial nonlinear controller (29) (case 1)
``lqr``           discrete LQR of the design model's linearization (case 2's
                  initial policy), Q = 0.01·I, R = I
``pq``            conventional PQ control of the GTI (PID, paper's gains), no UPQC (case 1)
``pss-only``      UPQC idle (u = 0): the SG's PSS and governor alone
``none``          UPQC idle and the PSS out of service: no supplementary control
================  ===============================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..game.errors import ParameterError
from ..models import NonlinearInitialPolicy, load_preset, lqr_policy

__all__ = ["CONTROLLERS", "PAPER_SETTINGS", "ControllerChoice", "case_variant", "make_controller",
           "train_hji_for"]

CONTROLLERS = ("hji", "nonlinear-29", "lqr", "pq", "pss-only", "none", "hji-bounded")
# the paper's game settings (Q, R, P, γ, Ω, mesh, basis, initial policy) per case
PAPER_SETTINGS = {"case1-weak-grid": "case1-paper", "case2-lv-microgrid": "case2-paper"}


@dataclass
class ControllerChoice:
    """A controller ready for a case.

    Attributes
    ----------
    name : str
    policy : callable or None
        ``u = policy(x)`` for the design state x = [ϕ̂, υ] (None: UPQC idle).
    pss : bool
        Whether the SG's PSS stays in service.
    info : dict
        Training record (weights, iterations, time) or parameters, for the report.
    """

    name: str
    policy: object
    pss: bool = True
    info: dict = field(default_factory=dict)


def case_variant(name: str) -> str:
    """The case variant a controller needs: the PQ baseline has no UPQC."""
    return "pq" if name == "pq" else "upqc"


def train_hji_for(case_name: str, design, progress=None, u_bound=None):
    """Train the HJI controller on ``design`` with the paper's settings of the case.

    ``u_bound``: the UPQC rating ū (pu); the cost then bounds ‖u‖ ≤ ū, unless the
    settings set their own bound (:meth:`~weakgrid.models.TrainingProblem.with_rating`).
    """
    base = load_preset(PAPER_SETTINGS[case_name])
    base.system = design
    if base.raw.get("initial_policy", {}).get("kind") == "nonlinear-29":
        ip = base.raw["initial_policy"]
        base.initial_policy = NonlinearInitialPolicy.on_design_model(design, ip["gain"],
                                                                     ip["phase"])
    else:
        ip = base.raw.get("initial_policy", {})
        base.initial_policy = lqr_policy(design, float(ip.get("Q", 0.01)) * np.eye(2),
                                         float(ip.get("R", 1.0)) * np.eye(2))
    base.name = f"{case_name}-derived"
    base.published = {}
    if u_bound is not None and np.isfinite(u_bound):
        base = base.with_rating(float(u_bound))
    return base, base.train(progress=progress)


def make_controller(name: str, case_name: str, design, trained=None,
                    u_bound=None) -> ControllerChoice:
    """Build controller ``name`` for a case whose design model is ``design``.

    ``trained`` may carry an already trained HJI controller (a GameController) so
    that one training serves every scenario with the same design model.
    ``u_bound`` is the UPQC rating, used by ``hji-bounded``.
    """
    if name not in CONTROLLERS:
        raise ParameterError("controller", name, f"choose one of {CONTROLLERS}")
    if name == "hji-bounded":
        if u_bound is None or not np.isfinite(u_bound):
            raise ParameterError("controller", name, "needs the UPQC rating (Vmax) of the case")
        ctl = trained if trained is not None and trained.cost.bound is not None else \
            train_hji_for(case_name, design, u_bound=u_bound)[1]
        return ControllerChoice(name, ctl.control, info={
            "weights": ctl.weights.tolist(), "iterations": ctl.iterations,
            "train_seconds": ctl.train_seconds, "u_bound": ctl.cost.bound.to_dict()})
    if name == "hji":
        ctl = trained if trained is not None and trained.cost.bound is None else train_hji_for(case_name, design)[1]
        return ControllerChoice(name, ctl.control, info={
            "weights": ctl.weights.tolist(), "iterations": ctl.iterations,
            "train_seconds": ctl.train_seconds})
    if name == "nonlinear-29":
        pol = NonlinearInitialPolicy.on_design_model(design, 125.0, 0.069)
        return ControllerChoice(name, pol, info=pol.to_dict())
    if name == "lqr":
        pol = lqr_policy(design, 0.01 * np.eye(2), np.eye(2))
        return ControllerChoice(name, pol, info=pol.to_dict())
    if name == "pq":
        return ControllerChoice(name, None)
    if name == "pss-only":
        return ControllerChoice(name, None)
    return ControllerChoice(name, None, pss=False)
