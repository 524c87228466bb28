"""weakgrid.game — zero-sum games on discrete-time control-affine systems.

Knows nothing about power systems: control-affine systems, polynomial bases,
the two-loop HJI policy iteration and its exact special case, the LQ game.
"""

# Lazy (PEP 562): a name is imported from its module on first use, so that importing one
# submodule (e.g. ``weakgrid.game.errors``) does not load SciPy and the solvers.
_WHERE = {
    "bases": ("PolynomialBasis", "even_monomials", "full_monomials", "from_generator",
              "paper_basis", "quadratic_basis"),
    "controller": ("GameController", "load_controller"),
    "cost": ("GameCost",),
    "errors": ("ControlHessianError", "ConvergenceError", "GammaTooSmallError",
               "InitialPolicyError", "NonFiniteError", "ParameterError", "ShapeError",
               "WeakgridError"),
    "hji": ("IterationRecord", "SolverSettings", "closed_loop_spectral_radius", "solve_hji"),
    "lq": ("LQGameSolution", "LQRError", "attenuation_limit", "dlqr", "solve_game_riccati"),
    "mesh": ("GridMesh", "PointMesh", "mesh_from_dict"),
    "policies": ("LinearPolicy",),
    "rollout": ("Rollout", "rollout"),
    "system": ("ControlAffineSystem", "FunctionSystem", "LinearSystem", "register_system"),
}
_MODULE_OF = {name: mod for mod, names in _WHERE.items() for name in names}


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


__all__ = [
    "PolynomialBasis", "even_monomials", "full_monomials", "from_generator", "paper_basis",
    "quadratic_basis",
    "GameController", "load_controller", "GameCost", "ControlHessianError", "ConvergenceError",
    "GammaTooSmallError", "InitialPolicyError", "NonFiniteError", "ParameterError", "ShapeError",
    "WeakgridError", "IterationRecord", "SolverSettings", "closed_loop_spectral_radius",
    "solve_hji", "LQGameSolution", "LQRError", "attenuation_limit", "dlqr",
    "solve_game_riccati", "GridMesh", "PointMesh", "mesh_from_dict", "LinearPolicy", "Rollout",
    "rollout", "ControlAffineSystem", "FunctionSystem", "LinearSystem", "register_system",
]
