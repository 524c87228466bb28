"""weakgrid.models — the paper's design models (Section II), control laws and presets.

Names are imported from their modules on first use (PEP 562), so that ``weakgrid --help`` and
a look-up of the preset names do not load SciPy. Importing the package registers the design
model (10) and its C emitter (NumPy only), as before.
"""

from . import design as _design  # noqa: F401  (registers the system kind "upqc-design")
from . import export as _export  # noqa: F401  (registers the C emitter of (10))

_WHERE = {
    "design": ("UPQCDesignModel", "gti_design_model", "sg_design_model"),
    "policies": ("NonlinearInitialPolicy", "lqr_policy"),
    "problem": ("TrainingProblem", "load_preset", "load_problem", "preset_names",
                "problem_from_dict"),
}
_MODULE_OF = {name: mod for mod, names in _WHERE.items() for name in names}


def load_controller(path):
    """Read a controller file written by ``weakgrid train`` (design models registered)."""
    from ..game.controller import load_controller as _load_controller

    return _load_controller(path)


def __getattr__(name):
    mod = _MODULE_OF.get(name)
    if mod is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f".{mod}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_MODULE_OF))


__all__ = ["UPQCDesignModel", "gti_design_model", "sg_design_model", "NonlinearInitialPolicy",
           "lqr_policy", "TrainingProblem", "load_preset", "load_problem", "preset_names",
           "problem_from_dict", "load_controller"]
