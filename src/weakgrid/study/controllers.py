"""The controllers a study compares: a registry ``kind → builder``.

=================  ==========================================================================
kind               what
=================  ==========================================================================
``hji``            the game-theoretic controller (24)/(23) trained on the design model derived
                   from the grid's operating point, with the study's design settings
``hji-bounded``    beyond the paper: the HJI controller trained with the UPQC rating as an
                   input bound ‖u‖ ≤ ū in the cost (constrained-input penalty; option:
                   ``u_bound`` to bound by another value than ``upqc.rating``)
``nonlinear-29``   the paper's initial nonlinear controller (29) (options: gain, phase)
``lqr``            discrete LQR of the design model's linearization (options: Q, R)
``pq``             conventional PQ control of a GTI (PID, paper's gains), no UPQC
``pss-only``       UPQC idle (u = 0): the grid as it is, the SG's PSS and governor alone
``none``           UPQC idle and the SG's stabilizer(s) out of service: no supplementary
                   control. Only the baseline machine's (the controlled machine if it is an
                   SG, else the SG the study follows, ``report.speed_of``: see
                   :func:`weakgrid.study.build.baseline_machine`) stabilizers are taken out,
                   whatever their model, before the grid is initialized: every other unit
                   keeps its own and the grid starts at equilibrium
``file``           a trained controller file (``weakgrid train``/``design``; option: path)
=================  ==========================================================================

A study names the controllers it compares in ``[controllers] compare``; options go in
``[controllers.NAME]`` (with ``kind = …`` when NAME is not itself a kind). A new kind is one
function ``builder(ctx) -> ControllerChoice`` added to :data:`CONTROLLER_KINDS` (and, if it
needs a grid variant other than the UPQC in service, an entry in :data:`VARIANT_OF`: a change
to the grid is made before its initialization, never after it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..game.errors import ParameterError
from ..models import NonlinearInitialPolicy, load_preset, lqr_policy, problem_from_dict

__all__ = ["CONTROLLER_KINDS", "VARIANT_OF", "ControllerChoice", "BuildContext",
           "controller_kind", "controller_variant", "make_controller", "design_problem",
           "train_hji"]


@dataclass
class ControllerChoice:
    """A controller ready for a grid.

    Attributes
    ----------
    name : str
    policy : callable or None
        ``u = policy(x)`` for the design state x = [ϕ̂, υ] (None: UPQC idle); a trained
        controller is the :class:`~weakgrid.game.controller.GameController` itself (its call
        is ``control``, its ``rows`` the batched form, :class:`weakgrid.study.law.StudyLaw`).
    info : dict
        Training record (weights, iterations, time) or parameters, for the report.
    """

    name: str
    policy: object
    info: dict = field(default_factory=dict)


@dataclass
class BuildContext:
    """What a controller builder receives."""

    study: object
    name: str
    options: dict
    design: object
    trained: object = None


def _options(study, name) -> dict:
    o = study.data["controllers"].get(name, {})
    return o if isinstance(o, dict) else {}


def controller_kind(study, name) -> str:
    """The kind of controller ``name`` of ``study`` (its ``kind`` option, else the name)."""
    return _options(study, name).get("kind", name)


def design_problem(study, design):
    """The training problem: the study's design settings with the derived model (10)."""
    ds = study.data["design"]
    over = {k: ds[k] for k in ("cost", "mesh", "basis", "initial_policy", "solver") if k in ds}
    base = load_preset(ds["settings"])
    if over:
        raw = dict(base.raw)
        raw.update(over)
        base = problem_from_dict(raw, source=f"{study.source} (design)")
    base.system = design
    ip = base.raw.get("initial_policy", {})
    if ip.get("kind") == "nonlinear-29":
        base.initial_policy = NonlinearInitialPolicy.on_design_model(design, ip["gain"],
                                                                     ip["phase"])
    elif ip.get("kind") == "linear":
        pass
    else:
        base.initial_policy = lqr_policy(design, float(ip.get("Q", 0.01)) * np.eye(2),
                                         float(ip.get("R", 1.0)) * np.eye(2))
    base.name = f"{study.name}-derived"
    base.published = {}
    return base


