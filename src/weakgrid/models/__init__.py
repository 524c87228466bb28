"""weakgrid.models — the paper's design models (Section II), control laws and presets."""

from ..game.controller import load_controller as _load_controller
from . import export as _export  # noqa: F401  (registers the C emitter of (10))
from .design import UPQCDesignModel, gti_design_model, sg_design_model
from .policies import NonlinearInitialPolicy, lqr_policy
from .problem import TrainingProblem, load_preset, load_problem, preset_names, problem_from_dict


def load_controller(path):
    """Read a controller file written by ``weakgrid train`` (design models registered)."""
    return _load_controller(path)


__all__ = ["UPQCDesignModel", "gti_design_model", "sg_design_model", "NonlinearInitialPolicy",
           "lqr_policy", "TrainingProblem", "load_preset", "load_problem", "preset_names",
           "problem_from_dict", "load_controller"]
