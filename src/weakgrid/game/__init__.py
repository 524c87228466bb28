"""weakgrid.game — zero-sum games on discrete-time control-affine systems.

Knows nothing about power systems: control-affine systems, polynomial bases,
the two-loop HJI policy iteration and its exact special case, the LQ game.
"""

from .bases import PolynomialBasis, even_monomials, from_generator, paper_basis, quadratic_basis
from .controller import GameController, load_controller
from .cost import GameCost
from .errors import (
    ControlHessianError,
    ConvergenceError,
    GammaTooSmallError,
    InitialPolicyError,
    NonFiniteError,
    ParameterError,
    ShapeError,
    WeakgridError,
)
from .hji import IterationRecord, SolverSettings, closed_loop_spectral_radius, solve_hji
from .lq import LQGameSolution, LQRError, attenuation_limit, dlqr, solve_game_riccati
from .mesh import GridMesh, PointMesh, mesh_from_dict
from .policies import LinearPolicy
from .rollout import Rollout, rollout
from .system import ControlAffineSystem, FunctionSystem, LinearSystem, register_system

__all__ = [
    "PolynomialBasis", "even_monomials", "from_generator", "paper_basis", "quadratic_basis",
    "GameController", "load_controller", "GameCost", "ControlHessianError", "ConvergenceError",
    "GammaTooSmallError", "InitialPolicyError", "NonFiniteError", "ParameterError", "ShapeError",
    "WeakgridError", "IterationRecord", "SolverSettings", "closed_loop_spectral_radius",
    "solve_hji", "LQGameSolution", "LQRError", "attenuation_limit", "dlqr",
    "solve_game_riccati", "GridMesh", "PointMesh", "mesh_from_dict", "LinearPolicy", "Rollout",
    "rollout", "ControlAffineSystem", "FunctionSystem", "LinearSystem", "register_system",
]