def train_hji(study, design, progress=None):
    """``(problem, GameController)``: the HJI controller trained on ``design``."""
    base = design_problem(study, design)
    return base, base.train(progress=progress)


def _hji(ctx):
    ctl = ctx.trained if ctx.trained is not None else train_hji(ctx.study, ctx.design)[1]
    return ControllerChoice(ctx.name, ctl, info={
        "weights": ctl.weights.tolist(), "iterations": ctl.iterations,
        "train_seconds": ctl.train_seconds})


_BOUNDED = {}   # (design settings, design model, bound) -> trained controller, per process


def _hji_bounded(ctx):
    from ..sweep.cache import canonical_json

    ubar = float(ctx.options.get("u_bound", ctx.study.data["upqc"]["rating"]))
    key = canonical_json([ctx.study.data["design"], ctx.design.to_dict(), ubar])
    ctl = _BOUNDED.get(key)
    if ctl is None:   # every run of one operating point shares one training
        ctl = _BOUNDED[key] = design_problem(ctx.study, ctx.design).with_rating(ubar).train()
    return ControllerChoice(ctx.name, ctl, info={
        "weights": ctl.weights.tolist(), "iterations": ctl.iterations,
        "train_seconds": ctl.train_seconds, "u_bound": ctl.cost.bound.to_dict()})


def _n29(ctx):
    pol = NonlinearInitialPolicy.on_design_model(ctx.design, float(ctx.options.get("gain", 125.0)),
                                                 float(ctx.options.get("phase", 0.069)))
    return ControllerChoice(ctx.name, pol, info=pol.to_dict())


def _lqr(ctx):
    pol = lqr_policy(ctx.design, float(ctx.options.get("Q", 0.01)) * np.eye(2),
                     float(ctx.options.get("R", 1.0)) * np.eye(2))
    return ControllerChoice(ctx.name, pol, info=pol.to_dict())


def _idle(ctx):
    return ControllerChoice(ctx.name, None)


def _file(ctx):
    from ..models import load_controller

    path = ctx.options.get("path")
    if not path:
        raise ParameterError(f"controllers.{ctx.name}.path", None, "give the controller file")
    ctl = load_controller(ctx.study.resolve(path))
    return ControllerChoice(ctx.name, ctl, info={"file": str(path)})


CONTROLLER_KINDS = {"hji": _hji, "hji-bounded": _hji_bounded, "nonlinear-29": _n29, "lqr": _lqr, "pq": _idle,
                    "pss-only": _idle, "none": _idle, "file": _file}
# grid variant a kind needs (default "upqc"): the PQ baseline has no UPQC; `none` has the UPQC
# and the baseline machine's stabilizers out of service (:data:`weakgrid.study.build.VARIANTS`)
VARIANT_OF = {"pq": "pq", "none": "no-pss"}


def controller_variant(study, name) -> str:
    """The grid variant controller ``name`` needs: ``"pq"`` (no UPQC) for the PQ baseline,
    ``"no-pss"`` (the baseline machine's stabilizers out) for ``none``, else ``"upqc"``."""
    return VARIANT_OF.get(controller_kind(study, name), "upqc")


def make_controller(study, name: str, design, trained=None) -> ControllerChoice:
    """Build controller ``name`` of ``study`` for the design model ``design``.

    ``trained`` may carry an already trained HJI controller (a GameController) so that one
    training serves every scenario with the same design model.
    """
    if name not in study.controllers:
        raise ParameterError("controller", name, f"not compared in this study; choose one of "
                             f"{study.controllers} (controllers.compare)")
    kind = controller_kind(study, name)
    if kind not in CONTROLLER_KINDS:
        raise ParameterError(f"controllers.{name}.kind", kind,
                             f"choose one of {sorted(CONTROLLER_KINDS)}")
    return CONTROLLER_KINDS[kind](BuildContext(study, name, _options(study, name), design,
                                               trained))
