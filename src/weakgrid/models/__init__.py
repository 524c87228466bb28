"""weakgrid.models — the paper's design models (Section II), control laws and presets.

Names are imported from their modules on first use (PEP 562), so that ``weakgrid --help`` and
a look-up of the preset names load nothing but the standard library. The design model (10)
and its C emitter are registered (:func:`_register`) at the first use of any name of the
package, and by :func:`load_controller`.
"""


def _register():
    from . import design, export  # noqa: F401  (system kind "upqc-design" and its C emitter)

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

    _register()
    return _load_controller(path)


def __getattr__(name):
    mod = _MODULE_OF.get(name)
    if mod is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    _register()
    value = getattr(importlib.import_module(f".{mod}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_MODULE_OF))


__all__ = ["UPQCDesignModel", "gti_design_model", "sg_design_model", "NonlinearInitialPolicy",
           "lqr_policy", "TrainingProblem", "load_preset", "load_problem", "preset_names",
           "problem_from_dict", "load_controller"]
